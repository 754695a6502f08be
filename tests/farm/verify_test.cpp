// --verify (docs/farm.md, "Verification"): a forging peer — a leased worker that returns well-formed
// results with wrong values — against the master's verification. Without --verify its bricks
// change the output (the documented gap); with --verify 1 nothing it returns is merged and it is
// banned; --verify 0.25 catches a peer that forges every brick (made certain here by the seed:
// the first brick it forges is in the sample), and every brick it had merged is computed again,
// even those already streamed to the sink (merged once more from the journal).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>
#include <zmq.hpp>

#include "farm_test_util.h"
#include "frep/master/journal.h"
#include "frep/net/wire.h"

using namespace farmtest;

namespace {

// sphereJob() (64^3 voxels) in bricks of 16: 64 bricks, 4 x-slabs of 16.
constexpr int kBricks = 64, kPerSlab = 16;

FarmOptions clusterOptions(double verify, uint64_t seed = 0) {
  FarmOptions o;
  o.brickVoxels = 16;
  o.heartbeatMs = scaledMs(100);
  o.liveness = 5;
  o.noWorkerTimeoutSec = scaledSec(20);
  o.verifyFraction = verify;
  o.verifySeed = seed;
  return o;
}

SampleResult reference(const JobSpec& j) {
  FarmOptions o = clusterOptions(-1);
  o.workers = 0;
  return runJob(j, o).result;
}

bool sameLeaves(const std::vector<LeafBlock>& a, const std::vector<LeafBlock>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].origin != b[i].origin || a[i].values != b[i].values || a[i].active != b[i].active) return false;
  return true;
}

// The bricks of the sample for this job, seed and fraction.
std::set<uint64_t> sampleOf(const JobSpec& j, uint64_t seed, double fraction) {
  std::set<uint64_t> s;
  for (uint64_t b = 0; b < kBricks; ++b)
    if (verifySelected(jobIdOf(j), seed, b, fraction)) s.insert(b);
  return s;
}

// A peer that answers every task at once with a well-formed result (right CRC, a leaf inside the
// brick) whose values are a lie, on its own thread, until the master says bye (or `stop`).
struct ForgingPeer {
  std::atomic<bool> stop{false}, gotBye{false};
  std::atomic<int> forged{0};
  std::thread thread;
  ForgingPeer(const std::string& ep, const std::string& id) {
    thread = std::thread([this, ep, id] {
      zmq::context_t ctx(1);
      zmq::socket_t s(ctx, zmq::socket_type::dealer);
      s.set(zmq::sockopt::linger, 200);
      s.set(zmq::sockopt::routing_id, id);
      s.connect(ep);
      Envelope hello;
      hello.mutable_hello()->set_worker_id(id);
      send(s, "", hello);
      auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
      while (!stop && !gotBye && std::chrono::steady_clock::now() < deadline) {
        zmq::pollitem_t item{static_cast<void*>(s), 0, ZMQ_POLLIN, 0};
        zmq::poll(&item, 1, std::chrono::milliseconds(20));
        Incoming in;
        std::string err;
        while (receive(s, false, in, &err)) {
          if (!err.empty()) continue;
          if (in.envelope.body_case() == Envelope::kBye) gotBye = true;
          if (in.envelope.body_case() != Envelope::kTask) continue;
          const Task& t = in.envelope.task();
          BrickOutput out;
          LeafBlock l = LeafBlock::cleared();
          l.origin = {t.lo(0), t.lo(1), t.lo(2)};
          l.values.fill(42.0f);
          l.active.fill(~0ull);
          out.leaves.push_back(l);
          std::string payload = encodePayload(Operation::Sample, out);
          Envelope r;
          r.set_job_id(in.envelope.job_id());
          r.mutable_result()->set_brick_id(t.brick_id());
          r.mutable_result()->set_leaves(1);
          r.mutable_result()->set_payload_crc32(crc32Of(payload.data(), payload.size()));
          send(s, "", r, &payload);
          ++forged;
        }
        Envelope hb;
        hb.mutable_heartbeat();
        send(s, "", hb);
      }
    });
  }
  void waitForged(int n) {
    waitUntil([&] { return forged >= n; }, std::chrono::seconds(5));
  }
  ~ForgingPeer() {
    stop = true;
    if (thread.joinable()) thread.join();
  }
};

