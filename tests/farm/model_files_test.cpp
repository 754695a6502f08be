// Files a model reads travel inside the job (JobSpec.model_files) with the FNV-1a hash of their
// bytes; a worker refuses a file whose bytes do not hash to it, naming the file (issue 11).
#include "farm_test_util.h"

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

}  // namespace
}  // namespace farmtest
