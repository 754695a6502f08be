// The scheduling loop: the socket, the peers' messages, liveness, local workers, dispatch.

#include <spdlog/spdlog.h>
#include <algorithm>
#include <fstream>

#include "frep/net/curve.h"
#include "frep/worker/brick.h"
#include "master.h"

namespace frep::farm::detail {

namespace {

// The master socket's kernel receive buffer (ZMQ_RCVBUF; 0: the kernel's own). Results are large
// (a sample brick ~150 kB), and on a short round trip (local workers, a LAN) receive autotuning
// sizes each connection's window to the tiny bandwidth-delay product, below one result, so a
// result crossed in several window updates: a fixed 4 MiB took the senders 61 -> 52 us of CPU a
// brick and the master 1.06x the bricks a second (bench_farm, 30 runs each, alternated). A fixed
// buffer turns autotuning off and the kernel caps it at net.core.rmem_max: it is set only where
// that allows 1 MiB or more (a fixed 208 KiB, Debian's default cap, was 0.78x the rate).
int receiveBufferBytes() {
  std::ifstream f("/proc/sys/net/core/rmem_max");
  long long allowed = 0;
  if (!(f >> allowed) || allowed < (1 << 20)) return 0;
  return int(std::min<long long>(allowed, 4 << 20));
}

}  // namespace

void Master::runFarm() {
  // Compile once here too: a model that does not compile fails before any worker starts.
  describeErrorBounds(*compileJobModel(job_), &report_.errorBounds);
  for (const std::string& line : describeExactTerms(job_)) report_.errorBounds.push_back(line);
  zmq::context_t ctx(1);
  std::unique_ptr<ZapAuthenticator> zap;
  CurveKeys keys;
  if (!opt_.curveDir.empty()) {
    keys = loadCurveKeys(opt_.curveDir, true);
    zap = std::make_unique<ZapAuthenticator>(ctx, keys.authorized);
  }
  zmq::socket_t router(ctx, zmq::socket_type::router);
  router.set(zmq::sockopt::linger, 0);
  router.set(zmq::sockopt::router_mandatory, 1);
  // ZMQ_MAXMSGSIZE is socket-wide (every peer, welcomed or not) and per frame: the largest
  // frame this job can need. A bigger frame makes ZeroMQ close that connection before it
  // allocates the frame. ZMQ_RCVHWM bounds the frames queued per connection; the per-peer
  // hello limit is ours (frameLimit), checked before parsing.
  router.set(zmq::sockopt::maxmsgsize, int64_t(std::min<size_t>(std::max(kMaxEnvelopeBytes, payloadLimit_), 256u << 20)));
  router.set(zmq::sockopt::rcvhwm, kRouterRcvHwm);
  if (const int bytes = receiveBufferBytes()) router.set(zmq::sockopt::rcvbuf, bytes);  // before bind: accepted connections inherit it
  if (zap) applyCurveServer(router, keys);
  std::string endpoint = opt_.listen.empty() ? "tcp://127.0.0.1:*" : opt_.listen;
  router.bind(endpoint);
  endpoint = router.get(zmq::sockopt::last_endpoint);
  spdlog::info("master listening on {}", endpoint);
  if (opt_.onListening) opt_.onListening(endpoint);
  if (opt_.progressJson)
    std::printf("{\"event\":\"listening\",\"endpoint\":\"%s\",\"bricks\":%zu}\n", endpoint.c_str(), bricks_.size()),
        std::fflush(stdout);

  std::unique_ptr<LocalWorkers> local;
  int wanted = 0;
  if (opt_.listen.empty()) {
    wanted = localWorkerCount();
    std::vector<std::string> args{"--connect", endpoint, "--threads", std::to_string(opt_.workerThreads),
                                  "--log-level", opt_.logLevel, "--master-timeout", "10"};
    if (!opt_.curveDir.empty()) args.insert(args.end(), {"--curve", opt_.curveDir});
    local = std::make_unique<LocalWorkers>(opt_.workerExecutable, args);
    local->spawn(wanted);
  }
  // Local workers that die are replaced with back-off: the delay doubles (100 ms .. 2 s)
  // while no brick finishes and resets when one does; once more workers than
  // futileLimit have been started since the last brick finished, none can: fail fast.
  const int futileLimit = wanted + 2 * (opt_.maxAttempts + 1);
  int futileSpawns = wanted, respawnDelayMs = 0;
  size_t progressAtSpawn = done_ + poisoned_;
  auto nextSpawn = Clock::now();

  auto lastBeat = Clock::now();
  auto lastAlive = Clock::now();
  auto lastTurn = Clock::now();
  const auto hb = std::chrono::milliseconds(opt_.heartbeatMs);
  const auto window = std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness);
  const FrameLimit frameLimit = [this](const std::string& rid) {
    return peers_.count(rid) || aliases_.count(rid) ? kMaxEnvelopeBytes + payloadLimit_ : kMaxHelloBytes;
  };
  while (done_ + poisoned_ < bricks_.size()) {
    zmq::pollitem_t item{static_cast<void*>(router), 0, ZMQ_POLLIN, 0};
    try {
      zmq::poll(&item, 1, std::chrono::milliseconds(std::max(5, opt_.heartbeatMs / 4)));
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR) throw;
    }
    if (gStop) {
      report_.interrupted = true;
      spdlog::warn("stop requested: no more dispatching, journal flushed; continue with --resume");
      break;
    }
    // Drain at most a bounded batch per turn so timers still run under a flood.
    for (int n = 0; n < 256; ++n) {
      Incoming in;
      std::string err;
      if (!receive(router, true, in, &err, frameLimit)) break;
      // Only results in a row share a batch: anything else sees the state they leave.
      if (!err.empty() || in.envelope.body_case() != Envelope::kResult) verifyArrivals(router);
      handle(router, in, err);
    }
    verifyArrivals(router);
    rethrowMergeError();
    auto now = Clock::now();
    // The master's own stall (SIGSTOP, swapping, a slow disk): a turn is at most a poll
    // (a quarter beat) and a bounded drain, so a gap longer than the liveness window means
    // the master was deaf, not its peers silent. Refresh every peer instead of counting them
    // dead, and move the lease timers on (steady clock: wall-clock jumps do not count).
    if (now - lastTurn > window) {
      ++report_.masterStalls;
      auto gap = now - lastTurn;
      spdlog::warn("the master stalled for {:.1f} s (longer than the liveness window): its workers are not counted dead",
                   std::chrono::duration<double>(gap).count());
      for (auto& [rid, p] : peers_) p.expiry = std::max(p.expiry, now + window);
      for (uint64_t id : leased_) bricks_[id].firstLease += gap;
      lastAlive = now;
    }
    lastTurn = now;
    expireDeadPeers(now);
    if (local) {
      local->reap();
      if (done_ + poisoned_ > progressAtSpawn) {
        progressAtSpawn = done_ + poisoned_;
        futileSpawns = 0;
        respawnDelayMs = 0;
      }
      int missing = wanted - local->running();
      if (missing > 0 && now >= nextSpawn && done_ + poisoned_ < bricks_.size()) {
        if (futileSpawns + missing > futileLimit)
          throw std::runtime_error("local workers keep dying: " + std::to_string(futileSpawns) +
                                   " started since the last brick finished (last one " + local->lastExit() +
                                   "); run with --log-level info, or --workers 0 to compute in-process");
        futileSpawns += missing;
        local->spawn(missing);
        respawnDelayMs = std::min(2000, respawnDelayMs ? 2 * respawnDelayMs : 100);
        nextSpawn = now + std::chrono::milliseconds(respawnDelayMs);
      }
    }
    reissueOverdue(now);
    dispatch(router, now);
    if (now - lastBeat >= hb) {
      giveUpStarvedChecks(now);
      for (auto& [rid, p] : peers_) {
        Envelope e;
        e.set_job_id(jobId_);
        e.mutable_heartbeat();
        send(router, rid, e);
      }
      lastBeat = now;
    }
    if (!peers_.empty()) lastAlive = now;
    else if (std::chrono::duration<double>(now - lastAlive).count() > opt_.noWorkerTimeoutSec) {
      throw std::runtime_error("no worker has been alive for " + std::to_string(opt_.noWorkerTimeoutSec) +
                               " s (" + std::to_string(bricks_.size() - done_ - poisoned_) + " bricks left)");
    }
    progress_->update(done_, report_.pointEvals, int(peers_.size()));
  }
  // Tell every worker the job is over; local ones exit, cluster ones too.
  for (auto& [rid, p] : peers_) {
    Envelope e;
    e.set_job_id(jobId_);
    e.mutable_bye()->set_reason(report_.interrupted ? "master stopping" : "job done");
    send(router, rid, e);
  }
  if (zap) report_.curveRejected = zap->rejected();
  // The byes leave while the context closes (it waits for them up to the linger) instead of
  // after a fixed sleep; local workers exit on theirs while the master merges, and are reaped
  // (and signalled, should one still run) when the master is done (retired_).
  router.set(zmq::sockopt::linger, 100);
  retired_ = std::move(local);
}

