// The master against scripted hostile peers over loopback (docs/farm.md, "Threat model"):
// only a brick's leaseholder can answer for it or be charged for it, strangers may send only a
// small hello, and garbage drops the peer, never the brick.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <set>
#include <thread>
#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "farm_test_util.h"
#include "frep/net/wire.h"

using namespace farmtest;

namespace {

FarmOptions clusterOptions() {
  FarmOptions o;
  o.brickVoxels = 32;
  o.heartbeatMs = scaledMs(100);
  o.liveness = 3;
  o.noWorkerTimeoutSec = scaledSec(20);
  return o;
}

void expectSameLeaves(const SampleResult& ref, const SampleResult& got) {
  ASSERT_EQ(got.leaves.size(), ref.leaves.size());
  for (size_t i = 0; i < ref.leaves.size(); ++i) {
    ASSERT_EQ(got.leaves[i].origin, ref.leaves[i].origin);
    ASSERT_EQ(got.leaves[i].values, ref.leaves[i].values);
    ASSERT_EQ(got.leaves[i].active, ref.leaves[i].active);
  }
}

SampleResult reference(const JobSpec& j) {
  FarmOptions o = clusterOptions();
  o.workers = 0;
  return runJob(j, o).result;
}

// A peer scripted by the test: a DEALER that speaks the protocol by hand.
struct ScriptedPeer {
  zmq::socket_t s;
  ScriptedPeer(zmq::context_t& ctx, const std::string& ep, const std::string& id, bool hello = true)
      : s(ctx, zmq::socket_type::dealer) {
    s.set(zmq::sockopt::linger, 200);
    s.set(zmq::sockopt::routing_id, id);
    s.connect(ep);
    if (hello) sayHello(id);
  }
  void sayHello(const std::string& id) {
    Envelope h;
    h.mutable_hello()->set_worker_id(id);
    send(s, "", h);
  }
  // Envelopes of one kind received within ms, or until count of them arrived.
  std::vector<Envelope> collect(Envelope::BodyCase kind, size_t count, int ms = 5000) {
    return collectEnvelopes(s, kind, count, ms);
  }
  void fail(uint64_t jobId, uint64_t brick, bool handedBack) {
    Envelope f;
    f.set_job_id(jobId);
    f.mutable_failed()->set_brick_id(brick);
    f.mutable_failed()->set_error(handedBack ? "handed back by the test" : "forged failure");
    f.mutable_failed()->set_handed_back(handedBack);
    send(s, "", f);
  }
  // A well-formed result for `brick` (right CRC, inside the brick) whose leaf is a lie.
  void forgeResult(uint64_t jobId, const Task& t, bool corruptCrc = false) {
    BrickOutput out;
    LeafBlock l = LeafBlock::cleared();
    l.origin = {t.lo(0), t.lo(1), t.lo(2)};
    l.values.fill(42.0f);
    l.active.fill(~0ull);
    out.leaves.push_back(l);
    std::string payload = encodePayload(Operation::Sample, out);
    Envelope r;
    r.set_job_id(jobId);
    r.mutable_result()->set_brick_id(t.brick_id());
    r.mutable_result()->set_leaves(1);
    r.mutable_result()->set_payload_crc32(crc32Of(payload.data(), payload.size()) ^ (corruptCrc ? 1u : 0u));
    send(s, "", r, &payload);
  }
  void handBackAndLeave(uint64_t jobId, const std::vector<Envelope>& tasks) {
    for (const Envelope& t : tasks) fail(jobId, t.task().brick_id(), true);
    Envelope bye;
    bye.mutable_bye()->set_reason("test");
    send(s, "", bye);
  }
};

int runRealWorker(const std::string& ep) { return WorkerProcess(ep).wait(30); }

// Peak resident set of this process (VmHWM), bytes.
uint64_t vmHwmBytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  return 0;
}

}  // namespace

