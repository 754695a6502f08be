// The lease table on a made-up clock: no sockets, no sleeps, no workers. Each test drives
// LeaseTable with time points of its own and checks exactly which brick goes to which peer,
// when a peer is dead, when a brick is poisoned and why (docs/farm.md, "Faults" and "Failing
// peers"). The same rules run through sockets in fault_test.cpp and hostile_peer_test.cpp.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "frep/farm/lease_table.h"

namespace frep::farm {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

// A table of `bricks` bricks on a clock that only moves when a test says so; records what it
// sent and what it poisoned.
struct Fixture {
  LeaseTime now = LeaseTime{} + seconds(1000);
  std::vector<std::pair<std::string, uint64_t>> sent;  // (routing id, brick), in order
  std::map<uint64_t, std::string> poisoned;            // brick -> the count that poisoned it
  std::set<std::string> unreachable;                   // peers a send fails to
  std::map<uint64_t, std::set<std::string>> opinions;  // the master's excluded workers
  LeaseTable table;

  explicit Fixture(size_t bricks, LeasePolicy policy = {}) {
    LeaseTable::Hooks hooks;
    hooks.poisoned = [this](uint64_t id, const std::string&, const std::string& count) { poisoned[id] = count; };
    hooks.excluded = [this](uint64_t id, const std::string& w) { return opinions[id].count(w) > 0; };
    table = LeaseTable(bricks, policy, hooks);
  }
  void dispatch() {
    table.dispatch(now, [this](const std::string& rid, uint64_t brick, uint32_t) {
      if (unreachable.count(rid)) return false;
      sent.emplace_back(rid, brick);
      return true;
    });
  }
  PeerLease& join(const std::string& rid, bool proven = true, uint32_t threads = 1) {
    PeerLease& p = table.join(rid, "w-" + rid, threads, now);
    if (proven) table.heard(p, now);
    return p;
  }
  std::vector<uint64_t> inflight(const std::string& rid) {
    auto& s = table.peers().at(rid).inflight;
    return {s.begin(), s.end()};
  }
  // The peer returns brick `id` and it is merged.
  void finish(const std::string& rid, uint64_t id) {
    table.release(id, rid);
    table.complete(id);
    table.credit(table.peers().at(rid).workerId);
  }
};

TEST(LeaseTable, EachPeerGetsItsCreditOfBricksInOrder) {
  Fixture f(20);
  f.join("a");
  f.join("b");
  f.dispatch();
  // kCredit rounds over the peers in routing-id order: a0 b1 a2 b3 ...
  ASSERT_EQ(f.sent.size(), size_t(2 * kCredit));
  for (size_t i = 0; i < f.sent.size(); ++i) {
    EXPECT_EQ(f.sent[i].first, i % 2 ? "b" : "a");
    EXPECT_EQ(f.sent[i].second, i);
  }
  EXPECT_EQ(f.inflight("a"), (std::vector<uint64_t>{0, 2, 4, 6}));
  EXPECT_EQ(f.table.brick(0).phase, BrickPhase::Leased);
  EXPECT_EQ(f.table.brick(0).attempts, 1u);
  EXPECT_EQ(f.table.brick(19).phase, BrickPhase::Pending);
  // A merged brick frees its holder's credit: the next pending brick goes to it.
  f.finish("a", 0);
  f.sent.clear();
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("a"), uint64_t(8)));
  EXPECT_EQ(f.table.done(), 1u);
}

// Near the end of the job the credit shrinks: a peer's (r + 1)-th brick only while the queue
// holds r for every peer, so that a worker does not keep bricks queued behind its running one
// while another, done, has nothing (the tail of a 2-worker run).
TEST(LeaseTable, NearTheEndAPeerGetsAnotherBrickOnlyWhileTheQueueHasOneForEveryPeer) {
  Fixture f(5);
  f.join("a");
  f.join("b");
  f.dispatch();
  // a0 b1 (3 left); round 1 needs 2: a2 (2 left), b3 (1 left); round 2 needs 4: none.
  EXPECT_EQ(f.inflight("a"), (std::vector<uint64_t>{0, 2}));
  EXPECT_EQ(f.inflight("b"), (std::vector<uint64_t>{1, 3}));
  EXPECT_EQ(f.table.brick(4).phase, BrickPhase::Pending);
  // b finishes both: brick 4 goes to it (round 0), not as a's third.
  f.finish("b", 1);
  f.finish("b", 3);
  f.sent.clear();
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("b"), uint64_t(4)));
  // A peer alone keeps its whole credit (AnIdlePeerGetsTheOldestStragglerOnce).
  Fixture g(5);
  g.join("a");
  g.dispatch();
  EXPECT_EQ(g.inflight("a"), (std::vector<uint64_t>{0, 1, 2, 3}));
}

