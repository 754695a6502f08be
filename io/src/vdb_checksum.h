// The checksum frep sample seals into its .vdb files and frep mesh verifies before OpenVDB parses
// anything (OpenVDB's reader trusts the file: a flipped bit in the topology can corrupt its heap).
// The grid's metadata entry frep_grid_checksum (a 16-hex-digit string) holds the FNV-1a 64 hash
// of every byte of the file but the header's UUID (the writer derives that from the rest),
// computed with those 16 digits as '0'. The header's format version is covered: OpenVDB parses a
// grid by the version it is told, so an edited version alone makes it read garbage.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace frep::io {

inline constexpr const char* kGridChecksumKey = "frep_grid_checksum";
constexpr size_t kVdbUuidAt = 21, kVdbUuidLength = 36;  // after magic, versions and offsets flag
constexpr size_t kChecksumDigits = 16;

// The hash of the bytes outside the UUID, the checksum's digits at `digitsAt` counted as '0'.
inline std::string vdbChecksum(const std::string& bytes, size_t digitsAt) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (i == kVdbUuidAt) i += kVdbUuidLength;
    if (i >= bytes.size()) break;
    const unsigned char c = i >= digitsAt && i < digitsAt + kChecksumDigits ? '0' : uint8_t(bytes[i]);
    h = (h ^ c) * 0x100000001b3ULL;
  }
  char hex[kChecksumDigits + 1];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

// The header's UUID frep sample writes: derived from the seal's 16 digits (OpenVDB stamps a random
// one into every file it writes). A file whose seal no longer matches but whose UUID is still the
// one its digits give kept frep's header: damaged in place, refused. A tool that rewrote the file
// (vdb_tool, pyopenvdb keep the seal's metadata) stamped its own UUID: a foreign grid, read.
inline std::string vdbUuidForChecksum(const std::string& digits) {
  uint64_t h1 = 1469598103934665603ULL, h2 = 0x9e3779b97f4a7c15ULL;
  for (const char c : digits) {
    h1 = (h1 ^ uint8_t(c)) * 1099511628211ULL;
    h2 = (h2 ^ uint8_t(c)) * 0x100000001b3ULL + (h2 >> 29);
  }
  char uuid[40];
  std::snprintf(uuid, sizeof uuid, "%08llx-%04llx-%04llx-%04llx-%012llx", (unsigned long long)(h1 >> 32),
                (unsigned long long)((h1 >> 16) & 0xffff), (unsigned long long)(h1 & 0xffff),
                (unsigned long long)(h2 >> 48), (unsigned long long)(h2 & 0xffffffffffffULL));
  return std::string(uuid, kVdbUuidLength);
}

}  // namespace frep::io
