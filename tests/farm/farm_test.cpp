// The farm against the in-process run: identical leaves and tiles for any worker count, and
// through worker faults (workers started and abused by the test itself, master in this process).
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "farm_test_util.h"

using namespace farmtest;

namespace {

JobSpec job(int res) { return partJob("sample", res); }

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

}  // namespace

TEST(Farm, InProcessEqualsDirectSampling) {
  JobSpec j = job(96);
  FarmOutcome o = runJob(j, fast(0));
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
  FarmOutcome ref = runJob(j, fast(0));
  // With 4 workers also decoding on the scheduling loop alone (decodeThreads 1), as before the
  // decode threads: the same bytes either way.
  for (auto [w, decodeThreads] : {std::pair{1, 0}, {2, 0}, {4, 0}, {4, 1}}) {
    FarmOptions opt = fast(w);
    opt.decodeThreads = decodeThreads;
    FarmOutcome o = runJob(j, opt);
    SCOPED_TRACE(std::to_string(w) + " workers, decodeThreads " + std::to_string(decodeThreads));
    expectSame(ref.result, o.result);
    EXPECT_EQ(o.report.bricksComputed, ref.report.bricks);
    EXPECT_EQ(o.report.pointEvals, ref.report.pointEvals);
    EXPECT_TRUE(o.report.poisoned.empty());
  }
}

TEST(Farm, WorkerKilledMidBrickIsReplaced) {
  JobSpec j = job(96);
  FarmOutcome ref = runJob(j, fast(0));
  FarmOptions o = fast(0);
  MasterThread m(j, o);
  WorkerProcess steady(m.endpoint(), {slowMs(30)});
  StartedFile victimStarted("victim");
  WorkerProcess victim(m.endpoint(), {slowMs(400), victimStarted.env()});
  ASSERT_TRUE(victimStarted.wait()) << "the victim never started a brick";  // it holds one now
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
  FarmOutcome ref = runJob(j, fast(0));
  FarmOptions o = fast(0);
  LogWatch log;
  MasterThread m(j, o);
  // The sleeper starts alone and is stopped once it holds a brick (a fixed delay missed that on
  // a loaded machine); the steady worker then has to finish the job.
  StartedFile started("sleeper");
  WorkerProcess sleeper(m.endpoint(), {slowMs(40), started.env()});
  ASSERT_TRUE(started.wait()) << "the worker never started a brick";
  kill(sleeper.pid, SIGSTOP);
  WorkerProcess steady(m.endpoint(), {slowMs(40)});
  // It stays stopped until the master has counted it dead (5 x 100 ms of silence), unless the
  // job ended first.
  waitUntil([&] { return m.finished || log.count("silent past its liveness window") > 0; });
  kill(sleeper.pid, SIGCONT);
  m.join();
  ASSERT_EQ(m.error, "");
  expectSame(ref.result, m.outcome.result);
  EXPECT_GE(m.outcome.report.deadWorkers, 1u);
}

TEST(Farm, SigtermedWorkerHandsItsBrickBack) {
  JobSpec j = job(96);
  FarmOutcome ref = runJob(j, fast(0));
  FarmOptions o = fast(0);
  MasterThread m(j, o);
  WorkerProcess steady(m.endpoint(), {slowMs(30)});
  StartedFile leaverStarted("leaver");
  WorkerProcess leaver(m.endpoint(), {slowMs(500), leaverStarted.env()});
  ASSERT_TRUE(leaverStarted.wait()) << "the leaver never started a brick";  // it holds one now
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
  FarmOutcome out = runJob(j, o);
  unsetenv("FREP_TEST_CRASH_BRICK");
  ASSERT_EQ(out.report.poisoned.size(), 1u);
  EXPECT_EQ(out.report.poisoned[0].brick, 3u);
  EXPECT_NE(out.report.poisoned[0].error.find("died"), std::string::npos);
  EXPECT_EQ(out.report.bricksComputed, out.report.bricks - 1);  // the rest finished
}

TEST(Farm, ResumeRecomputesOnlyUnjournaledBricks) {
  JobSpec j = job(96);
  FarmOutcome ref = runJob(j, fast(0));
  std::string journal = std::filesystem::temp_directory_path() / ("frep-test-" + std::to_string(getpid()) + ".journal");
  FarmOptions o = fast(0);
  o.journalPath = journal;
  FarmOutcome first = runJob(j, o);
  tearJournal(journal, 10, 7);  // the first 10 records and a torn one
  o.resume = true;
  FarmOutcome resumed = runJob(j, o);
  expectSame(ref.result, resumed.result);
  EXPECT_EQ(resumed.report.bricksFromJournal, 10u);
  EXPECT_EQ(resumed.report.bricksComputed, ref.report.bricks - 10);
  EXPECT_LT(resumed.report.pointEvals, ref.report.pointEvals);
  std::filesystem::remove(journal);
}

// With a journal, the master keeps merged "sample" payloads as received up to
// FarmOptions::heldPayloadBytes and reads the others back from the journal for the merge: the
// same bytes whether it holds all of them, some (a budget of a few payloads) or none.
TEST(Farm, HeldOrReadBackPayloadsMergeToTheSameResult) {
  JobSpec j = job(96);
  FarmOutcome ref = runJob(j, fast(0));
  const std::string journal =
      std::filesystem::temp_directory_path() / ("frep-test-held-" + std::to_string(getpid()) + ".journal");
  for (size_t budget : {size_t(256) << 20, size_t(100) << 10, size_t(0)}) {
    FarmOptions o = fast(2);
    o.journalPath = journal;
    o.heldPayloadBytes = budget;
    FarmOutcome got = runJob(j, o);
    SCOPED_TRACE("held payload budget " + std::to_string(budget));
    expectSame(ref.result, got.result);
    EXPECT_TRUE(got.report.poisoned.empty());
  }
  std::filesystem::remove(journal);
}

