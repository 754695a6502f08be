// The allocator policy of the processes that compute bricks (frep-worker) and of the masters
// (frep mesh, frep sample).
#pragma once

#include <cstddef>

namespace frep::farm {

// The policy, set once before the work starts. Freed memory stays in the process instead of
// going back to the kernel after every brick and block: glibc serves blocks above its mmap
// threshold (at most 32 MiB, adapted at run time) by fresh mappings and trims the heap's top
// above 128 KiB, so each brick's vectors (mesh pieces, quadrics, samples) were page-faulted in
// again. Every thread allocates from the main arena, and the heap is advised for transparent
// huge pages (adviseHugePages), so fresh memory faults in 2 MiB at a time. At 256^3 the default
// mesh took 130,000 faults before, 25,000 after (docs/mesh.md). What is freed stays reusable
// until exit or an explicit malloc_trim, which would also drop the heap's huge-page advice (so
// the master's mesh merge does not trim where the policy is applied).
void applyAllocatorPolicy();
// Whether this process called applyAllocatorPolicy.
bool allocatorPolicyApplied();

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with transparent huge
// pages (madvise MADV_HUGEPAGE; a hint, ignored where unsupported). For a large buffer filled
// once, before its first write: on this paravirtualised machine the first touch of fresh memory
// costs ~12 us per 4 KiB page (0.35 GB/s), in 2 MiB pages 0.5-0.9 GB/s, or ~10 GB/s when they
// were freed shortly before (docs/farm.md, "Throughput"). applyAllocatorPolicy advises the heap so.
void adviseHugePages(void* data, size_t bytes);

}  // namespace frep::farm