uint64_t mergedFrom(const FarmReport& r, const std::string& worker) {
  auto it = r.perWorker.find(worker);
  return it == r.perWorker.end() ? 0 : it->second.bricks;
}

}  // namespace

// The gap --verify closes: a leased peer's well-formed lies are merged (issue 31: 80 of 125
// bricks of a mesh job). Here the forger joins first and forges what it is leased.
TEST(Verify, WithoutVerifyAForgingPeerChangesTheOutput) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  MasterThread master(j, clusterOptions(-1));
  const std::string ep = master.endpoint();
  ForgingPeer forger(ep, "forger");
  forger.waitForged(8);
  WorkerProcess honest(ep);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty());
  EXPECT_GE(mergedFrom(r, "forger"), 8u);
  EXPECT_EQ(r.liarsBanned, 0u);
  EXPECT_FALSE(sameLeaves(ref.leaves, master.outcome.result.leaves)) << "the forged values were not merged";
  std::printf("[ forging  ] without --verify: %llu of %d bricks merged from the forger\n",
              static_cast<unsigned long long>(mergedFrom(r, "forger")), kBricks);
}

// --verify 1: every brick is merged only once two distinct workers returned the same bytes. The
// forger forges every brick before the honest workers join; the first brick they decide convicts
// it, and nothing it returned is merged.
TEST(Verify, VerifyOneMergesOnlyWhatTwoWorkersAgreeOnAndBansTheForger) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  MasterThread master(j, clusterOptions(1));
  const std::string ep = master.endpoint();
  ForgingPeer forger(ep, "forger");
  forger.waitForged(16);
  WorkerProcess a(ep), b(ep);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty());
  EXPECT_EQ(r.liarsBanned, 1u);
  EXPECT_GE(r.verifyMismatches, 1u);
  EXPECT_EQ(r.verifiedBricks, uint64_t(kBricks));
  EXPECT_EQ(mergedFrom(r, "forger"), 0u);
  EXPECT_EQ(r.bricksRedone, 0u) << "nothing of the forger's was merged, so nothing is redone";
  EXPECT_TRUE(forger.gotBye);
  EXPECT_TRUE(sameLeaves(ref.leaves, master.outcome.result.leaves));
  std::printf("[ forging  ] --verify 1: the forger forged %d results, 0 merged; %llu mismatches, banned\n",
              forger.forged.load(), static_cast<unsigned long long>(r.verifyMismatches));
}

// --verify 0.25 and a peer that forges every brick: it is caught at the first brick of the
// sample it returns (certain here: the seed puts brick 0, the first it is leased, in the sample;
// without a chosen seed, a peer that returned k bricks escapes with probability 0.75^k), and the
// bricks it had merged unchecked are computed again by the others.
TEST(Verify, AQuarterCatchesAPeerThatForgesEveryBrick) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  uint64_t seed = 1;
  while (!verifySelected(jobIdOf(j), seed, 0, 0.25)) ++seed;
  const std::set<uint64_t> sample = sampleOf(j, seed, 0.25);
  MasterThread master(j, clusterOptions(0.25, seed));
  const std::string ep = master.endpoint();
  ForgingPeer forger(ep, "forger");
  forger.waitForged(24);
  WorkerProcess a(ep), b(ep);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty());
  EXPECT_EQ(r.liarsBanned, 1u);
  EXPECT_EQ(r.verifiedBricks, sample.size()) << "the sample is the seed's";
  EXPECT_GE(r.bricksRedone, 1u);
  EXPECT_EQ(mergedFrom(r, "forger"), 0u);
  EXPECT_EQ(r.bricksComputed, uint64_t(kBricks));
  EXPECT_TRUE(sameLeaves(ref.leaves, master.outcome.result.leaves));
  std::printf("[ forging  ] --verify 0.25 (%zu of %d bricks in the sample): the forger forged %d results, %llu had "
              "been merged and were computed again; banned\n",
              sample.size(), kBricks, forger.forged.load(), static_cast<unsigned long long>(r.bricksRedone));
}

