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

#include "farm.pb.h"
#include "frep/sample.h"

namespace frep::farm {

struct BrickOutput {
  std::vector<LeafBlock> leaves;
  std::vector<Tile> tiles;
  SampleStats stats;
};

// The grid a job samples.
GridSpec gridOf(const JobSpec& job);

// Stable 64-bit id of a job (FNV-1a over its serialized spec): results are keyed by it.
uint64_t jobIdOf(const JobSpec& job);

// Compiles a job's model (HyperFun source, object, params, iso) to a tape. Throws
// std::runtime_error with the diagnostics when the model does not compile.
TapePtr compileJobModel(const JobSpec& job);

// Compiled models by job id, so a worker compiles each model once.
class ModelCache {
 public:
  TapePtr get(const JobSpec& job, uint64_t jobId);

 private:
  std::mutex mutex_;
  std::unordered_map<uint64_t, TapePtr> tapes_;
};

// Samples the region [lo, hi) of the job's grid.
BrickOutput computeBrick(const TapePtr& tape, const JobSpec& job, const std::array<int32_t, 3>& lo,
                         const std::array<int32_t, 3>& hi, int threads);

// Payload frame codec (little-endian): "FRB2", u32 leaves, u32 tiles, tiles (origin[3], size,
// inside as i32 each), leaves (origin[3] i32, u32 flags, active mask 8 x u64, then either 512
// float values, or when every inactive voxel holds +-m (flag 1): a mask of the positive
// inactive voxels (8 x u64), m as a float, and the active voxels' values only).
std::string encodeBrick(const BrickOutput& out);
// Returns false (with a reason) on a malformed payload; never reads out of bounds.
bool decodeBrick(const void* data, size_t size, BrickOutput& out, std::string* error);

uint32_t crc32Of(const void* data, size_t size);

}  // namespace frep::farm
