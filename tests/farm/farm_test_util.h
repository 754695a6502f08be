// Shared by the farm tests: a test model and job, fast farm options, and worker processes and a
// master thread that the tests start, signal and join themselves.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <future>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>
#include <zmq.hpp>

#include "frep/worker/brick.h"
#include "frep/master/farm_master.h"
#include "frep/net/wire.h"

extern char** environ;

namespace farmtest {

using namespace frep;
using namespace frep::farm;

// A block with a spherical bite: flat faces, edges, corners and a curved pocket, with surface
// in most bricks.
inline const char* kPartModel = R"(
my_model(x[3], a[1]) {
  array c[3], v[3];
  c = [0.3, 0.2, 0.4];
  v = [-0.7, -0.6, -0.5];
  b = hfBlock(x, v, 1.4, 1.2, 1.0);
  ball = hfSphere(x, c, 0.45);
  my_model = b \ ball;
}
)";

// A ball of radius 0.8 sampled on 64^3 voxels of [-1, 1]^3 (band 3).
inline JobSpec sphereJob() {
  JobSpec j;
  j.set_operation("sample");
  j.set_model_source("my_model(x[3], a[1]) { my_model = 0.64 - x[1]^2 - x[2]^2 - x[3]^2; }");
  j.set_model_name("sphere.hf");
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 64));
  j.set_band(3);
  return j;
}

inline JobSpec partJob(const std::string& operation, int res) {
  JobSpec j;
  j.set_operation(operation);
  j.set_model_source(kPartModel);
  j.set_model_name("test.hf");
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, res));
  if (operation == "sample") j.set_band(3);
  return j;
}

// The factor by which every time the tests set or wait is stretched: FREP_TEST_TIME_SCALE (at
// least 1, default 1). The sanitizer runs set it (tests/sanitize/run_sanitizers.sh): TSan slows
// every process several times, and a heartbeat of 100 ms then misses its window on a loaded
// machine. Heartbeats, liveness windows, timeouts and the pauses measured against them grow
// together, so what a test compares (a death against a window, a window against a stall) holds.
inline double timeScale() {
  static const double scale = [] {
    const char* e = std::getenv("FREP_TEST_TIME_SCALE");
    const double v = e ? std::atof(e) : 1;
    return v >= 1 ? v : 1;
  }();
  return scale;
}
inline int scaledMs(int ms) { return int(ms * timeScale()); }
inline int scaledSec(int s) { return scaledMs(s * 1000) / 1000; }
inline std::chrono::milliseconds scaled(std::chrono::milliseconds d) {
  return std::chrono::milliseconds(scaledMs(int(d.count())));
}
// A test hook's pause (FREP_TEST_SLOW_MS=ms for the worker), scaled like the heartbeats.
inline std::string slowMs(int ms) { return "FREP_TEST_SLOW_MS=" + std::to_string(scaledMs(ms)); }

// Heartbeats of 100 ms (times the scale) so that dead workers are found within half a second.
inline FarmOptions fast(int workers, int brick = 32) {
  FarmOptions o;
  o.workers = workers;
  o.brickVoxels = brick;
  o.heartbeatMs = scaledMs(100);
  o.liveness = 5;
  o.workerExecutable = FREP_WORKER_PATH;
  o.noWorkerTimeoutSec = scaledSec(30);
  return o;
}

// Cuts a journal after its header and first `records` records, plus `tornBytes` of the next
// one, as if the master had died while writing it.
inline void tearJournal(const std::string& path, int records, size_t tornBytes) {
  std::ifstream in(path, std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), {});
  size_t pos = 12;  // magic + job id
  for (int r = 0; r < records; ++r) {
    uint64_t size;
    std::memcpy(&size, all.data() + pos + 12, 8);  // brick id, crc, size
    pos += 20 + size;
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(all.data(), std::streamsize(pos + tornBytes));
}

