// A job's helpers, shared by the master, the workers and the CLI: its operation, its grid, its
// id and its model files' hashes (pure functions of the JobSpec).
#pragma once

#include <cstdint>
#include <string>

#include "farm.pb.h"
#include "frep/sampling/sample.h"

namespace frep::farm {

// What a job computes (JobSpec.operation).
enum class Operation { Sample, Mesh, Render };
// "sample" (or empty, proto3's default), "mesh" and "render"; throws std::invalid_argument otherwise.
Operation operationOf(const JobSpec& job);

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

}  // namespace frep::farm
