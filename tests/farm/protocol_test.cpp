// The master against hostile or mismatched peers: it must refuse, count and carry on.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <thread>
#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "frep/net/curve.h"
#include "farm_test_util.h"
#include "frep/net/wire.h"

using namespace farmtest;

namespace {

FarmOptions clusterOptions() {
  FarmOptions o;
  o.brickVoxels = 32;
  o.heartbeatMs = scaledMs(100);
  o.noWorkerTimeoutSec = scaledSec(20);
  return o;
}

// Runs a worker to its end; returns its exit code.
int runWorker(const std::string& endpoint, std::vector<std::string> extra = {}) {
  return WorkerProcess(endpoint, {}, std::move(extra)).wait(20);
}

// A DEALER connected to the master, speaking for the test.
zmq::socket_t peerOf(zmq::context_t& ctx, const std::string& endpoint) {
  zmq::socket_t peer(ctx, zmq::socket_type::dealer);
  peer.set(zmq::sockopt::linger, 0);
  peer.connect(endpoint);
  return peer;
}

}  // namespace

TEST(Protocol, RogueClientIsCountedAndTheJobCompletes) {
  JobSpec j = sphereJob();
  FarmOptions inProcess;
  inProcess.workers = 0;
  FarmOutcome ref = runJob(j, inProcess);
  LogWatch log;
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();

  zmq::context_t ctx(1);
  // One connection per kind of garbage: the first garbage bans a routing id (the rest of what
  // it sends is ignored, uncounted).
  std::vector<zmq::socket_t> rogues;
  auto rogueSocket = [&]() -> zmq::socket_t& {
    rogues.emplace_back(ctx, zmq::socket_type::dealer);
    rogues.back().set(zmq::sockopt::linger, 0);
    rogues.back().connect(ep);
    return rogues.back();
  };
  std::mt19937 rng(7);
  std::string junk(300, '\0');
  for (auto& c : junk) c = char(rng());
  rogues.reserve(8);
  rogueSocket().send(zmq::buffer(junk));  // random bytes
  Envelope hello;
  hello.set_proto_major(kProtoMajor);
  hello.mutable_hello()->set_worker_id("rogue");
  std::string bytes;
  hello.SerializeToString(&bytes);
  rogueSocket().send(zmq::buffer(bytes.substr(0, bytes.size() - 3)));  // truncated protobuf
  std::vector<zmq::const_buffer> three{zmq::buffer(bytes), zmq::str_buffer("a"), zmq::str_buffer("b")};
  zmq::send_multipart(rogueSocket(), three);  // wrong frame count
  std::string huge(2 << 20, 'x');
  rogueSocket().send(zmq::buffer(huge));  // oversized frame
  // A forged result for a brick the rogue never leased, with a bad payload.
  Envelope forged;
  forged.set_proto_major(kProtoMajor);
  forged.set_job_id(jobIdOf(j));
  forged.mutable_result()->set_brick_id(1);
  forged.SerializeToString(&bytes);
  std::vector<zmq::const_buffer> withPayload{zmq::buffer(bytes), zmq::str_buffer("garbage")};
  zmq::send_multipart(rogueSocket(), withPayload);

  // The master has handled the garbage once it logged three drops (the oversized frame may be
  // refused by ZeroMQ itself, unlogged).
  waitUntil([&] { return log.count("dropped a malformed message") + log.count("dropped an oversized message") >= 3; });
  EXPECT_EQ(runWorker(ep), 0);  // a real worker finishes the job
  master.join();
  const FarmOutcome& out = master.outcome;
  ASSERT_EQ(master.error, "");
  EXPECT_GE(out.report.malformed + out.report.oversized, 3u);
  EXPECT_EQ(out.result.leaves.size(), ref.result.leaves.size());
  for (size_t i = 0; i < ref.result.leaves.size(); ++i) ASSERT_EQ(out.result.leaves[i].values, ref.result.leaves[i].values);
}