// Streaming to a sink: the forger's bricks fill slab 0 (none of it in the sample, by the seed),
// which is streamed before the forger is caught on slab 1. Its values must not stay in the
// output: the sink is restarted and the job merged once more from the journal, where the forged
// records were revoked and computed again.
TEST(Verify, AForgerCaughtAfterItsSlabWasStreamedIsMergedAgainFromTheJournal) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  uint64_t seed = 1;
  auto slab0Clear = [&](uint64_t s) {
    for (uint64_t b = 0; b < kPerSlab; ++b)
      if (verifySelected(jobIdOf(j), s, b, 0.25)) return false;
    return verifySelected(jobIdOf(j), s, kPerSlab, 0.25);
  };
  while (!slab0Clear(seed)) ++seed;
  const std::string dir = ::testing::TempDir() + "verify_stream/";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  FarmOptions o = clusterOptions(0.25, seed);
  o.journalPath = dir + "out.journal";
  std::vector<LeafBlock> streamed;
  int restarts = 0;
  o.sampleSink.leaves = [&](const std::vector<LeafBlock>& leaves) { streamed.insert(streamed.end(), leaves.begin(), leaves.end()); };
  o.sampleSink.restart = [&] {
    ++restarts;
    streamed.clear();
  };
  MasterThread master(j, o);
  const std::string ep = master.endpoint();
  ForgingPeer forger(ep, "forger");
  forger.waitForged(kPerSlab + 8);
  WorkerProcess a(ep), b(ep);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty());
  EXPECT_EQ(r.liarsBanned, 1u);
  EXPECT_GE(r.bricksRedone, uint64_t(kPerSlab));
  EXPECT_TRUE(r.restreamed);
  EXPECT_EQ(restarts, 1);
  EXPECT_EQ(r.leaves, ref.leaves.size());
  EXPECT_TRUE(sameLeaves(ref.leaves, streamed)) << "the forged slab stayed in the stream";
}

// Honest workers agree: --verify F checks exactly the seed's sample (the same bricks for the same
// job and seed), 1 checks every brick, and the output is the unchecked run's. One local worker
// cannot be checked: said in the report, merged as before.
TEST(Verify, HonestWorkersAgreeOnTheSeedsSample) {
  JobSpec j = partJob("sample", 64);
  FarmOptions plain = fast(2, 16);
  FarmOutcome ref = runJob(j, plain);
  for (double f : {0.3, 1.0}) {
    FarmOptions o = fast(2, 16);
    o.verifyFraction = f;
    o.verifySeed = 7;
    FarmOutcome got = runJob(j, o);
    SCOPED_TRACE("--verify " + std::to_string(f));
    size_t expected = 0;
    for (uint64_t b = 0; b < got.report.bricks; ++b) expected += verifySelected(jobIdOf(j), 7, b, f);
    EXPECT_EQ(got.report.verifiedBricks, expected);
    EXPECT_EQ(got.report.verifyMismatches, 0u);
    EXPECT_EQ(got.report.liarsBanned, 0u);
    EXPECT_EQ(got.report.verifySeed, 7u);
    EXPECT_TRUE(got.report.verifyUnavailable.empty());
    EXPECT_TRUE(sameLeaves(ref.result.leaves, got.result.leaves));
  }
  FarmOptions one = fast(1, 16);
  one.verifyFraction = 1;
  FarmOutcome lone = runJob(j, one);
  EXPECT_EQ(lone.report.verifiedBricks, 0u);
  EXPECT_NE(lone.report.verifyUnavailable.find("one local worker"), std::string::npos) << lone.report.verifyUnavailable;
  EXPECT_NE(lone.report.toJson().find("\"unavailable\": \"one local worker"), std::string::npos);
  EXPECT_TRUE(sameLeaves(ref.result.leaves, lone.result.leaves));
}

