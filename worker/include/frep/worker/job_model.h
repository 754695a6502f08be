// A job's model: compiled to the tape its bricks are computed on (workers, the master's
// in-process mode), checked and described by the master before any worker starts (the report's
// error bounds), and the field and camera the CLI's in-process steps use. No brick computation
// here (brick.h), so the master's farm loop and the CLI need only frep_job_model.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "frep/farm/job.h"
#include "farm.pb.h"
#include "frep/expressions/tape.h"
#include "frep/geometry/vec3.h"
#include "frep/lang/hyperfun.h"
#include "frep/render/raycast.h"

namespace frep::farm {

// Compiles a job's model (HyperFun source, object, params, iso) to a tape; for "render" the
// tape of the field clipped to the RenderSpec's box and composed with its camera (viewTape).
// Throws std::runtime_error with the diagnostics when the model does not compile.
TapePtr compileJobModel(const JobSpec& job);
// The job's model as compiled elsewhere in this process from the same inputs (the frep command
// compiles the model file from disk, and the job carries those bytes): the job's compilations in
// this process (compileJobModel, jobFieldOf) then reuse it instead of compiling it again.
void rememberCompiledModel(const JobSpec& job, const lang::Model& model);
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

}  // namespace frep::farm
