// Runs the built frep binary in a scratch directory and captures exit code, stdout and stderr.
#pragma once

#include <gtest/gtest.h>
#include <dirent.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace frep_cli_test {

struct RunResult {
  int code = -1;
  std::string out, err;
};

inline std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline bool fileExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

// A fresh directory per test, removed afterwards; models are written into it.
class FrepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = ::testing::TempDir() + "frep_cli_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::system(("rm -rf '" + dir_ + "'").c_str()); }

  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }

  // args are appended to the binary's path; the working directory is the test's directory.
  RunResult run(const std::string& args) const { return capture("'" FREP_BINARY "' " + args); }

  // A shell command run in the test's directory, its exit code and output captured.
  RunResult capture(const std::string& command) const {
    std::string cmd = "cd '" + dir_ + "' && " + command + " >" + path(".out") + " 2>" + path(".err");
    int status = std::system(cmd.c_str());
    RunResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readText(path(".out"));
    r.err = readText(path(".err"));
    std::remove(path(".out").c_str());
    std::remove(path(".err").c_str());
    return r;
  }

  // Names in the directory (hidden temporary files included), sorted, space-separated.
  std::string listing() const {
    std::set<std::string> names;
    if (DIR* d = ::opendir(dir_.c_str())) {
      while (dirent* e = ::readdir(d))
        if (std::string(e->d_name) != "." && std::string(e->d_name) != "..") names.insert(e->d_name);
      ::closedir(d);
    }
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : " ") + n;
    return s;
  }

  std::string dir_;
};

// f = 1 - |x|^2 (radius 1 + a[1]); exact values at dyadic points.
inline const char* kSphere =
    "-- a sphere of radius 1 + a[1]\n"
    "my_model(x[3], a[1])\n"
    "{\n"
    "  r = 1 + a[1];\n"
    "  my_model = r*r - x[1]*x[1] - x[2]*x[2] - x[3]*x[3];\n"
    "}\n";

}  // namespace frep_cli_test
