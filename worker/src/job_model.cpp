// A job's model compiled to the tape the bricks are computed on, and what the report says about it.
#include "frep/worker/job_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "frep/extremum/extremum.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/primitives/ops.h"
#include "frep/lang/field.h"
#include "frep/lang/hyperfun.h"

namespace frep::farm {

namespace {
std::string& workerDataDir() {
  static std::string dir;
  return dir;
}
}  // namespace

void setWorkerDataDir(const std::string& dir) { workerDataDir() = dir; }

namespace {
// The model of the last job compiled in this process, for the next compilation of the same
// inputs: one frep process compiles a job's model up to three times (the command's tape for the
// simplification, the in-process bricks, the report's exact terms), each as long as the first
// (1.2 ms for the L-slab ⊕ ball, a 12³ run's tenth; more for a large mesh's convex cover). A
// model's expressions are immutable, so callers on any thread may share them.
class LastModel {
 public:
  std::optional<lang::Model> find(const JobSpec& job, const std::string& dataDir) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!has_ || !sameInputs(job, dataDir)) return std::nullopt;
    return model_;
  }
  void keep(const JobSpec& job, const std::string& dataDir, const lang::Model& model) {
    std::lock_guard<std::mutex> lock(mutex_);
    inputs_.Clear();
    inputs_.set_object(job.object());
    inputs_.set_model_source(job.model_source());
    inputs_.set_model_name(job.model_name());
    *inputs_.mutable_model_files() = job.model_files();
    dataDir_ = dataDir;
    model_ = model;
    has_ = true;
  }

 private:
  // What lang::compile reads in jobField: the object, the source and its name, the job's files
  // and the worker's data folder.
  bool sameInputs(const JobSpec& job, const std::string& dataDir) const {
    if (job.object() != inputs_.object() || job.model_source() != inputs_.model_source() ||
        job.model_name() != inputs_.model_name() || dataDir != dataDir_ ||
        job.model_files_size() != inputs_.model_files_size())
      return false;
    for (int i = 0; i < job.model_files_size(); ++i)
      if (job.model_files(i).path() != inputs_.model_files(i).path() ||
          job.model_files(i).contents() != inputs_.model_files(i).contents())
        return false;
    return true;
  }
  std::mutex mutex_;
  JobSpec inputs_;
  std::string dataDir_;
  lang::Model model_;
  bool has_ = false;
};

// Never destroyed: its expressions must not outlive the tables they are interned in at exit.
LastModel& lastModel() {
  static LastModel& last = *new LastModel;
  return last;
}

lang::Model compiledModel(const JobSpec& job) {
  LastModel& last = lastModel();
  if (std::optional<lang::Model> m = last.find(job, workerDataDir())) return *m;
  lang::CompileOptions opt;
  opt.object = job.object();
  // Only the job's own files, or the worker's --data-dir: never a path the master names.
  opt.fileAccess =
      workerDataDir().empty() ? lang::CompileOptions::FileAccess::JobOnly : lang::CompileOptions::FileAccess::DataDir;
  opt.dataDir = workerDataDir();
  for (const auto& f : job.model_files()) opt.files[f.path()] = f.contents();
  lang::CompileResult r = lang::compile(job.model_source(), job.model_name(), opt);
  if (!r.ok) {
    std::string msg;
    for (auto& d : r.diagnostics)
      if (d.severity == lang::Diagnostic::Severity::Error) msg += d.format() + "\n";
    throw std::runtime_error(msg.empty() ? "model does not compile" : msg);
  }
  last.keep(job, workerDataDir(), r.model);
  return r.model;
}

Expr jobField(const JobSpec& job, uint32_t* dimsOut) {
  checkModelFiles(job);
  const lang::Model model = compiledModel(job);
  lang::FieldSpec spec;
  spec.params.assign(job.params().begin(), job.params().end());
  spec.iso = job.iso();
  spec.axis.assign(job.map_axis().begin(), job.map_axis().end());
  spec.constant.assign(job.map_constant().begin(), job.map_constant().end());
  Expr f = lang::fieldOf(model, spec);
  if (operationOf(job) == Operation::Render) {
    const RenderSpec& v = job.render();
    if (v.section_values_size() > 0) {  // the union of the sections (geometric types C, G)
      const size_t c = size_t(v.section_coordinate());
      if (c >= spec.axis.size() || spec.axis[c] != -1)
        throw std::invalid_argument("job: the section coordinate is not a constant of the mapping");
      for (int k = 0; k < v.section_values_size(); ++k) {
        spec.constant[c] = v.section_values(k);
        const Expr section = lang::fieldOf(model, spec);
        f = k == 0 ? section : max(f, section);
      }
    }
    if (v.clip_lo_size() != 3 || v.clip_hi_size() != 3)
      throw std::invalid_argument("job: render clip box needs 3 values each");
    f = clipToBox(f, {v.clip_lo(0), v.clip_lo(1), v.clip_lo(2)}, {v.clip_hi(0), v.clip_hi(1), v.clip_hi(2)});
  }
  const uint32_t dims = spec.axis.empty() ? uint32_t(model.xSize) : 3u;
  if (frep::numVars(f) > 3)
    throw std::runtime_error("the field has " + std::to_string(frep::numVars(f)) +
                             " coordinates: map x[4..] to constants (-x)");
  *dimsOut = dims;
  return f;
}
}  // namespace

