// The job helpers (frep/farm/job.h): a job's grid, id, operation and model files' hashes.
#include "frep/farm/job.h"

#include <cstdio>
#include <stdexcept>

namespace frep::farm {

GridSpec gridOf(const JobSpec& job) {
  if (job.origin_size() != 3 || job.dims_size() != 3)
    throw std::invalid_argument("job: origin and dims need 3 values each");
  GridSpec g;
  for (int a = 0; a < 3; ++a) {
    g.origin[a] = job.origin(a);
    g.dims[a] = job.dims(a);
  }
  g.voxel = job.voxel();
  return g;
}

void setGrid(JobSpec& job, const GridSpec& grid) {
  job.clear_origin();
  job.clear_dims();
  for (int a = 0; a < 3; ++a) {
    job.add_origin(grid.origin[a]);
    job.add_dims(grid.dims[a]);
  }
  job.set_voxel(grid.voxel);
}

uint64_t jobIdOf(const JobSpec& job) {
  std::string bytes;
  job.SerializeToString(&bytes);  // deterministic for a given message (no maps in JobSpec)
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

uint64_t modelFileHash(const std::string& contents) {
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : contents) h = (h ^ c) * 1099511628211ULL;
  return h;
}

void checkModelFiles(const JobSpec& job) {
  auto hex = [](uint64_t h) {
    char b[17];
    std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h));
    return std::string(b);
  };
  for (const auto& f : job.model_files()) {
    const uint64_t got = modelFileHash(f.contents());
    if (got != f.hash())
      throw std::runtime_error("model file '" + f.path() + "': its " + std::to_string(f.contents().size()) +
                               " bytes hash to " + hex(got) + " but the job says " + hex(f.hash()) +
                               "; refusing it (damaged in transit, or a master from another release)");
  }
}

Operation operationOf(const JobSpec& job) {
  if (job.operation().empty() || job.operation() == "sample") return Operation::Sample;
  if (job.operation() == "mesh") return Operation::Mesh;
  if (job.operation() == "render") return Operation::Render;
  throw std::invalid_argument("job: unknown operation '" + job.operation() + "' (expected sample, mesh or render)");
}

}  // namespace frep::farm
