// How the merged leaves get to their places: each leaf of a kept payload is a record (where it
// starts, how long it is: scanBrick's leafAt) and a slab's records, sorted by origin
// (leaf_order.h), are decoded in that order into consecutive blocks (Master::mergeLeaves, and
// streamed in pieces of kSinkPieceLeaves, Master::mergeSlabs).
#pragma once

#include <cstddef>
#include <cstdint>

#include "frep/sampling/sample.h"

namespace frep::farm {

struct LeafRecord {
  const char* at = nullptr;  // inside a verified payload that outlives the decode
  uint32_t bytes = 0;        // to the next record (the last: to the payload's end)
};

// Decodes records[0, n) into out[0, n) (decodeLeafAt). The payloads arrived long before their
// merge and left the caches, and consecutive records lie in different payloads: each record's
// bytes and its block are fetched a few leaves ahead, which the hardware prefetcher cannot guess.
// A record that does not decode (its payload changed since it was verified) is std::logic_error.
void decodeLeafRecords(const LeafRecord* records, size_t n, LeafBlock* out);

}  // namespace frep::farm