TEST(LeaseTable, AnIdlePeerGetsTheLastBrickQueuedAtAnother) {
  // b computes two bricks at once: the two it holds run, none is queued, so a, done with
  // its own and nothing pending, gets nothing before the straggler rule.
  Fixture f(5);
  f.join("a");
  f.join("b", true, 2);
  f.dispatch();  // a0 b1, then a2 b3 (4 waits: NearTheEndAPeerGets...)
  EXPECT_EQ(f.inflight("a"), (std::vector<uint64_t>{0, 2}));
  EXPECT_EQ(f.inflight("b"), (std::vector<uint64_t>{1, 3}));
  f.finish("a", 0);
  f.finish("a", 2);
  f.dispatch();
  EXPECT_EQ(f.inflight("a"), (std::vector<uint64_t>{4}));
  f.finish("a", 4);
  f.sent.clear();
  f.dispatch();
  EXPECT_TRUE(f.sent.empty());
  EXPECT_EQ(f.table.stats().queuedReissues, 0u);

  // One thread each: a, alone at first, holds its whole credit 0 1 2 3 and computes 0; b,
  // idle once nothing is pending, gets the one a would start last (3), then 2, never 0.
  Fixture g(5);
  g.join("a");
  g.dispatch();
  g.join("b");
  g.finish("a", 1);
  g.now += milliseconds(10);
  g.dispatch();  // b: 4; a keeps 0 2 3
  EXPECT_EQ(g.inflight("a"), (std::vector<uint64_t>{0, 2, 3}));
  EXPECT_EQ(g.inflight("b"), (std::vector<uint64_t>{4}));
  EXPECT_EQ(g.table.stats().queuedReissues, 0u);
  g.finish("b", 4);
  g.sent.clear();
  g.now += milliseconds(10);
  g.dispatch();
  ASSERT_EQ(g.sent.size(), 1u);
  EXPECT_EQ(g.sent[0], std::make_pair(std::string("b"), uint64_t(3)));
  EXPECT_EQ(g.table.stats().queuedReissues, 1u);
  EXPECT_EQ(g.table.brick(3).holders.size(), 2u);
  g.finish("b", 3);  // merged from b: a's copy is cancelled (no longer its credit)
  EXPECT_EQ(g.inflight("a"), (std::vector<uint64_t>{0, 2}));
  g.sent.clear();
  g.dispatch();
  ASSERT_EQ(g.sent.size(), 1u);
  EXPECT_EQ(g.sent[0], std::make_pair(std::string("b"), uint64_t(2)));
  // b idle once more, a holding only the brick it computes: nothing before the straggler
  // rule's second, and 2 (a backup already) is not issued a third time.
  g.finish("b", 2);
  g.sent.clear();
  g.dispatch();
  EXPECT_TRUE(g.sent.empty());
  EXPECT_EQ(g.table.stats().queuedReissues, 2u);
  EXPECT_EQ(g.table.stats().stragglerReissues, 0u);
}

TEST(LeaseTable, ASilentPeerIsDeadAfterItsWindowAndItsBricksGoBack) {
  LeasePolicy policy;
  policy.liveWindow = milliseconds(3000);
  Fixture f(4, policy);
  f.join("a");
  f.dispatch();
  ASSERT_EQ(f.inflight("a").size(), 4u);
  f.now += milliseconds(3000);  // exactly the window: still alive
  EXPECT_EQ(f.table.expire(f.now), 0u);
  f.now += milliseconds(1);
  EXPECT_EQ(f.table.expire(f.now), 1u);
  EXPECT_TRUE(f.table.peers().empty());
  EXPECT_EQ(f.table.stats().deadWorkers, 1u);
  // The brick it was computing (its oldest lease) is suspect; the others are plain retries.
  EXPECT_TRUE(f.table.brick(0).suspect);
  for (uint64_t id = 1; id < 4; ++id) EXPECT_FALSE(f.table.brick(id).suspect) << id;
  for (uint64_t id = 0; id < 4; ++id) EXPECT_EQ(f.table.brick(id).phase, BrickPhase::Pending) << id;
  EXPECT_EQ(f.table.stats().suspectBricks, 1u);
  EXPECT_EQ(f.table.stats().retries, 4u);
  EXPECT_TRUE(f.poisoned.empty());
}

