#include "frep/master/leaf_records.h"

#include <stdexcept>
#include <string>

#include "frep/farm/brick_codec.h"

namespace frep::farm {

namespace {
// Leaves fetched ahead of the one being decoded: far enough to cover a memory access (~100 ns)
// at ~100 ns a leaf, near enough that what was fetched is still in the cache when decoded.
constexpr size_t kAhead = 4;

void fetch(const LeafRecord& r, const LeafBlock* block) {
  for (uint32_t b = 0; b < r.bytes; b += 64) __builtin_prefetch(r.at + b);
  if (r.bytes) __builtin_prefetch(r.at + r.bytes - 1);  // the last line, whatever the record's alignment
  const char* to = reinterpret_cast<const char*>(block);
  for (size_t b = 0; b < sizeof(LeafBlock); b += 64) __builtin_prefetch(to + b, 1);
}
}  // namespace

void decodeLeafRecords(const LeafRecord* records, size_t n, LeafBlock* out) {
  for (size_t i = 0; i < n && i < kAhead; ++i) fetch(records[i], out + i);
  for (size_t i = 0; i < n; ++i) {
    if (i + kAhead < n) fetch(records[i + kAhead], out + i + kAhead);
    if (!decodeLeafAt(records[i].at, records[i].bytes, out[i]))
      throw std::logic_error("a verified leaf record (" + std::to_string(records[i].bytes) +
                             " bytes) no longer decodes");
  }
}

}  // namespace frep::farm
