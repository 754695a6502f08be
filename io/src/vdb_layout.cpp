// The .vdb file's layout, checked before OpenVDB parses anything; see vdb_layout.h.
#include "vdb_layout.h"

#include <openvdb/version.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "frep/io/error.h"
#include "vdb_checksum.h"

namespace frep::io {
namespace {

// The file's layout checked before OpenVDB sees it (OpenVDB trusts every length it reads and
// reads past the end of a truncated file): the header, the file's metadata, each grid's
// descriptor and metadata, every length bounded by what is left, the grids' offsets increasing
// and the last grid ending exactly at the end of the file. Throws Error(kExitIoError).
class LayoutCheck {
 public:
  LayoutCheck(const std::string& path, std::string bytes) : path_(path), b_(std::move(bytes)) {}

  // True when the file carries frep sample's seal (and it matched).
  bool run() {
    if (u32(4) != 0 || u32(0) != 0x56444220) fail("not a VDB file (bad magic number)");
    pos_ = 8;
    const uint32_t version = u32();
    if (version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION || version > openvdb::OPENVDB_FILE_VERSION)
      fail("file format version " + std::to_string(version) + " is not supported (" +
           std::to_string(openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) + " to " +
           std::to_string(openvdb::OPENVDB_FILE_VERSION) + ")");
    skip(8);  // library version
    if (byte() != 1) fail("the file has no grid offsets (a stream, not a file)");
    skip(36);  // UUID
    metaMap(b_.size());
    const uint32_t grids = u32();
    if (grids > remaining() / 36) fail("declares " + std::to_string(grids) + " grids");
    for (uint32_t g = 0; g < grids; ++g) {
      string();  // name
      string();  // type
      string();  // instance parent
      const uint64_t gridPos = u64(), blockPos = u64(), endPos = u64();
      if (gridPos != pos_ || blockPos < gridPos || endPos < blockPos || endPos > b_.size())
        fail("grid " + std::to_string(g) + "'s offsets " + std::to_string(gridPos) + ", " + std::to_string(blockPos) +
             ", " + std::to_string(endPos) + " do not fit in the file's " + std::to_string(b_.size()) +
             " bytes (truncated or damaged)");
      skip(4);  // compression flags
      metaMap(blockPos);
      pos_ = endPos;
    }
    if (pos_ != b_.size())
      fail(std::to_string(b_.size() - pos_) + " bytes after the last grid (damaged, or not written by OpenVDB)");
    // frep sample's files are sealed. OpenVDB's tools keep the seal's metadata when they rewrite
    // a grid but stamp their own UUID: a seal that no longer matches under frep's UUID is damage
    // in place, refused; under another UUID it marks a foreign grid (vdb_checksum.h).
    mismatch_ = checksumAt_ && b_.compare(checksumAt_, kChecksumDigits, vdbChecksum(b_, checksumAt_)) != 0;
    if (mismatch_ &&
        b_.compare(kVdbUuidAt, kVdbUuidLength, vdbUuidForChecksum(b_.substr(checksumAt_, kChecksumDigits))) == 0)
      fail("the contents do not match " + std::string(kGridChecksumKey) +
           " and the header is still frep sample's (the file is damaged)");
    return checksumAt_ != 0 && !mismatch_;
  }
  bool mismatch() const { return mismatch_; }

 private:
  [[noreturn]] void fail(const std::string& why) const { throw ioError("cannot read VDB '" + path_ + "': " + why); }
  uint64_t remaining() const { return b_.size() - pos_; }
  void need(uint64_t n) const {
    if (n > remaining())
      fail("truncated at byte " + std::to_string(b_.size()) + " (needs " + std::to_string(n) + " more bytes at " +
           std::to_string(pos_) + ")");
  }
  void skip(uint64_t n) {
    need(n);
    pos_ += n;
  }
  uint32_t u32(size_t at) const {
    uint32_t v = 0;
    if (at + 4 <= b_.size()) std::memcpy(&v, b_.data() + at, 4);
    return v;
  }
  uint32_t u32() {
    need(4);
    uint32_t v = u32(pos_);
    pos_ += 4;
    return v;
  }
  uint64_t u64() {
    need(8);
    uint64_t v;
    std::memcpy(&v, b_.data() + pos_, 8);
    pos_ += 8;
    return v;
  }
  uint8_t byte() {
    need(1);
    return uint8_t(b_[pos_++]);
  }
  std::string string() {
    const uint32_t n = u32();
    need(n);
    pos_ += n;
    return b_.substr(pos_ - n, n);
  }
  // OpenVDB's MetaMap: count, then (name, type name, size, value) each; within [pos_, end).
  void metaMap(uint64_t end) {
    const uint32_t count = u32();
    for (uint32_t i = 0; i < count; ++i) {
      const std::string name = string(), type = string();
      const uint32_t size = u32();
      if (name == kGridChecksumKey && type == "string" && size == kChecksumDigits) checksumAt_ = pos_;
      skip(size);
      if (pos_ > end) fail("metadata runs past its grid (damaged)");
    }
  }

  std::string path_, b_;
  uint64_t pos_ = 0;
  uint64_t checksumAt_ = 0;  // the checksum's digits, if the file has them
  bool mismatch_ = false;
};

}  // namespace

VdbLayout checkVdbLayout(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw ioError("cannot read VDB '" + path + "': " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw ioError("cannot read VDB '" + path + "': not a regular file");
  if (uint64_t(st.st_size) > kMaxVdbBytes)
    throw ioError("cannot read VDB '" + path + "': " + std::to_string(st.st_size) + " bytes, more than the " +
                  std::to_string(kMaxVdbBytes >> 30) + " GiB frep mesh reads");
  std::ifstream in(path, std::ios::binary);
  std::string bytes(size_t(st.st_size), '\0');
  if (!in.read(bytes.data(), std::streamsize(bytes.size())) || in.peek() != EOF)
    throw ioError("cannot read VDB '" + path + "': the file changed or could not be read to its end");
  VdbLayout layout;
  layout.bytes = uint64_t(st.st_size);
  layout.contentHash = vdbChecksum(bytes, bytes.size());  // no digits counted as '0'
  LayoutCheck check(path, std::move(bytes));
  layout.sealed = check.run();
  layout.sealMismatch = check.mismatch();
  return layout;
}

}  // namespace frep::io