void Master::handle(zmq::socket_t& router, Incoming& in, const std::string& err) {
  if (banned_.count(in.routingId)) return;  // dropped for garbage before: ignored
  // A worker that reconnected speaks under its new routing id; late frames on the old one
  // are its frames too.
  if (!peers_.count(in.routingId))
    if (auto a = aliases_.find(in.routingId); a != aliases_.end() && peers_.count(a->second))
      in.routingId = a->second;
  if (!err.empty()) {
    ++(in.oversized ? report_.oversized : report_.malformed);
    spdlog::warn("dropped a malformed message from {}: {}", printable(in.routingId), err);
    ban(router, in.routingId, err);
    return;
  }
  const Envelope& e = in.envelope;
  if (e.ByteSizeLong() > kMaxEnvelopeBytes || (in.payload && in.payload->size() > payloadLimit())) {
    ++report_.oversized;
    spdlog::warn("dropped an oversized message from {}", printable(in.routingId));
    ban(router, in.routingId, "oversized message");
    return;
  }
  if (e.proto_major() != kProtoMajor) {
    ++report_.refused;
    Envelope r;
    r.mutable_reject()->set_reason("protocol major " + std::to_string(e.proto_major()) +
                                   " is not supported: this master speaks " + std::to_string(kProtoMajor) + "." +
                                   std::to_string(kProtoMinor) + " (use a frep-worker from the same release)");
    send(router, in.routingId, r);
    spdlog::warn("refused {}: protocol major {}", printable(in.routingId), e.proto_major());
    return;
  }
  auto now = Clock::now();
  auto it = peers_.find(in.routingId);
  if (e.body_case() == Envelope::kHello) {
    const std::string wid = e.hello().worker_id().empty() ? printable(in.routingId) : e.hello().worker_id();
    if (bannedWorkers_.count(wid)) {
      ++report_.refused;
      Envelope r;
      r.mutable_reject()->set_reason("worker " + wid + " was banned from this job: it failed bricks that other workers computed, or returned results other workers outvoted");
      send(router, in.routingId, r);
      return;
    }
    if (it == peers_.end() && !adoptReconnected(wid, in.routingId, e.hello()) && peers_.size() >= kMaxPeers) {
      ++report_.refused;
      Envelope r;
      r.mutable_reject()->set_reason("the farm is full (" + std::to_string(kMaxPeers) + " workers)");
      send(router, in.routingId, r);
      return;
    }
    Peer& p = peers_[in.routingId];
    p.workerId = wid;
    p.unreachable = false;  // a new connection
    p.threads = std::max(1u, e.hello().threads());
    p.expiry = now + std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness);
    ++report_.workersSeen;
    Envelope w;
    w.set_job_id(jobId_);
    w.mutable_welcome()->set_heartbeat_ms(uint32_t(opt_.heartbeatMs));
    w.mutable_welcome()->set_liveness(uint32_t(opt_.liveness));
    *w.mutable_welcome()->mutable_job() = job_;  // once per connection; tasks name it by jobId_
    send(router, in.routingId, w);
    spdlog::info("worker {} joined ({} threads, {})", p.workerId, p.threads, e.hello().build());
    return;
  }
  if (it == peers_.end()) {
    // A worker from before a master restart, or a stranger: ask for a hello first.
    if (e.body_case() == Envelope::kResult) ++report_.lateResults;
    Envelope r;
    r.mutable_reset();
    send(router, in.routingId, r);
    return;
  }
  Peer& p = it->second;
  p.expiry = now + std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness);
  p.proven = true;
  switch (e.body_case()) {
    case Envelope::kHeartbeat:
      break;
    case Envelope::kResult:
      onResult(router, in, p);
      break;
    case Envelope::kFailed:
      onFailed(e, in.routingId, p);
      break;
    case Envelope::kBye:
      spdlog::info("worker {} left: {}", p.workerId, e.bye().reason());
      dropPeer(in.routingId, Departure::Left);
      break;
    default:
      ++report_.malformed;
      break;
  }
}

