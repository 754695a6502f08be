// The layout of a .vdb file checked before OpenVDB sees it (OpenVDB trusts every length it reads):
// a regular file of at most 16 GiB read to its end, the header, the metadata, each grid's
// descriptor and offsets bounded by the file, and whether frep sample's seal (vdb_checksum.h)
// still matches when the file has one. The .vdb reader and the .vdb fuzz target share it.
#pragma once

#include <cstdint>
#include <string>

namespace frep::io {

constexpr uint64_t kMaxVdbBytes = uint64_t(16) << 30;  // frep mesh reads at most 16 GiB

struct VdbLayout {
  uint64_t bytes = 0;   // the file's size
  bool sealed = false;  // it carries frep_grid_checksum and its contents match it
  // It carries frep_grid_checksum but its contents no longer match: rewritten by another tool
  // (vdb_tool, pyopenvdb keep the metadata) or damaged; read as a foreign grid, with a note.
  bool sealMismatch = false;
  std::string contentHash;  // vdbChecksum of the whole file but the UUID: its identity in provenance
};

// Throws Error(kExitIoError) naming the path and what is wrong.
VdbLayout checkVdbLayout(const std::string& path);

}  // namespace frep::io