TEST(Protocol, WorkerOfAnotherProtocolMajorIsRefusedWithAReason) {
  JobSpec j = sphereJob();
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  zmq::socket_t peer = peerOf(ctx, ep);
  Envelope hello;
  hello.set_proto_major(kProtoMajor + 1);
  hello.mutable_hello()->set_worker_id("future");
  std::string bytes;
  hello.SerializeToString(&bytes);
  peer.send(zmq::buffer(bytes));
  zmq::pollitem_t item{static_cast<void*>(peer), 0, ZMQ_POLLIN, 0};
  zmq::poll(&item, 1, std::chrono::milliseconds(5000));
  ASSERT_TRUE(item.revents & ZMQ_POLLIN);
  zmq::message_t reply;
  ASSERT_TRUE(peer.recv(reply));
  Envelope r;
  ASSERT_TRUE(r.ParseFromArray(reply.data(), int(reply.size())));
  ASSERT_EQ(r.body_case(), Envelope::kReject);
  EXPECT_NE(r.reject().reason().find("protocol major " + std::to_string(kProtoMajor + 1)), std::string::npos)
      << r.reject().reason();
  EXPECT_EQ(runWorker(ep), 0);
  master.join();
  const FarmOutcome& out = master.outcome;
  ASSERT_EQ(master.error, "");
  EXPECT_EQ(out.report.refused, 1u);
}

// A peer whose connection is gone while it is still registered (it crashed or reconnected and
// its liveness window has not run out) must not swallow the brick the master tries to lease to
// it: that brick goes back to the queue. It was lost once, and the master then waited forever
// for it while other workers heartbeated (frep mesh/sample with a crashing brick hung).
TEST(Protocol, BrickForAPeerThatVanishedGoesBackToTheQueue) {
  JobSpec j = sphereJob();
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 0, 0}, 64));  // 64x32x32: two bricks of 32
  FarmOptions inProcess = clusterOptions();
  inProcess.workers = 0;
  FarmOutcome ref = runJob(j, inProcess);
  ASSERT_EQ(ref.report.bricks, 2u);
  FarmOptions o = clusterOptions();
  o.heartbeatMs = scaledMs(400);  // liveness window 2.4 s: the vanished peer stays registered meanwhile
  o.noWorkerTimeoutSec = scaledSec(5);
  MasterThread master(j, o);
  const std::string ep = master.endpoint();

  zmq::context_t ctx(1);
  auto peer = [&](const char* id) {
    zmq::socket_t s(ctx, zmq::socket_type::dealer);
    s.set(zmq::sockopt::linger, 1000);
    s.set(zmq::sockopt::routing_id, id);
    s.connect(ep);
    Envelope hello;
    hello.mutable_hello()->set_worker_id(id);
    send(s, "", hello);
    return s;
  };
  auto collect = [](zmq::socket_t& s, Envelope::BodyCase kind, size_t count) {
    return collectEnvelopes(s, kind, count, 10000);
  };
  // "y" leases both bricks (two in flight per worker): nothing is pending.
  zmq::socket_t y = peer("y");
  std::vector<Envelope> held = collect(y, Envelope::kTask, 2);
  ASSERT_EQ(held.size(), 2u);
  // "x" joins with room for two bricks and vanishes without a bye.
  {
    zmq::socket_t x = peer("x");
    ASSERT_EQ(collect(x, Envelope::kWelcome, 1).size(), 1u);
  }
  // The master sees the disconnect once its side of x's connection is closed (only y's is left).
  EXPECT_TRUE(waitUntil([&] { return masterSideConnections(ep) == 1; }, std::chrono::seconds(10)));
  // "y" hands both bricks back and leaves: the master offers them to "x" first (it is idle).
  for (const Envelope& t : held) {
    Envelope f;
    f.set_job_id(jobIdOf(j));
    f.mutable_failed()->set_brick_id(t.task().brick_id());
    f.mutable_failed()->set_attempt(t.task().attempt());
    f.mutable_failed()->set_error("handed back by the test");
    f.mutable_failed()->set_handed_back(true);
    send(y, "", f);
  }
  Envelope bye;
  bye.mutable_bye()->set_reason("test");
  send(y, "", bye);
  // A real worker computes whatever is queued; a lost brick would leave the master waiting.
  EXPECT_EQ(runWorker(ep), 0);
  master.join();
  const FarmOutcome& out = master.outcome;
  ASSERT_EQ(master.error, "");
  EXPECT_FALSE(out.report.interrupted);
  EXPECT_TRUE(out.report.poisoned.empty());
  EXPECT_EQ(out.report.bricksComputed, 2u);
  ASSERT_EQ(out.result.leaves.size(), ref.result.leaves.size());
  for (size_t i = 0; i < ref.result.leaves.size(); ++i) ASSERT_EQ(out.result.leaves[i].values, ref.result.leaves[i].values);
}

