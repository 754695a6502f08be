// The CRC-32 of result payloads and journal records (worker/crc32.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frep::farm {

// zlib's CRC-32 of the bytes (polynomial 0x04C11DB7, reflected, initial and final value all
// ones), by the fastest method this CPU has.
uint32_t crc32Of(const void* data, size_t size);

// How crc32Of can compute it (each gives zlib's value): zlib's tables, carry-less
// multiplication (PCLMULQDQ), four lanes of it at once (AVX-512 VPCLMULQDQ). crc32Methods: the
// ones this CPU has, slowest first; crc32With falls back to a slower one for short buffers.
enum class Crc32Method { Zlib, Clmul, WideClmul };
std::vector<Crc32Method> crc32Methods();
uint32_t crc32With(Crc32Method method, const void* data, size_t size);

}  // namespace frep::farm
