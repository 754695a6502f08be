// The master's scheduling loop (see farm_master.h and docs/farm.md for the guarantees).
#include "farm_master.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <deque>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>
#include <zmq.hpp>

#include "brick.h"
#include "curve.h"
#include "frep/meshing/mesh_merge.h"
#include "journal.h"
#include "local_workers.h"
#include "progress.h"
#include "wire.h"

namespace frep::farm {

namespace {

using Clock = std::chrono::steady_clock;
std::atomic<bool> gStop{false};
void onStopSignal(int) { gStop = true; }

// Installs SIGTERM/SIGINT handlers for the lifetime of a job, restoring the old ones after.
struct SignalScope {
  struct sigaction oldTerm {}, oldInt {};
  SignalScope() {
    gStop = false;
    struct sigaction sa {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, &oldTerm);
    sigaction(SIGINT, &sa, &oldInt);
  }
  ~SignalScope() {
    sigaction(SIGTERM, &oldTerm, nullptr);
    sigaction(SIGINT, &oldInt, nullptr);
  }
};

constexpr size_t kMaxEnvelopeBytes = 1 << 20;  // a task or result header is a few KB at most
constexpr int kCredit = 2;                     // bricks in flight per worker (hides latency)

enum class BrickPhase { Pending, Leased, Done, Poisoned };

struct Brick {
  uint64_t id = 0;
  std::array<int32_t, 3> lo{}, hi{};
  BrickPhase phase = BrickPhase::Pending;
  int failures = 0;  // failed attempts and worker deaths while holding it
  uint32_t attempts = 0;
  std::map<std::string, Clock::time_point> holders;  // routing id -> lease start
  Clock::time_point firstLease{};
  bool backupIssued = false, leaseReissued = false;
  std::string lastError;
  size_t maxLeaves = 0;  // upper bound on leaves in the region (payload sanity check)
};

struct Peer {
  std::string workerId;
  uint32_t threads = 1;
  Clock::time_point expiry;
  std::set<uint64_t> inflight;
};

class Master {
 public:
  Master(const JobSpec& job, const FarmOptions& opt)
      : job_(job), opt_(opt), jobId_(jobIdOf(job)), grid_(gridOf(job)), op_(operationOf(job)) {
    if (opt.brickVoxels < 8 || opt.brickVoxels % 8 != 0)
      throw std::invalid_argument("--brick must be a positive multiple of 8 voxels");
    plan();
  }

  FarmOutcome run() {
    SignalScope signals;
    start_ = Clock::now();
    if (!opt_.journalPath.empty()) {
      journal_ = std::make_unique<Journal>(opt_.journalPath, jobId_, opt_.resume, [&](uint64_t id, const std::string& payload) {
        if (id >= bricks_.size() || bricks_[id].phase == BrickPhase::Done) return;
        BrickOutput out;
        std::string err;
        if (!decodePayload(op_, payload.data(), payload.size(), out, &err) || !insideBrick(out, bricks_[id])) return;
        commit(id, std::move(out), "journal", false);
        ++report_.bricksFromJournal;
      });
      if (report_.bricksFromJournal)
        spdlog::info("resumed {} of {} bricks from {}", report_.bricksFromJournal, bricks_.size(), opt_.journalPath);
    }
    progress_ = std::make_unique<Progress>(opt_.progressBar, opt_.progressJson, bricks_.size());
    if (done_ + poisoned_ < bricks_.size()) {
      if (opt_.workers == 0 && opt_.listen.empty()) runInProcess();
      else runFarm();
    }
    progress_->finish(done_, report_.pointEvals, int(peers_.size()));
    if (journal_) journal_->flush();
    return finish();
  }

