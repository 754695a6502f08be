// crc32Of (crc32.h): zlib's CRC-32 (polynomial 0x04C11DB7, bit-reflected, initial and final
// value all ones), the checksum of every result payload and journal record. On a CPU with
// carry-less multiplication (PCLMULQDQ) the bulk of the buffer is folded 64 bytes a step (2.3x
// zlib's table-driven speed here), with AVX-512's VPCLMULQDQ 256 bytes a step (8x); what
// remains (the last < 16 bytes and the folded 16) goes through zlib, so every path gives zlib's
// value: the wire and the journals are unchanged. A file of its own so that builds needing
// only the checksum (the journal's fuzz target) do not pull in the core.
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "frep/farm/crc32.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define FREP_CRC32_CLMUL 1
#endif

namespace frep::farm {

namespace {

uint32_t crc32Zlib(uLong c, const unsigned char* p, size_t size) {
  while (size > 0) {
    const uInt n = size > (1u << 30) ? (1u << 30) : uInt(size);
    c = crc32(c, p, n);
    p += n;
    size -= n;
  }
  return uint32_t(c);
}

#ifdef FREP_CRC32_CLMUL
// Folding (the CRC's linearity over GF(2)): a 128-bit block X of the message followed by D more
// bits contributes X(x) * x^D mod P to the CRC, which two 64 x 32-bit carry-less products give
// with the constants x^(D+63) mod P and x^(D-1) mod P (the -1: a product of two bit-reflected
// operands comes out shifted by one degree). Bit-reflected as the CRC register is: bit 31 - d
// holds the coefficient of x^d.
constexpr uint32_t xPowModP(unsigned e) {
  uint32_t r = 0x80000000u;  // x^0
  for (; e > 0; --e) r = (r >> 1) ^ ((r & 1u) ? 0xEDB88320u : 0u);  // times x, reduced mod P
  return r;
}

// The two constants of a fold across D bits, each in its 64-bit lane (degree d at bit 63 - d).
struct FoldConstants {
  uint64_t low, high;  // for X's first 64 bits (the higher degrees), for its last 64
};
constexpr FoldConstants foldAcross(unsigned bits) {
  return {uint64_t(xPowModP(bits + 63)) << 32, uint64_t(xPowModP(bits - 1)) << 32};
}

__attribute__((target("pclmul,sse4.1"))) inline __m128i fold(__m128i x, __m128i k) {
  return _mm_xor_si128(_mm_clmulepi64_si128(x, k, 0x00), _mm_clmulepi64_si128(x, k, 0x11));
}

__attribute__((target("pclmul,sse4.1"))) inline __m128i constants(const FoldConstants& k) {
  return _mm_set_epi64x(int64_t(k.high), int64_t(k.low));
}

__attribute__((target("pclmul,sse4.1"))) inline __m128i load(const unsigned char* p) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
}

// The message so far folded into `a` (the 16 bytes before p), then the rest: 16 bytes a step,
// and the last < 16 bytes after `a`'s own CRC from a zero register, through zlib.
__attribute__((target("pclmul,sse4.1"))) uint32_t finish(__m128i a, const unsigned char* p, size_t size) {
  const __m128i by128 = constants(foldAcross(128));
  for (; size >= 16; p += 16, size -= 16) a = _mm_xor_si128(fold(a, by128), load(p));
  unsigned char folded[16];
  std::memcpy(folded, &a, sizeof folded);
  const uLong c = crc32(0xFFFFFFFFul, folded, sizeof folded);  // zlib inverts: register 0
  return crc32Zlib(c, p, size);
}

// size >= 64. Four blocks of 16 bytes in flight, each folded across the 512 bits to its next.
__attribute__((target("pclmul,sse4.1"))) uint32_t crc32Clmul(const unsigned char* p, size_t size) {
  const __m128i by512 = constants(foldAcross(512)), by128 = constants(foldAcross(128));
  // The initial register (all ones) enters as an xor into the first 32 bits of the message.
  __m128i a0 = _mm_xor_si128(load(p), _mm_cvtsi32_si128(-1));
  __m128i a1 = load(p + 16), a2 = load(p + 32), a3 = load(p + 48);
  p += 64, size -= 64;
  for (; size >= 64; p += 64, size -= 64) {
    a0 = _mm_xor_si128(fold(a0, by512), load(p));
    a1 = _mm_xor_si128(fold(a1, by512), load(p + 16));
    a2 = _mm_xor_si128(fold(a2, by512), load(p + 32));
    a3 = _mm_xor_si128(fold(a3, by512), load(p + 48));
  }
  a1 = _mm_xor_si128(fold(a0, by128), a1);
  a2 = _mm_xor_si128(fold(a1, by128), a2);
  return finish(_mm_xor_si128(fold(a2, by128), a3), p, size);
}

// The same with AVX-512's VPCLMULQDQ (four 16-byte blocks a register, each lane folded on its
// own): size >= 256, four registers in flight, folded across 2048 bits. About 3x crc32Clmul.
__attribute__((target("avx512f,vpclmulqdq"))) inline __m512i fold4(__m512i x, __m512i k) {
  return _mm512_xor_si512(_mm512_clmulepi64_epi128(x, k, 0x00), _mm512_clmulepi64_epi128(x, k, 0x11));
}

__attribute__((target("avx512f"))) inline __m512i constants4(const FoldConstants& k) {
  const auto lo = int64_t(k.low), hi = int64_t(k.high);
  return _mm512_set_epi64(hi, lo, hi, lo, hi, lo, hi, lo);
}

__attribute__((target("avx512f,vpclmulqdq,pclmul,sse4.1"))) uint32_t crc32Wide(const unsigned char* p, size_t size) {
  const __m512i by2048 = constants4(foldAcross(2048)), by512 = constants4(foldAcross(512));
  const __m128i by128 = constants(foldAcross(128));
  __m512i a[4];
  for (int i = 0; i < 4; ++i) a[i] = _mm512_loadu_si512(p + 64 * i);
  a[0] = _mm512_xor_si512(a[0], _mm512_castsi128_si512(_mm_cvtsi32_si128(-1)));
  p += 256, size -= 256;
  for (; size >= 256; p += 256, size -= 256)
    for (int i = 0; i < 4; ++i) a[i] = _mm512_xor_si512(fold4(a[i], by2048), _mm512_loadu_si512(p + 64 * i));
  for (int i = 1; i < 4; ++i) a[i] = _mm512_xor_si512(fold4(a[i - 1], by512), a[i]);
  unsigned char lanes[64];
  _mm512_storeu_si512(lanes, a[3]);
  __m128i x = load(lanes);
  for (int i = 1; i < 4; ++i) x = _mm_xor_si128(fold(x, by128), load(lanes + 16 * i));
  return finish(x, p, size);
}

bool hasClmul() {
  static const bool has = __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("sse4.1");
  return has;
}
bool hasWideClmul() {
  static const bool has = hasClmul() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("vpclmulqdq");
  return has;
}
#endif

}  // namespace

std::vector<Crc32Method> crc32Methods() {
  std::vector<Crc32Method> m{Crc32Method::Zlib};
#ifdef FREP_CRC32_CLMUL
  if (hasClmul()) m.push_back(Crc32Method::Clmul);
  if (hasWideClmul()) m.push_back(Crc32Method::WideClmul);
#endif
  return m;
}

uint32_t crc32With(Crc32Method method, const void* data, size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
#ifdef FREP_CRC32_CLMUL
  if (method == Crc32Method::WideClmul && size >= 256 && hasWideClmul()) return crc32Wide(p, size);
  if (method != Crc32Method::Zlib && size >= 64 && hasClmul()) return crc32Clmul(p, size);
#endif
  return crc32Zlib(crc32(0L, Z_NULL, 0), p, size);
}

uint32_t crc32Of(const void* data, size_t size) {
  static const Crc32Method best = crc32Methods().back();
  return crc32With(best, data, size);
}

}  // namespace frep::farm
