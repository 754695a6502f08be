// FarmOptions::sampleSink: the merged sample streamed slab by slab (as each slab's bricks are all
// merged) hands over exactly the tiles and leaves, in exactly the order, that FarmOutcome::result
// holds without it, each slab's tiles before its leaves, its leaves in pieces of
// kSinkPieceLeaves in a few reused buffers; whatever order the bricks arrive in, and when the job
// does not complete or the sink fails.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>
#include <zmq.hpp>

#include "farm_test_util.h"

using namespace farmtest;

namespace {

// What a sink saw: the tiles (and for each call, how many leaves had come before it), the leaves
// (and each call's count and buffer).
struct Streamed {
  std::vector<Tile> tiles;
  std::vector<size_t> tileCallSizes, leavesBeforeTileCall;
  std::vector<LeafBlock> leaves;
  std::vector<size_t> callSizes;
  std::vector<const LeafBlock*> buffers;
  SampleSink sink() {
    SampleSink s;
    s.tiles = [this](const std::vector<Tile>& t) {
      tileCallSizes.push_back(t.size());
      leavesBeforeTileCall.push_back(leaves.size());
      tiles.insert(tiles.end(), t.begin(), t.end());
    };
    s.leaves = [this](const std::vector<LeafBlock>& piece) {
      leaves.insert(leaves.end(), piece.begin(), piece.end());
      callSizes.push_back(piece.size());
      buffers.push_back(piece.data());
    };
    return s;
  }
  // The leaves handed over per x-slab (of `brick` voxels) that had any, in the order of the calls.
  std::vector<size_t> slabSizes(int brick) const;
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

// The x-slab (of `brick` voxels) of a leaf or tile origin.
int slabOf(const std::array<int32_t, 3>& origin, int brick) { return origin[0] / brick; }

std::vector<size_t> Streamed::slabSizes(int brick) const {
  std::vector<size_t> sizes;
  for (size_t i = 0; i < leaves.size(); ++i)
    if (i == 0 || slabOf(leaves[i].origin, brick) != slabOf(leaves[i - 1].origin, brick)) sizes.push_back(1);
    else ++sizes.back();
  return sizes;
}

// The stream against the result built without a sink: the same tiles and leaves in the same
// order, result.leaves empty; each leaves call within one x-slab of bricks, a slab's calls of
// kSinkPieceLeaves leaves but its last (1 to kSinkPieceLeaves), in at most one buffer per core;
// one tiles call per x-slab that has tiles, before any leaf of that slab or a later one.
void expectStreamedAsMerged(const FarmOutcome& ref, const FarmOutcome& got, const Streamed& s, int brick) {
  EXPECT_TRUE(got.result.leaves.empty());
  expectSameTiles(ref.result.tiles, s.tiles);
  expectSameTiles(ref.result.tiles, got.result.tiles);
  expectSameLeaves(ref.result.leaves, s.leaves);
  EXPECT_EQ(got.report.leaves, ref.result.leaves.size());
  size_t at = 0;
  for (size_t k = 0; k < s.callSizes.size(); ++k) {
    ASSERT_GT(s.callSizes[k], 0u);
    ASSERT_LE(s.callSizes[k], kSinkPieceLeaves);
    const int slab = slabOf(s.leaves[at].origin, brick);
    for (size_t i = at; i < at + s.callSizes[k]; ++i)
      ASSERT_EQ(slabOf(s.leaves[i].origin, brick), slab) << "call " << k << ", leaf " << i;
    at += s.callSizes[k];
    const bool slabsLast = at == s.leaves.size() || slabOf(s.leaves[at].origin, brick) != slab;
    if (!slabsLast) EXPECT_EQ(s.callSizes[k], kSinkPieceLeaves) << "call " << k << " is not its slab's last";
  }
  std::set<const LeafBlock*> buffers(s.buffers.begin(), s.buffers.end());
  EXPECT_LE(buffers.size(), std::max(1u, std::thread::hardware_concurrency()));
  std::vector<int> slabsWithTiles;
  for (const Tile& t : ref.result.tiles)
    if (slabsWithTiles.empty() || slabsWithTiles.back() != slabOf(t.origin, brick)) slabsWithTiles.push_back(slabOf(t.origin, brick));
  ASSERT_EQ(s.tileCallSizes.size(), slabsWithTiles.size());
  size_t tile = 0;
  for (size_t c = 0; c < s.tileCallSizes.size(); ++c) {
    const int slab = slabsWithTiles[c];
    for (size_t i = tile; i < tile + s.tileCallSizes[c]; ++i)
      ASSERT_EQ(slabOf(s.tiles[i].origin, brick), slab) << "tiles call " << c << ", tile " << i;
    tile += s.tileCallSizes[c];
    for (size_t i = 0; i < s.leavesBeforeTileCall[c]; ++i)  // only leaves of earlier slabs came first
      ASSERT_LT(slabOf(s.leaves[i].origin, brick), slab) << "tiles call " << c << " came after leaf " << i;
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
      EXPECT_EQ(s.slabSizes(32).size(), 3u);
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

// Sends the scripted result of a task.
void answer(zmq::socket_t& s, uint64_t jobId, const Task& t) {
  BrickOutput b = scriptedBrick(t.brick_id(), {t.lo(0), t.lo(1), t.lo(2)});
  std::string payload = encodePayload(Operation::Sample, b);
  Envelope r;
  r.set_job_id(jobId);
  r.mutable_result()->set_brick_id(t.brick_id());
  r.mutable_result()->set_attempt(t.attempt());
  r.mutable_result()->set_leaves(uint32_t(b.leaves.size()));
  r.mutable_result()->set_payload_crc32(crc32Of(payload.data(), payload.size()));
  send(s, "", r, &payload);
}

// A scripted worker: answers each task at once with scriptedBrick, until told bye. With
// `holdFirst` it keeps its first task and answers it last, once no task came for a while (the
// bricks of the slab it is in arrive out of order, after those of later slabs); the result is
// the same whenever it comes.
void scriptedWorker(const std::string& ep, const std::string& id, std::atomic<bool>& stop, bool holdFirst = false) {
  zmq::context_t ctx(1);
  zmq::socket_t s(ctx, zmq::socket_type::dealer);
  s.set(zmq::sockopt::linger, 200);
  s.connect(ep);
  Envelope hello;
  hello.mutable_hello()->set_worker_id(id);
  send(s, "", hello);
  std::optional<Envelope> held;
  bool answeredHeld = false;
  int idleTurns = 0;
  while (!stop) {
    zmq::pollitem_t item{static_cast<void*>(s), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, std::chrono::milliseconds(20));
    Incoming in;
    bool tasks = false;
    while (receive(s, false, in, nullptr)) {
      if (in.envelope.body_case() == Envelope::kBye) return;
      if (in.envelope.body_case() != Envelope::kTask) continue;
      tasks = true;
      if (holdFirst && !held) {
        held = in.envelope;
        continue;
      }
      answer(s, in.envelope.job_id(), in.envelope.task());
    }
    idleTurns = tasks ? 0 : idleTurns + 1;
    if (held && !answeredHeld && idleTurns >= 5) {
      answer(s, held->job_id(), held->task());
      answeredHeld = true;
    }
  }
}

FarmOutcome scriptedJob(const std::string& journal, const SampleSink& sink, bool outOfOrder = false) {
  JobSpec j = partJob("sample", 128);  // 4 x 4 x 4 bricks of 32
  FarmOptions o;
  o.brickVoxels = 32;
  o.heartbeatMs = scaledMs(500);
  o.liveness = 10;
  o.noWorkerTimeoutSec = scaledSec(30);
  o.journalPath = journal;
  o.sampleSink = sink;
  MasterThread m(j, o);
  const std::string ep = m.endpoint();
  std::atomic<bool> stop{false};
  std::thread a(scriptedWorker, ep, "scripted-a", std::ref(stop), outOfOrder),
      b(scriptedWorker, ep, "scripted-b", std::ref(stop), false);
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
// Pre-encoded payloads as bench_farm --master-only replays them, slabs of different sizes (the
// largest last, one empty), from the journal and from the payload arena, the bricks in the order
// they were leased or one of the first slab's last of all; the merge without a sink checked
// first against the scripted leaves sorted independently.
TEST(SampleSink, StreamsScriptedPayloadsSlabBySlabWhateverTheirOrder) {
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
  for (bool journal : {false, true})
    for (bool outOfOrder : {false, true}) {
      SCOPED_TRACE(std::string("journal ") + (journal ? "on" : "off") + (outOfOrder ? ", out of order" : ""));
      const std::string path = journal ? "/tmp/frep_sample_sink_scripted." + std::to_string(getpid()) + ".journal" : "";
      if (journal) std::remove(path.c_str());
      FarmOutcome ref = scriptedJob(path, {}, outOfOrder);
      if (journal) std::remove(path.c_str());
      ASSERT_EQ(ref.report.bricks, 64u);
      expectSameLeaves(want, ref.result.leaves);
      expectSameTiles(wantTiles, ref.result.tiles);
      Streamed s;
      FarmOutcome got = scriptedJob(path, s.sink(), outOfOrder);
      if (journal) std::remove(path.c_str());
      expectStreamedAsMerged(ref, got, s, 32);
      const std::vector<size_t> slabs = s.slabSizes(32);
      ASSERT_EQ(slabs.size(), 3u);  // x-slab 1 is empty
      EXPECT_LT(slabs[0], slabs[2]);
      EXPECT_GT(slabs[2], kSinkPieceLeaves);  // streamed in more than one piece
    }
}

namespace {

// The leaves of `from` in x-slabs [slabLo, slabHi) of 32 voxels, but not in the box [lo, hi).
std::vector<LeafBlock> leavesOf(const std::vector<LeafBlock>& from, int slabLo, int slabHi,
                                const std::array<int32_t, 3>& lo = {}, const std::array<int32_t, 3>& hi = {}) {
  std::vector<LeafBlock> out;
  for (const LeafBlock& l : from) {
    const int slab = slabOf(l.origin, 32);
    bool inBox = true;
    for (int a = 0; a < 3; ++a) inBox = inBox && l.origin[a] >= lo[a] && l.origin[a] < hi[a];
    if (slab >= slabLo && slab < slabHi && !inBox) out.push_back(l);
  }
  return out;
}

}  // namespace

// A job that does not complete hands over the slabs before the first one it did not complete;
// result.leaves holds the merged leaves of the others: with the first slab's brick 3 poisoned,
// nothing is handed over; with brick 21 of the last slab (27 bricks of 32^3, 9 a slab), the
// first two slabs are, and result.leaves is the last slab without that brick's leaves.
TEST(SampleSink, AnIncompleteJobHandsOverTheSlabsBeforeItsFirstIncompleteOne) {
  JobSpec j = partJob("sample", 96);
  FarmOutcome ref = runJob(j, fast(0));
  for (const char* crash : {"3", "21"}) {
    SCOPED_TRACE(std::string("brick ") + crash + " poisoned");
    FarmOptions o = fast(2);
    Streamed s;
    o.sampleSink = s.sink();
    setenv("FREP_TEST_CRASH_BRICK", crash, 1);
    FarmOutcome got = runJob(j, o);
    unsetenv("FREP_TEST_CRASH_BRICK");
    ASSERT_EQ(got.report.poisoned.size(), 1u);
    const PoisonedBrick& p = got.report.poisoned[0];
    EXPECT_EQ(s.leaves.size() + got.result.leaves.size(), got.report.leaves);
    if (std::string(crash) == "3") {
      EXPECT_TRUE(s.tileCallSizes.empty());
      EXPECT_TRUE(s.callSizes.empty());
      expectSameLeaves(leavesOf(ref.result.leaves, 0, 3, p.lo, p.hi), got.result.leaves);
    } else {
      ASSERT_EQ(p.lo, (std::array<int32_t, 3>{64, 32, 0}));
      expectSameLeaves(leavesOf(ref.result.leaves, 0, 2), s.leaves);
      expectSameLeaves(leavesOf(ref.result.leaves, 2, 3, p.lo, p.hi), got.result.leaves);
    }
  }
}

// A sink that throws ends the job with its error, as if the master had died in the middle of
// the merge; what was journaled by then is not computed again by a resume, which hands over the
// same tiles and leaves as a job that never failed.
TEST(SampleSink, AFailingSinkEndsTheJobAndAResumeStreamsTheSame) {
  JobSpec j = partJob("sample", 96);  // 27 bricks of 32^3, 3 slabs
  FarmOutcome ref = runJob(j, fast(0));
  const std::string path = "/tmp/frep_sample_sink_fail." + std::to_string(getpid()) + ".journal";
  std::remove(path.c_str());
  FarmOptions o = fast(0);
  o.journalPath = path;
  int secondSlabCalls = 0;
  o.sampleSink.leaves = [&](const std::vector<LeafBlock>& piece) {
    if (slabOf(piece.front().origin, 32) != 1) return;
    ++secondSlabCalls;
    throw std::runtime_error("the consumer failed");  // at the second slab's first piece
  };
  try {
    runJob(j, o);
    ADD_FAILURE() << "the sink's error did not end the job";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "the consumer failed");
  }
  EXPECT_EQ(secondSlabCalls, 1);
  o.resume = true;
  Streamed s;
  o.sampleSink = s.sink();
  FarmOutcome got = runJob(j, o);
  std::remove(path.c_str());
  EXPECT_GE(got.report.bricksFromJournal, 18u);  // the first two slabs' bricks were journaled before their merge
  EXPECT_EQ(got.report.bricksFromJournal + got.report.bricksComputed, got.report.bricks);
  expectStreamedAsMerged(ref, got, s, 32);
}
