// SIGTERM and SIGINT during a long extremum search (issue 34): a blobby object summed with a
// ball by branch-and-bound, which frep meshes at 64^3 in about 20 s (on one core; more when the
// machine is busy). Signalled after about a second, an in-process run (--workers 0) and a run
// on local workers both end at once with exit 6 (docs/cli.md), no output, no temporary file and
// no worker left running. The time limit only tells a stopped run from one that ran to its end.
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hardening_fixture.h"

namespace frep_cli_test {
namespace {

using Clock = std::chrono::steady_clock;

const char* kSlowSum =
    "blob(x[3], a[1]) {\n"
    "  array x0[3], y0[3], z0[3], ai[3], bi[3];\n"
    "  x0 = [-0.8, 0.8, 0]; y0 = [0, 0, 1.0]; z0 = [0, 0, 0];\n"
    "  ai = [2, 2, 3]; bi = [1, 1, 0.8];\n"
    "  blob = hfBlobby(x, x0, y0, z0, ai, bi, 0.4);\n"
    "}\n"
    "ball(x[3], a[1]) { array c[3]; c = [0, 0, 0]; ball = hfSphere(x, c, 0.3); }\n"
    "my_model(x[3], a[1]) { my_model = frMinkowski(x, blob, ball); }\n";

struct Ended {
  int code = -1;                // exit code, or -1 when killed by a signal
  double seconds = 0;           // from the signal to the exit
  std::vector<pid_t> children;  // frep's children when it was signalled (local workers)
};

std::vector<pid_t> childrenOf(pid_t pid) {
  std::vector<pid_t> out;
  std::ifstream f("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
  for (pid_t c; f >> c;) out.push_back(c);
  return out;
}

// A process that is gone, or a zombie nobody reaped (then its parent is gone too: the test
// process would be its reaper only for frep itself).
bool running(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(f, line)) return false;
  const size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

class InterruptSearch : public Hardening {
 protected:
  // Starts frep with `args` in the test's directory, waits `afterMs`, sends `sig`, waits for the
  // end (a hang guard of 60 s: a run that was not stopped takes about that long or more).
  Ended signalDuring(const std::vector<std::string>& args, int sig, int afterMs = 1000) {
    pid_t pid = ::fork();
    if (pid == 0) {
      if (::chdir(dir_.c_str()) != 0) ::_exit(99);
      int devnull = ::open("/dev/null", O_WRONLY);
      ::dup2(devnull, 1), ::dup2(devnull, 2);
      std::vector<char*> argv{const_cast<char*>(FREP_BINARY)};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(FREP_BINARY, argv.data());
      ::_exit(98);
    }
    Ended e;
    if (pid < 0) return e;
    std::this_thread::sleep_for(std::chrono::milliseconds(afterMs));
    e.children = childrenOf(pid);
    ::kill(pid, sig);
    const auto t0 = Clock::now();
    int status = 0;
    while (::waitpid(pid, &status, WNOHANG) == 0) {
      if (Clock::now() - t0 > std::chrono::seconds(60)) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    e.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    e.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return e;
  }
};

TEST_F(InterruptSearch, SigtermEndsAnInProcessMeshAtOnce) {
  write("sum.hf", kSlowSum);
  const Ended e = signalDuring(
      {"mesh", "sum.hf", "-b", "3", "--res", "64", "--workers", "0", "--no-progress", "-O", "sum.ply"}, SIGTERM);
  EXPECT_EQ(e.code, 6) << listing();
  EXPECT_LT(e.seconds, 3.0);  // stopped: to its end it takes 20 s or more
  EXPECT_FALSE(fileExists(path("sum.ply"))) << listing();
  EXPECT_TRUE(noTemporaries()) << listing();
}

TEST_F(InterruptSearch, SigintEndsInProcessSampleAndRender) {
  write("sum.hf", kSlowSum);
  const Ended s = signalDuring(
      {"sample", "sum.hf", "-b", "3", "--res", "96", "--workers", "0", "--no-progress", "-O", "sum.vdb"}, SIGINT);
  EXPECT_EQ(s.code, 6) << listing();
  EXPECT_LT(s.seconds, 3.0);
  EXPECT_FALSE(fileExists(path("sum.vdb"))) << listing();
  EXPECT_TRUE(noTemporaries()) << listing();
  const Ended r = signalDuring(
      {"render", "sum.hf", "-b", "3", "--size", "512x512", "--workers", "0", "--no-progress", "-O", "sum.png"}, SIGINT);
  EXPECT_EQ(r.code, 6) << listing();
  EXPECT_LT(r.seconds, 3.0);
  EXPECT_FALSE(fileExists(path("sum.png"))) << listing();
  EXPECT_TRUE(noTemporaries()) << listing();
}

TEST_F(InterruptSearch, SigtermStopsTheLocalWorkersToo) {
  write("sum.hf", kSlowSum);
  const Ended e = signalDuring(
      {"mesh", "sum.hf", "-b", "3", "--res", "64", "--workers", "2", "--brick", "32", "--no-progress", "-O", "sum.ply"},
      SIGTERM, 1500);
  EXPECT_EQ(e.code, 6) << listing();
  EXPECT_LT(e.seconds, 3.0);
  EXPECT_FALSE(fileExists(path("sum.ply"))) << listing();
  EXPECT_TRUE(noTemporaries()) << listing();
  EXPECT_FALSE(e.children.empty()) << "no local worker had started";
  for (pid_t c : e.children) EXPECT_FALSE(running(c)) << "local worker " << c << " still runs";
}

TEST_F(InterruptSearch, SigtermEndsAMeasureWithinARound) {
  write("sum.hf", kSlowSum);
  const Ended e = signalDuring({"measure", "sum.hf", "-b", "3", "--no-progress", "--tolerance", "0.0001"}, SIGTERM);
  EXPECT_EQ(e.code, 6);
  EXPECT_LT(e.seconds, 3.0);
}

}  // namespace
}  // namespace frep_cli_test
