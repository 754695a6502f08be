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

#include "frep/farm/brick_codec.h"
#include "frep/farm/crc32.h"
#include "frep/farm/job.h"
#include "farm.pb.h"
#include "frep/meshing/mesh.h"
#include "frep/render/raycast.h"
#include "frep/sampling/sample.h"

namespace frep::farm {

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

}  // namespace frep::farm