// A hello with the worker id of a peer under another routing id: the worker reconnected
// (its master went silent, e.g. stopped). It keeps the leases of the bricks it says it still
// has (hello.holding); the others' results went out on the connection it closed and may be
// lost, so those bricks go back to the queue (a late copy is a former holder's duplicate).
// Keeping them leased would hold the worker's credit for results that never come: with every
// worker reconnected, the job would wait for ever.
bool Master::adoptReconnected(const std::string& workerId, const std::string& rid, const Hello& hello) {
  auto old = std::find_if(peers_.begin(), peers_.end(), [&](auto& kv) { return kv.second.workerId == workerId; });
  if (old == peers_.end()) return false;
  std::string oldRid = old->first;
  Peer moved = std::move(old->second);
  peers_.erase(old);
  const std::set<uint64_t> still(hello.holding().begin(), hello.holding().end());
  std::vector<uint64_t> lost;
  for (uint64_t id : moved.inflight) {
    auto& h = bricks_[id].holders;
    auto node = h.extract(oldRid);
    if (node && still.count(id)) {
      node.key() = rid;
      h.insert(std::move(node));
    } else {
      lost.push_back(id);
    }
  }
  for (uint64_t id : lost) {
    moved.inflight.erase(id);
    Brick& b = bricks_[id];
    if (b.phase == BrickPhase::Leased && b.holders.empty())
      requeue(b, "its result was lost when worker " + workerId + " reconnected", false);
  }
  peers_[rid] = std::move(moved);
  if (aliases_.size() >= kMaxAliases) aliases_.clear();
  aliases_[oldRid] = rid;
  ++report_.reconnects;
  spdlog::info("worker {} reconnected: it keeps {} lease(s), {} brick(s) go back to the queue", workerId,
               peers_[rid].inflight.size(), lost.size());
  return true;
}

