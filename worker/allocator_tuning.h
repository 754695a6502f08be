// The allocator policy of the processes that compute bricks (frep-worker) and merge meshes (frep mesh).
#pragma once

namespace frep::farm {

// Keeps freed memory in the process instead of handing it back to the kernel after every
// brick and block: glibc serves blocks above its mmap threshold (at most 32 MiB, adapted at
// run time) by fresh mappings and trims the heap's top above 128 KiB, so each brick's
// vectors (mesh pieces, quadrics, samples) are page-faulted in again; at 256^3 that was
// 150,000 faults and ~10% of a mesh job's CPU (docs/mesh.md). The peak resident size is
// unchanged; what is freed stays reusable until exit or an explicit malloc_trim (the master's
// merge calls it to keep its memory flat).
void keepFreedMemory();

}  // namespace frep::farm
