// The global allocation functions, replaced ([new.delete], replaceable) so that AllocationCap can
// refuse oversized requests from code frepfarm does not control (OpenVDB's readers). Everything
// else allocates as before: malloc/free underneath, and no cap outside an AllocationCap.
#include "allocation_cap.h"

#include <cstdlib>
#include <new>

namespace {
thread_local size_t tCap = ~size_t(0);

void* allocate(size_t n) {
  if (n > tCap) throw std::bad_alloc();
  for (;;) {
    if (void* p = std::malloc(n ? n : 1)) return p;
    std::new_handler h = std::get_new_handler();
    if (!h) throw std::bad_alloc();
    h();
  }
}
}  // namespace

namespace frep::io {
AllocationCap::AllocationCap(size_t maxBytes) : previous_(tCap) { tCap = maxBytes < tCap ? maxBytes : tCap; }
AllocationCap::~AllocationCap() { tCap = previous_; }
}  // namespace frep::io

void* operator new(size_t n) { return allocate(n); }
void* operator new[](size_t n) { return allocate(n); }
void* operator new(size_t n, const std::nothrow_t&) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](size_t n, const std::nothrow_t&) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