TEST(LeaseTable, HeardPeersStayAliveAndAStalledMasterCountsNoOneDead) {
  LeasePolicy policy;
  policy.liveWindow = milliseconds(3000);
  Fixture f(2, policy);
  PeerLease& a = f.join("a");
  f.dispatch();
  const LeaseTime leasedAt = f.table.brick(0).firstLease;
  f.now += milliseconds(2500);
  f.table.heard(a, f.now);
  f.now += milliseconds(2500);  // 5 s since the lease, 2.5 s since it was heard
  EXPECT_EQ(f.table.expire(f.now), 0u);
  // The master itself was stopped for 60 s: its turn comes late. Not its peers' silence.
  const LeaseTime last = f.now;
  f.now += seconds(60);
  EXPECT_EQ(f.table.turn(last, f.now), seconds(60));
  EXPECT_EQ(f.table.stats().masterStalls, 1u);
  EXPECT_EQ(f.table.expire(f.now), 0u);
  EXPECT_EQ(f.table.brick(0).firstLease, leasedAt + seconds(60));  // lease timers moved on too
  // A turn within the window is no stall.
  EXPECT_EQ(f.table.turn(f.now, f.now + milliseconds(3000)), LeaseClock::duration::zero());
  EXPECT_EQ(f.table.stats().masterStalls, 1u);
  // Its peer may be asleep in its longest reconnect backoff (32 s after a minute's silence):
  // alive until that and a window have passed, dead after.
  f.now += kReconnectMaxBackoff + milliseconds(3000);
  EXPECT_EQ(f.table.expire(f.now), 0u);
  f.now += milliseconds(1);
  EXPECT_EQ(f.table.expire(f.now), 1u);
}

// A hello sent while the master was stopped is read only after the stall is seen (ZeroMQ's I/O
// thread was stopped too): its peer, joined with a fresh window, may be asleep in its backoff
// (the worker gave up on that connection), so it too has the stall's grace.
TEST(LeaseTable, APeerThatJoinsJustAfterAStallHasItsGrace) {
  LeasePolicy policy;
  policy.liveWindow = milliseconds(1000);
  Fixture f(2, policy);
  f.join("a");
  const LeaseTime last = f.now;
  f.now += seconds(3);
  EXPECT_EQ(f.table.turn(last, f.now), seconds(3));
  f.now += milliseconds(4);
  f.join("stale");              // window until now + 1 s
  f.now += milliseconds(2000);  // silent past its own window: its worker sleeps 2 s
  EXPECT_EQ(f.table.expire(f.now), 0u);
  f.now += milliseconds(3000);  // past the grace: 3 s + the first backoff + a window after the wake
  EXPECT_EQ(f.table.expire(f.now), 2u);
}

TEST(LeaseTable, ASuspectGoesAloneToAFreshPeerAndFreshKillersPoisonIt) {
  LeasePolicy policy;
  policy.maxAttempts = 3;
  Fixture f(3, policy);
  f.join("a");
  f.dispatch();
  f.now += seconds(10);
  f.table.expire(f.now);  // "a" dies computing brick 0: suspect, not charged
  ASSERT_TRUE(f.table.brick(0).suspect);
  for (int killer = 0; killer < 3; ++killer) {
    const std::string rid = "k" + std::to_string(killer);
    f.join(rid);
    f.sent.clear();
    f.dispatch();
    // The suspect goes first and alone: a peer holding it gets nothing else.
    ASSERT_GE(f.sent.size(), 1u);
    EXPECT_EQ(f.sent[0], std::make_pair(rid, uint64_t(0)));
    EXPECT_EQ(f.inflight(rid), std::vector<uint64_t>{0});
    f.now += seconds(10);
    f.table.expire(f.now);
    EXPECT_EQ(f.table.brick(0).killers.size(), size_t(killer + 1));
  }
  ASSERT_EQ(f.poisoned.count(0), 1u);
  EXPECT_EQ(f.poisoned[0], "3 workers died computing it alone");
  EXPECT_EQ(f.table.brick(0).phase, BrickPhase::Poisoned);
  EXPECT_EQ(f.table.poisonedCount(), 1u);
  EXPECT_EQ(f.table.brick(0).lastError, "worker w-k2 died while computing it");
}