TEST(Protocol, CurveMasterRefusesWorkersWithoutTheKeys) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("frep-curve-" + std::to_string(getpid()));
  fs::path other = dir / "other";
  generateCurveKeys(dir.string());
  generateCurveKeys(other.string());
  // An intruder who knows the master's public key but holds an unlisted worker key.
  fs::path intruder = dir / "intruder";
  fs::create_directories(intruder);
  fs::copy_file(dir / "master.pub", intruder / "master.pub");
  fs::copy_file(other / "worker.pub", intruder / "worker.pub");
  fs::copy_file(other / "worker.key", intruder / "worker.key");
  JobSpec j = sphereJob();
  FarmOptions o = clusterOptions();
  o.curveDir = dir.string();
  MasterThread master(j, o);
  const std::string ep = master.endpoint();
  // Plain TCP: the handshake never completes, the worker gives up (75) without joining.
  EXPECT_EQ(runWorker(ep, {"--master-timeout", "1"}), 75);
  // Keys of another farm: the handshake fails, gives up too.
  EXPECT_EQ(runWorker(ep, {"--master-timeout", "1", "--curve", other.string()}), 75);
  // The master's public key but an unauthorized worker key: refused by the ZAP handler.
  EXPECT_EQ(runWorker(ep, {"--master-timeout", "1", "--curve", intruder.string()}), 75);
  // The right keys: joins and finishes the job.
  EXPECT_EQ(runWorker(ep, {"--curve", dir.string()}), 0);
  master.join();
  const FarmOutcome& out = master.outcome;
  ASSERT_EQ(master.error, "");
  EXPECT_EQ(out.report.workersSeen, 1);
  EXPECT_GE(out.report.curveRejected, 1u);
  EXPECT_TRUE(out.report.poisoned.empty());
  fs::remove_all(dir);
}

TEST(Protocol, PayloadCodecRejectsMalformedInput) {
  BrickOutput b;
  LeafBlock l = LeafBlock::cleared();
  l.origin = {8, 16, 24};
  l.values.fill(1.5f);
  l.active.fill(~0ull);
  b.leaves.push_back(l);
  b.tiles.push_back(Tile{{0, 0, 0}, 8, true});
  std::string s = encodeBrick(b);
  BrickOutput back;
  std::string err;
  ASSERT_TRUE(decodeBrick(s.data(), s.size(), back, &err));
  EXPECT_EQ(back.leaves[0].values, l.values);
  EXPECT_FALSE(decodeBrick(s.data(), s.size() - 1, back, &err));
  EXPECT_FALSE(decodeBrick("FRB2", 4, back, &err));
  std::string bad = s;
  bad[12 + 20] = 3;  // leaf origin x = 3: not a multiple of 8
  EXPECT_FALSE(decodeBrick(bad.data(), bad.size(), back, &err));
  // A surface leaf: half active; inactive voxels +-0.25 travel as signs only.
  LeafBlock half = LeafBlock::cleared();
  half.origin = {0, 0, 0};
  for (int i = 0; i < kLeafVoxels; ++i) {
    bool active = (i % 2) == 0;
    if (active) half.active[size_t(i >> 6)] |= uint64_t(1) << (i & 63);
    half.values[size_t(i)] = active ? float(i) * 0.001f : (i % 4 == 1 ? 0.25f : -0.25f);
  }
  BrickOutput h;
  h.leaves.push_back(half);
  std::string hs = encodeBrick(h);
  EXPECT_LT(hs.size(), 12 + 92 + 64 + 4 + 256 * 4 + 1);
  ASSERT_TRUE(decodeBrick(hs.data(), hs.size(), back, &err)) << err;
  EXPECT_EQ(back.leaves[0].values, half.values);
  EXPECT_EQ(back.leaves[0].active, half.active);
  // Random corruption never crashes the decoder.
  std::mt19937 rng(3);
  for (int k = 0; k < 2000; ++k) {
    std::string m = hs;
    for (int j = 0; j < 4; ++j) m[rng() % m.size()] = char(rng());
    m.resize(rng() % (m.size() + 1));
    decodeBrick(m.data(), m.size(), back, &err);
  }
}