// A peer that sent garbage: a welcomed one is told bye and its bricks go back to the queue,
// not charged; its routing id is ignored from now on (bounded list, oldest forgotten).
void Master::ban(zmq::socket_t& router, const std::string& rid, const std::string& why) {
  if (peers_.count(rid)) {
    Envelope bye;
    bye.set_job_id(jobId_);
    bye.mutable_bye()->set_reason("dropped by the master: " + why);
    send(router, rid, bye);
    spdlog::warn("worker {} dropped: {}", peers_[rid].workerId, why);
    dropPeer(rid, Departure::Dropped);
  }
  if (!banned_.insert(rid).second) return;
  ++report_.bannedPeers;
  bannedOrder_.push_back(rid);
  if (bannedOrder_.size() > kMaxBanned) {
    banned_.erase(bannedOrder_.front());
    bannedOrder_.pop_front();
  }
}

std::string Master::printable(const std::string& rid) {
  std::string s;
  for (unsigned char c : rid) s += (c >= 32 && c < 127) ? char(c) : '?';
  return s.empty() ? "?" : s;
}

// Only the brick's leaseholder may answer for it: anything else is foreign and dropped.
// Returns whether `rid` holds the brick; counts a foreign message otherwise.
bool Master::holds(const Brick& b, const std::string& rid, const Peer& p, const char* what) {
  if (b.holders.count(rid)) return true;
  if (p.everHeld.count(b.id)) {
    ++report_.duplicates;  // a former holder's late copy (cancelled, re-leased or done)
    return false;
  }
  ++report_.foreignResults;
  spdlog::warn("dropped a {} for brick {} from {}, which does not hold it", what, b.id, p.workerId);
  return false;
}