TEST(LeaseTable, WorkersThatFinishedBricksCountHalfAsKillers) {
  LeasePolicy policy;
  policy.maxAttempts = 1;  // one fresh killer poisons; a worker that finished others is churn
  Fixture f(4, policy);
  f.join("a");
  f.dispatch();
  f.now += seconds(10);
  f.table.expire(f.now);  // brick 0 suspect
  for (int i = 0; i < 2; ++i) {
    const std::string rid = "old" + std::to_string(i);
    f.join(rid);
    f.table.credit("w-" + rid);   // it has finished a brick
    f.now += milliseconds(6001);  // a suspect waits two windows for a fresh worker, then takes this one
    f.sent.clear();
    f.dispatch();
    ASSERT_EQ(f.sent.size(), 1u);
    EXPECT_EQ(f.sent[0], std::make_pair(rid, uint64_t(0)));
    f.now += seconds(10);
    f.table.expire(f.now);
    EXPECT_EQ(f.table.brick(0).weakKillers.size(), size_t(i + 1));
    EXPECT_EQ(f.poisoned.count(0), size_t(i));  // 2 x maxAttempts of them poison it
  }
  EXPECT_EQ(f.poisoned[0], "2 workers died computing it alone");
}

TEST(LeaseTable, PeersThatNeverProvedAliveAreNotChargedForTheirDeath) {
  Fixture f(1);
  for (int i = 0; i < 10; ++i) {
    f.join("v" + std::to_string(i), /*proven=*/false);
    f.dispatch();
    f.now += seconds(10);
    f.table.expire(f.now);
  }
  // Hello-and-vanish peers: they are never given the suspect (not proven), so no death counts.
  ASSERT_EQ(f.sent.size(), 1u);  // only the first, before it was suspect
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("v0"), uint64_t(0)));
  EXPECT_TRUE(f.poisoned.empty());
  EXPECT_TRUE(f.table.brick(0).killers.empty());
  EXPECT_EQ(f.table.brick(0).phase, BrickPhase::Pending);
}

TEST(LeaseTable, TwoWorkersFailingABrickPoisonIt) {
  Fixture f(1);
  PeerLease& a = f.join("a");
  f.join("b");
  f.dispatch();
  ASSERT_EQ(f.inflight("a"), std::vector<uint64_t>{0});
  f.table.release(0, "a");
  f.table.countFailure(a, 0);
  f.table.requeue(0, "boom", true, f.now, a.workerId);
  EXPECT_EQ(f.table.brick(0).phase, BrickPhase::Pending);
  // Not back to the worker that failed it while another could take it.
  f.sent.clear();
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0].first, "b");
  PeerLease& b = f.table.peers().at("b");
  f.table.release(0, "b");
  f.table.countFailure(b, 0);
  f.table.requeue(0, "boom", true, f.now, b.workerId);
  ASSERT_EQ(f.poisoned.count(0), 1u);
  EXPECT_EQ(f.poisoned[0], "2 workers failed it");
  EXPECT_EQ(f.table.brick(0).lastError, "boom");
}

TEST(LeaseTable, TheOnlyWorkerThatFailedABrickGetsItBackAfterTwoWindows) {
  LeasePolicy policy;
  policy.liveWindow = milliseconds(3000);
  policy.maxAttempts = 3;
  Fixture f(2, policy);
  PeerLease& a = f.join("a");
  f.dispatch();
  f.finish("a", 1);  // it has computed another brick: its word is credible
  f.table.release(0, "a");
  f.table.requeue(0, "boom", true, f.now, a.workerId);
  f.sent.clear();
  f.now += milliseconds(6000);  // two windows, not more
  f.dispatch();
  EXPECT_TRUE(f.sent.empty());
  f.now += milliseconds(1);
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("a"), uint64_t(0)));
  // Its failures count up to maxAttempts.
  for (int i = 2; i <= 3; ++i) {
    f.table.release(0, "a");
    f.table.requeue(0, "boom", true, f.now, a.workerId);
    if (i < 3) {
      f.now += milliseconds(6001);
      f.dispatch();
    }
  }
  ASSERT_EQ(f.poisoned.count(0), 1u);
  EXPECT_EQ(f.poisoned[0], "3 failures");
}