// scanBrick (the master's verification) and decodeLeafAt (its merge, leaf by leaf in sorted
// order) share decodeBrick's parser: on every truncation and on random corruption of a payload
// with compact and full leaves and tiles, scanBrick accepts what decodeBrick accepts, and each
// leaf record it finds decodes alone to decodeBrick's leaf.
TEST(Protocol, ScanAndDecodeInPlaceAcceptExactlyWhatDecodeAccepts) {
  BrickOutput b;
  for (int k = 0; k < 3; ++k) {
    LeafBlock l = LeafBlock::cleared();
    l.origin = {8 * k, 16, 24};
    for (int i = 0; i < kLeafVoxels; ++i) {
      const bool active = k == 0 || (i + k) % 3 == 0;
      if (active) l.active[size_t(i >> 6)] |= uint64_t(1) << (i & 63);
      // Leaf 2's inactive voxels are not all +-m: it travels in full.
      l.values[size_t(i)] = active ? 0.01f * float(i - 200) : (k == 2 ? float(i % 5) : (i % 2 ? 0.5f : -0.5f));
    }
    b.leaves.push_back(l);
  }
  b.tiles = {Tile{{0, 0, 0}, 8, true}, Tile{{32, 0, 0}, 16, false}};
  const std::string s = encodeBrick(b);
  auto agree = [&](const std::string& m) {
    BrickOutput full;
    std::vector<std::array<int32_t, 3>> origins;
    std::vector<Tile> tiles;
    std::vector<uint32_t> leafAt;
    std::string e1, e2;
    const bool decoded = decodeBrick(m.data(), m.size(), full, &e1);
    const bool scanned = scanBrick(m.data(), m.size(), origins, tiles, leafAt, &e2);
    ASSERT_EQ(decoded, scanned) << e1 << " / " << e2;
    if (!decoded) {
      EXPECT_EQ(e1, e2);
      return;
    }
    ASSERT_EQ(origins.size(), full.leaves.size());
    ASSERT_EQ(leafAt.size(), full.leaves.size());
    ASSERT_EQ(tiles.size(), full.tiles.size());
    for (size_t l = 0; l < origins.size(); ++l) {
      EXPECT_EQ(origins[l], full.leaves[l].origin);
      // Each leaf's record, from its leafAt to the next (the last: to the end), decodes alone to
      // the same leaf, bit for bit (corruption makes NaNs); a byte less or more is refused.
      const size_t end = l + 1 < leafAt.size() ? leafAt[l + 1] : m.size();
      ASSERT_LT(leafAt[l], end);
      LeafBlock placed;
      ASSERT_TRUE(decodeLeafAt(m.data() + leafAt[l], end - leafAt[l], placed)) << "leaf " << l;
      EXPECT_EQ(placed.origin, full.leaves[l].origin);
      EXPECT_EQ(placed.active, full.leaves[l].active);
      EXPECT_EQ(std::memcmp(placed.values.data(), full.leaves[l].values.data(), sizeof full.leaves[l].values), 0);
      EXPECT_FALSE(decodeLeafAt(m.data() + leafAt[l], end - leafAt[l] - 1, placed));
      if (end < m.size()) EXPECT_FALSE(decodeLeafAt(m.data() + leafAt[l], end - leafAt[l] + 1, placed));
    }
  };
  agree(s);
  BrickOutput back;
  std::string err;
  ASSERT_TRUE(decodeBrick(s.data(), s.size(), back, &err));
  for (size_t l = 0; l < b.leaves.size(); ++l) EXPECT_EQ(back.leaves[l].values, b.leaves[l].values);
  for (size_t n = 0; n < s.size(); ++n) agree(s.substr(0, n));  // every truncation is refused by all
  std::mt19937 rng(11);
  for (int k = 0; k < 3000; ++k) {
    std::string m = s;
    for (int j = 0; j < 3; ++j) m[rng() % m.size()] = char(rng());
    agree(m);
  }
}