void Master::expireDeadPeers(Clock::time_point now) {
  std::vector<std::string> dead;
  for (auto& [rid, p] : peers_)
    if (now > p.expiry) dead.push_back(rid);
  for (auto& rid : dead) {
    ++report_.deadWorkers;
    spdlog::warn("worker {} silent past its liveness window: dead, its bricks go back to the queue",
                 peers_[rid].workerId);
    dropPeer(rid, Departure::Dead);
  }
}

void Master::sendTask(zmq::socket_t& router, const std::string& rid, Peer& p, Brick& b, Clock::time_point now) {
  Envelope e;
  e.set_job_id(jobId_);
  Task* t = e.mutable_task();
  t->set_brick_id(b.id);
  t->set_attempt(++b.attempts);
  for (int a = 0; a < 3; ++a) {
    t->add_lo(b.lo[a]);
    t->add_hi(b.hi[a]);
  }
  if (!send(router, rid, e)) {
    // No route to the peer: its connection closed without a bye (it crashed or reconnected)
    // and its liveness window has not run out yet. dispatch() already took a pending brick
    // off pending_: put it back, or no one would lease it again and the job would never end
    // (the loop keeps waiting while the other workers heartbeat). A reissued or backup copy
    // stays leased to its other holders and goes back to the reissue queue (it was due).
    if (b.phase == BrickPhase::Pending) (b.suspect ? suspects_ : pending_).push_front(b.id);
    else reissue_.push_back(b.id);
    // The peer gets nothing more; it keeps its leases until its liveness window runs out
    // (then it is dead, expireDeadPeers) or it says hello again under a new connection (a
    // worker whose master was stalled reconnects: adoptReconnected), so one death is
    // judged one way, whichever way it is noticed first.
    if (!p.unreachable) spdlog::info("worker {} unreachable: no more bricks for it", p.workerId);
    p.unreachable = true;
    return;
  }
  if (b.phase != BrickPhase::Leased) b.firstLease = now;
  b.phase = BrickPhase::Leased;
  leased_.insert(b.id);
  b.holders[rid] = now;
  p.inflight.insert(b.id);
  p.everHeld.insert(b.id);
}