TEST(LeaseTable, AnOverdueLeaseIsIssuedOnceMoreToAnotherPeer) {
  LeasePolicy policy;
  policy.leaseSeconds = 5;
  policy.liveWindow = seconds(100);
  Fixture f(1, policy);
  f.join("a");
  f.join("b");
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  f.now += seconds(5);
  f.table.reissueOverdue(f.now);
  EXPECT_EQ(f.table.stats().leaseReissues, 0u);
  f.now += milliseconds(1);
  f.table.reissueOverdue(f.now);
  f.table.reissueOverdue(f.now);  // once per lease
  EXPECT_EQ(f.table.stats().leaseReissues, 1u);
  f.sent.clear();
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("b"), uint64_t(0)));
  EXPECT_EQ(f.table.brick(0).holders.size(), 2u);
  EXPECT_EQ(f.table.brick(0).attempts, 2u);
  // Whichever result comes first is merged; the other holder's copy is then a former holder's.
  f.finish("b", 0);
  EXPECT_TRUE(f.table.brick(0).holders.empty());
  EXPECT_TRUE(f.inflight("a").empty());
  EXPECT_EQ(f.table.holding(0, "a", f.table.peers().at("a")), Holding::FormerHolder);
  EXPECT_EQ(f.table.holding(0, "c", PeerLease{}), Holding::Stranger);
}

TEST(LeaseTable, AnIdlePeerGetsTheOldestStragglerOnce) {
  LeasePolicy policy;
  policy.liveWindow = seconds(100);
  Fixture f(3, policy);
  f.join("a", true, 3);
  f.dispatch();  // a holds 0, 1, 2 and computes them all (three threads: none queued)
  f.join("b");
  for (double s : {1.0, 1.0, 1.0}) f.table.addBrickSeconds(s);
  EXPECT_EQ(f.table.medianBrickSeconds(), 1.0);
  f.sent.clear();
  f.now += seconds(2);  // threshold: max(1, 2 x median) = 2 s, not passed
  f.dispatch();
  EXPECT_TRUE(f.sent.empty());
  f.now += milliseconds(1);
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("b"), uint64_t(0)));
  EXPECT_EQ(f.table.stats().stragglerReissues, 1u);
  // Once: another idle peer gets the next straggler, not brick 0 again.
  f.join("c");
  f.sent.clear();
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("c"), uint64_t(1)));
  f.finish("c", 1);
  f.finish("b", 0);
  f.sent.clear();
  f.dispatch();  // brick 2 is the last straggler; 0 and 1 are done
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0].second, 2u);
}

TEST(LeaseTable, AnUnreachablePeerGetsNothingMoreAndTheBrickStaysQueued) {
  Fixture f(2);
  f.join("a");
  f.join("b");
  f.unreachable.insert("a");
  f.dispatch();
  EXPECT_TRUE(f.table.peers().at("a").unreachable);
  EXPECT_TRUE(f.inflight("a").empty());
  // Brick 0 went back to the front of the queue: "b" got it, then brick 1.
  ASSERT_EQ(f.sent.size(), 2u);
  EXPECT_EQ(f.sent[0], std::make_pair(std::string("b"), uint64_t(0)));
  EXPECT_EQ(f.sent[1], std::make_pair(std::string("b"), uint64_t(1)));
  // A hello under a new connection makes it reachable again.
  f.table.join("a", "w-a", 1, f.now);
  EXPECT_FALSE(f.table.peers().at("a").unreachable);
}