namespace {
// A fake master: a ROUTER on a free loopback port, and the worker process connected to it.
struct FakeMaster {
  zmq::context_t ctx{1};
  zmq::socket_t router{ctx, zmq::socket_type::router};
  std::string endpoint;
  FakeMaster() {
    router.set(zmq::sockopt::linger, 0);
    router.bind("tcp://127.0.0.1:*");
    endpoint = router.get(zmq::sockopt::last_endpoint);
  }
  // The next message (waits up to 10 s).
  Incoming next() {
    Incoming in;
    std::string err;
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline) {
      zmq::pollitem_t item{static_cast<void*>(router), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(100));
      if (receive(router, true, in, &err)) {
        EXPECT_EQ(err, "");
        return in;
      }
    }
    ADD_FAILURE() << "nothing from the worker";
    return in;
  }
  // The next message that is not a heartbeat.
  Incoming nextNotHeartbeat() {
    for (;;) {
      Incoming in = next();
      if (in.envelope.body_case() != Envelope::kHeartbeat) return in;
    }
  }
  void welcome(const std::string& rid, const JobSpec& job, uint64_t jobId) {
    Envelope w;
    w.set_job_id(jobId);
    w.mutable_welcome()->set_heartbeat_ms(uint32_t(scaledMs(100)));
    *w.mutable_welcome()->mutable_job() = job;
    send(router, rid, w);
  }
};
}  // namespace

// Protocol 2: the job travels once per connection, in the welcome; tasks carry its id only, so
// a job with megabytes of model (here a 1 MiB comment) costs its bytes once per worker, not per brick.
// LeafBlock is not zeroed when made (the master's merge decodes into a resized vector): the
// decoders must write all of every leaf. Decoded over all-zero and over all-one bytes, every
// leaf comes out the same, bit for bit, for each leaf form (all active, compact, in full).
TEST(Protocol, DecodingWritesEveryByteOfALeafWhateverWasThereBefore) {
  BrickOutput b;
  for (int k = 0; k < 3; ++k) {
    LeafBlock l = LeafBlock::cleared();
    l.origin = {8 * k, 8, 16};
    for (int i = 0; i < kLeafVoxels; ++i) {
      const bool active = k == 0 || (i < 256 && (i * 7 + k) % 5 < 2);  // rows of 8 all, some or none active
      if (active) l.active[size_t(i >> 6)] |= uint64_t(1) << (i & 63);
      l.values[size_t(i)] = active ? 0.02f * float(i - 300) : (k == 2 ? float(i % 3) : (i % 3 ? 0.75f : -0.75f));
    }
    b.leaves.push_back(l);
  }
  const std::string s = encodeBrick(b);
  auto decodedOver = [&](unsigned char fill, bool inPlace) {
    std::vector<LeafBlock> leaves(b.leaves.size());
    std::memset(static_cast<void*>(leaves.data()), fill, leaves.size() * sizeof(LeafBlock));
    std::string err;
    if (inPlace) {  // as the master's merge does: scanned, then leaf record by leaf record
      std::vector<std::array<int32_t, 3>> origins;
      std::vector<Tile> tiles;
      std::vector<uint32_t> leafAt;
      EXPECT_TRUE(scanBrick(s.data(), s.size(), origins, tiles, leafAt, &err)) << err;
      for (size_t l = 0; l < leafAt.size(); ++l) {
        const size_t end = l + 1 < leafAt.size() ? leafAt[l + 1] : s.size();
        EXPECT_TRUE(decodeLeafAt(s.data() + leafAt[l], end - leafAt[l], leaves[l])) << "leaf " << l;
      }
    } else {
      BrickOutput out;
      out.leaves = leaves;
      out.leaves.clear();  // the filled memory stays its capacity: decodeBrick's resize reuses it
      EXPECT_TRUE(decodeBrick(s.data(), s.size(), out, &err)) << err;
      return out.leaves;
    }
    return leaves;
  };
  for (bool inPlace : {false, true}) {
    const std::vector<LeafBlock> zeros = decodedOver(0x00, inPlace), ones = decodedOver(0xFF, inPlace);
    ASSERT_EQ(zeros.size(), b.leaves.size());
    for (size_t l = 0; l < b.leaves.size(); ++l) {
      for (const std::vector<LeafBlock>* d : {&zeros, &ones}) {
        EXPECT_EQ((*d)[l].origin, b.leaves[l].origin) << l;
        EXPECT_EQ((*d)[l].active, b.leaves[l].active) << l;
        EXPECT_EQ(std::memcmp((*d)[l].values.data(), b.leaves[l].values.data(), sizeof b.leaves[l].values), 0) << l;
      }
    }
  }
  const LeafBlock c = LeafBlock::cleared();
  for (float v : c.values) EXPECT_EQ(v, 0.0f);
  for (uint64_t w : c.active) EXPECT_EQ(w, 0u);
  EXPECT_EQ(c.origin, (std::array<int32_t, 3>{0, 0, 0}));
}

