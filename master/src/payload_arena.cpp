#include "frep/master/payload_arena.h"

#include <sys/mman.h>

#include <algorithm>
#include <cstring>
#include <new>

namespace frep::farm {

namespace {
char* mapChunk(size_t bytes) {
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  return static_cast<char*>(p);
}
}  // namespace

PayloadArena::~PayloadArena() {
  for (Chunk& c : chunks_)
    if (c.base) ::munmap(c.base, c.bytes);
}

PayloadArena::Piece& PayloadArena::Piece::operator=(Piece&& o) noexcept {
  if (this != &o) {
    reset();
    arena_ = o.arena_, chunk_ = o.chunk_, data_ = o.data_, size_ = o.size_;
    o.arena_ = nullptr, o.data_ = nullptr, o.size_ = 0;
  }
  return *this;
}

void PayloadArena::Piece::reset() {
  if (arena_) arena_->release(chunk_);
  arena_ = nullptr, data_ = nullptr, size_ = 0;
}

PayloadArena::Piece PayloadArena::add(const void* data, size_t size) {
  Piece piece;
  char* at = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (chunks_.empty() || !chunks_.back().base || chunks_.back().bytes - chunks_.back().used < size) {
      // A payload bigger than a chunk gets a chunk of its own size (page-rounded).
      const size_t bytes = std::max(chunkBytes_, (size + 4095) & ~size_t(4095));
      if (!chunks_.empty() && chunks_.back().base && chunks_.back().live == 0) {  // every payload in it released
        ::munmap(chunks_.back().base, chunks_.back().bytes);
        chunks_.back().base = nullptr;
      }
      chunks_.push_back(Chunk{mapChunk(bytes), bytes, 0, 0});
    }
    Chunk& c = chunks_.back();
    at = c.base + c.used;
    c.used += (size + 63) & ~size_t(63);  // cache-line aligned payloads
    c.used = std::min(c.used, c.bytes);
    ++c.live;
    piece.arena_ = this;
    piece.chunk_ = chunks_.size() - 1;
  }
  if (size) std::memcpy(at, data, size);
  piece.data_ = at;
  piece.size_ = size;
  return piece;
}

void PayloadArena::release(size_t chunk) {
  std::lock_guard<std::mutex> lock(mutex_);
  Chunk& c = chunks_[chunk];
  if (--c.live > 0 || chunk + 1 == chunks_.size()) return;  // the last chunk still takes payloads
  ::munmap(c.base, c.bytes);
  c.base = nullptr;
}

size_t PayloadArena::chunksHeld() const {
  std::lock_guard<std::mutex> lock(mutex_);
  size_t n = 0;
  for (const Chunk& c : chunks_) n += c.base != nullptr;
  return n;
}

}  // namespace frep::farm
