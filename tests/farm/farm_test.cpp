// The farm against the in-process run: identical leaves and tiles for any worker count, and
// through worker faults (workers started and abused by the test itself, master in this process).
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "brick.h"
#include "farm_master.h"

using namespace frep;
using namespace frep::farm;

extern char** environ;

namespace {

const char* kModel = R"(
-- a block with a spherical bite and a blended bump: enough bricks with surface in them
my_model(x[3], a[1]) {
  array c[3], v[3];
  c = [0.3, 0.2, 0.4];
  v = [-0.7, -0.6, -0.5];
  b = hfBlock(x, v, 1.4, 1.2, 1.0);
  ball = hfSphere(x, c, 0.45);
  my_model = b \ ball;
}
)";

JobSpec job(int res) {
  JobSpec j;
  j.set_operation("sample");
  j.set_model_source(kModel);
  j.set_model_name("test.hf");
  GridSpec g = GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, res);
  for (int a = 0; a < 3; ++a) {
    j.add_origin(g.origin[a]);
    j.add_dims(g.dims[a]);
  }
  j.set_voxel(g.voxel);
  j.set_band(3);
  return j;
}

void expectSame(const SampleResult& a, const SampleResult& b) {
  ASSERT_EQ(a.leaves.size(), b.leaves.size());
  for (size_t i = 0; i < a.leaves.size(); ++i) {
    ASSERT_EQ(a.leaves[i].origin, b.leaves[i].origin);
    ASSERT_EQ(a.leaves[i].values, b.leaves[i].values);
    ASSERT_EQ(a.leaves[i].active, b.leaves[i].active);
  }
  ASSERT_EQ(a.tiles.size(), b.tiles.size());
  for (size_t i = 0; i < a.tiles.size(); ++i) {
    ASSERT_EQ(a.tiles[i].origin, b.tiles[i].origin);
    ASSERT_EQ(a.tiles[i].size, b.tiles[i].size);
    ASSERT_EQ(a.tiles[i].inside, b.tiles[i].inside);
  }
}

FarmOptions fast(int workers) {
  FarmOptions o;
  o.workers = workers;
  o.brickVoxels = 32;
  o.heartbeatMs = 100;
  o.liveness = 5;
  o.workerExecutable = FREP_WORKER_PATH;
  o.noWorkerTimeoutSec = 30;
  return o;
}

// A worker process started by the test (cluster-mode style), so the test can signal it.
struct WorkerProcess {
  pid_t pid = 0;
  WorkerProcess(const std::string& endpoint, std::vector<std::string> env = {}) {
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

// Runs the master on a fixed loopback port in a thread; returns when the job ends.
struct MasterThread {
  FarmOutcome outcome;
  std::string error;
  std::thread thread;
  MasterThread(const JobSpec& j, FarmOptions o) {
    thread = std::thread([this, j, o] {
      try {
        outcome = runSampleJob(j, o);
      } catch (const std::exception& e) {
        error = e.what();
      }
    });
  }
  void join() { thread.join(); }
};

int freePort() {
  static int next = 20000 + (getpid() % 5000) * 2;
  return next++;
}

}  // namespace

TEST(Farm, InProcessEqualsDirectSampling) {
  JobSpec j = job(96);
  FarmOutcome o = runSampleJob(j, fast(0));
  TapePtr tape = compileJobModel(j);
  SampleResult direct = sample(tape, gridOf(j));
  // Bricks tile differently than one octree, so compare leaves only here.
  ASSERT_EQ(o.result.leaves.size(), direct.leaves.size());
  for (size_t i = 0; i < direct.leaves.size(); ++i) {
    ASSERT_EQ(o.result.leaves[i].origin, direct.leaves[i].origin);
    ASSERT_EQ(o.result.leaves[i].values, direct.leaves[i].values);
  }
  EXPECT_EQ(o.report.bricks, 27u);
  EXPECT_EQ(o.report.bricksComputed, 27u);
}

TEST(Farm, OneTwoAndFourWorkersGiveTheInProcessResult) {
  JobSpec j = job(96);
  FarmOutcome ref = runSampleJob(j, fast(0));
  for (int w : {1, 2, 4}) {
    FarmOutcome o = runSampleJob(j, fast(w));
    SCOPED_TRACE(w);
    expectSame(ref.result, o.result);
    EXPECT_EQ(o.report.bricksComputed, ref.report.bricks);
    EXPECT_EQ(o.report.pointEvals, ref.report.pointEvals);
    EXPECT_TRUE(o.report.poisoned.empty());
  }
}

TEST(Farm, WorkerKilledMidBrickIsReplaced) {
  JobSpec j = job(96);
  FarmOutcome ref = runSampleJob(j, fast(0));
  FarmOptions o = fast(0);
  o.listen = "tcp://127.0.0.1:" + std::to_string(freePort());
  MasterThread m(j, o);
  WorkerProcess steady(o.listen, {"FREP_TEST_SLOW_MS=30"});
  WorkerProcess victim(o.listen, {"FREP_TEST_SLOW_MS=400"});
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // victim holds a brick now
  kill(victim.pid, SIGKILL);
  victim.wait();
  m.join();
  ASSERT_EQ(m.error, "");
  expectSame(ref.result, m.outcome.result);
  EXPECT_GE(m.outcome.report.deadWorkers, 1u);
  EXPECT_GE(m.outcome.report.retries, 1u);
}

TEST(Farm, StoppedWorkerPastLivenessThenContinuedChangesNothing) {
  JobSpec j = job(96);
  FarmOutcome ref = runSampleJob(j, fast(0));
  FarmOptions o = fast(0);
  o.listen = "tcp://127.0.0.1:" + std::to_string(freePort());
  MasterThread m(j, o);
  WorkerProcess steady(o.listen, {"FREP_TEST_SLOW_MS=40"});
  WorkerProcess sleeper(o.listen, {"FREP_TEST_SLOW_MS=40"});
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(sleeper.pid, SIGSTOP);
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));  // > 5 x 100 ms liveness
  kill(sleeper.pid, SIGCONT);
  m.join();
  ASSERT_EQ(m.error, "");
  expectSame(ref.result, m.outcome.result);
  EXPECT_GE(m.outcome.report.deadWorkers, 1u);
}