// Before the lease check a peer that only said hello could submit any brick and have it merged.
TEST(HostilePeer, ForgedResultForAnotherPeersBrickIsNotMerged) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  LogWatch log;
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  ScriptedPeer a(ctx, ep, "a");
  std::vector<Envelope> held = a.collect(Envelope::kTask, 2);
  ASSERT_EQ(held.size(), 2u);
  ScriptedPeer b(ctx, ep, "b");
  std::vector<Envelope> bHeld = b.collect(Envelope::kTask, 2);
  ASSERT_EQ(bHeld.size(), 2u);
  for (const Envelope& t : held) b.forgeResult(jobIdOf(j), t.task());  // a's bricks, forged by b
  const std::string foreign = "from b, which does not hold it";
  EXPECT_TRUE(log.waitFor(foreign, 2)) << "the master never dropped b's forgeries";  // before a leaves
  a.handBackAndLeave(jobIdOf(j), held);
  b.handBackAndLeave(jobIdOf(j), bHeld);
  EXPECT_EQ(runRealWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_EQ(r.foreignResults, 2u);
  EXPECT_TRUE(r.poisoned.empty());
  expectSameLeaves(ref, master.outcome.result);
}

TEST(HostilePeer, FailuresAndCorruptResultsFromNonHoldersDoNotPoison) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  LogWatch log;
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  ScriptedPeer a(ctx, ep, "a");
  std::vector<Envelope> held = a.collect(Envelope::kTask, 2);
  ASSERT_EQ(held.size(), 2u);
  ScriptedPeer b(ctx, ep, "b");
  std::vector<Envelope> bHeld = b.collect(Envelope::kTask, 2);
  ASSERT_EQ(bHeld.size(), 2u);
  // A step that another peer's message must follow waits until the master has handled it (it
  // logs every message it drops as foreign, and every departure).
  const std::string foreign = "from b, which does not hold it";
  // b fails a's first brick again and again and sends corrupt results for its second; then
  // (after a handed them back) for every brick of the job, leased or pending.
  for (int k = 0; k < 5; ++k) {
    b.fail(jobIdOf(j), held[0].task().brick_id(), false);
    b.forgeResult(jobIdOf(j), held[1].task(), /*corruptCrc=*/true);
  }
  EXPECT_TRUE(log.waitFor(foreign, 10));
  a.handBackAndLeave(jobIdOf(j), held);
  EXPECT_TRUE(log.waitFor("worker a left"));
  for (uint64_t id = 0; id < 8; ++id)
    if (id != bHeld[0].task().brick_id() && id != bHeld[1].task().brick_id())
      for (int k = 0; k < 4; ++k) b.fail(jobIdOf(j), id, false);
  // b's hand-back follows on the same connection, so the master handles these first.
  b.handBackAndLeave(jobIdOf(j), bHeld);
  EXPECT_EQ(runRealWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty());
  EXPECT_GE(r.foreignResults, 10u);
  EXPECT_EQ(r.bricksComputed, 8u);
  expectSameLeaves(ref, master.outcome.result);
}

// Peers that say hello and vanish: the master leases them bricks they never see; their
// deaths must not be charged to those bricks (before: each vanishing peer charged both).
TEST(HostilePeer, HelloAndVanishPeersDoNotPoison) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  LogWatch log;
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  for (int k = 0; k < 6; ++k) {
    const std::string id = "vanish-" + std::to_string(k);
    {
      ScriptedPeer v(ctx, ep, id);
      ASSERT_EQ(v.collect(Envelope::kTask, 2).size(), 2u);
      v.s.set(zmq::sockopt::linger, 0);
    }
    // Its death (silence past the liveness window) is what is tested: wait until the master
    // counted it dead, before the next one says hello.
    EXPECT_TRUE(log.waitFor("worker " + id + " silent past its liveness window"));
  }
  EXPECT_EQ(runRealWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty()) << r.poisoned.size() << " brick(s) poisoned";
  EXPECT_GE(r.deadWorkers, 6u);
  expectSameLeaves(ref, master.outcome.result);
}

