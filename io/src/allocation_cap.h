// A cap on the size of any single allocation made by the current thread while an AllocationCap
// is alive: a larger request throws std::bad_alloc before any memory is touched. The .vdb reader
// holds one while OpenVDB parses a file, since OpenVDB allocates whatever sizes the file states
// (a damaged or crafted compressed-block size of 2^58 bytes, found by tests/fuzz's vdb target)
// and neither the layout checks nor the seal can see inside the grids' compressed data.
#pragma once

#include <cstddef>

namespace frep::io {

class AllocationCap {
 public:
  explicit AllocationCap(size_t maxBytes);
  ~AllocationCap();
  AllocationCap(const AllocationCap&) = delete;
  AllocationCap& operator=(const AllocationCap&) = delete;

 private:
  size_t previous_;
};

}  // namespace frep::io
