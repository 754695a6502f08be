// One brick of a job: the unit of work a worker computes and the master merges. The same code
// runs in workers and in the master's in-process mode (--workers 0), which is why the farm's
// output is bit-identical to the in-process run.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "crc32.h"
#include "farm.pb.h"
#include "frep/meshing/mesh.h"
#include "frep/render/raycast.h"
#include "frep/sampling/sample.h"

namespace frep::farm {

// What a job computes (JobSpec.operation).
enum class Operation { Sample, Mesh, Render };
// "sample" (or empty, proto3's default), "mesh" and "render"; throws std::invalid_argument otherwise.
Operation operationOf(const JobSpec& job);

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

// The grid a job samples, and setting it (origin, dims, voxel) on a job.
GridSpec gridOf(const JobSpec& job);
void setGrid(JobSpec& job, const GridSpec& grid);

// The content hash of a model file (ModelFile.hash): 64-bit FNV-1a of its bytes.
uint64_t modelFileHash(const std::string& contents);
// Throws std::runtime_error naming the first model file whose contents do not hash to its
// ModelFile.hash (a worker refuses such a job: damaged in transit, or a mismatched master).
void checkModelFiles(const JobSpec& job);

// Stable 64-bit id of a job (FNV-1a over its serialized spec): results are keyed by it.
uint64_t jobIdOf(const JobSpec& job);

// Compiles a job's model (HyperFun source, object, params, iso) to a tape; for "render" the
// tape of the field clipped to the RenderSpec's box and composed with its camera (viewTape).
// Throws std::runtime_error with the diagnostics when the model does not compile.
TapePtr compileJobModel(const JobSpec& job);
// One line per exact Minkowski algebra term of the model (Roerdink: no search, error bound 0),
// for the report next to describeErrorBounds' lines.
std::vector<std::string> describeExactTerms(const JobSpec& job);

// Compiled models by job id, so a worker compiles each model once.
// The directory a worker's jobs may read model files from when the job does not ship them
// (frep-worker --data-dir; empty, the default: none). A job's model is compiled with
// CompileOptions::FileAccess::JobOnly, or DataDir with this directory: a master can never make
// a worker (nor itself) open another path it names.
void setWorkerDataDir(const std::string& dir);

class ModelCache {
 public:
  TapePtr get(const JobSpec& job, uint64_t jobId);

 private:
  std::mutex mutex_;
  std::unordered_map<uint64_t, TapePtr> tapes_;
};

// The error bound of each extremum node of a model (one line each, for the job report).
std::string describeErrorBounds(const Tape& tape, std::vector<std::string>* lines);

// The job's field over x, y, z, before the camera ("render": clipped, the sections' union).
Expr jobFieldOf(const JobSpec& job);

// A "render" job's camera and options (std::invalid_argument for a malformed RenderSpec).
Camera cameraOf(const JobSpec& job);
RenderOptions renderOptionsOf(const JobSpec& job);
// The field drawn: f restricted to the box, as hfp draws only inside -b.
Expr clipToBox(const Expr& f, const Vec3& lo, const Vec3& hi);

// Computes the region [lo, hi) of the job's grid: samples it ("sample"), meshes its cells
// ("mesh", core meshRegion with the job's MeshSpec) or casts its pixels' rays ("render",
// castRegion; the region must be made of whole kRenderTile tiles). threads: 0 = all cores; never changes the
// result.
BrickOutput computeBrick(const TapePtr& tape, const JobSpec& job, const std::array<int32_t, 3>& lo,
                         const std::array<int32_t, 3>& hi, int threads);

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
