// One brick's result and the payload codecs that carry it from a worker to the master: what
// the master and the CLI need to read results without linking the compute side (worker/).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "frep/farm/job.h"
#include "frep/meshing/mesh.h"
#include "frep/render/raycast.h"
#include "frep/sampling/sample.h"

namespace frep::farm {

// One brick's result. "sample": leaves and tiles; "mesh": piece (the core mesher's MeshPiece of
// the brick's cells); "render": hits (castRegion's hits of the brick's pixels [lo, hi) in x, y,
// row-major). stats holds the counters reported to the master (for "mesh": pointEvals =
// grid-point + root-finding + gradient evaluations).
struct BrickOutput {
  std::vector<LeafBlock> leaves;
  std::vector<Tile> tiles;
  SampleStats stats;
  uint64_t extremumSearches = 0, extremumUncertified = 0;  // this brick's extremum searches
  uint64_t extremumSignDecided = 0;  // ... sign-only searches that stopped at a certain sign
  double extremumWidestGap = 0;      // ... the widest gap an uncertified one left
  MeshPiece piece;
  std::vector<RayHit> hits;
  std::array<int32_t, 3> tileLo{}, tileHi{};  // "render": the region of `hits`
};
// Payload frame codec (little-endian): "FRB2", u32 leaves, u32 tiles, tiles (origin[3], size,
// inside as i32 each), leaves (origin[3] i32, u32 flags, active mask 8 x u64, then either 512
// float values, or when every inactive voxel holds +-m (flag 1): a mask of the positive
// inactive voxels (8 x u64), m as a float, and the active voxels' values only).
std::string encodeBrick(const BrickOutput& out);
// Returns false (with a reason) on a malformed payload; never reads out of bounds.
bool decodeBrick(const void* data, size_t size, BrickOutput& out, std::string* error);
// The same checks as decodeBrick (the same parser), keeping only the leaves' origins (in payload
// order), where each leaf's record starts in the payload (leafAt, bytes from its start) and the
// tiles: the master verifies a result without expanding its values. A payload of 4 GiB or more
// (which the master never receives) is refused.
bool scanBrick(const void* data, size_t size, std::vector<std::array<int32_t, 3>>& origins, std::vector<Tile>& tiles,
               std::vector<uint32_t>& leafAt, std::string* error);
// Decodes one leaf record of a payload that scanBrick accepted: the `bytes` from a leafAt to the
// next one (the last: to the payload's end) into `leaf` (its origin, mask and values), as
// decodeBrick decodes that leaf. False, without reading past them, if the bytes are not exactly
// one well-formed leaf record.
bool decodeLeafAt(const char* record, size_t bytes, LeafBlock& leaf);

// Mesh piece codec (little-endian, version in the magic): "FRM4", regionLo (3 x i32), the
// piece's MeshStats (6 x u64: cells visited, crossed, root evals, gradient evals, sample point
// evals, fallback edges), u32 vertices, u32 triangles; per vertex: its key as a
// varint (the first absolute, then the increase over the previous key: keys strictly increase),
// position and normal (6 x f64, bit-exact); per triangle: the first index as a zigzag varint
// delta from the previous triangle's first index, the other two as zigzag varint deltas from
// the first. Then the simplifier's carry (SimplifyCarry, mesh.h; empty for raw pieces): 6 x u64
// counters (collapses, rejected for topology, shape, error, intersection, model evaluations),
// u32 carried vertices, each a varint index (the first absolute, then the increase), 11 x f64
// quadric, a u8 moved flag and a u32 settled tag; a u8 flag, and when 1 one state byte per triangle. Varints are
// LEB128 (7 bits a byte, at most 10 bytes).
std::string encodeMeshPiece(const MeshPiece& piece);
// Returns false (with a reason) on a malformed payload: bad magic, truncation, counts beyond
// the size, keys not strictly increasing, a varint that overflows, a non-finite coordinate, a
// triangle index out of range or repeated, trailing bytes. Never reads out of bounds.
bool decodeMeshPiece(const void* data, size_t size, MeshPiece& out, std::string* error);

// Render tile codec (little-endian): "FRR1", the region tileLo and tileHi (3 x i32 each), then
// per pixel (row-major) a kind byte (RayHit::Kind) and, for a hit, depth, point and normal
// (7 x f64, bit-exact).
std::string encodeRenderTile(const BrickOutput& out);
// Returns false (with a reason) on a malformed payload: bad magic, an empty or negative region,
// an unknown kind, a non-finite value, truncation or trailing bytes. Never reads out of bounds.
bool decodeRenderTile(const void* data, size_t size, BrickOutput& out, std::string* error);

// The job's payload codec: encodeBrick/decodeBrick for "sample", encodeMeshPiece/decodeMeshPiece
// (into out.piece, with out.stats.pointEvals from the piece's stats) for "mesh",
// encodeRenderTile/decodeRenderTile for "render".
std::string encodePayload(Operation op, const BrickOutput& out);
bool decodePayload(Operation op, const void* data, size_t size, BrickOutput& out, std::string* error);

}  // namespace frep::farm