// Polls `pred` until it holds or `timeout` has passed; returns whether it held. Tests wait for
// the condition they need (a worker holds a brick, the master logged what it did) instead of a
// fixed time, which is slow where the machine is fast and too short where it is loaded.
// Timeouts are scaled (timeScale()).
template <class Pred>
bool waitUntil(Pred pred, std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
  const auto deadline = std::chrono::steady_clock::now() + scaled(timeout);
  for (;;) {
    if (pred()) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// The file a frep-worker creates when it starts its first brick (env(): the worker's test hook
// FREP_TEST_STARTED_FILE): once it exists the worker holds a brick, in its FREP_TEST_SLOW_MS
// pause if it has one.
struct StartedFile {
  std::string path;
  explicit StartedFile(const std::string& name) : path("/tmp/frep_farm_test_" + name + "." + std::to_string(getpid())) {
    std::remove(path.c_str());
  }
  ~StartedFile() { std::remove(path.c_str()); }
  std::string env() const { return "FREP_TEST_STARTED_FILE=" + path; }
  bool wait(std::chrono::milliseconds timeout = std::chrono::seconds(30)) const {
    return waitUntil([&] { return access(path.c_str(), F_OK) == 0; }, timeout);
  }
};

// What the master logs from construction to destruction (it logs every peer it drops, every
// death and departure): a test waits for the line saying the master did what the test needs.
// Made before the master thread starts and destroyed after it ends (spdlog's sink list is not
// guarded against concurrent logging).
struct LogWatch {
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(4096);
  LogWatch() { spdlog::default_logger()->sinks().push_back(sink); }
  ~LogWatch() {
    auto& sinks = spdlog::default_logger()->sinks();
    sinks.erase(std::remove(sinks.begin(), sinks.end(), sink), sinks.end());
  }
  // Lines so far that contain `text`.
  size_t count(const std::string& text) const {
    size_t n = 0;
    for (const std::string& line : sink->last_formatted()) n += line.find(text) != std::string::npos;
    return n;
  }
  bool waitFor(const std::string& text, size_t n = 1,
               std::chrono::milliseconds timeout = std::chrono::seconds(30)) const {
    return waitUntil([&] { return count(text) >= n; }, timeout);
  }
};

// Connections the master's side (local port of `endpoint`, tcp://127.0.0.1:PORT) still has open
// (established, or closed by the peer and not yet by the master), from /proc/net/tcp: once a peer
// closed its socket and this count dropped, the master's ZeroMQ has let go of the connection.
inline int masterSideConnections(const std::string& endpoint) {
  const unsigned port = unsigned(std::stoul(endpoint.substr(endpoint.rfind(':') + 1)));
  int n = 0;
  for (const char* table : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream in(table);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::istringstream f(line);
      std::string slot, local, remote, state;
      f >> slot >> local >> remote >> state;
      const unsigned localPort = unsigned(std::stoul(local.substr(local.rfind(':') + 1), nullptr, 16));
      if (localPort == port && (state == "01" || state == "08")) ++n;  // ESTABLISHED, CLOSE_WAIT
    }
  }
  return n;
}

// A frep-worker started by the test (as a cluster's launcher would), so the test can signal it.
struct WorkerProcess {
  pid_t pid = 0;
  explicit WorkerProcess(const std::string& endpoint, std::vector<std::string> env = {},
                         std::vector<std::string> extra = {}) {
    std::vector<std::string> args{FREP_WORKER_PATH, "--connect", endpoint, "--threads", "1", "--log-level", "off"};
    if (std::find(extra.begin(), extra.end(), "--master-timeout") == extra.end())
      args.insert(args.end(), {"--master-timeout", std::to_string(scaledSec(5))});
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> envs;
    for (char** e = environ; *e; ++e) envs.push_back(*e);
    for (auto& e : env) envs.push_back(e);
    std::vector<char*> envp;
    for (auto& e : envs) envp.push_back(e.data());
    envp.push_back(nullptr);
    EXPECT_EQ(posix_spawn(&pid, FREP_WORKER_PATH, nullptr, nullptr, argv.data(), envp.data()), 0);
  }
  // The exit code (128 + signal if killed); -2 if it had to be killed after timeoutSec (scaled).
  int wait(int timeoutSec = 60) {
    int status = 0;
    if (!waitUntil([&] { return waitpid(pid, &status, WNOHANG) != 0; }, std::chrono::seconds(timeoutSec))) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      pid = 0;
      return -2;
    }
    pid = 0;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  ~WorkerProcess() {
    if (pid) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
};

// The master of a job on its own thread, bound to a free loopback port (cluster mode);
// endpoint() waits until it listens, join() until the job ends.
struct MasterThread {
  FarmOutcome outcome;
  std::string error;
  std::atomic<bool> finished{false};
  std::thread thread;
  std::promise<std::string> bound;
  std::shared_future<std::string> boundFuture = bound.get_future().share();
  MasterThread(const JobSpec& j, FarmOptions o) {
    o.listen = "tcp://127.0.0.1:*";
    o.onListening = [this](const std::string& ep) { bound.set_value(ep); };
    thread = std::thread([this, j, o] {
      try {
        outcome = runJob(j, o);
      } catch (const std::exception& e) {
        error = e.what();
        if (boundFuture.wait_for(std::chrono::seconds(0)) != std::future_status::ready) bound.set_value("");
      }
      finished = true;
    });
  }
  std::string endpoint() { return boundFuture.get(); }
  void join() { thread.join(); }
};

// The envelopes of one kind a scripted peer receives within `ms` (scaled), or until `count` of
// them arrived.
inline std::vector<Envelope> collectEnvelopes(zmq::socket_t& s, Envelope::BodyCase kind, size_t count, int ms) {
  std::vector<Envelope> got;
  auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(scaledMs(ms));
  while (got.size() < count && std::chrono::steady_clock::now() < deadline) {
    zmq::pollitem_t item{static_cast<void*>(s), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, std::chrono::milliseconds(20));
    Incoming in;
    std::string err;
    while (got.size() < count && receive(s, false, in, &err))
      if (err.empty() && in.envelope.body_case() == kind) got.push_back(in.envelope);
  }
  return got;
}

}  // namespace farmtest
