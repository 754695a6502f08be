// The scheduling loop: the socket, the peers' messages, liveness, local workers, dispatch.

#include <spdlog/spdlog.h>
#include <algorithm>
#include <fstream>

#include "frep/net/curve.h"
#include "frep/worker/job_model.h"
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
  size_t progressAtSpawn = leases_.done() + leases_.poisonedCount();
  auto nextSpawn = Clock::now();

  auto lastBeat = Clock::now();
  auto lastAlive = Clock::now();
  auto lastTurn = Clock::now();
  const auto hb = std::chrono::milliseconds(opt_.heartbeatMs);
  const FrameLimit frameLimit = [this](const std::string& rid) {
    return peers().count(rid) || aliases_.count(rid) ? kMaxEnvelopeBytes + payloadLimit_ : kMaxHelloBytes;
  };
  while (!leases_.over()) {
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
    // The master's own stall (SIGSTOP, swapping, a slow disk): every peer refreshed instead of
    // counted dead, the lease timers moved on (LeaseTable::turn).
    if (const auto gap = leases_.turn(lastTurn, now); gap != Clock::duration::zero()) {
      spdlog::warn("the master stalled for {:.1f} s (longer than the liveness window): its workers are not counted dead",
                   std::chrono::duration<double>(gap).count());
      lastAlive = now;
    }
    lastTurn = now;
    leases_.expire(now);
    if (local) {
      local->reap();
      if (leases_.done() + leases_.poisonedCount() > progressAtSpawn) {
        progressAtSpawn = leases_.done() + leases_.poisonedCount();
        futileSpawns = 0;
        respawnDelayMs = 0;
      }
      int missing = wanted - local->running();
      if (missing > 0 && now >= nextSpawn && !leases_.over()) {
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
    leases_.reissueOverdue(now);
    leases_.dispatch(now, [&](const std::string& rid, uint64_t id, uint32_t attempt) {
      return sendTask(router, rid, id, attempt);
    });
    if (now - lastBeat >= hb) {
      giveUpStarvedChecks(now);
      for (auto& [rid, p] : peers()) {
        Envelope e;
        e.set_job_id(jobId_);
        e.mutable_heartbeat();
        send(router, rid, e);
      }
      lastBeat = now;
    }
    if (!peers().empty()) lastAlive = now;
    else if (std::chrono::duration<double>(now - lastAlive).count() > opt_.noWorkerTimeoutSec) {
      throw std::runtime_error("no worker has been alive for " + std::to_string(opt_.noWorkerTimeoutSec) +
                               " s (" + std::to_string(bricks_.size() - leases_.done() - leases_.poisonedCount()) + " bricks left)");
    }
    progress_->update(leases_.done(), report_.pointEvals, int(peers().size()));
  }
  // Tell every worker the job is over; local ones exit, cluster ones too.
  for (auto& [rid, p] : peers()) {
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
  if (!peers().count(in.routingId))
    if (auto a = aliases_.find(in.routingId); a != aliases_.end() && peers().count(a->second))
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
  auto it = peers().find(in.routingId);
  if (e.body_case() == Envelope::kHello) {
    const std::string wid = e.hello().worker_id().empty() ? printable(in.routingId) : e.hello().worker_id();
    if (bannedWorkers_.count(wid)) {
      ++report_.refused;
      Envelope r;
      r.mutable_reject()->set_reason("worker " + wid + " was banned from this job: it failed bricks that other workers computed, or returned results other workers outvoted");
      send(router, in.routingId, r);
      return;
    }
    if (it == peers().end() && !adoptReconnected(wid, in.routingId, e.hello()) && peers().size() >= kMaxPeers) {
      ++report_.refused;
      Envelope r;
      r.mutable_reject()->set_reason("the farm is full (" + std::to_string(kMaxPeers) + " workers)");
      send(router, in.routingId, r);
      return;
    }
    Peer& p = leases_.join(in.routingId, wid, e.hello().threads(), now);
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
  if (it == peers().end()) {
    // A worker from before a master restart, or a stranger: ask for a hello first.
    if (e.body_case() == Envelope::kResult) ++report_.lateResults;
    Envelope r;
    r.mutable_reset();
    send(router, in.routingId, r);
    return;
  }
  Peer& p = it->second;
  leases_.heard(p, now);
  switch (e.body_case()) {
    case Envelope::kHeartbeat:
      break;
    case Envelope::kResult:
      noteWorkerTime(p.workerId, e.result());
      onResult(router, in, p);
      break;
    case Envelope::kFailed:
      onFailed(e, in.routingId, p);
      break;
    case Envelope::kBye:
      spdlog::info("worker {} left: {}", p.workerId, e.bye().reason());
      leases_.drop(in.routingId, Departure::Left, now);
      break;
    default:
      ++report_.malformed;
      break;
  }
}

// The worker's account of its time, from every result it sends (the worker's word: a report's
// diagnostics only, docs/farm.md "Scaling").
void Master::noteWorkerTime(const std::string& workerId, const Result& r) {
  WorkerShare& s = workerTime_[workerId];
  ++s.results;
  s.computeCpuSeconds += r.compute_cpu_seconds();
  s.taskCpuSeconds += r.task_cpu_seconds();
  s.processCpuSeconds = std::max(s.processCpuSeconds, r.process_cpu_seconds());
  s.idleSeconds += r.idle_seconds();
  if (s.firstIdleSeconds < 0) s.firstIdleSeconds = r.idle_seconds();
  lastResultAt_[workerId] = Clock::now();
}

// The workers' time counters to the report, for the workers with a brick merged (the others
// are not in it), and each one's tail: from its last result to the job's last.
void Master::reportWorkerTime() {
  Clock::time_point last{};
  for (auto& [w, t] : lastResultAt_) last = std::max(last, t);
  for (auto& [w, share] : report_.perWorker) {
    auto t = workerTime_.find(w);
    if (t == workerTime_.end()) continue;  // in-process, or bricks from the journal
    share.results = t->second.results;
    share.computeCpuSeconds = t->second.computeCpuSeconds;
    share.taskCpuSeconds = t->second.taskCpuSeconds;
    share.processCpuSeconds = t->second.processCpuSeconds;
    share.idleSeconds = t->second.idleSeconds;
    share.firstIdleSeconds = t->second.firstIdleSeconds;
    share.tailIdleSeconds = std::chrono::duration<double>(last - lastResultAt_[w]).count();
  }
}

// A hello with the worker id of a peer under another routing id: the worker reconnected
// (its master went silent, e.g. stopped). It keeps the leases of the bricks it says it still
// has (hello.holding); the others' results went out on the connection it closed and may be
// lost, so those bricks go back to the queue (a late copy is a former holder's duplicate).
// Keeping them leased would hold the worker's credit for results that never come: with every
// worker reconnected, the job would wait for ever.
bool Master::adoptReconnected(const std::string& workerId, const std::string& rid, const Hello& hello) {
  std::string oldRid;
  size_t lost = 0;
  const std::set<uint64_t> still(hello.holding().begin(), hello.holding().end());
  if (!leases_.adopt(workerId, rid, still, Clock::now(), &oldRid, &lost)) return false;
  if (aliases_.size() >= kMaxAliases) aliases_.clear();
  aliases_[oldRid] = rid;
  ++report_.reconnects;
  spdlog::info("worker {} reconnected: it keeps {} lease(s), {} brick(s) go back to the queue", workerId,
               peers()[rid].inflight.size(), lost);
  return true;
}

// A peer that sent garbage: a welcomed one is told bye and its bricks go back to the queue,
// not charged; its routing id is ignored from now on (bounded list, oldest forgotten). `rid` is
// a copy: banWorker passes the key of the peer entry that leases_.drop erases (a use after free
// that TSan found, HostilePeer.APeerThatFailsEverythingIsBannedAndTheJobCompletes).
void Master::ban(zmq::socket_t& router, std::string rid, const std::string& why) {
  if (peers().count(rid)) {
    Envelope bye;
    bye.set_job_id(jobId_);
    bye.mutable_bye()->set_reason("dropped by the master: " + why);
    send(router, rid, bye);
    spdlog::warn("worker {} dropped: {}", peers()[rid].workerId, why);
    leases_.drop(rid, Departure::Dropped, Clock::now());
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
  const Holding h = leases_.holding(b.id, rid, p);
  if (h == Holding::Holder) return true;
  if (h == Holding::FormerHolder) {
    ++report_.duplicates;  // a former holder's late copy (cancelled, re-leased or done)
    return false;
  }
  ++report_.foreignResults;
  spdlog::warn("dropped a {} for brick {} from {}, which does not hold it", what, b.id, p.workerId);
  return false;
}

}  // namespace frep::farm::detail