 private:
  void plan() {
    const int b = opt_.brickVoxels;
    int n[3];
    for (int a = 0; a < 3; ++a) n[a] = (grid_.dims[a] + b - 1) / b;
    for (int i = 0; i < n[0]; ++i)
      for (int j = 0; j < n[1]; ++j)
        for (int k = 0; k < n[2]; ++k) {
          Brick br;
          br.id = bricks_.size();
          br.lo = {i * b, j * b, k * b};
          br.hi = {std::min((i + 1) * b, grid_.dims[0]), std::min((j + 1) * b, grid_.dims[1]),
                   std::min((k + 1) * b, grid_.dims[2])};
          size_t leaves = 1;
          for (int a = 0; a < 3; ++a) leaves *= size_t((br.hi[a] - br.lo[a] + 7) / 8);
          br.maxLeaves = leaves;
          bricks_.push_back(br);
          pending_.push_back(br.id);
        }
    outputs_.resize(bricks_.size());
    report_.bricks = bricks_.size();
    size_t leaves = 0;
    for (auto& br : bricks_) leaves = std::max(leaves, br.maxLeaves);
    payloadLimit_ = 12 + leaves * (16 + 64 + 2048) + leaves * 8 * 20 + 4096;
    if (op_ == Operation::Mesh) {
      // At most 8 vertices per grid point (7 edges and a feature vertex; a varint key and 6
      // doubles each, and maybe a carried quadric: a varint, 11 doubles and a flag) and 12
      // triangles per cell (3 varints of at most 5 bytes each and a state byte).
      const size_t b = size_t(opt_.brickVoxels);
      payloadLimit_ = 4096 + 8 * (b + 1) * (b + 1) * (b + 1) * (10 + 48 + 5 + 88 + 1) + 12 * b * b * b * 16;
    }
  }

  // A brick's result is final: keep it, journal it, count it.
  void commit(uint64_t id, BrickOutput&& out, const std::string& who, bool computed) {
    Brick& b = bricks_[id];
    b.phase = BrickPhase::Done;
    b.holders.clear();
    leased_.erase(id);
    ++done_;
    if (op_ == Operation::Sample) {
      report_.leaves += out.leaves.size();
      report_.tiles += out.tiles.size();
    }
    if (computed) {
      ++report_.bricksComputed;
      report_.pointEvals += out.stats.pointEvals;
      report_.intervalEvals += out.stats.intervalEvals;
      report_.nanValues += out.stats.nanValues;
      report_.domainErrors.add(out.stats.domainErrors);
      report_.extremumSearches += out.extremumSearches;
      report_.extremumUncertified += out.extremumUncertified;
      auto& share = report_.perWorker[who];
      ++share.bricks;
      share.pointEvals += out.stats.pointEvals;
    }
    outputs_[id] = std::move(out);
  }

  void runInProcess() {
    TapePtr tape = compileJobModel(job_);
    describeErrorBounds(*tape, &report_.errorBounds);
    for (const std::string& line : describeExactTerms(job_)) report_.errorBounds.push_back(line);
    for (Brick& b : bricks_) {
      if (b.phase == BrickPhase::Done) continue;
      if (gStop) {
        report_.interrupted = true;
        return;
      }
      auto t0 = Clock::now();
      BrickOutput out = computeBrick(tape, job_, b.lo, b.hi, opt_.threads);
      report_.perWorker["in-process"].computeSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
      if (journal_) journal_->append(b.id, encodePayload(op_, out));
      commit(b.id, std::move(out), "in-process", true);
      progress_->update(done_, report_.pointEvals, 1);
    }
  }

  // ---- the farm -------------------------------------------------------------------------

  void runFarm() {
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
    router.set(zmq::sockopt::maxmsgsize, int64_t(256) << 20);
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
      wanted = opt_.workers > 0 ? opt_.workers : int(std::max(1u, std::thread::hardware_concurrency()));
      std::vector<std::string> args{"--connect", endpoint, "--threads", std::to_string(opt_.workerThreads),
                                    "--log-level", opt_.logLevel, "--master-timeout", "10"};
      if (!opt_.curveDir.empty()) args.insert(args.end(), {"--curve", opt_.curveDir});
      local = std::make_unique<LocalWorkers>(opt_.workerExecutable, args);
      local->spawn(wanted);
    }
    int respawnBudget = 3 * std::max(wanted, 1) + 3 * opt_.maxAttempts;

    auto lastBeat = Clock::now();
    auto lastAlive = Clock::now();
    const auto hb = std::chrono::milliseconds(opt_.heartbeatMs);
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
        if (!receive(router, true, in, &err)) break;
        handle(router, in, err);
      }
      auto now = Clock::now();
      expireDeadPeers(now);
      if (local) {
        int exited = local->reap();
        int missing = wanted - local->running();
        if (exited && missing > 0 && respawnBudget > 0 && done_ + poisoned_ < bricks_.size()) {
          int n = std::min(missing, respawnBudget);
          respawnBudget -= n;
          local->spawn(n);
        }
      }
      reissueOverdue(now);
      dispatch(router, now);
      if (now - lastBeat >= hb) {
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
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (local) local->terminateAll();
  }

