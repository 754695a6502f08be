// Output files appear whole on commit, or not at all.
#include "frep/io/atomic_output.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "exit_codes.h"

using namespace frep::cli;
using namespace frep::io;

namespace {
bool exists(const std::string& p) {
  struct stat st;
  return ::stat(p.c_str(), &st) == 0;
}
}  // namespace

TEST(AtomicOutput, CommitRenamesTheTemporaryFile) {
  std::string path = testing::TempDir() + "atomic_commit.txt";
  std::remove(path.c_str());
  {
    AtomicOutput out("--out", path);
    EXPECT_TRUE(exists(out.tempPath()));
    EXPECT_NE(out.tempPath(), path);
    std::ofstream(out.tempPath()) << "done";
    EXPECT_FALSE(exists(path));
    out.commit();
    EXPECT_FALSE(exists(out.tempPath()));
  }
  std::string text;
  std::ifstream(path) >> text;
  EXPECT_EQ(text, "done");
  std::remove(path.c_str());
}

TEST(AtomicOutput, NoCommitLeavesNothing) {
  std::string path = testing::TempDir() + "atomic_abandon.txt";
  std::remove(path.c_str());
  std::string temp;
  {
    AtomicOutput out("--out", path);
    temp = out.tempPath();
  }
  EXPECT_FALSE(exists(temp));
  EXPECT_FALSE(exists(path));
}

TEST(AtomicOutput, UnwritableDirectoryFailsUpFront) {
  try {
    AtomicOutput out("-O/--out", "/nonexistent-dir/out.vdb");
    FAIL();
  } catch (const CliError& e) {
    EXPECT_EQ(e.code, kExitIoError);
    EXPECT_EQ(std::string(e.what()), "-O/--out: cannot write '/nonexistent-dir/out.vdb': No such file or directory");
  }
}
