#include "frep/farm/leaf_expand.h"

#include <array>
#include <cstring>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define FREP_LEAF_EXPAND_AVX512 1
#endif

namespace frep::farm {

namespace {

// For each byte of sign bits, the float sign bit of each of its 8 voxels (set where the bit is 0: -m).
constexpr auto kNegativeSigns = [] {
  std::array<std::array<uint32_t, 8>, 256> t{};
  for (size_t b = 0; b < 256; ++b)
    for (size_t i = 0; i < 8; ++i) t[b][i] = ((b >> i) & 1u) ? 0u : 0x80000000u;
  return t;
}();

// A byte (8 voxels) at a time: every voxel +-m from its sign bit (xor of a sign mask, which the
// compiler vectorises), then the active ones from the stream (a whole active row in one copy).
const char* expandBytewise(float* values, const uint64_t active[8], const uint64_t positive[8], uint32_t m,
                           const char* src) {
  for (int k = 0; k < 64; ++k) {
    const uint8_t signs = uint8_t(positive[k >> 3] >> (8 * (k & 7)));
    const uint8_t act = uint8_t(active[k >> 3] >> (8 * (k & 7)));
    float* v = values + 8 * k;
    uint32_t bits[8];
    for (int b = 0; b < 8; ++b) bits[b] = m ^ kNegativeSigns[signs][b];
    std::memcpy(v, bits, sizeof bits);
    if (act == 0xFF) {
      std::memcpy(v, src, 8 * sizeof(float));
      src += 8 * sizeof(float);
      continue;
    }
    for (unsigned rest = act; rest; rest &= rest - 1) {
      std::memcpy(v + __builtin_ctz(rest), src, sizeof(float));
      src += sizeof(float);
    }
  }
  return src;
}

#ifdef FREP_LEAF_EXPAND_AVX512
// 16 voxels a step: +-m blended by the sign bits, the active lanes loaded from the stream by an
// expanding load, which reads only as many values as the mask has bits (nothing past them).
__attribute__((target("avx512f,popcnt"))) const char* expandAvx512(float* values, const uint64_t active[8],
                                                                   const uint64_t positive[8], uint32_t m,
                                                                   const char* src) {
  const __m512i plus = _mm512_set1_epi32(int(m)), minus = _mm512_set1_epi32(int(m ^ 0x80000000u));
  for (int k = 0; k < 32; ++k) {
    const auto act = __mmask16(active[k >> 2] >> (16 * (k & 3)));
    const auto pos = __mmask16(positive[k >> 2] >> (16 * (k & 3)));
    const __m512i signs = _mm512_mask_blend_epi32(pos, minus, plus);
    _mm512_storeu_si512(values + 16 * k, _mm512_mask_expandloadu_epi32(signs, act, src));
    src += sizeof(float) * size_t(_mm_popcnt_u32(act));
  }
  return src;
}

__attribute__((target("popcnt"))) size_t countWithPopcnt(const uint64_t mask[8]) {
  size_t n = 0;
  for (int w = 0; w < 8; ++w) n += size_t(_mm_popcnt_u64(mask[w]));
  return n;
}

bool hasPopcnt() {
  static const bool has = __builtin_cpu_supports("popcnt");
  return has;
}

bool hasAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("popcnt");
  return has;
}
#endif

}  // namespace

size_t countVoxels(const uint64_t mask[8]) {
#ifdef FREP_LEAF_EXPAND_AVX512
  if (hasPopcnt()) return countWithPopcnt(mask);
#endif
  size_t n = 0;
  for (int w = 0; w < 8; ++w) n += size_t(__builtin_popcountll(mask[w]));
  return n;
}

std::vector<LeafExpansion> leafExpansions() {
  std::vector<LeafExpansion> ways{LeafExpansion::Bytewise};
#ifdef FREP_LEAF_EXPAND_AVX512
  if (hasAvx512()) ways.push_back(LeafExpansion::Avx512);
#endif
  return ways;
}

const char* expandCompactLeafWith(LeafExpansion how, float* values, const uint64_t active[8],
                                  const uint64_t positive[8], uint32_t m, const char* stream) {
#ifdef FREP_LEAF_EXPAND_AVX512
  if (how == LeafExpansion::Avx512 && hasAvx512()) return expandAvx512(values, active, positive, m, stream);
#endif
  return expandBytewise(values, active, positive, m, stream);
}

const char* expandCompactLeaf(float* values, const uint64_t active[8], const uint64_t positive[8], uint32_t m,
                              const char* stream) {
  static const LeafExpansion best = leafExpansions().back();
  return expandCompactLeafWith(best, values, active, positive, m, stream);
}

}  // namespace frep::farm