// Strangers may send a hello of at most 64 KiB; a bigger message is dropped unparsed and bans
// its routing id (its later hello is ignored). Frames over the job's largest possible frame
// are refused by ZeroMQ before they are allocated: many hostile peers sending 64 MiB frames
// leave the master's memory flat (before: accepted up to 256 MiB each).
TEST(HostilePeer, BigFramesFromUnwelcomedPeersAreDroppedWithBoundedMemory) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  LogWatch log;
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  {
    ScriptedPeer big(ctx, ep, "big", /*hello=*/false);
    std::string frame(100 << 10, 'x');
    big.s.send(zmq::buffer(frame));
    EXPECT_TRUE(log.waitFor("message from big"));  // dropped and banned before its hello
    big.sayHello("big");
    EXPECT_EQ(big.collect(Envelope::kWelcome, 1, 800).size(), 0u) << "a banned peer was welcomed";
  }
  // Hostile peers send 64 MiB frames from one shared buffer (zero-copy: the test's own
  // memory does not grow with the frames sent).
  static std::string huge(64 << 20, 'h');
  const uint64_t before = vmHwmBytes();
  {
    // ZeroMQ refuses a frame over the limit by closing its connection: each hostile socket's
    // monitor counts those closings, and the test waits until every frame sent was refused.
    std::vector<zmq::socket_t> hostile, monitors;
    for (int k = 0; k < 8; ++k) {
      hostile.emplace_back(ctx, zmq::socket_type::dealer);
      hostile.back().set(zmq::sockopt::linger, 0);
      const std::string monitor = "inproc://hostile-" + std::to_string(k);
      ASSERT_EQ(zmq_socket_monitor(static_cast<void*>(hostile.back()), monitor.c_str(), ZMQ_EVENT_DISCONNECTED), 0);
      monitors.emplace_back(ctx, zmq::socket_type::pair);
      monitors.back().connect(monitor);
      hostile.back().connect(ep);
    }
    for (int round = 0; round < 2; ++round)
      for (auto& h : hostile) {
        zmq::message_t m(huge.data(), huge.size(), [](void*, void*) {}, nullptr);
        h.send(m, zmq::send_flags::dontwait);
      }
    int refused = 0;
    const bool allRefused = waitUntil(
        [&] {
          zmq::message_t event;
          for (auto& m : monitors)
            while (m.recv(event, zmq::recv_flags::dontwait)) refused += event.more();  // an event's first frame
          return refused >= 2 * int(hostile.size());
        },
        std::chrono::seconds(20));
    EXPECT_TRUE(allRefused) << refused << " of " << 2 * hostile.size() << " frames refused";
    for (auto& h : hostile) zmq_socket_monitor(static_cast<void*>(h), nullptr, 0);
  }
  const uint64_t grown = vmHwmBytes() - before;
  std::printf("master peak RSS growth with 8 peers x 2 x 64 MiB frames: %.1f MiB\n", double(grown) / (1 << 20));
  EXPECT_LT(grown, uint64_t(128) << 20);
  EXPECT_EQ(runRealWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_GE(r.oversized, 1u);
  EXPECT_GE(r.bannedPeers, 1u);
  EXPECT_EQ(r.workersSeen, 1);  // only the real worker was welcomed
  expectSameLeaves(ref, master.outcome.result);
}

TEST(HostilePeer, ListenOnTheNetworkWithoutCurveNeedsInsecure) {
  EXPECT_TRUE(isLoopbackEndpoint("tcp://127.0.0.1:5555"));
  EXPECT_TRUE(isLoopbackEndpoint("tcp://localhost:*"));
  EXPECT_TRUE(isLoopbackEndpoint("tcp://[::1]:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://*:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://0.0.0.0:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://eth0:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://10.0.0.1:5555"));
  FarmOptions o = clusterOptions();
  o.listen = "tcp://*:5555";
  try {
    runJob(sphereJob(), o);
    ADD_FAILURE() << "an open farm on the network was not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--insecure"), std::string::npos) << e.what();
  }
}

// Garbage from a welcomed peer drops the peer, not its bricks: four peers in turn say hello, are
// leased the same two bricks (a dropped peer's bricks go back to the front of the queue) and send
// an unparsable frame. Were garbage charged to the bricks, the third would poison both; instead
// each peer is banned, told bye, and a real worker finishes the job as --workers 0 does.
TEST(HostilePeer, GarbageFromAWelcomedPeerDropsThePeerNotItsBricks) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  for (int k = 0; k < 4; ++k) {
    ScriptedPeer g(ctx, ep, "garbage-" + std::to_string(k));
    ASSERT_EQ(g.collect(Envelope::kTask, 2).size(), 2u) << k;
    const std::string junk = "\xff\xff\xff\xff not a protobuf envelope";
    g.s.send(zmq::buffer(junk));
    EXPECT_EQ(g.collect(Envelope::kBye, 1, 2000).size(), 1u) << "peer " << k << " was not dropped";
    g.s.set(zmq::sockopt::linger, 0);
  }
  EXPECT_EQ(runRealWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty()) << r.poisoned.size() << " brick(s) poisoned";
  EXPECT_GE(r.malformed, 4u);
  EXPECT_EQ(r.bannedPeers, 4u);
  EXPECT_EQ(r.bricksComputed, 8u);
  expectSameLeaves(ref, master.outcome.result);
}