TEST(Protocol, TheWelcomeCarriesTheJobAndTasksOnlyItsId) {
  JobSpec j = sphereJob();
  std::string comment;
  while (comment.size() < (1u << 20)) comment += "-- a comment line that only makes the model big\n";
  j.set_model_source(comment + j.model_source());
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  zmq::socket_t peer = peerOf(ctx, ep);
  Envelope hello;
  hello.mutable_hello()->set_worker_id("inspector");
  send(peer, "", hello);
  Incoming in;
  auto receiveBody = [&](Envelope::BodyCase want) {
    std::string err;
    for (auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
         std::chrono::steady_clock::now() < deadline;) {
      zmq::pollitem_t item{static_cast<void*>(peer), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(100));
      while (receive(peer, false, in, &err))
        if (in.envelope.body_case() == want) return true;
    }
    return false;
  };
  ASSERT_TRUE(receiveBody(Envelope::kWelcome));
  EXPECT_EQ(in.envelope.job_id(), jobIdOf(j));
  EXPECT_EQ(jobIdOf(in.envelope.welcome().job()), jobIdOf(j));
  EXPECT_GT(in.bytes, 1u << 20);
  for (int k = 0; k < 2; ++k) {  // the worker's credit: two tasks
    ASSERT_TRUE(receiveBody(Envelope::kTask));
    EXPECT_EQ(in.envelope.job_id(), jobIdOf(j));
    EXPECT_LT(in.bytes, 128u) << "a task carries the brick and the job's id, not the job";
  }
  Envelope bye;  // leaves: its bricks go back to the queue, uncharged
  bye.mutable_bye()->set_reason("inspected");
  send(peer, "", bye);
  EXPECT_EQ(runWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  EXPECT_TRUE(master.outcome.report.poisoned.empty());
  EXPECT_EQ(master.outcome.report.bricksComputed, master.outcome.report.bricks);
}

// A welcome whose job does not hash to the envelope's job id (a master of another release, a
// damaged frame) is refused: the worker computes nothing under a wrong id and exits 78.
TEST(Protocol, WorkerRefusesAWelcomeWhoseJobIsNotTheJobId) {
  FakeMaster m;
  WorkerProcess worker(m.endpoint);
  Incoming hello = m.nextNotHeartbeat();
  ASSERT_EQ(hello.envelope.body_case(), Envelope::kHello);
  m.welcome(hello.routingId, sphereJob(), jobIdOf(sphereJob()) + 1);
  EXPECT_EQ(worker.wait(20), 78);
}

// A task naming another job than the welcome's is handed back (not the brick's fault) and the
// worker says hello again, so the master's welcome brings it the job.
TEST(Protocol, ATaskOfAnUnknownJobIsHandedBackAndTheWorkerSaysHelloAgain) {
  FakeMaster m;
  WorkerProcess worker(m.endpoint);
  Incoming hello = m.nextNotHeartbeat();
  ASSERT_EQ(hello.envelope.body_case(), Envelope::kHello);
  const JobSpec j = sphereJob();
  m.welcome(hello.routingId, j, jobIdOf(j));
  Envelope task;
  task.set_job_id(jobIdOf(j) ^ 0x5a5a);
  task.mutable_task()->set_brick_id(7);
  task.mutable_task()->set_attempt(1);
  for (int a = 0; a < 3; ++a) task.mutable_task()->add_lo(0), task.mutable_task()->add_hi(32);
  send(m.router, hello.routingId, task);
  Incoming failed = m.nextNotHeartbeat();
  ASSERT_EQ(failed.envelope.body_case(), Envelope::kFailed);
  EXPECT_EQ(failed.envelope.failed().brick_id(), 7u);
  EXPECT_TRUE(failed.envelope.failed().handed_back());
  Incoming again = m.nextNotHeartbeat();
  EXPECT_EQ(again.envelope.body_case(), Envelope::kHello);
  // The same task under the welcome's id is computed.
  task.set_job_id(jobIdOf(j));
  send(m.router, hello.routingId, task);
  Incoming result = m.nextNotHeartbeat();
  ASSERT_EQ(result.envelope.body_case(), Envelope::kResult);
  EXPECT_EQ(result.envelope.job_id(), jobIdOf(j));
  EXPECT_EQ(result.envelope.result().brick_id(), 7u);
  Envelope bye;
  bye.mutable_bye()->set_reason("done");
  send(m.router, hello.routingId, bye);
  EXPECT_EQ(worker.wait(20), 0);
}
