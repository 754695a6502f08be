// Internal to core: a stable LSD radix sort on a 64-bit key, for the mesher's large sorts of
// edge records by edge key (tens of thousands a brick, where std::sort's comparisons and
// mispredicted branches dominated). 8 bits a pass; the bytes every key shares are skipped.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace frep {

// Sorts v by key(element) (uint64_t), keeping the order of equal keys.
template <typename T, typename Key>
void radixSortByKey(std::vector<T>& v, Key key) {
  const size_t n = v.size();
  if (n < 512) {
    std::stable_sort(v.begin(), v.end(), [&](const T& a, const T& b) { return key(a) < key(b); });
    return;
  }
  std::vector<std::array<size_t, 256>> count(8);  // every byte's histogram (zeroed), in one pass
  for (const T& x : v) {
    const uint64_t k = key(x);
    for (int b = 0; b < 8; ++b) ++count[size_t(b)][(k >> (8 * b)) & 255];
  }
  const uint64_t first = key(v[0]);
  std::vector<T> buffer(n);
  T* src = v.data();
  T* dst = buffer.data();
  for (int b = 0; b < 8; ++b) {
    std::array<size_t, 256>& c = count[size_t(b)];
    if (c[(first >> (8 * b)) & 255] == n) continue;  // every key has this byte
    size_t at = 0;
    for (size_t& slot : c) {
      const size_t m = slot;
      slot = at;
      at += m;
    }
    for (size_t i = 0; i < n; ++i) dst[c[(key(src[i]) >> (8 * b)) & 255]++] = src[i];
    std::swap(src, dst);
  }
  if (src != v.data()) std::copy(src, src + n, v.data());
}

}  // namespace frep
