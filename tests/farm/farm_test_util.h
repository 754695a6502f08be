// Shared by the farm tests: a test model and job, fast farm options, and worker processes and a
// master thread that the tests start, signal and join themselves.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <thread>
#include <vector>

#include "brick.h"
#include "farm_master.h"

extern char** environ;

namespace farmtest {

using namespace frep;
using namespace frep::farm;

// A block with a spherical bite: flat faces, edges, corners and a curved pocket, with surface
// in most bricks.
inline const char* kPartModel = R"(
my_model(x[3], a[1]) {
  array c[3], v[3];
  c = [0.3, 0.2, 0.4];
  v = [-0.7, -0.6, -0.5];
  b = hfBlock(x, v, 1.4, 1.2, 1.0);
  ball = hfSphere(x, c, 0.45);
  my_model = b \ ball;
}
)";

inline JobSpec partJob(const std::string& operation, int res) {
  JobSpec j;
  j.set_operation(operation);
  j.set_model_source(kPartModel);
  j.set_model_name("test.hf");
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, res));
  if (operation == "sample") j.set_band(3);
  return j;
}

// Heartbeats of 100 ms so that dead workers are found within half a second.
inline FarmOptions fast(int workers, int brick = 32) {
  FarmOptions o;
  o.workers = workers;
  o.brickVoxels = brick;
  o.heartbeatMs = 100;
  o.liveness = 5;
  o.workerExecutable = FREP_WORKER_PATH;
  o.noWorkerTimeoutSec = 30;
  return o;
}

// Loopback ports for cluster-mode tests, distinct per test process.
inline int freePort(int base) {
  static int next = base + (getpid() % 5000) * 2;
  return next++;
}

// A frep-worker started by the test (as a cluster's launcher would), so the test can signal it.
struct WorkerProcess {
  pid_t pid = 0;
  explicit WorkerProcess(const std::string& endpoint, std::vector<std::string> env = {}) {
    std::vector<std::string> args{FREP_WORKER_PATH, "--connect", endpoint, "--threads", "1", "--log-level", "off",
                                  "--master-timeout", "5"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> envs;
    for (char** e = environ; *e; ++e) envs.push_back(*e);
    for (auto& e : env) envs.push_back(e);
    std::vector<char*> envp;
    for (auto& e : envs) envp.push_back(e.data());
    envp.push_back(nullptr);
    EXPECT_EQ(posix_spawn(&pid, FREP_WORKER_PATH, nullptr, nullptr, argv.data(), envp.data()), 0);
  }
  int wait() {
    int status = 0;
    waitpid(pid, &status, 0);
    pid = 0;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  ~WorkerProcess() {
    if (pid) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
};

// The master of a job on its own thread; join() returns when the job ends.
struct MasterThread {
  FarmOutcome outcome;
  std::string error;
  std::thread thread;
  MasterThread(const JobSpec& j, FarmOptions o) {
    thread = std::thread([this, j, o] {
      try {
        outcome = runJob(j, o);
      } catch (const std::exception& e) {
        error = e.what();
      }
    });
  }
  void join() { thread.join(); }
};

}  // namespace farmtest