namespace {
Vec3 vec3(const google::protobuf::RepeatedField<double>& v, const char* name) {
  if (v.size() != 3) throw std::invalid_argument(std::string("job: ") + name + " needs 3 values");
  return {v[0], v[1], v[2]};
}
}  // namespace

void rememberCompiledModel(const JobSpec& job, const lang::Model& model) {
  lastModel().keep(job, workerDataDir(), model);
}

Expr jobFieldOf(const JobSpec& job) {
  uint32_t dims = 0;
  return jobField(job, &dims);
}

TapePtr compileJobModel(const JobSpec& job) {
  uint32_t dims = 0;
  Expr f = jobField(job, &dims);
  if (operationOf(job) == Operation::Render) return viewTape(f, cameraOf(job));
  if (job.cut_lo_size() || job.cut_hi_size()) {
    const Vec3 lo = vec3(job.cut_lo(), "cut_lo"), hi = vec3(job.cut_hi(), "cut_hi");
    for (int a = 0; a < 3; ++a)
      if (!(std::isfinite(lo[a]) && std::isfinite(hi[a]) && lo[a] < hi[a]))
        throw std::invalid_argument("job: the cut box needs finite cut_lo < cut_hi on every axis");
    f = cutByBox(f, lo, hi);  // solid ∩ box: closed where the box cuts the solid
  }
  return Tape::compile(f, std::min(dims, 3u));
}

Expr clipToBox(const Expr& f, const Vec3& lo, const Vec3& hi) {
  Expr e = f;
  for (uint32_t i = 0; i < 3; ++i) {
    e = min(e, Expr::x(i) - lo[i]);
    e = min(e, hi[i] - Expr::x(i));
  }
  return e;
}

Camera cameraOf(const JobSpec& job) {
  const RenderSpec& v = job.render();
  Camera c;
  c.eye = vec3(v.eye(), "eye");
  c.right = vec3(v.right(), "right");
  c.up = vec3(v.up(), "up");
  c.forward = vec3(v.forward(), "forward");
  c.perspective = v.perspective();
  c.halfWidth = v.half_width();
  return c;
}

RenderOptions renderOptionsOf(const JobSpec& job) {
  const GridSpec g = gridOf(job);
  RenderOptions o;
  o.width = g.dims[0], o.height = g.dims[1];
  o.nearDepth = job.render().near_depth(), o.farDepth = job.render().far_depth();
  o.footprint = !job.render().no_footprint();
  return o;
}

std::vector<std::string> describeExactTerms(const JobSpec& job) {
  uint32_t dims = 0;
  return minkowski::describeExact(jobField(job, &dims));
}

TapePtr ModelCache::get(const JobSpec& job, uint64_t jobId) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = tapes_.find(jobId);
  if (it != tapes_.end()) return it->second;
  TapePtr t = compileJobModel(job);
  tapes_[jobId] = t;
  return t;
}

std::string describeErrorBounds(const Tape& tape, std::vector<std::string>* lines) {
  std::string all;
  for (const ExtremumEntry& e : tape.extrema()) {
    const ExtremumSpec& s = *e.spec;
    std::string line;
    if (s.method == ExtremumMethod::Grid) {
      // Pasko-Minkowski §4: the grid's solid M satisfies A_d + B_d ⊂ M ⊂ A + B, d = sqrt(p)/2 eps.
      const double d = std::sqrt(double(s.numParams())) / 2.0 * s.eps;
      line = "grid search (eps " + std::to_string(s.eps) + " over " + std::to_string(s.numParams()) +
             " parameters): set inclusion A_d + B_d in M in A + B with d = " + std::to_string(d);
    } else {
      char tol[32];
      std::snprintf(tol, sizeof tol, "%g", s.tolerance);
      line = "branch-and-bound: values within " + std::string(tol) +
             " of the extremum where the search certified it; sign-only searches certify the sign; searches that "
             "ran out of boxes are counted as uncertified, with the widest gap they left";
    }
    if (lines) lines->push_back(line);
    all += (all.empty() ? "" : "; ") + line;
  }
  return all;
}
}  // namespace frep::farm