TEST(Farm, SigtermedWorkerHandsItsBrickBack) {
  JobSpec j = job(96);
  FarmOutcome ref = runSampleJob(j, fast(0));
  FarmOptions o = fast(0);
  o.listen = "tcp://127.0.0.1:" + std::to_string(freePort());
  MasterThread m(j, o);
  WorkerProcess steady(o.listen, {"FREP_TEST_SLOW_MS=30"});
  WorkerProcess leaver(o.listen, {"FREP_TEST_SLOW_MS=500"});
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  kill(leaver.pid, SIGTERM);
  EXPECT_EQ(leaver.wait(), 0);
  m.join();
  ASSERT_EQ(m.error, "");
  expectSame(ref.result, m.outcome.result);
  EXPECT_GE(m.outcome.report.handedBack, 1u);
}

TEST(Farm, BrickThatKillsWorkersIsPoisonedAndNamed) {
  JobSpec j = job(64);
  FarmOptions o = fast(2);
  setenv("FREP_TEST_CRASH_BRICK", "3", 1);
  FarmOutcome out = runSampleJob(j, o);
  unsetenv("FREP_TEST_CRASH_BRICK");
  ASSERT_EQ(out.report.poisoned.size(), 1u);
  EXPECT_EQ(out.report.poisoned[0].brick, 3u);
  EXPECT_NE(out.report.poisoned[0].error.find("died"), std::string::npos);
  EXPECT_EQ(out.report.bricksComputed, out.report.bricks - 1);  // the rest finished
}

TEST(Farm, ResumeRecomputesOnlyUnjournaledBricks) {
  JobSpec j = job(96);
  FarmOutcome ref = runSampleJob(j, fast(0));
  std::string journal = std::filesystem::temp_directory_path() / ("frep-test-" + std::to_string(getpid()) + ".journal");
  FarmOptions o = fast(0);
  o.journalPath = journal;
  FarmOutcome first = runSampleJob(j, o);
  // Keep the header and the first 10 records, as if the master had died there.
  {
    std::ifstream in(journal, std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(in)), {});
    size_t pos = 12;
    for (int r = 0; r < 10; ++r) {
      uint64_t size;
      std::memcpy(&size, all.data() + pos + 12, 8);
      pos += 20 + size;
    }
    std::ofstream out(journal, std::ios::binary | std::ios::trunc);
    out.write(all.data(), std::streamsize(pos + 7));  // plus a torn record
  }
  o.resume = true;
  FarmOutcome resumed = runSampleJob(j, o);
  expectSame(ref.result, resumed.result);
  EXPECT_EQ(resumed.report.bricksFromJournal, 10u);
  EXPECT_EQ(resumed.report.bricksComputed, ref.report.bricks - 10);
  EXPECT_LT(resumed.report.pointEvals, ref.report.pointEvals);
  std::filesystem::remove(journal);
}

TEST(Farm, JournalOfAnotherJobIsRefused) {
  std::string journal = std::filesystem::temp_directory_path() / ("frep-test-other-" + std::to_string(getpid()) + ".journal");
  FarmOptions o = fast(0);
  o.journalPath = journal;
  runSampleJob(job(40), o);
  o.resume = true;
  EXPECT_THROW(runSampleJob(job(48), o), std::runtime_error);
  std::filesystem::remove(journal);
}

TEST(Farm, StragglerBrickIsIssuedOnceMoreToAnIdleWorker) {
  JobSpec j = job(64);
  FarmOutcome ref = runSampleJob(j, fast(0));
  FarmOptions o = fast(0);
  o.listen = "tcp://127.0.0.1:" + std::to_string(freePort());
  MasterThread m(j, o);
  // The slow worker joins first and takes the first bricks; the fast one finishes the rest,
  // then gets a copy of the oldest brick still running (after max(1 s, 2 x median)).
  WorkerProcess slow(o.listen, {"FREP_TEST_SLOW_MS=4000"});
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  WorkerProcess quick(o.listen);
  m.join();
  ASSERT_EQ(m.error, "");
  expectSame(ref.result, m.outcome.result);
  EXPECT_GE(m.outcome.report.stragglerReissues, 1u);
  EXPECT_EQ(m.outcome.report.retries, 0u);  // nothing failed: the copies were backups
}
