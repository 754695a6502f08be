// The allocator policy of the processes that compute bricks (frep-worker) and merge meshes (frep mesh).
#pragma once

#include <cstddef>

namespace frep::farm {

// Keeps freed memory in the process instead of handing it back to the kernel after every
// brick and block: glibc serves blocks above its mmap threshold (at most 32 MiB, adapted at
// run time) by fresh mappings and trims the heap's top above 128 KiB, so each brick's
// vectors (mesh pieces, quadrics, samples) are page-faulted in again; at 256^3 that was
// 150,000 faults and ~10% of a mesh job's CPU (docs/mesh.md). The peak resident size is
// unchanged; what is freed stays reusable until exit or an explicit malloc_trim (the master's
// merge calls it to keep its memory flat).
void keepFreedMemory();

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with transparent huge
// pages (madvise MADV_HUGEPAGE; a hint, ignored where unsupported). For a large buffer filled
// once, before its first write: on this paravirtualised machine the first touch of fresh memory
// costs ~12 us per 4 KiB page (0.35 GB/s), in 2 MiB pages 0.5-0.9 GB/s, or ~10 GB/s when they
// were freed shortly before (docs/farm.md, "Throughput"). keepFreedMemory advises the heap so.
void adviseHugePages(void* data, size_t bytes);

}  // namespace frep::farm