// Results received in a row are decoded together and judged in arrival order: a peer that sends
// a corrupt result (banned) and right behind it a well-formed forged one for its other brick
// must not have the second merged, whether or not both landed in one batch. The forged brick
// goes back to the queue uncharged; the corrupt one is charged once.
TEST(HostilePeer, AResultBehindACorruptOneFromTheSamePeerIsNotMerged) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  ScriptedPeer a(ctx, ep, "a");
  std::vector<Envelope> held = a.collect(Envelope::kTask, 2);
  ASSERT_EQ(held.size(), 2u);
  a.forgeResult(jobIdOf(j), held[0].task(), /*corruptCrc=*/true);
  a.forgeResult(jobIdOf(j), held[1].task());
  EXPECT_EQ(a.collect(Envelope::kBye, 1, 2000).size(), 1u) << "the peer was not dropped";
  a.s.set(zmq::sockopt::linger, 0);
  EXPECT_EQ(runRealWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty());
  EXPECT_EQ(r.bannedPeers, 1u);
  EXPECT_EQ(r.bricksComputed, 8u);
  EXPECT_EQ(r.perWorker.count("a"), 0u);
  expectSameLeaves(ref, master.outcome.result);
}

// A worker whose master went silent reconnects under a new routing id and lists the bricks it
// still has (Hello.holding): the leases it no longer holds (their results went out on the
// closed connection) go back to the queue and come to it again. Before, it kept them: with every
// worker reconnected, no credit was left for their reissue and the job waited for ever.
TEST(HostilePeer, AReconnectedWorkerGetsBackTheBricksItNoLongerHas) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  zmq::context_t ctx(1);
  std::vector<Envelope> held;
  {
    ScriptedPeer first(ctx, ep, "first", false);
    first.sayHello("w");
    held = first.collect(Envelope::kTask, 2);  // at least two (its credit)
    ASSERT_EQ(held.size(), 2u);
    for (Envelope& e : first.collect(Envelope::kTask, 64, 50)) held.push_back(e);  // the rest of its credit, sent together
  }  // the old connection closes with every lease
  const uint64_t kept = held[0].task().brick_id();
  std::set<uint64_t> lost;
  for (size_t i = 1; i < held.size(); ++i) lost.insert(held[i].task().brick_id());
  ScriptedPeer again(ctx, ep, "again", false);
  Envelope h;
  h.mutable_hello()->set_worker_id("w");
  h.mutable_hello()->add_holding(kept);
  send(again.s, "", h);
  // Its lost leases come back to it (with any the old connection was sent but this test did not
  // read in time, which are lost too), never the one it still has.
  std::set<uint64_t> back;
  std::vector<Envelope> more;
  while (!std::includes(back.begin(), back.end(), lost.begin(), lost.end()) && more.size() < 16) {
    std::vector<Envelope> one = again.collect(Envelope::kTask, 1);
    ASSERT_EQ(one.size(), 1u) << "the reconnected worker got too few bricks: its lost leases still held its credit";
    more.push_back(one[0]);
    back.insert(one[0].task().brick_id());
  }
  EXPECT_TRUE(std::includes(back.begin(), back.end(), lost.begin(), lost.end()));
  EXPECT_EQ(back.count(kept), 0u) << "the brick it still has was leased again";
  held.resize(1);  // hand back what it holds now: the kept brick and those that came back
  held.insert(held.end(), more.begin(), more.end());
  again.handBackAndLeave(jobIdOf(j), held);
  EXPECT_EQ(runRealWorker(ep), 0);
  master.join();
  ASSERT_EQ(master.error, "");
  EXPECT_EQ(master.outcome.report.reconnects, 1u);
  EXPECT_TRUE(master.outcome.report.poisoned.empty());
  expectSameLeaves(ref, master.outcome.result);
}

