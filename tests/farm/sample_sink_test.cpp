// FarmOptions::sampleSink: the merged sample streamed slab by slab hands over exactly the
// leaves, in exactly the order, that FarmOutcome::result.leaves holds without it, the tiles
// first, and every slab in one reused buffer.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>
#include <zmq.hpp>

#include "farm_test_util.h"

using namespace farmtest;

namespace {

// What a sink saw: the tiles, each slab's leaves and where the buffer was.
struct Streamed {
  std::vector<Tile> tiles;
  int tileCalls = 0;
  size_t leavesBeforeTiles = 0;
  std::vector<LeafBlock> leaves;
  std::vector<size_t> slabSizes;
  std::vector<const LeafBlock*> buffers;
  SampleSink sink() {
    SampleSink s;
    s.tiles = [this](const std::vector<Tile>& t) {
      ++tileCalls;
      leavesBeforeTiles = leaves.size();
      tiles = t;
    };
    s.leaves = [this](const std::vector<LeafBlock>& slab) {
      leaves.insert(leaves.end(), slab.begin(), slab.end());
      slabSizes.push_back(slab.size());
      buffers.push_back(slab.data());
    };
    return s;
  }
};

void expectSameLeaves(const std::vector<LeafBlock>& want, const std::vector<LeafBlock>& got) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(got[i].origin, want[i].origin) << "leaf " << i;
    ASSERT_EQ(got[i].values, want[i].values) << "leaf " << i;
    ASSERT_EQ(got[i].active, want[i].active) << "leaf " << i;
  }
}

void expectSameTiles(const std::vector<Tile>& want, const std::vector<Tile>& got) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(got[i].origin, want[i].origin) << "tile " << i;
    ASSERT_EQ(got[i].size, want[i].size) << "tile " << i;
    ASSERT_EQ(got[i].inside, want[i].inside) << "tile " << i;
  }
}

// The stream against the result built without a sink: same tiles (handed over once, before any
// leaf), same leaves in the same order, result.leaves empty, one slab per x-slab of bricks that
// has leaves (each within its slab), all in one buffer.
void expectStreamedAsMerged(const FarmOutcome& ref, const FarmOutcome& got, const Streamed& s, int brick) {
  EXPECT_TRUE(got.result.leaves.empty());
  EXPECT_EQ(s.tileCalls, 1);
  EXPECT_EQ(s.leavesBeforeTiles, 0u);
  expectSameTiles(ref.result.tiles, s.tiles);
  expectSameTiles(ref.result.tiles, got.result.tiles);
  expectSameLeaves(ref.result.leaves, s.leaves);
  EXPECT_EQ(got.report.leaves, ref.result.leaves.size());
  size_t at = 0;
  std::vector<int> slabsWithLeaves;
  for (const LeafBlock& l : ref.result.leaves)
    if (slabsWithLeaves.empty() || slabsWithLeaves.back() != l.origin[0] / brick) slabsWithLeaves.push_back(l.origin[0] / brick);
  ASSERT_EQ(s.slabSizes.size(), slabsWithLeaves.size());
  for (size_t k = 0; k < s.slabSizes.size(); ++k) {
    EXPECT_GT(s.slabSizes[k], 0u);
    for (size_t i = at; i < at + s.slabSizes[k]; ++i)
      ASSERT_EQ(s.leaves[i].origin[0] / brick, slabsWithLeaves[k]) << "slab " << k << ", leaf " << i;
    at += s.slabSizes[k];
    EXPECT_EQ(s.buffers[k], s.buffers[0]) << "slab " << k << " was handed over in another buffer";
  }
}

}  // namespace

// A real job (a block with a spherical bite, 3 x-slabs of 32^3 bricks), in-process and on 2
// local workers, with and without a journal.
TEST(SampleSink, StreamsTheLeavesAndTilesOfARealJobAsTheResultHoldsThem) {
  JobSpec j = partJob("sample", 96);
  FarmOutcome ref = runJob(j, fast(0));
  ASSERT_GT(ref.result.leaves.size(), 100u);
  ASSERT_FALSE(ref.result.tiles.empty());
  for (int workers : {0, 2})
    for (bool journal : {false, true}) {
      SCOPED_TRACE(std::to_string(workers) + " workers, journal " + (journal ? "on" : "off"));
      FarmOptions o = fast(workers);
      const std::string path = "/tmp/frep_sample_sink_test." + std::to_string(getpid()) + ".journal";
      std::remove(path.c_str());
      if (journal) o.journalPath = path;
      Streamed s;
      o.sampleSink = s.sink();
      FarmOutcome got = runJob(j, o);
      std::remove(path.c_str());
      expectStreamedAsMerged(ref, got, s, 32);
      EXPECT_EQ(s.slabSizes.size(), 3u);
    }
}

