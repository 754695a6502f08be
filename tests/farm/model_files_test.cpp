// Files a model reads travel inside the job (JobSpec.model_files) with the FNV-1a hash of their
// bytes; a worker refuses a file whose bytes do not hash to it, naming the file (issue 11).
#include <cmath>

#include "farm_test_util.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/field_function.h"
#include "frep/lang/hyperfun.h"
#include "frep/lang/library/library.h"

namespace farmtest {
namespace {

JobSpec jobWithFile(bool corrupt) {
  JobSpec j = partJob("sample", 48);
  ModelFile* f = j.add_model_files();
  f->set_path("parts/cube.obj");
  f->set_contents("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  f->set_hash(modelFileHash(f->contents()) ^ (corrupt ? 1u : 0u));
  return j;
}

TEST(ModelFiles, TheHashIsCheckedBeforeTheModelCompiles) {
  EXPECT_NO_THROW(checkModelFiles(jobWithFile(false)));
  try {
    checkModelFiles(jobWithFile(true));
    ADD_FAILURE() << "a file whose bytes do not match its hash was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("model file 'parts/cube.obj'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("refusing it"), std::string::npos) << e.what();
  }
  EXPECT_THROW(compileJobModel(jobWithFile(true)), std::runtime_error);
  EXPECT_NE(compileJobModel(jobWithFile(false)), nullptr);
}

// Through runJob with real frep-worker processes: the master compiles the job first (the same
// brick code), so it refuses the job before dispatching it; a worker given such a job (another
// master) fails each brick with the same message, and the bricks are poisoned.
TEST(ModelFiles, AJobWithAFileWhoseHashDiffersIsRefusedNamingTheFile) {
  FarmOutcome out;
  try {
    out = runJob(jobWithFile(true), fast(2));
  } catch (const std::exception& e) {
    std::printf("refused: %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("model file 'parts/cube.obj'"), std::string::npos) << e.what();
    return;
  }
  ASSERT_FALSE(out.report.poisoned.empty());
  EXPECT_NE(out.report.poisoned[0].error.find("model file 'parts/cube.obj'"), std::string::npos)
      << out.report.poisoned[0].error;
}

// A process keeps the last model it compiled (job_model.cpp): compiling the same inputs again
// gives the same field, while any input that changes (a file's bytes, the source, the object)
// compiles again, never serving a stale model. The "mesh" file here holds a ball's radius
// (farm_tests does not link the real readers; this loader stands in for them).
class BallFromFile : public frep::FieldFunction {
 public:
  explicit BallFromFile(double r) : r_(r) {}
  std::string describe() const override { return "ball " + std::to_string(r_); }
  uint64_t contentHash() const override { return std::hash<double>()(r_); }
  bool sameContent(const frep::FieldFunction& o) const override {
    auto* b = dynamic_cast<const BallFromFile*>(&o);
    return b && b->r_ == r_;
  }
  double value(const double p[3]) const override { return r_ - std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]); }
  double gradient(const double p[3], double g[3]) const override {
    const double n = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int k = 0; k < 3; ++k) g[k] = n > 0 ? -p[k] / n : 0;
    return r_ - n;
  }
  frep::Interval bound(const frep::Interval box[3]) const override {
    double near = 0, far = 0;
    for (int k = 0; k < 3; ++k) {
      const double lo = std::abs(box[k].lo), hi = std::abs(box[k].hi);
      const double m = box[k].lo <= 0 && box[k].hi >= 0 ? 0 : std::min(lo, hi);
      near += m * m, far += std::max(lo, hi) * std::max(lo, hi);
    }
    return {r_ - std::sqrt(far), r_ - std::sqrt(near)};
  }

 private:
  double r_;
};

JobSpec ballJob(const std::string& radius, const std::string& source) {
  JobSpec j = partJob("sample", 16);
  j.set_model_source(source);
  ModelFile* f = j.add_model_files();
  f->set_path("ball.stl");
  f->set_contents(radius);
  f->set_hash(modelFileHash(radius));
  return j;
}

TEST(ModelFiles, TheLastModelIsReusedOnlyForTheSameInputs) {
  const frep::lang::FileFieldLoader before = frep::lang::fileFieldLoader();
  int loads = 0;
  frep::lang::setFileFieldLoader([&loads](const frep::lang::FileFieldRequest& r) {
    ++loads;
    frep::lang::LoadedFileField out;
    out.field = std::make_shared<BallFromFile>(std::stod(*r.bytes));
    out.fileHash = modelFileHash(*r.bytes);
    return out;
  });
  const std::string source = "ball(x[3], a[1]) { ball = frMesh(x, \"ball.stl\"); }\n";
  const double p[3] = {1.5, 0, 0};  // outside the ball of radius 1, inside that of radius 2
  auto valueAt = [&](const JobSpec& job) { return frep::PointEvaluator().eval(*compileJobModel(job), p); };
  EXPECT_DOUBLE_EQ(valueAt(ballJob("1", source)), -0.5);
  EXPECT_DOUBLE_EQ(valueAt(ballJob("1", source)), -0.5);
  (void)jobFieldOf(ballJob("1", source));
  EXPECT_EQ(loads, 1) << "the same inputs compiled again";
  EXPECT_DOUBLE_EQ(valueAt(ballJob("2", source)), 0.5) << "a file whose bytes changed served the old model";
  EXPECT_DOUBLE_EQ(valueAt(ballJob("1", source)), -0.5) << "the file changed back";
  EXPECT_EQ(loads, 3);
  (void)jobFieldOf(ballJob("1", "\n" + source));
  EXPECT_EQ(loads, 4) << "a changed source served the old model";
  JobSpec other = ballJob("1", source + "big(x[3], a[1]) { big = frMesh(x, \"ball.stl\") + 1; }\n");
  EXPECT_DOUBLE_EQ(valueAt(other), -0.5);
  other.set_object("big");
  EXPECT_DOUBLE_EQ(valueAt(other), 0.5) << "another object of the same file served the old model";
  // A model compiled elsewhere in the process from the same inputs (the frep command compiles the
  // file from disk before it makes the job) is taken as it is.
  frep::lang::CompileOptions options;
  options.files["ball.stl"] = "3";
  const frep::lang::CompileResult compiled = frep::lang::compile(source, "test.hf", options);
  ASSERT_TRUE(compiled.ok);
  const int loadsBefore = loads;
  rememberCompiledModel(ballJob("3", source), compiled.model);
  EXPECT_DOUBLE_EQ(valueAt(ballJob("3", source)), 1.5);
  EXPECT_EQ(loads, loadsBefore) << "the remembered model was compiled again";
  frep::lang::setFileFieldLoader(before);
}

}  // namespace
}  // namespace farmtest
