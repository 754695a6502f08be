// Faults that are nobody's attack (docs/farm.md, "Faults"): workers that keep dying on
// whatever brick they hold (churn) must not poison innocent bricks, a master that was itself
// stopped must not count its workers dead, and the embedded farm respawns its workers with
// back-off while bricks finish and fails fast when none can.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "farm_test_util.h"

using namespace farmtest;

namespace {

void expectSame(const SampleResult& ref, const SampleResult& got) {
  ASSERT_EQ(got.leaves.size(), ref.leaves.size());
  for (size_t i = 0; i < ref.leaves.size(); ++i) {
    ASSERT_EQ(got.leaves[i].origin, ref.leaves[i].origin);
    ASSERT_EQ(got.leaves[i].values, ref.leaves[i].values);
  }
  ASSERT_EQ(got.tiles.size(), ref.tiles.size());
}

// FNV-1a of the leaves and tiles, to compare a result across a process boundary.
uint64_t digest(const SampleResult& r) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  for (auto& l : r.leaves) {
    mix(l.origin.data(), sizeof l.origin);
    mix(l.values.data(), sizeof l.values);
    mix(l.active.data(), sizeof l.active);
  }
  for (auto& t : r.tiles) {  // field by field: a Tile has padding
    mix(t.origin.data(), sizeof t.origin);
    mix(&t.size, sizeof t.size);
    mix(&t.inside, sizeof t.inside);
  }
  return h;
}

}  // namespace

// Every worker dies on the brick after its first (FREP_TEST_DIE_AFTER=1), one worker after
// another: deaths land on different bricks. Before, each death charged both bricks the worker
// held and the bricks retried first were charged again until poisoned.
TEST(Faults, ChurnOfWorkersDyingOnRandomBricksPoisonsNothing) {
  JobSpec j = partJob("sample", 64);  // 8 bricks of 32
  FarmOutcome ref = runJob(j, fast(0));
  FarmOptions o = fast(0);
  o.liveness = 3;
  MasterThread m(j, o);
  const std::string ep = m.endpoint();
  int deaths = 0;
  for (int k = 0; k < 60 && !m.finished; ++k) {
    WorkerProcess w(ep, {"FREP_TEST_DIE_AFTER=1"});
    if (w.wait(30) == 128 + SIGABRT) ++deaths;
  }
  m.join();
  ASSERT_EQ(m.error, "");
  const FarmReport& r = m.outcome.report;
  EXPECT_TRUE(r.poisoned.empty()) << r.poisoned.size() << " brick(s) poisoned by churn";
  EXPECT_GE(deaths, 4);
  EXPECT_EQ(r.bricksComputed, r.bricks);
  expectSame(ref.result, m.outcome.result);
}

// The embedded farm under the same churn: its workers are respawned as long as bricks finish
// (before: 15 respawns, then it idled until the no-worker timeout).
TEST(Faults, EmbeddedFarmRespawnsDyingWorkersWhileBricksFinish) {
  JobSpec j = partJob("sample", 96);  // 27 bricks of 32: more than 15 respawns
  FarmOutcome ref = runJob(j, fast(0));
  setenv("FREP_TEST_DIE_AFTER", "1", 1);
  FarmOutcome out = runJob(j, fast(2));
  unsetenv("FREP_TEST_DIE_AFTER");
  EXPECT_TRUE(out.report.poisoned.empty());
  EXPECT_GE(out.report.deadWorkers, 10u);
  expectSame(ref.result, out.result);
}

// Workers that can never finish a brick (they exit at once): fail fast with a clear message
// (frep exits 7), instead of idling until the no-worker timeout.
TEST(Faults, EmbeddedFarmFailsFastWhenNoWorkerCanFinishABrick) {
  JobSpec j = partJob("sample", 64);
  FarmOptions o = fast(2);
  o.workerExecutable = "/bin/false";
  o.noWorkerTimeoutSec = 60;
  auto t0 = std::chrono::steady_clock::now();
  try {
    runJob(j, o);
    ADD_FAILURE() << "the job ended without workers";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("local workers keep dying"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exited with 1"), std::string::npos) << e.what();
  }
  std::printf("failed after %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

// The master itself is stopped (SIGSTOP) for three liveness windows in the middle of a job:
// its workers' silence was its own. Before, it counted them dead when it woke (and they, having
// reconnected under new connections, lost their leases).
TEST(Faults, StoppedMasterDoesNotCountItsWorkersDead) {
  // fork() is safe only in a process with one thread (ctest runs each test in its own).
  if (std::distance(std::filesystem::directory_iterator("/proc/self/task"), std::filesystem::directory_iterator{}) > 1)
    GTEST_SKIP() << "needs a process of its own (run it alone, as ctest does)";
  JobSpec j = partJob("sample", 96);  // 27 bricks
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  StartedFile started("stopped_master");  // a worker of the child's holds a brick
  pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the master, with two local workers that take 60 ms a brick
    close(fds[0]);
    setenv("FREP_TEST_SLOW_MS", std::to_string(scaledMs(60)).c_str(), 1);
    setenv("FREP_TEST_STARTED_FILE", started.path.c_str(), 1);
    char line[256];
    try {
      FarmOutcome out = runJob(j, fast(2));
      std::snprintf(line, sizeof line, "%llu %llu %llu %zu\n", (unsigned long long)digest(out.result),
                    (unsigned long long)out.report.deadWorkers, (unsigned long long)out.report.masterStalls,
                    out.report.poisoned.size());
    } catch (const std::exception& e) {
      std::snprintf(line, sizeof line, "error %s\n", e.what());
    }
    ssize_t n = write(fds[1], line, strlen(line));
    _exit(n > 0 ? 0 : 1);
  }
  close(fds[1]);
  EXPECT_TRUE(started.wait());  // workers joined, bricks running
  kill(child, SIGSTOP);
  // The stall itself is under test: the master must stay stopped for longer than the liveness
  // window (0.5 s, scaled), three windows as the test says; nothing to wait for but time.
  std::this_thread::sleep_for(scaled(std::chrono::milliseconds(1500)));
  kill(child, SIGCONT);
  std::string got;
  char buf[256];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) got.append(buf, size_t(n));
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  // The in-process reference only now: it starts TBB's threads, and a fork after that could
  // leave the child's thread pool locked.
  const uint64_t want = digest(runJob(j, fast(0)).result);
  unsigned long long hash = 0, dead = 0, stalls = 0;
  size_t poisoned = 0;
  ASSERT_EQ(std::sscanf(got.c_str(), "%llu %llu %llu %zu", &hash, &dead, &stalls, &poisoned), 4) << got;
  EXPECT_EQ(hash, want);
  EXPECT_EQ(dead, 0u);
  EXPECT_GE(stalls, 1u);
  EXPECT_EQ(poisoned, 0u);
}
