// frep-worker main loop. Threads: the I/O thread (this one) owns the DEALER socket and never
// computes, so heartbeats keep flowing while a brick runs; the compute thread takes tasks
// from a queue and wakes the I/O thread through an inproc PAIR when a result is ready.
#include "frep/worker/worker.h"

#include <spdlog/spdlog.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <memory>
#include <random>
#include <thread>
#include <zmq.hpp>

#include "frep/worker/brick.h"
#include "frep/net/curve.h"
#include "frep/net/wire.h"
#include "frep/farm/lease_table.h"

namespace frep::farm {

namespace {

using Clock = std::chrono::steady_clock;
std::atomic<bool> gTerminate{false};
void onSignal(int) { gTerminate = true; }

std::string makeWorkerId() {
  char host[256] = "host";
  gethostname(host, sizeof host - 1);
  std::random_device rd;
  return std::string(host) + "-" + std::to_string(getpid()) + "-" + std::to_string(rd() % 100000);
}

// CPU seconds of the calling thread, and of the whole process (the scaling counters of a Result).
double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Outgoing {
  Envelope env;
  std::string payload;
  bool hasPayload = false;
};

// A task with the job it belongs to (the welcome's: tasks carry only its id, protocol 2).
struct Lease {
  Task task;
  std::shared_ptr<const JobSpec> job;
  uint64_t jobId = 0;
};

// The compute side: a queue of tasks in, a queue of finished messages out.
class ComputeThread {
 public:
  ComputeThread(zmq::context_t& ctx, int threads) : threads_(threads), wakeSend_(ctx, zmq::socket_type::pair) {
    wakeSend_.set(zmq::sockopt::linger, 0);
    wakeSend_.connect("inproc://frep-worker-wake");
    thread_ = std::thread([this] { loop(); });
  }
  ~ComputeThread() {
    {
      std::lock_guard<std::mutex> l(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    // A brick in progress cannot be interrupted; the process exits without waiting for it.
    thread_.detach();
  }
  void push(Lease lease) {
    {
      std::lock_guard<std::mutex> l(mutex_);
      queue_.push_back(std::move(lease));
    }
    cv_.notify_all();
  }
  void cancel(uint64_t brick) {
    std::lock_guard<std::mutex> l(mutex_);
    for (auto it = queue_.begin(); it != queue_.end(); ++it)
      if (it->task.brick_id() == brick) {
        queue_.erase(it);
        return;
      }
  }
  // Tasks not yet finished (queued and running), for hand-back on SIGTERM.
  std::vector<Task> unfinished() {
    std::lock_guard<std::mutex> l(mutex_);
    std::vector<Task> v;
    for (const Lease& q : queue_) v.push_back(q.task);
    if (running_) v.push_back(running_->task);
    return v;
  }
  // Every brick still here: queued, running, or computed and not yet sent (a reconnect's hello).
  std::vector<uint64_t> holding() {
    std::lock_guard<std::mutex> l(mutex_);
    std::vector<uint64_t> v;
    for (const Lease& q : queue_) v.push_back(q.task.brick_id());
    if (running_) v.push_back(running_->task.brick_id());
    for (const Outgoing& o : done_) {
      if (o.env.has_result()) v.push_back(o.env.result().brick_id());
      else if (o.env.has_failed()) v.push_back(o.env.failed().brick_id());
    }
    return v;
  }
  size_t pending() {
    std::lock_guard<std::mutex> l(mutex_);
    return queue_.size() + (running_ ? 1 : 0);
  }
  bool popResult(Outgoing& o) {
    std::lock_guard<std::mutex> l(mutex_);
    if (done_.empty()) return false;
    o = std::move(done_.front());
    done_.pop_front();
    return true;
  }

 private:
  void loop() {
    auto idleSince = Clock::now();  // the compute thread's last brick ended (or it started)
    for (;;) {
      Lease lease;
      double idle = 0;
      {
        std::unique_lock<std::mutex> l(mutex_);
        cv_.wait(l, [&] { return stop_ || !queue_.empty(); });
        if (stop_) return;
        idle = std::chrono::duration<double>(Clock::now() - idleSince).count();
        lease = std::move(queue_.front());
        queue_.pop_front();
        running_ = std::make_unique<Lease>(lease);
      }
      const double cpu0 = threadCpuSeconds();
      Outgoing out = compute(lease);
      if (out.env.has_result()) {
        Result* r = out.env.mutable_result();
        r->set_idle_seconds(idle);
        r->set_task_cpu_seconds(threadCpuSeconds() - cpu0);
        r->set_process_cpu_seconds(processCpuSeconds());
      }
      idleSince = Clock::now();
      {
        std::lock_guard<std::mutex> l(mutex_);
        running_.reset();
        if (stop_) return;
        done_.push_back(std::move(out));
      }
      wakeSend_.send(zmq::str_buffer("!"), zmq::send_flags::dontwait);
    }
  }

  Outgoing compute(const Lease& lease) {
    const Task& task = lease.task;
    const JobSpec& job = *lease.job;
    Outgoing out;
    out.env.set_job_id(lease.jobId);
    // Test hook (documented in docs/farm.md): crash on a chosen brick to exercise poisoning.
    if (const char* crash = std::getenv("FREP_TEST_CRASH_BRICK"))
      if (std::strtoull(crash, nullptr, 10) == task.brick_id()) std::abort();
    // Test hook: churn, a worker that dies on whatever brick comes after its first N.
    // It dies once its earlier results are out (handed to the I/O thread and given time to
    // leave the socket), so that the bricks it finished count as finished.
    if (const char* n = std::getenv("FREP_TEST_DIE_AFTER"))
      if (++started_ > std::strtoull(n, nullptr, 10)) {
        for (int i = 0; i < 300; ++i) {
          {
            std::lock_guard<std::mutex> l(mutex_);
            if (done_.empty()) break;
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        std::abort();
      }
    // Test hook: the file appears when the first brick starts (a test stops the worker only then).
    if (const char* f = std::getenv("FREP_TEST_STARTED_FILE"))
      if (!announcedStart_) {
        if (FILE* file = std::fopen(f, "w")) std::fclose(file);
        announcedStart_ = true;
      }
    if (const char* slow = std::getenv("FREP_TEST_SLOW_MS"))
      std::this_thread::sleep_for(std::chrono::milliseconds(std::atoi(slow)));
    try {
      TapePtr tape = cache_.get(job, lease.jobId);
      if (task.lo_size() != 3 || task.hi_size() != 3) throw std::invalid_argument("task: lo/hi need 3 values");
      std::array<int32_t, 3> lo{task.lo(0), task.lo(1), task.lo(2)}, hi{task.hi(0), task.hi(1), task.hi(2)};
      auto t0 = Clock::now();
      const double cpu0 = threadCpuSeconds();
      const Operation op = operationOf(job);
      BrickOutput b = computeBrick(tape, job, lo, hi, threads_);
      const double computeCpu = threadCpuSeconds() - cpu0;
      double secs = std::chrono::duration<double>(Clock::now() - t0).count();
      out.payload = encodePayload(op, b);
      out.hasPayload = true;
      Result* r = out.env.mutable_result();
      r->set_brick_id(task.brick_id());
      r->set_attempt(task.attempt());
      r->set_leaves(uint32_t(b.leaves.size()));
      r->set_tiles(uint32_t(b.tiles.size()));
      r->set_vertices(uint32_t(b.piece.vertices.size()));
      r->set_triangles(uint32_t(b.piece.triangles.size()));
      r->set_point_evals(b.stats.pointEvals);
      r->set_interval_evals(b.stats.intervalEvals);
      r->set_nan_values(b.stats.nanValues);
      r->set_payload_crc32(crc32Of(out.payload.data(), out.payload.size()));
      r->set_compute_seconds(secs);
      r->set_compute_cpu_seconds(computeCpu);
      for (uint64_t n : b.stats.domainErrors.n) r->add_domain_errors(n);
      r->set_extremum_searches(b.extremumSearches);
      r->set_extremum_uncertified(b.extremumUncertified);
      r->set_extremum_sign_decided(b.extremumSignDecided);
      r->set_extremum_widest_gap(b.extremumWidestGap);
    } catch (const std::exception& e) {
      Failed* f = out.env.mutable_failed();
      f->set_brick_id(task.brick_id());
      f->set_attempt(task.attempt());
      f->set_error(e.what());
    }
    return out;
  }

  int threads_;
  uint64_t started_ = 0;         // bricks this worker started (FREP_TEST_DIE_AFTER)
  bool announcedStart_ = false;  // FREP_TEST_STARTED_FILE written
  zmq::socket_t wakeSend_;
  ModelCache cache_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Lease> queue_;
  std::unique_ptr<Lease> running_;
  std::deque<Outgoing> done_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace

int runWorker(const WorkerOptions& opt) {
  std::signal(SIGTERM, onSignal);
  std::signal(SIGINT, onSignal);
  zmq::context_t ctx(1);
  zmq::socket_t wakeRecv(ctx, zmq::socket_type::pair);
  wakeRecv.set(zmq::sockopt::linger, 0);
  wakeRecv.bind("inproc://frep-worker-wake");
  int threads = opt.threads > 0 ? opt.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  ComputeThread compute(ctx, threads);

  CurveKeys keys;
  if (!opt.curveDir.empty()) keys = loadCurveKeys(opt.curveDir, /*server=*/false);

  const std::string workerId = makeWorkerId();
  int heartbeatMs = 500, liveness = 5;
  auto lastMasterContact = Clock::now();
  int backoffMs = int(kReconnectFirstBackoff.count());
  uint64_t jobId = 0;                  // the job of the last welcome (jobIdOf(*job))
  std::shared_ptr<const JobSpec> job;  // its spec: tasks carry only its id

  for (;;) {  // one iteration per connection
    zmq::socket_t sock(ctx, zmq::socket_type::dealer);
    sock.set(zmq::sockopt::linger, 0);
    sock.set(zmq::sockopt::routing_id, workerId + "-" + std::to_string(backoffMs) + "-" +
                                           std::to_string(Clock::now().time_since_epoch().count() % 1000000));
    if (!opt.curveDir.empty()) applyCurveClient(sock, keys);
    sock.connect(opt.endpoint);
    // The hello, with the bricks the worker has when it is sent (a reconnect's leases).
    auto sayHello = [&] {
      Envelope hello;
      Hello* h = hello.mutable_hello();
      h->set_build(std::string("frepfarm ") + FREP_VERSION);
      h->set_threads(uint32_t(threads));
      h->set_worker_id(workerId);
      for (uint64_t id : compute.holding()) h->add_holding(id);
      send(sock, "", hello);
    };
    sayHello();
    spdlog::info("worker {}: connecting to {}", workerId, opt.endpoint);
    auto heard = Clock::now();
    auto lastBeat = Clock::now();
    bool welcomed = false;

    for (;;) {
      zmq::pollitem_t items[] = {{static_cast<void*>(sock), 0, ZMQ_POLLIN, 0},
                                 {static_cast<void*>(wakeRecv), 0, ZMQ_POLLIN, 0}};
      try {
        zmq::poll(items, 2, std::chrono::milliseconds(std::max(10, heartbeatMs / 4)));
      } catch (const zmq::error_t& e) {
        if (e.num() != EINTR) throw;
      }
      auto now = Clock::now();
      if (gTerminate) {
        // Never welcomed and holding nothing (e.g. still connecting when a small job ended):
        // nobody to tell, so no wait for frames to leave.
        if (!welcomed && compute.holding().empty()) std::_Exit(kWorkerOk);
        // Hand every unfinished brick back, say bye, leave.
        for (const Task& t : compute.unfinished()) {
          Envelope f;
          f.set_job_id(jobId);
          Failed* fl = f.mutable_failed();
          fl->set_brick_id(t.brick_id());
          fl->set_attempt(t.attempt());
          fl->set_error("worker received SIGTERM");
          fl->set_handed_back(true);
          send(sock, "", f);
        }
        Envelope bye;
        bye.mutable_bye()->set_reason("SIGTERM");
        send(sock, "", bye);
        spdlog::info("worker {}: terminating on signal, bricks handed back", workerId);
        std::this_thread::sleep_for(std::chrono::milliseconds(100));  // let the frames leave
        std::_Exit(kWorkerOk);
      }
      if (items[1].revents & ZMQ_POLLIN) {
        zmq::message_t m;
        while (wakeRecv.recv(m, zmq::recv_flags::dontwait)) {}
      }
      Outgoing out;
      while (compute.popResult(out)) send(sock, "", out.env, out.hasPayload ? &out.payload : nullptr);

      if (items[0].revents & ZMQ_POLLIN) {
        Incoming in;
        std::string err;
        while (receive(sock, false, in, &err)) {
          heard = lastMasterContact = now;
          backoffMs = int(kReconnectFirstBackoff.count());
          if (!err.empty()) {
            spdlog::warn("worker {}: malformed message from master: {}", workerId, err);
            continue;
          }
          const Envelope& e = in.envelope;
          switch (e.body_case()) {
            case Envelope::kWelcome:
              // The job must be the one the envelope names: a master of another release, or
              // a damaged frame, would have us compute something else under its id.
              if (!e.welcome().has_job() || jobIdOf(e.welcome().job()) != e.job_id()) {
                spdlog::error("worker {}: the master's welcome carries {} job {:016x}; refusing it", workerId,
                              e.welcome().has_job() ? "a job that does not hash to its" : "no job for its", e.job_id());
                std::_Exit(kWorkerRejected);
              }
              if (!job || jobId != e.job_id()) job = std::make_shared<const JobSpec>(e.welcome().job());
              jobId = e.job_id();
              welcomed = true;
              if (e.welcome().heartbeat_ms() > 0) heartbeatMs = int(e.welcome().heartbeat_ms());
              if (e.welcome().liveness() > 0) liveness = int(e.welcome().liveness());
              spdlog::info("worker {}: welcomed (heartbeat {} ms)", workerId, heartbeatMs);
              break;
            case Envelope::kReject:
              spdlog::error("worker {}: refused by the master: {}", workerId, e.reject().reason());
              std::_Exit(kWorkerRejected);
            case Envelope::kTask:
              if (!job || e.job_id() != jobId) {
                // Not the job of this connection's welcome: not the brick's fault. Hand it back
                // and say hello again, whose welcome brings the job.
                Envelope f;
                f.set_job_id(e.job_id());
                Failed* fl = f.mutable_failed();
                fl->set_brick_id(e.task().brick_id());
                fl->set_attempt(e.task().attempt());
                fl->set_error("the worker was not welcomed to this job");
                fl->set_handed_back(true);
                send(sock, "", f);
                sayHello();
                break;
              }
              compute.push(Lease{e.task(), job, jobId});
              break;
            case Envelope::kCancel:
              compute.cancel(e.cancel().brick_id());
              break;
            case Envelope::kReset:
              spdlog::info("worker {}: master asks for a new hello", workerId);
              sayHello();
              break;
            case Envelope::kBye:
              spdlog::info("worker {}: master says bye ({})", workerId, e.bye().reason());
              std::_Exit(kWorkerOk);
            default:
              break;
          }
        }
      }
      if (now - lastBeat >= std::chrono::milliseconds(heartbeatMs)) {
        Envelope hb;
        hb.set_job_id(jobId);
        hb.mutable_heartbeat();
        send(sock, "", hb);
        lastBeat = now;
      }
      if (now - heard > std::chrono::milliseconds(heartbeatMs * liveness)) {
        if (std::chrono::duration<double>(now - lastMasterContact).count() > opt.masterTimeoutSec) {
          spdlog::error("worker {}: no master at {} for {} s, giving up", workerId, opt.endpoint, opt.masterTimeoutSec);
          std::_Exit(kWorkerNoMaster);
        }
        spdlog::warn("worker {}: master silent{}, reconnecting in {} ms", workerId, welcomed ? "" : " (no welcome)",
                     backoffMs);
        break;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(backoffMs));
    backoffMs = std::min(backoffMs * 2, int(kReconnectMaxBackoff.count()));
  }
}

}  // namespace frep::farm