void Master::dispatch(zmq::socket_t& router, Clock::time_point now) {
  // Cluster mode: give the expected workers a short grace period to join, so that the first
  // bricks spread over the whole farm instead of queuing on the earliest worker.
  if (opt_.expectWorkers > 0 && int(peers_.size()) < opt_.expectWorkers) {
    if (peers_.empty()) return;
    if (!firstJoin_) firstJoin_ = now;
    if (now - *firstJoin_ < std::chrono::seconds(5)) return;
  }
  // Peers in routing-id order: dispatch order never changes the output, only the schedule.
  std::vector<std::string> rids;
  for (auto& [rid, p] : peers_) rids.push_back(rid);
  auto holdsSuspect = [&](const Peer& p) {
    return std::any_of(p.inflight.begin(), p.inflight.end(), [&](uint64_t id) { return bricks_[id].suspect; });
  };
  // Takes the first brick of `queue` that `cand` may take (its phase `phase`), passing over at
  // most kMaxSkippedForPeer that it failed before (they stay at the front, in order).
  auto takeFrom = [&](std::deque<uint64_t>& queue, const Peer& cand, std::optional<uint64_t>& next) {
    std::vector<uint64_t> skipped;
    while (!queue.empty() && !next && skipped.size() < kMaxSkippedForPeer) {
      uint64_t id = queue.front();
      queue.pop_front();
      if (bricks_[id].phase != BrickPhase::Pending) continue;
      if (mayTake(cand, bricks_[id], now)) next = id;
      else skipped.push_back(id);
    }
    queue.insert(queue.begin(), skipped.begin(), skipped.end());
  };
  for (int round = 0; round < kCredit; ++round)
    for (auto& rid : rids) {
      auto it = peers_.find(rid);
      if (it == peers_.end() || it->second.unreachable || int(it->second.inflight.size()) > round ||
          holdsSuspect(it->second))
        continue;
      // A suspect brick goes only alone to a worker that has shown it is alive, a fresh one
      // unless it has waited two liveness windows for one (onDeath).
      const Peer& cand = it->second;
      const bool isolates = cand.proven && cand.inflight.empty() &&
                            (cand.finished == 0 || suspects_.empty() ||
                             now - bricks_[suspects_.front()].suspectSince > 2 * liveWindow());
      std::optional<uint64_t> next;
      if (isolates) takeFrom(suspects_, cand, next);
      std::vector<uint64_t> notHere;  // suspect copies due again, for an isolating worker
      while (!reissue_.empty() && !next) {
        uint64_t id = reissue_.front();
        reissue_.pop_front();
        if (bricks_[id].phase != BrickPhase::Leased || bricks_[id].holders.count(rid)) continue;
        if ((bricks_[id].suspect && !isolates) || bricks_[id].failedBy.count(cand.workerId) ||
            holdsOpinion(bricks_[id], cand.workerId))
          notHere.push_back(id);
        else next = id;
      }
      reissue_.insert(reissue_.begin(), notHere.begin(), notHere.end());
      if (!next) takeFrom(pending_, cand, next);
      if (!next) continue;
      sendTask(router, rid, it->second, bricks_[*next], now);
    }
  // Stragglers: nothing queued and a worker idle -> the oldest long-running brick, once more.
  if (!pending_.empty() || !suspects_.empty()) return;
  double threshold = std::max(1.0, 2 * medianBrickSeconds());
  for (auto& rid : rids) {
    auto it = peers_.find(rid);
    if (it == peers_.end() || it->second.unreachable || !it->second.inflight.empty()) continue;
    Brick* oldest = nullptr;
    for (uint64_t id : leased_)
      if (Brick& b = bricks_[id]; !b.backupIssued && !b.suspect && !b.holders.count(rid) &&
          !b.failedBy.count(it->second.workerId) && !holdsOpinion(b, it->second.workerId) &&
          std::chrono::duration<double>(now - b.firstLease).count() > threshold &&
          (!oldest || b.firstLease < oldest->firstLease))
        oldest = &b;
    if (!oldest) return;
    oldest->backupIssued = true;
    ++report_.stragglerReissues;
    spdlog::info("brick {} is a straggler: issued once more to {}", oldest->id, it->second.workerId);
    sendTask(router, rid, it->second, *oldest, now);
  }
}

}  // namespace frep::farm::detail