// A payload the master reads back from its journal for the merge (docs/farm.md,
// "Back-pressure"; all of them here, heldPayloadBytes 0) that changed after it was written is
// refused by the CRC-32 it was verified with (an I/O error naming the journal and the brick),
// never merged.
TEST(Farm, AJournalRecordChangedBeforeTheMergeIsRefused) {
  const std::string journal =
      std::filesystem::temp_directory_path() / ("frep-test-changed-" + std::to_string(getpid()) + ".journal");
  FarmOptions o = fast(0);
  o.journalPath = journal;
  o.heldPayloadBytes = 0;
  MasterThread m(job(96), o);  // 27 bricks, one slow worker: the job lasts seconds after its first record
  WorkerProcess w(m.endpoint(), {slowMs(200)});
  const std::uintmax_t firstPayload = 12 + 20;  // journal header, then the first record's
  auto firstRecordWritten = [&] {  // its header and its whole payload
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(journal, ec);
    if (ec || size < firstPayload) return false;
    uint64_t payloadSize = 0;
    std::ifstream in(journal, std::ios::binary);
    in.seekg(12 + 12);
    in.read(reinterpret_cast<char*>(&payloadSize), sizeof payloadSize);
    return in && payloadSize >= 4 && size >= firstPayload + payloadSize;
  };
  waitUntil([&] { return m.finished || firstRecordWritten(); }, std::chrono::seconds(60));
  kill(w.pid, SIGSTOP);  // no more bricks meanwhile, however slow this thread was
  const bool late = m.finished;
  {
    std::fstream f(journal, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(firstPayload));
    f.put('X');  // the payload's magic, "FRB2", which every payload has
  }
  kill(w.pid, SIGCONT);
  m.join();
  if (late) GTEST_SKIP() << "the job ended before its journal could be changed (this thread stalled for seconds)";
  EXPECT_NE(m.error.find("changed after it was written"), std::string::npos) << m.error;
  std::filesystem::remove(journal);
}

TEST(Farm, JournalOfAnotherJobIsRefused) {
  std::string journal = std::filesystem::temp_directory_path() / ("frep-test-other-" + std::to_string(getpid()) + ".journal");
  FarmOptions o = fast(0);
  o.journalPath = journal;
  runJob(job(40), o);
  o.resume = true;
  EXPECT_THROW(runJob(job(48), o), std::runtime_error);
  std::filesystem::remove(journal);
}

TEST(Farm, StragglerBrickIsIssuedOnceMoreToAnIdleWorker) {
  JobSpec j = job(64);
  FarmOutcome ref = runJob(j, fast(0));
  FarmOptions o = fast(0);
  MasterThread m(j, o);
  // The slow worker joins first and takes the first bricks; the fast one finishes the rest,
  // then gets a copy of the oldest brick still running (after max(1 s, 2 x median)).
  StartedFile slowStarted("slow");
  WorkerProcess slow(m.endpoint(), {"FREP_TEST_SLOW_MS=4000", slowStarted.env()});
  ASSERT_TRUE(slowStarted.wait()) << "the slow worker never started a brick";
  WorkerProcess quick(m.endpoint());
  m.join();
  ASSERT_EQ(m.error, "");
  expectSame(ref.result, m.outcome.result);
  EXPECT_GE(m.outcome.report.stragglerReissues, 1u);
  EXPECT_EQ(m.outcome.report.retries, 0u);  // nothing failed: the copies were backups
}

TEST(Farm, ExtremumModelsReportTheirSearchesAndErrorBounds) {
  // A ball of radius 0.5 offset by 0.25 (a max over a ball of radius 0.25: Pasko-Survey offset
  // 3), branch-and-bound to within 0.05.
  JobSpec j;
  j.set_operation("sample");
  j.set_model_source(R"(
ball(x[3], a[1]) { ball = 0.25 - x[1]^2 - x[2]^2 - x[3]^2; }
my_model(x[3], a[1]) { array o[2]; o = [0, 0.05]; my_model = frOffsetR(x, ball, 0.25, o); }
)");
  j.set_model_name("offset.hf");
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 16));
  j.set_band(1);
  FarmOutcome in = runJob(j, fast(0, 8)), farm = runJob(j, fast(2, 8));
  expectSame(in.result, farm.result);
  EXPECT_GT(in.report.extremumSearches, 0u);
  EXPECT_EQ(farm.report.extremumSearches, in.report.extremumSearches);
  EXPECT_EQ(farm.report.extremumUncertified, 0u);
  ASSERT_EQ(farm.report.errorBounds.size(), 1u);
  EXPECT_NE(farm.report.errorBounds[0].find("branch-and-bound: values within 0.05"), std::string::npos)
      << farm.report.errorBounds[0];
  EXPECT_NE(farm.report.toJson().find("\"error_bounds\""), std::string::npos);
  EXPECT_EQ(farm.report.extremumSignDecided, in.report.extremumSignDecided);  // what the searches decided
  EXPECT_NE(farm.report.toJson().find("\"sign_decided\""), std::string::npos);
}