namespace {

// The leaves a scripted worker returns for brick `id` at `lo` (32^3 bricks, 64 leaf places):
// their count grows with x and varies by brick, x-slab 1 has none (no slab handed over), the
// places are taken in a scrambled order (the merge must sort them), each leaf's values say
// where it is; one inside tile at the last place where it is free.
BrickOutput scriptedBrick(uint64_t id, const std::array<int32_t, 3>& lo) {
  BrickOutput b;
  const int slab = lo[0] / 32;
  const int count = slab == 1 ? 0 : int((id * 7) % 13) + 10 * slab;
  for (int n = 0; n < count; ++n) {
    const int place = (n * 37 + int(id)) % 63;  // 37 is prime to 63: distinct places
    LeafBlock l = LeafBlock::cleared();
    l.origin = {lo[0] + 8 * (place / 16), lo[1] + 8 * ((place / 4) % 4), lo[2] + 8 * (place % 4)};
    for (int v = 0; v < kLeafVoxels; ++v) {
      l.values[size_t(v)] = float(l.origin[0] * 3 + l.origin[1] * 5 + l.origin[2] * 7 + v) * 1e-3f;
      if ((v + place) % 3 == 0) l.active[size_t(v >> 6)] |= uint64_t(1) << (v & 63);
    }
    b.leaves.push_back(l);
  }
  if (count < 63) b.tiles.push_back(Tile{{lo[0] + 24, lo[1] + 24, lo[2] + 24}, 8, true});
  return b;
}

// A scripted worker: answers each task at once with scriptedBrick, until told bye.
void scriptedWorker(const std::string& ep, const std::string& id, std::atomic<bool>& stop) {
  zmq::context_t ctx(1);
  zmq::socket_t s(ctx, zmq::socket_type::dealer);
  s.set(zmq::sockopt::linger, 200);
  s.connect(ep);
  Envelope hello;
  hello.mutable_hello()->set_worker_id(id);
  send(s, "", hello);
  while (!stop) {
    zmq::pollitem_t item{static_cast<void*>(s), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, std::chrono::milliseconds(20));
    Incoming in;
    while (receive(s, false, in, nullptr)) {
      if (in.envelope.body_case() == Envelope::kBye) return;
      if (in.envelope.body_case() != Envelope::kTask) continue;
      const Task& t = in.envelope.task();
      BrickOutput b = scriptedBrick(t.brick_id(), {t.lo(0), t.lo(1), t.lo(2)});
      std::string payload = encodePayload(Operation::Sample, b);
      Envelope r;
      r.set_job_id(in.envelope.job_id());
      r.mutable_result()->set_brick_id(t.brick_id());
      r.mutable_result()->set_attempt(t.attempt());
      r.mutable_result()->set_leaves(uint32_t(b.leaves.size()));
      r.mutable_result()->set_payload_crc32(crc32Of(payload.data(), payload.size()));
      send(s, "", r, &payload);
    }
  }
}

FarmOutcome scriptedJob(const std::string& journal, const SampleSink& sink) {
  JobSpec j = partJob("sample", 128);  // 4 x 4 x 4 bricks of 32
  FarmOptions o;
  o.brickVoxels = 32;
  o.heartbeatMs = 500;
  o.liveness = 10;
  o.noWorkerTimeoutSec = 30;
  o.journalPath = journal;
  o.sampleSink = sink;
  MasterThread m(j, o);
  const std::string ep = m.endpoint();
  std::atomic<bool> stop{false};
  std::thread a(scriptedWorker, ep, "scripted-a", std::ref(stop)), b(scriptedWorker, ep, "scripted-b", std::ref(stop));
  m.join();
  stop = true;
  a.join();
  b.join();
  EXPECT_EQ(m.error, "");
  return m.outcome;
}

}  // namespace

// Pre-encoded payloads as bench_farm --master-only replays them, slabs of different sizes (the
// largest last, one empty), from the journal and from the payload arena; the merge without a
// sink checked first against the scripted leaves sorted independently.
TEST(SampleSink, StreamsScriptedPayloadsSlabBySlabInOneBuffer) {
  std::vector<LeafBlock> want;
  std::vector<Tile> wantTiles;
  uint64_t id = 0;
  for (int x = 0; x < 128; x += 32)
    for (int y = 0; y < 128; y += 32)
      for (int z = 0; z < 128; z += 32, ++id) {
        BrickOutput b = scriptedBrick(id, {x, y, z});
        want.insert(want.end(), b.leaves.begin(), b.leaves.end());
        wantTiles.insert(wantTiles.end(), b.tiles.begin(), b.tiles.end());
      }
  sortByOrigin(want, wantTiles);
  for (bool journal : {false, true}) {
    SCOPED_TRACE(std::string("journal ") + (journal ? "on" : "off"));
    const std::string path = journal ? "/tmp/frep_sample_sink_scripted." + std::to_string(getpid()) + ".journal" : "";
    if (journal) std::remove(path.c_str());
    FarmOutcome ref = scriptedJob(path, {});
    if (journal) std::remove(path.c_str());
    ASSERT_EQ(ref.report.bricks, 64u);
    expectSameLeaves(want, ref.result.leaves);
    expectSameTiles(wantTiles, ref.result.tiles);
    Streamed s;
    FarmOutcome got = scriptedJob(path, s.sink());
    if (journal) std::remove(path.c_str());
    expectStreamedAsMerged(ref, got, s, 32);
    ASSERT_EQ(s.slabSizes.size(), 3u);  // x-slab 1 is empty
    EXPECT_LT(s.slabSizes[0], s.slabSizes[2]);
  }
}

// A sink only streams a complete job: with a brick poisoned nothing is handed over, and the
// merged leaves stay in the result, as without a sink.
TEST(SampleSink, AnIncompleteJobHandsNothingOver) {
  JobSpec j = partJob("sample", 64);
  FarmOptions o = fast(2);
  Streamed s;
  o.sampleSink = s.sink();
  setenv("FREP_TEST_CRASH_BRICK", "3", 1);
  FarmOutcome got = runJob(j, o);
  unsetenv("FREP_TEST_CRASH_BRICK");
  ASSERT_EQ(got.report.poisoned.size(), 1u);
  EXPECT_EQ(s.tileCalls, 0);
  EXPECT_TRUE(s.slabSizes.empty());
  EXPECT_GT(got.result.leaves.size(), 0u);
  EXPECT_EQ(got.result.leaves.size(), got.report.leaves);
}
