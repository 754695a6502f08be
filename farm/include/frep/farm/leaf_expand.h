// Expanding a compact FRB2 leaf (docs/farm.md, "The FRB2 sample payload"): every inactive voxel
// holds +m or -m by its bit in `positive`, the active ones take the next values of the stream,
// in voxel order. The decoders (worker/brick.cpp) check the stream's length first.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frep::farm {

// Writes the 512 values of a leaf to `values` (m is a float's bits): voxel i is m where bit i of
// `positive` is set and m with its sign bit flipped where it is not, or, where bit i of
// `active` is set, the next 4 bytes of `stream`. Returns the stream past what it used
// (4 bytes per active voxel).
const char* expandCompactLeaf(float* values, const uint64_t active[8], const uint64_t positive[8], uint32_t m,
                              const char* stream);

// The number of bits set in a leaf's mask (its active voxels: the values a compact leaf's stream
// holds), with the CPU's popcnt instruction when it has one (the build targets plain x86-64,
// where __builtin_popcountll is a library call: 2% of the master's CPU, twice per leaf).
size_t countVoxels(const uint64_t mask[8]);

// The ways it can run on this CPU, slowest first (expandCompactLeaf takes the last): 8 voxels
// a step, or AVX-512's expanding loads (16 voxels an instruction). Each gives the same bits.
enum class LeafExpansion { Bytewise, Avx512 };
std::vector<LeafExpansion> leafExpansions();
const char* expandCompactLeafWith(LeafExpansion how, float* values, const uint64_t active[8],
                                  const uint64_t positive[8], uint32_t m, const char* stream);

}  // namespace frep::farm