TEST(Verify, MeshPiecesAgreeToo) {
  JobSpec j = partJob("mesh", 48);
  FarmOutcome ref = runJob(j, fast(2, 16));
  FarmOptions o = fast(2, 16);
  o.verifyFraction = 1;
  FarmOutcome got = runJob(j, o);
  EXPECT_EQ(got.report.verifiedBricks, got.report.bricks);
  EXPECT_EQ(got.report.verifyMismatches, 0u);
  EXPECT_EQ(got.mesh.positions, ref.mesh.positions);
  EXPECT_EQ(got.mesh.triangles, ref.mesh.triangles);
}

// The sample's seed goes to the journal: a resumed job (whose options name no seed) checks the
// same bricks as the run it continues.
TEST(Verify, AResumedJobChecksTheSameBricks) {
  JobSpec j = partJob("sample", 64);
  const std::string dir = ::testing::TempDir() + "verify_resume/";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  FarmOptions o = fast(2, 16);
  o.journalPath = dir + "out.journal";
  o.verifyFraction = 0.5;
  FarmOutcome first = runJob(j, o);
  ASSERT_NE(first.report.verifySeed, 0u);
  // Keep the seed's record and 10 bricks' records.
  tearJournal(o.journalPath, 11, 0);
  std::set<uint64_t> journaled;
  {
    std::ifstream in(o.journalPath, std::ios::binary);
    in.seekg(12);
    uint64_t brick = 0, size = 0;
    uint32_t crc = 0;
    while (in.read(reinterpret_cast<char*>(&brick), 8) && in.read(reinterpret_cast<char*>(&crc), 4) &&
           in.read(reinterpret_cast<char*>(&size), 8)) {
      if (brick != kJournalVerifySeed) journaled.insert(brick);
      in.seekg(std::streamoff(size), std::ios::cur);
    }
  }
  ASSERT_EQ(journaled.size(), 10u);
  o.resume = true;
  FarmOutcome resumed = runJob(j, o);
  EXPECT_EQ(resumed.report.verifySeed, first.report.verifySeed);
  size_t expected = 0;
  for (uint64_t b = 0; b < resumed.report.bricks; ++b)
    expected += !journaled.count(b) && verifySelected(jobIdOf(j), first.report.verifySeed, b, 0.5);
  EXPECT_EQ(resumed.report.bricksFromJournal, 10u);
  EXPECT_EQ(resumed.report.verifiedBricks, expected);
  EXPECT_TRUE(sameLeaves(first.result.leaves, resumed.result.leaves));
}

// Two workers that disagree and no third to decide: no majority, so the bricks are poisoned
// (named) after the no-worker timeout rather than merged either way. A lone cluster worker's
// checked bricks are merged unchecked after it, and the report says verification could not run.
TEST(Verify, WithoutAThirdWorkerADisagreementPoisonsAndALoneWorkerIsMergedUnchecked) {
  JobSpec j = sphereJob();
  {
    FarmOptions o = clusterOptions(1);
    o.noWorkerTimeoutSec = scaledSec(2);
    MasterThread master(j, o);
    const std::string ep = master.endpoint();
    ForgingPeer forger(ep, "forger");
    forger.waitForged(4);
    WorkerProcess honest(ep);
    master.join();
    ASSERT_EQ(master.error, "");
    const FarmReport& r = master.outcome.report;
    EXPECT_EQ(r.poisoned.size(), size_t(kBricks));
    for (const PoisonedBrick& p : r.poisoned)
      EXPECT_NE(p.error.find("returned different results and no other worker joined"), std::string::npos) << p.error;
    EXPECT_EQ(r.liarsBanned, 0u);
  }
  {
    FarmOptions o = clusterOptions(0.5, 3);
    o.noWorkerTimeoutSec = scaledSec(2);
    MasterThread master(j, o);
    WorkerProcess lone(master.endpoint());
    master.join();
    ASSERT_EQ(master.error, "");
    const FarmReport& r = master.outcome.report;
    EXPECT_TRUE(r.poisoned.empty());
    EXPECT_EQ(r.unverifiedBricks, sampleOf(j, 3, 0.5).size());
    EXPECT_NE(r.verifyUnavailable.find("no second worker"), std::string::npos) << r.verifyUnavailable;
    EXPECT_TRUE(sameLeaves(reference(j).leaves, master.outcome.result.leaves));
  }
}
