#include "frep/farm/allocator_tuning.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>

namespace frep::farm {

namespace {

constexpr size_t kHugePage = size_t(2) << 20;

// The heap's room (glibc's top pad): one extension of the break covers a brick's or a mesh
// merge's working set, so the one madvise below covers what follows.
constexpr size_t kHeapRoom = size_t(1) << 30;

bool applied = false;

}  // namespace

void adviseHugePages(void* data, size_t bytes) {
  const uintptr_t begin = reinterpret_cast<uintptr_t>(data);
  const uintptr_t from = (begin + kHugePage - 1) & ~(kHugePage - 1), to = (begin + bytes) & ~(kHugePage - 1);
  if (to > from) madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);
}

void applyAllocatorPolicy() {
  constexpr int kBytes = 256 << 20;  // above any one vector of a brick at the job limits
  mallopt(M_MMAP_THRESHOLD, kBytes);
  mallopt(M_TRIM_THRESHOLD, kBytes);
  // Transparent huge pages for the heap: every thread allocates from the main arena (the
  // others are separate mappings nobody advises), the break is moved once by kHeapRoom
  // (address space only: pages are committed when touched), and that range is advised.
  // Fresh memory then faults in 2 MiB at a time instead of 4 KiB: a fault costs ~10 us on a
  // paravirtualised machine, ~0.5 s of a 256^3 mesh job (docs/mesh.md). With the kernel's
  // THP mode "never" the advice is ignored; a failure only means 4 KiB pages, as before.
  mallopt(M_ARENA_MAX, 1);
  mallopt(M_TOP_PAD, int(kHeapRoom));
  char* const before = static_cast<char*>(sbrk(0));
  void* volatile block = std::malloc(kHugePage);  // extends the break by kHeapRoom (volatile: the
  std::free(block);                               // pair is not elided; freed, the room stays)
  char* const after = static_cast<char*>(sbrk(0));
  if (after > before) adviseHugePages(before, size_t(after - before));
  applied = true;
}

bool allocatorPolicyApplied() { return applied; }

}  // namespace frep::farm