  void handle(zmq::socket_t& router, Incoming& in, const std::string& err) {
    if (!err.empty()) {
      ++report_.malformed;
      spdlog::warn("dropped a malformed message from {}: {}", printable(in.routingId), err);
      return;
    }
    const Envelope& e = in.envelope;
    if (e.ByteSizeLong() > kMaxEnvelopeBytes || (in.payload && in.payload->size() > payloadLimit())) {
      ++report_.oversized;
      spdlog::warn("dropped an oversized message from {}", printable(in.routingId));
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
      Peer& p = peers_[in.routingId];
      p.workerId = e.hello().worker_id().empty() ? printable(in.routingId) : e.hello().worker_id();
      p.threads = std::max(1u, e.hello().threads());
      p.expiry = now + std::chrono::milliseconds(opt_.heartbeatMs * opt_.liveness);
      ++report_.workersSeen;
      Envelope w;
      w.set_job_id(jobId_);
      w.mutable_welcome()->set_heartbeat_ms(uint32_t(opt_.heartbeatMs));
      w.mutable_welcome()->set_liveness(uint32_t(opt_.liveness));
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
    switch (e.body_case()) {
      case Envelope::kHeartbeat:
        break;
      case Envelope::kResult:
        onResult(in, p);
        break;
      case Envelope::kFailed:
        onFailed(e, in.routingId, p);
        break;
      case Envelope::kBye:
        spdlog::info("worker {} left: {}", p.workerId, e.bye().reason());
        dropPeer(in.routingId, false);
        break;
      default:
        ++report_.malformed;
        break;
    }
  }

  size_t payloadLimit() const { return payloadLimit_; }

  static std::string printable(const std::string& rid) {
    std::string s;
    for (unsigned char c : rid) s += (c >= 32 && c < 127) ? char(c) : '?';
    return s.empty() ? "?" : s;
  }

  void onResult(Incoming& in, Peer& p) {
    const Envelope& e = in.envelope;
    const Result& r = e.result();
    uint64_t id = r.brick_id();
    if (e.job_id() != jobId_ || id >= bricks_.size() || !in.payload) {
      ++report_.malformed;
      spdlog::warn("dropped a result for an unknown job or brick from {}", p.workerId);
      return;
    }
    p.inflight.erase(id);
    Brick& b = bricks_[id];
    b.holders.erase(in.routingId);
    if (b.phase == BrickPhase::Done || b.phase == BrickPhase::Poisoned) {
      ++report_.duplicates;
      return;
    }
    const auto& payload = *in.payload;
    BrickOutput out;
    std::string err;
    bool ok = crc32Of(payload.data(), payload.size()) == r.payload_crc32() &&
              decodePayload(op_, payload.data(), payload.size(), out, &err) && insideBrick(out, b);
    if (!ok) {
      ++report_.malformed;
      spdlog::warn("dropped a corrupt result for brick {} from {}: {}", id, p.workerId, err.empty() ? "crc or bounds" : err);
      if (b.holders.empty()) requeue(b, "corrupt result", true);
      return;
    }
    out.stats.pointEvals = r.point_evals();
    out.stats.intervalEvals = r.interval_evals();
    out.stats.nanValues = r.nan_values();
    out.extremumSearches = r.extremum_searches();
    out.extremumUncertified = r.extremum_uncertified();
    for (int k = 0; k < r.domain_errors_size() && k < int(kDomainErrorKinds); ++k)
      out.stats.domainErrors.n[k] = r.domain_errors(k);
    report_.perWorker[p.workerId].computeSeconds += r.compute_seconds();
    brickSeconds_.push_back(r.compute_seconds());
    if (journal_) journal_->append(id, std::string(static_cast<const char*>(payload.data()), payload.size()));
    // Other holders (straggler backups) may drop the brick.
    for (auto& [rid, t] : b.holders) {
      Envelope c;
      c.mutable_cancel()->set_brick_id(id);
      send(*routerForCancel_, rid, c);
    }
    commit(id, std::move(out), p.workerId, true);
  }

  bool insideBrick(const BrickOutput& out, const Brick& b) const {
    if (op_ == Operation::Mesh) {
      // The piece of this brick: every vertex on an edge starting at a grid point of the
      // brick's cells, [lo, hi] (a cell's far corners included).
      if (out.piece.regionLo != b.lo) return false;
      for (const MeshVertex& v : out.piece.vertices) {
        auto k = edgeKeyParts(v.key);
        for (int a = 0; a < 3; ++a)
          if (k[size_t(a)] < b.lo[a] || k[size_t(a)] > b.hi[a]) return false;
      }
      return true;
    }
    for (auto& l : out.leaves)
      for (int a = 0; a < 3; ++a)
        if (l.origin[a] < b.lo[a] || l.origin[a] >= b.hi[a]) return false;
    for (auto& t : out.tiles)
      for (int a = 0; a < 3; ++a)
        if (t.origin[a] < b.lo[a] || t.origin[a] >= b.hi[a]) return false;
    return out.leaves.size() <= b.maxLeaves;
  }

  void onFailed(const Envelope& e, const std::string& rid, Peer& p) {
    uint64_t id = e.failed().brick_id();
    if (id >= bricks_.size()) {
      ++report_.malformed;
      return;
    }
    p.inflight.erase(id);
    Brick& b = bricks_[id];
    b.holders.erase(rid);
    if (b.phase != BrickPhase::Leased || !b.holders.empty()) return;
    if (e.failed().handed_back()) {
      ++report_.handedBack;
      requeue(b, e.failed().error(), false);
    } else {
      spdlog::warn("brick {} failed on {}: {}", id, p.workerId, e.failed().error());
      requeue(b, e.failed().error(), true);
    }
  }

  void requeue(Brick& b, const std::string& why, bool counts) {
    b.lastError = why;
    leased_.erase(b.id);
    if (counts && ++b.failures >= opt_.maxAttempts) {
      b.phase = BrickPhase::Poisoned;
      ++poisoned_;
      report_.poisoned.push_back(PoisonedBrick{b.id, b.lo, b.hi, why});
      spdlog::error("brick {} [{},{},{})-({},{},{}) poisoned after {} failures: {}", b.id, b.lo[0], b.lo[1], b.lo[2],
                    b.hi[0], b.hi[1], b.hi[2], b.failures, why);
      return;
    }
    ++report_.retries;
    b.phase = BrickPhase::Pending;
    b.backupIssued = b.leaseReissued = false;
    pending_.push_front(b.id);  // retry soon: it may be the last one
  }

  void dropPeer(const std::string& rid, bool dead) {
    auto it = peers_.find(rid);
    if (it == peers_.end()) return;
    for (uint64_t id : it->second.inflight) {
      Brick& b = bricks_[id];
      b.holders.erase(rid);
      if (b.phase == BrickPhase::Leased && b.holders.empty())
        requeue(b, dead ? "worker " + it->second.workerId + " died while computing it" : "worker left", dead);
    }
    peers_.erase(it);
  }

  void expireDeadPeers(Clock::time_point now) {
    std::vector<std::string> dead;
    for (auto& [rid, p] : peers_)
      if (now > p.expiry) dead.push_back(rid);
    for (auto& rid : dead) {
      ++report_.deadWorkers;
      spdlog::warn("worker {} silent past its liveness window: dead, its bricks go back to the queue",
                   peers_[rid].workerId);
      dropPeer(rid, true);
    }
  }

  double medianBrickSeconds() const {
    if (brickSeconds_.empty()) return 0;
    std::vector<double> v = brickSeconds_;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }

  // Leases past their deadline are issued once more to someone else (the first holder keeps
  // running: whichever result comes first is merged).
  void reissueOverdue(Clock::time_point now) {
    double lease = opt_.leaseSeconds > 0 ? opt_.leaseSeconds : std::max(30.0, 10 * medianBrickSeconds());
    for (uint64_t id : leased_) {
      Brick& b = bricks_[id];
      if (b.leaseReissued) continue;
      if (std::chrono::duration<double>(now - b.firstLease).count() > lease) {
        b.leaseReissued = true;
        ++report_.leaseReissues;
        reissue_.push_back(b.id);
      }
    }
  }

  void sendTask(zmq::socket_t& router, const std::string& rid, Peer& p, Brick& b, Clock::time_point now) {
    Envelope e;
    e.set_job_id(jobId_);
    Task* t = e.mutable_task();
    t->set_brick_id(b.id);
    t->set_attempt(++b.attempts);
    for (int a = 0; a < 3; ++a) {
      t->add_lo(b.lo[a]);
      t->add_hi(b.hi[a]);
    }
    *t->mutable_job() = job_;
    if (!send(router, rid, e)) {
      // No route to the peer: its connection closed without a bye (it crashed or reconnected)
      // and its liveness window has not run out yet. dispatch() already took a pending brick
      // off pending_: put it back, or no one would lease it again and the job would never end
      // (the loop keeps waiting while the other workers heartbeat). A reissued or backup copy
      // stays leased to its other holders and goes back to the reissue queue (it was due).
      if (b.phase == BrickPhase::Pending) pending_.push_front(b.id);
      else reissue_.push_back(b.id);
      // A dead peer, as if silent past its liveness window: its bricks count a failure, so a
      // brick that kills its workers is poisoned whichever way the death is noticed first.
      ++report_.deadWorkers;
      spdlog::warn("worker {} unreachable: dead, its bricks go back to the queue", p.workerId);
      dropPeer(rid, true);
      return;
    }
    if (b.phase != BrickPhase::Leased) b.firstLease = now;
    b.phase = BrickPhase::Leased;
    leased_.insert(b.id);
    b.holders[rid] = now;
    p.inflight.insert(b.id);
  }

  void dispatch(zmq::socket_t& router, Clock::time_point now) {
    routerForCancel_ = &router;
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
    for (int round = 0; round < kCredit; ++round)
      for (auto& rid : rids) {
        auto it = peers_.find(rid);
        if (it == peers_.end() || int(it->second.inflight.size()) > round) continue;
        std::optional<uint64_t> next;
        while (!reissue_.empty() && !next) {
          uint64_t id = reissue_.front();
          reissue_.pop_front();
          if (bricks_[id].phase == BrickPhase::Leased && !bricks_[id].holders.count(rid)) next = id;
        }
        while (!pending_.empty() && !next) {
          uint64_t id = pending_.front();
          pending_.pop_front();
          if (bricks_[id].phase == BrickPhase::Pending) next = id;
        }
        if (!next) continue;
        sendTask(router, rid, it->second, bricks_[*next], now);
      }
    // Stragglers: nothing queued and a worker idle -> the oldest long-running brick, once more.
    if (!pending_.empty()) return;
    double threshold = std::max(1.0, 2 * medianBrickSeconds());
    for (auto& rid : rids) {
      auto it = peers_.find(rid);
      if (it == peers_.end() || !it->second.inflight.empty()) continue;
      Brick* oldest = nullptr;
      for (uint64_t id : leased_)
        if (Brick& b = bricks_[id]; !b.backupIssued && !b.holders.count(rid) &&
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

  FarmOutcome finish() {
    FarmOutcome o;
    report_.operation = op_ == Operation::Mesh ? "mesh" : "sample";
    if (op_ == Operation::Mesh && done_ == bricks_.size()) {
      // The merge step of a mesh job: the pieces stitched by global edge key (split-invariant).
      // mergePiecesReleasing frees each piece as soon as it is stitched: the master holds about
      // one copy of the output mesh instead of three (the same mesh as mergePieces).
      std::vector<MeshPiece> pieces;
      pieces.reserve(outputs_.size());
      for (auto& out : outputs_) pieces.push_back(std::move(out.piece));
      outputs_.clear();
      o.mesh = mergePiecesReleasing(pieces);
      report_.vertices = o.mesh.positions.size();
      report_.triangles = o.mesh.triangles.size();
    }
    o.result.grid = grid_;
    o.result.bandVoxels = job_.band();
    // One pass: order pointers to the bricks' leaves, then copy each leaf once (they are 2 KiB).
    std::vector<const LeafBlock*> order;
    for (auto& out : outputs_) {
      for (const LeafBlock& l : out.leaves) order.push_back(&l);
      o.result.tiles.insert(o.result.tiles.end(), out.tiles.begin(), out.tiles.end());
    }
    std::sort(order.begin(), order.end(), [](const LeafBlock* a, const LeafBlock* b) { return a->origin < b->origin; });
    o.result.leaves.reserve(order.size());
    for (const LeafBlock* l : order) o.result.leaves.push_back(*l);
    std::vector<LeafBlock> noLeaves;
    sortByOrigin(noLeaves, o.result.tiles);
    outputs_.clear();
    o.result.stats.pointEvals = report_.pointEvals;
    o.result.stats.intervalEvals = report_.intervalEvals;
    o.result.stats.nanValues = report_.nanValues;
    o.result.stats.domainErrors = report_.domainErrors;
    o.result.stats.denseEvals = uint64_t(grid_.dims[0]) * grid_.dims[1] * grid_.dims[2];
    report_.denseEvals = o.result.stats.denseEvals;
    report_.wallSeconds = std::chrono::duration<double>(Clock::now() - start_).count();
    report_.peakRssBytes = peakRssBytes();
    o.report = report_;
    return o;
  }

  JobSpec job_;
  FarmOptions opt_;
  uint64_t jobId_;
  GridSpec grid_;
  Operation op_;
  std::vector<Brick> bricks_;
  std::deque<uint64_t> pending_, reissue_;
  std::vector<BrickOutput> outputs_;
  std::map<std::string, Peer> peers_;
  std::vector<double> brickSeconds_;
  std::set<uint64_t> leased_;  // bricks in phase Leased (timers scan only these)
  size_t payloadLimit_ = 0;
  size_t done_ = 0, poisoned_ = 0;
  FarmReport report_;
  std::unique_ptr<Journal> journal_;
  std::unique_ptr<Progress> progress_;
  zmq::socket_t* routerForCancel_ = nullptr;
  std::optional<Clock::time_point> firstJoin_;
  Clock::time_point start_;
};

}  // namespace

std::string FarmReport::toJson() const {
  nlohmann::json j;
  j["wall_seconds"] = wallSeconds;
  j["peak_rss_bytes"] = peakRssBytes;
  j["bricks"] = {{"total", bricks}, {"computed", bricksComputed}, {"from_journal", bricksFromJournal}};
  j["evaluations"] = {{"point", pointEvals}, {"interval", intervalEvals}, {"dense_equivalent", denseEvals},
                      {"nan_values", nanValues}};
  nlohmann::json dom = nlohmann::json::object();
  for (size_t k = 0; k < kDomainErrorKinds; ++k) dom[domainErrorName(DomainError(k))] = domainErrors.n[k];
  j["domain_errors"] = dom;
  j["extremum"] = {{"searches", extremumSearches}, {"uncertified", extremumUncertified}, {"error_bounds", errorBounds}};
  j["operation"] = operation;
  if (operation == "mesh") {
    j["output"] = {{"vertices", vertices}, {"triangles", triangles}};
    if (simplifyTolerance > 0)
      j["output"]["simplification"] = {{"tolerance_voxels", simplifyTolerance},
                                       {"sharp_features", sharpFeatures},
                                       {"triangles_before", simplify.trianglesBefore},
                                       {"collapses", simplify.collapses},
                                       {"error_bound", simplify.errorBound},
                                       {"model_evaluations", simplify.modelEvals},
                                       {"rejected", {{"topology", simplify.rejectedTopology},
                                                     {"shape", simplify.rejectedShape},
                                                     {"error", simplify.rejectedError},
                                                     {"intersection", simplify.rejectedIntersection}}}};
  }
  else j["output"] = {{"leaves", leaves}, {"tiles", tiles}};
  j["faults"] = {{"retries", retries},           {"duplicates", duplicates},
                 {"late_results", lateResults},  {"malformed", malformed},
                 {"oversized", oversized},       {"dead_workers", deadWorkers},
                 {"handed_back", handedBack},    {"straggler_reissues", stragglerReissues},
                 {"lease_reissues", leaseReissues}, {"refused", refused},
                 {"curve_rejected", curveRejected}};
  j["workers_seen"] = workersSeen;
  nlohmann::json w = nlohmann::json::object();
  for (auto& [id, s] : perWorker)
    w[id] = {{"bricks", s.bricks},
             {"point_evals", s.pointEvals},
             {"compute_seconds", s.computeSeconds},
             {"share", pointEvals ? double(s.pointEvals) / double(pointEvals) : 0.0}};
  j["per_worker"] = w;
  nlohmann::json p = nlohmann::json::array();
  for (auto& b : poisoned)
    p.push_back({{"brick", b.brick}, {"lo", b.lo}, {"hi", b.hi}, {"error", b.error}});
  j["poisoned"] = p;
  j["interrupted"] = interrupted;
  return j.dump(2);
}

FarmOutcome runJob(const JobSpec& job, const FarmOptions& options) { return Master(job, options).run(); }

uint64_t peakRssBytes() {
  struct rusage ru {};
  if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
  return uint64_t(ru.ru_maxrss) * 1024;  // kilobytes on Linux
}

}  // namespace frep::farm
