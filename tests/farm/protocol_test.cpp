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

#include "curve.h"
#include "farm_test_util.h"
#include "wire.h"

using namespace farmtest;

namespace {

JobSpec sphereJob() {
  JobSpec j;
  j.set_operation("sample");
  j.set_model_source("my_model(x[3], a[1]) { my_model = 0.64 - x[1]^2 - x[2]^2 - x[3]^2; }");
  j.set_model_name("sphere.hf");
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 64));
  j.set_band(3);
  return j;
}

FarmOptions clusterOptions() {
  FarmOptions o;
  o.brickVoxels = 32;
  o.heartbeatMs = 100;
  o.noWorkerTimeoutSec = 20;
  return o;
}

// Runs a worker to its end; returns its exit code.
int runWorker(const std::string& endpoint, std::vector<std::string> extra = {}) {
  return WorkerProcess(endpoint, {}, std::move(extra)).wait(20);
}

}  // namespace

TEST(Protocol, RogueClientIsCountedAndTheJobCompletes) {
  JobSpec j = sphereJob();
  FarmOptions inProcess;
  inProcess.workers = 0;
  FarmOutcome ref = runJob(j, inProcess);
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

  std::this_thread::sleep_for(std::chrono::milliseconds(300));
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
  zmq::socket_t peer(ctx, zmq::socket_type::dealer);
  peer.set(zmq::sockopt::linger, 0);
  peer.connect(ep);
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
  EXPECT_NE(r.reject().reason().find("protocol major 2"), std::string::npos) << r.reject().reason();
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
  o.heartbeatMs = 400;  // liveness window 2.4 s: the vanished peer stays registered meanwhile
  o.noWorkerTimeoutSec = 5;
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
  std::this_thread::sleep_for(std::chrono::milliseconds(400));  // the master sees the disconnect
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
  LeafBlock l{};
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
  LeafBlock half{};
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
