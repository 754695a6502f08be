// Internal to io/src: a little-endian byte sink streamed to a file, shared by the mesh writers.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "frep/io/error.h"

namespace frep::io::detail {

// Little-endian bytes streamed to the file through a 1 MiB buffer: the file is never held in
// memory whole (a 512^3 mesh's PLY is ~0.4 GB), so writing adds nothing proportional to it.
class Bytes {
 public:
  explicit Bytes(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "wb")) {
    if (!file_) throw ioError("cannot write " + path);
    buf_.reserve(kChunk + 256);
  }
  ~Bytes() {
    if (file_) std::fclose(file_);
  }
  Bytes(const Bytes&) = delete;
  Bytes& operator=(const Bytes&) = delete;

  void u8(uint8_t v) { put(char(v)); }
  void u16(uint16_t v) {
    for (int i = 0; i < 2; ++i) put(char((v >> (8 * i)) & 0xff));
  }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) put(char((v >> (8 * i)) & 0xff));
  }
  void f32(float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    u32(v);
  }
  void text(const std::string& s) { text(s.data(), s.size()); }
  void text(const char* s, size_t n) {
    buf_.insert(buf_.end(), s, s + n);
    if (buf_.size() >= kChunk) drain();
  }
  void close() {
    drain();
    FILE* f = file_;
    file_ = nullptr;
    if (!ok_ || std::fclose(f) != 0) throw ioError("cannot write " + path_);
  }

 private:
  static constexpr size_t kChunk = size_t(1) << 20;
  void put(char c) {
    buf_.push_back(c);
    if (buf_.size() >= kChunk) drain();
  }
  void drain() {
    if (!buf_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), file_) != buf_.size()) ok_ = false;
    buf_.clear();
  }
  std::string path_;
  FILE* file_;
  std::vector<char> buf_;
  bool ok_ = true;
};

// One line, no control characters (headers are line-based).
inline std::string oneLine(const std::string& s) {
  std::string r = s;
  for (char& c : r)
    if (c == '\n' || c == '\r') c = ' ';
  return r;
}

}  // namespace frep::io::detail