namespace {
// A peer that answers `failed` to every task it is leased, on its own thread, until the master
// says bye (or `stop`). Then, when `helloAgain`, it says hello once more under a new connection
// and the same worker id, and records whether the master rejected it.
struct FailingPeer {
  std::atomic<bool> stop{false};
  std::atomic<int> failed{0};
  std::atomic<bool> gotBye{false}, rejectedAgain{false};
  std::thread thread;
  FailingPeer(const std::string& ep, const std::string& id, bool helloAgain) {
    thread = std::thread([this, ep, id, helloAgain] {
      zmq::context_t ctx(1);
      {
        ScriptedPeer p(ctx, ep, id);
        auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (!stop && !gotBye && std::chrono::steady_clock::now() < deadline) {
          zmq::pollitem_t item{static_cast<void*>(p.s), 0, ZMQ_POLLIN, 0};
          zmq::poll(&item, 1, std::chrono::milliseconds(20));
          Incoming in;
          std::string err;
          while (receive(p.s, false, in, &err)) {
            if (!err.empty()) continue;
            if (in.envelope.body_case() == Envelope::kTask) {
              p.fail(in.envelope.job_id(), in.envelope.task().brick_id(), false);
              ++failed;
            } else if (in.envelope.body_case() == Envelope::kBye) {
              gotBye = true;
            }
          }
          Envelope hb;
          hb.mutable_heartbeat();
          send(p.s, "", hb);
        }
      }
      if (!helloAgain || !gotBye) return;
      ScriptedPeer again(ctx, ep, id + "-again", false);
      again.sayHello(id);
      rejectedAgain = !again.collect(Envelope::kReject, 1, 3000).empty();
    });
  }
  ~FailingPeer() {
    stop = true;
    if (thread.joinable()) thread.join();
  }
};
}  // namespace

// Issue 31: one leased peer that answered `failed` to every task ended the whole job (its bricks
// came back to it, 13 poisoned in 1.4 s, exit 5). Now a brick it failed goes to another worker,
// it is banned once three of its failures are computed elsewhere (its worker id refused when it
// says hello again), nothing is poisoned and the output is the clean run's.
TEST(HostilePeer, APeerThatFailsEverythingIsBannedAndTheJobCompletes) {
  JobSpec j = sphereJob();
  SampleResult ref = reference(j);
  FarmOptions o = clusterOptions();
  o.brickVoxels = 16;  // 64 bricks
  const auto t0 = std::chrono::steady_clock::now();
  MasterThread master(j, o);
  const std::string ep = master.endpoint();
  FailingPeer failer(ep, "failer", /*helloAgain=*/true);
  // It fails bricks before the honest worker joins: those wait for another worker.
  waitUntil([&] { return failer.failed >= 8; }, std::chrono::seconds(5));
  EXPECT_GE(failer.failed, 8);
  WorkerProcess honest(ep, {slowMs(20)});
  master.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(honest.wait(30), 0);
  failer.stop = true;
  failer.thread.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_TRUE(r.poisoned.empty());
  EXPECT_EQ(r.failingPeersBanned, 1u);
  EXPECT_GE(r.refutedFailures, 3u);
  EXPECT_TRUE(failer.gotBye);
  EXPECT_TRUE(failer.rejectedAgain) << "the banned worker id was welcomed again";
  EXPECT_EQ(r.bricksComputed, 64u);
  expectSameLeaves(ref, master.outcome.result);
  std::printf("[ failing  ] the failing peer failed %d bricks; %llu refuted, banned; job %.2f s, 0 poisoned\n",
              failer.failed.load(), static_cast<unsigned long long>(r.refutedFailures), seconds);
}

// The job fails a brick only when two independent workers fail it: two peers that fail
// everything (and no honest worker) poison every brick, each failed by both, none by one alone.
TEST(HostilePeer, ABrickIsPoisonedWhenTwoWorkersFailIt) {
  JobSpec j = sphereJob();
  MasterThread master(j, clusterOptions());
  const std::string ep = master.endpoint();
  FailingPeer a(ep, "fails-a", false), b(ep, "fails-b", false);
  master.join();
  ASSERT_EQ(master.error, "");
  const FarmReport& r = master.outcome.report;
  EXPECT_EQ(r.poisoned.size(), 8u);
  for (const PoisonedBrick& p : r.poisoned) EXPECT_NE(p.error.find("forged failure"), std::string::npos);
  EXPECT_EQ(a.failed + b.failed, 16);  // each brick once by each
  EXPECT_EQ(r.failingPeersBanned, 0u);
}
