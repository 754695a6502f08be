// Where the master keeps the verified "sample" payloads of a job without a journal until the
// final merge (with one, the journal holds them): copied into large chunks, so the receive
// buffers are freed at once and reused instead of each message keeping a fresh ~150 kB
// allocation (its own mmap and munmap in glibc). A chunk is returned to the system as soon as
// every payload in it is released, so the merge, which releases them slab by slab, holds the
// payloads or the output, not both.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

namespace frep::farm {

class PayloadArena {
 public:
  // A payload held in the arena; releases it when destroyed (move-only).
  class Piece {
   public:
    Piece() = default;
    Piece(Piece&& o) noexcept { *this = std::move(o); }
    Piece& operator=(Piece&& o) noexcept;
    Piece(const Piece&) = delete;
    Piece& operator=(const Piece&) = delete;
    ~Piece() { reset(); }
    const char* data() const { return data_; }
    size_t size() const { return size_; }
    void reset();

   private:
    friend class PayloadArena;
    PayloadArena* arena_ = nullptr;
    size_t chunk_ = 0;
    const char* data_ = nullptr;
    size_t size_ = 0;
  };

  explicit PayloadArena(size_t chunkBytes = size_t(64) << 20) : chunkBytes_(chunkBytes) {}
  ~PayloadArena();
  PayloadArena(const PayloadArena&) = delete;
  PayloadArena& operator=(const PayloadArena&) = delete;

  // Copies the bytes in (safe from several threads at once; the copies run in parallel).
  Piece add(const void* data, size_t size);
  size_t chunksHeld() const;  // chunks not yet returned to the system (tests)

 private:
  struct Chunk {
    char* base = nullptr;  // nullptr once returned
    size_t bytes = 0, used = 0, live = 0;
  };
  void release(size_t chunk);
  size_t chunkBytes_;
  mutable std::mutex mutex_;
  std::vector<Chunk> chunks_;  // the last one takes new payloads
};

}  // namespace frep::farm