TEST(LeaseTable, AReconnectedWorkerKeepsTheLeasesItStillHolds) {
  Fixture f(4);
  f.join("old");
  f.dispatch();  // old holds 0..3
  std::string oldRid;
  size_t lost = 0;
  ASSERT_TRUE(f.table.adopt("w-old", "new", {1, 3}, f.now, &oldRid, &lost));
  EXPECT_EQ(oldRid, "old");
  EXPECT_EQ(lost, 2u);
  EXPECT_EQ(f.table.peers().count("old"), 0u);
  EXPECT_EQ(f.inflight("new"), (std::vector<uint64_t>{1, 3}));
  EXPECT_EQ(f.table.brick(1).holders.count("new"), 1u);
  EXPECT_EQ(f.table.brick(0).phase, BrickPhase::Pending);
  EXPECT_EQ(f.table.brick(2).phase, BrickPhase::Pending);
  EXPECT_FALSE(f.table.adopt("w-nobody", "x", {}, f.now, &oldRid, &lost));
}

TEST(LeaseTable, AWorkerRefutedThriceAndMoreThanTwiceTheMedianIsBanned) {
  Fixture f(8);
  for (const char* rid : {"a", "b", "c"}) f.join(rid);
  f.table.refute("w-b");  // b: 1, the others 0
  LeaseTable::Refutation r = f.table.refute("w-a");
  EXPECT_TRUE(r.known && r.first && !r.ban);
  r = f.table.refute("w-a");
  EXPECT_FALSE(r.first || r.ban);
  r = f.table.refute("w-a");  // 3 > 2 x median(0, 1) = 0
  EXPECT_TRUE(r.ban);
  EXPECT_EQ(r.refuted, 3u);
  // Where every worker is refuted as often (a model that fails everywhere), no one is banned.
  Fixture g(8);
  for (const char* rid : {"a", "b", "c"}) g.join(rid);
  for (int i = 0; i < 3; ++i)
    for (const char* w : {"w-b", "w-c"}) g.table.refute(w);
  for (int i = 0; i < 3; ++i) r = g.table.refute("w-a");
  EXPECT_FALSE(r.ban);
  EXPECT_FALSE(g.table.refute("w-gone").known);
  EXPECT_EQ(g.table.stats().refutedFailures, 10u);
}

TEST(LeaseTable, ABannedWorkersFailuresNoLongerCount) {
  Fixture f(1);
  PeerLease& a = f.join("a");
  f.join("b");
  f.dispatch();
  f.table.release(0, "a");
  f.table.countFailure(a, 0);
  f.table.requeue(0, "lie", true, f.now, a.workerId);
  ASSERT_EQ(f.table.brick(0).failures, 1);
  f.table.forgetFailures("w-a");
  EXPECT_EQ(f.table.brick(0).failures, 0);
  EXPECT_TRUE(f.table.brick(0).failedBy.empty());
}

TEST(LeaseTable, ABrickHeldForASecondOpinionGoesToAnotherWorker) {
  Fixture f(1);
  f.join("a");
  f.join("b");
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  ASSERT_EQ(f.sent[0].first, "a");
  // a's result is held; the brick waits for another worker's.
  f.opinions[0].insert("w-a");
  f.table.release(0, "a");
  f.table.awaitAnother(0);
  EXPECT_EQ(f.table.brick(0).phase, BrickPhase::Pending);
  f.sent.clear();
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0].first, "b");
}

TEST(LeaseTable, ExpectedWorkersGetFiveSecondsToJoin) {
  LeasePolicy policy;
  policy.expectWorkers = 2;
  policy.liveWindow = seconds(100);
  Fixture f(4, policy);
  f.dispatch();
  f.join("a");
  f.dispatch();
  EXPECT_TRUE(f.sent.empty());
  f.now += milliseconds(4999);
  f.dispatch();
  EXPECT_TRUE(f.sent.empty());
  f.now += milliseconds(1);
  f.dispatch();
  EXPECT_EQ(f.sent.size(), 4u);
}

TEST(LeaseTable, AMergedBrickTakenBackIsQueuedFirst) {
  Fixture f(3);
  f.join("a");
  f.dispatch();
  f.finish("a", 2);
  ASSERT_EQ(f.table.done(), 1u);
  f.table.reopen(2, true);
  EXPECT_EQ(f.table.done(), 0u);
  EXPECT_EQ(f.table.brick(2).phase, BrickPhase::Pending);
  f.sent.clear();
  f.dispatch();
  ASSERT_EQ(f.sent.size(), 1u);
  EXPECT_EQ(f.sent[0].second, 2u);
  EXPECT_FALSE(f.table.over());
}

}  // namespace
}  // namespace frep::farm
