// Farm figures, all measured in this run:
//  1. speed-up of a compute-heavy job from 1 to 2 local workers (this machine has 2 cores);
//  2. what a task costs the master to build with the job in it (protocol 1.x) and without
//     (protocol 2: the job goes once per worker, in the welcome);
//  3. the master's own throughput against fake workers that replay pre-encoded results (bricks
//     merged per second, the master's CPU per brick), decoding on the scheduling loop alone
//     against decoding on all cores, and streaming the merge into a sink that only counts the
//     leaves (FarmOptions::sampleSink: what a consumer that writes as it goes costs the master),
//     and from it how many real workers one master keeps busy at the brick time measured in 1;
//     the streamed runs once more with 64 fake workers (256 bricks in flight).
// `bench_farm --master-only` runs 2 and 3 (`--master-only --streaming`: only the streamed runs).
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "frep/farm/allocator_tuning.h"
#include "frep/worker/brick.h"
#include "frep/master/farm_master.h"
#include "frep/net/wire.h"

using namespace frep;
using namespace frep::farm;

namespace {

// Soft objects in HyperFun's sample-model style: a 9-term while loop, heavy per point.
const char* kHeavyModel = R"(
my_model(x[3], a[1]) {
  array x0[9], y0[9], z0[9], d[9];
  i = 1;
  while (i <= 9) loop
    x0[i] = 0.5 * cos(i * 0.7);
    y0[i] = 0.5 * sin(i * 1.3);
    z0[i] = 0.4 * sin(i * 0.5);
    d[i] = 0.55;
    i = i + 1;
  endloop;
  soft = hfSoft(x, x0, y0, z0, d, 0.3);
  my_model = soft & (0.9 - x[1]^2 - x[2]^2 - x[3]^2) + 0.02 * sin(20 * x[1]) * sin(20 * x[2]);
}
)";

JobSpec job(const char* source, int res) {
  JobSpec j;
  j.set_operation("sample");
  j.set_model_source(source);
  j.set_model_name("bench.hf");
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, res));
  j.set_band(3);
  return j;
}

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The payload a fake worker returns for the brick at `lo`: `leaves` leaf blocks inside it, each
// a typical surface leaf (about half its voxels in the band, so the compact FRB2 form). 128 such
// leaves make 151 kB; a real 64^3 surface brick of examples/blobby.hf at 1024^3 has 122 leaves
// with 274 active voxels on average, 155 kB (docs/farm.md, "The FRB2 sample payload"). Against
// another build: bench/bench_farm_ab.sh.
std::string fakePayload(const std::array<int32_t, 3>& lo, int leaves) {
  BrickOutput b;
  for (int i = 0; i < leaves; ++i) {
    LeafBlock l = LeafBlock::cleared();
    l.origin = {lo[0] + 8 * (i % 8), lo[1] + 8 * ((i / 8) % 8), lo[2] + 8 * (i / 64)};
    for (int v = 0; v < kLeafVoxels; ++v) {
      bool active = (v / 8) % 2 == 0;
      l.values[size_t(v)] = active ? 0.01f * float(v % 7) : (v < 256 ? 0.3f : -0.3f);
      if (active) l.active[size_t(v >> 6)] |= uint64_t(1) << (v & 63);
    }
    b.leaves.push_back(l);
  }
  return encodeBrick(b);
}

// The results the fake workers replay, encoded before the job starts (payload and CRC per brick).
struct Replay {
  int brickVoxels, perAxis, leaves;
  std::vector<std::string> payloads;  // by brick index (i * perAxis + j) * perAxis + k
  std::vector<uint32_t> crcs;
  const std::string& payload(const Task& t, uint32_t& crc) const {
    size_t i = (size_t(t.lo(0) / brickVoxels) * size_t(perAxis) + size_t(t.lo(1) / brickVoxels)) * size_t(perAxis) +
               size_t(t.lo(2) / brickVoxels);
    crc = crcs.at(i);
    return payloads.at(i);
  }
};

// Fake workers replay the pre-encoded results (sent without a copy), so what is measured is the
// master, not the workers. They run in a child process (this program with --fake-workers), so
// the master's CPU time is the parent's. They stand in for workers on other machines, so they
// cost this machine as little as they can: one thread and one ZeroMQ context (one I/O thread)
// serve every fake's dealer socket, instead of a thread and an I/O thread each (~99 against
// ~60 us of CPU a brick, taken from the 2 cores the master runs on).
void fakeWorkers(const std::string& ep, int fakes, const Replay& replay) {
  zmq::context_t ctx(1);
  std::vector<zmq::socket_t> sockets;
  for (int i = 0; i < fakes; ++i) {
    zmq::socket_t& s = sockets.emplace_back(ctx, zmq::socket_type::dealer);
    s.set(zmq::sockopt::linger, 0);
    s.connect(ep);
    Envelope hello;
    hello.mutable_hello()->set_worker_id("fake-" + std::to_string(i));  // distinct: a shared id reads as one worker reconnecting
    send(s, "", hello);
  }
  std::vector<zmq::pollitem_t> items;
  for (auto& s : sockets) items.push_back({static_cast<void*>(s), 0, ZMQ_POLLIN, 0});
  for (size_t open = sockets.size(); open > 0;) {
    zmq::poll(items.data(), items.size(), std::chrono::milliseconds(50));
    for (size_t w = 0; w < sockets.size(); ++w) {
      if (!items[w].socket) continue;  // told bye
      zmq::socket_t& s = sockets[w];
      Incoming in;
      while (receive(s, false, in, nullptr)) {
        if (in.envelope.body_case() == Envelope::kBye) {
          items[w].socket = nullptr, items[w].fd = -1, --open;  // zmq::poll skips a null socket with fd -1
          break;
        }
        if (in.envelope.body_case() != Envelope::kTask) continue;
        const Task& t = in.envelope.task();
        uint32_t crc = 0;
        const std::string& payload = replay.payload(t, crc);
        Envelope r;
        r.set_job_id(in.envelope.job_id());
        r.set_proto_major(kProtoMajor);
        r.set_proto_minor(kProtoMinor);
        Result* res = r.mutable_result();
        res->set_brick_id(t.brick_id());
        res->set_attempt(t.attempt());
        res->set_leaves(uint32_t(replay.leaves));
        res->set_payload_crc32(crc);
        std::string head = r.SerializeAsString();
        s.send(zmq::buffer(head), zmq::send_flags::sndmore);
        s.send(zmq::message_t(const_cast<char*>(payload.data()), payload.size(), nullptr), zmq::send_flags::none);
      }
    }
  }
}

// Child process: encodes every brick's result, says "ready", reads the master's endpoint from
// stdin, serves it with `fakes` workers until each is told bye and says "served" with the CPU
// seconds that took it (the share of this machine the stand-ins for remote workers used).
int runFakeWorkers(int fakes, int res, int brickVoxels, int leaves) {
  Replay replay{brickVoxels, (res + brickVoxels - 1) / brickVoxels, leaves, {}, {}};
  for (int i = 0; i < replay.perAxis; ++i)
    for (int j = 0; j < replay.perAxis; ++j)
      for (int k = 0; k < replay.perAxis; ++k) {
        replay.payloads.push_back(fakePayload({i * brickVoxels, j * brickVoxels, k * brickVoxels}, leaves));
        replay.crcs.push_back(crc32Of(replay.payloads.back().data(), replay.payloads.back().size()));
      }
  std::printf("ready\n");
  std::fflush(stdout);
  char ep[256] = {};
  if (!std::fgets(ep, sizeof ep, stdin)) return 1;
  std::string endpoint(ep);
  while (!endpoint.empty() && (endpoint.back() == '\n' || endpoint.back() == '\r')) endpoint.pop_back();
  struct rusage r0 {}, r1 {};
  getrusage(RUSAGE_SELF, &r0);
  fakeWorkers(endpoint, fakes, replay);
  getrusage(RUSAGE_SELF, &r1);
  auto secs = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  std::printf("served %.6f\n", secs(r1.ru_utime) + secs(r1.ru_stime) - secs(r0.ru_utime) - secs(r0.ru_stime));
  return 0;
}

// The fake workers' child process: its stdin takes the endpoint, its stdout says "ready", then
// "served" and its CPU seconds.
struct FakeFarm {
  pid_t pid = -1;
  FILE* toChild = nullptr;
  FILE* fromChild = nullptr;
  FakeFarm(int fakes, int res, int brickVoxels, int leaves) {
    int in[2], out[2];
    if (pipe(in) != 0 || pipe(out) != 0) throw std::runtime_error("pipe");
    pid = fork();
    if (pid == 0) {
      dup2(in[0], 0);
      dup2(out[1], 1);
      close(in[1]);
      close(out[0]);
      const std::string a[] = {std::to_string(fakes), std::to_string(res), std::to_string(brickVoxels),
                               std::to_string(leaves)};
      execl("/proc/self/exe", "bench_farm", "--fake-workers", a[0].c_str(), a[1].c_str(), a[2].c_str(), a[3].c_str(),
            static_cast<char*>(nullptr));
      _exit(127);
    }
    close(in[0]);
    close(out[1]);
    toChild = fdopen(in[1], "w");
    fromChild = fdopen(out[0], "r");
    char line[64] = {};
    if (!std::fgets(line, sizeof line, fromChild)) throw std::runtime_error("fake workers did not start");
  }
  void connect(const std::string& endpoint) {
    std::fprintf(toChild, "%s\n", endpoint.c_str());
    std::fflush(toChild);
  }
  // After the job (the fakes were told bye): the CPU seconds the child spent serving, or -1.
  double servedCpuSeconds() {
    char line[64] = {};
    double cpu = -1;
    if (std::fgets(line, sizeof line, fromChild) && std::sscanf(line, "served %lf", &cpu) == 1) return cpu;
    return -1;
  }
  ~FakeFarm() {
    if (toChild) std::fclose(toChild);
    if (fromChild) std::fclose(fromChild);
    int status = 0;
    waitpid(pid, &status, 0);
  }
};

double threadCpuSeconds() {
  struct rusage ru {};
  getrusage(RUSAGE_THREAD, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

double processCpuSeconds() {
  struct rusage ru {};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// The process's peak resident set restarts from its current one (clear_refs 5, Linux >= 4.0), so
// that each run's peak is its own, not the largest of the runs before it. False if refused.
bool resetPeakRss() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  f.close();
  return bool(f);
}

// VmHWM of /proc/self/status: the peak resident set since resetPeakRss, bytes (0 if unreadable).
uint64_t peakRssSinceReset() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  return 0;
}

struct MasterRun {
  double wall = 0, loopCpu = 0, processCpu = 0, peakRssMb = 0, fakesCpu = 0;
  uint64_t bricks = 0, leaves = 0;
};

// One job of the master against `fakes` replaying workers, with a journal as frep keeps one;
// `streaming`: the merge goes to a sink that counts the leaves (result.leaves stays empty).
MasterRun masterRun(int fakes, int res, int brickVoxels, int leaves, int decodeThreads, bool streaming) {
  FakeFarm farm(fakes, res, brickVoxels, leaves);
  JobSpec big = job("my_model(x[3], a[1]) { my_model = 1; }", res);
  FarmOptions o;
  o.listen = "tcp://127.0.0.1:*";
  o.onListening = [&](const std::string& ep) { farm.connect(ep); };
  o.brickVoxels = brickVoxels;
  o.heartbeatMs = 500;
  o.decodeThreads = decodeThreads;
  char journal[] = "/tmp/bench_farm_XXXXXX";
  int fd = mkstemp(journal);
  if (fd >= 0) close(fd);
  o.journalPath = journal;
  uint64_t streamed = 0;
  if (streaming) o.sampleSink.leaves = [&](const std::vector<LeafBlock>& slab) { streamed += slab.size(); };
  MasterRun m;
  const bool peakReset = resetPeakRss();
  std::thread master([&] {
    const double cpu0 = processCpuSeconds(), loop0 = threadCpuSeconds();
    FarmOutcome out = runJob(big, o);
    m.loopCpu = threadCpuSeconds() - loop0;
    m.processCpu = processCpuSeconds() - cpu0;
    m.wall = out.report.wallSeconds;
    m.bricks = out.report.bricks;
    m.leaves = out.report.leaves;
    m.peakRssMb = double(peakReset ? peakRssSinceReset() : out.report.peakRssBytes) / (1 << 20);
    if (streaming ? streamed != out.report.leaves || !out.result.leaves.empty()
                  : out.result.leaves.size() != out.report.leaves) {
      std::fprintf(stderr, "bench_farm: the merge lost leaves (%llu merged, %llu streamed, %zu in the result)\n",
                   (unsigned long long)out.report.leaves, (unsigned long long)streamed, out.result.leaves.size());
      std::exit(1);
    }
  });
  master.join();
  m.fakesCpu = farm.servedCpuSeconds();
  std::remove(journal);
  return m;
}

// 1. Speed-up of a compute-heavy job, 1 -> 2 local workers; returns the mean compute time of
// a 64^3 brick of it (the brick time the master must keep up with).
double workerSpeedUp() {
  double brickSeconds = 0;
  JobSpec heavy = job(kHeavyModel, 192);
  double t[3] = {0, 0, 0};
  uint64_t bricks = 0;
  for (int w : {1, 2}) {
    FarmOptions o;
    o.workers = w;
    o.brickVoxels = 32;
    o.workerExecutable = FREP_WORKER_PATH;
    auto t0 = std::chrono::steady_clock::now();
    FarmOutcome out = runJob(heavy, o);
    t[w] = seconds(t0);
    bricks = out.report.bricksComputed;
    std::printf("heavy model 192^3 (32^3 bricks), %d worker(s): %.2f s, %llu bricks, %llu point evals\n", w, t[w],
                (unsigned long long)bricks, (unsigned long long)out.report.pointEvals);
  }
  std::printf("speed-up 1 -> 2 workers: %.2fx\n\n", t[1] / t[2]);
  {
    // The brick time the master must keep up with: the same model in 64^3 bricks (the default).
    FarmOptions o;
    o.workers = 1;
    o.brickVoxels = 64;
    o.workerExecutable = FREP_WORKER_PATH;
    FarmOutcome out = runJob(job(kHeavyModel, 256), o);
    brickSeconds = out.report.perWorker.begin()->second.computeSeconds / double(out.report.bricks);
    std::printf("mean compute time of a 64^3 brick (heavy model, 256^3): %.4f s\n\n", brickSeconds);
  }
  return brickSeconds;
}

// 2. What protocol 2 saves per task: a 1.x task carried the whole job, so the master copied and
// serialized it (and the kernel and the worker moved and parsed it) once per brick. Measured
// here: building and serializing a task's envelope with and without a job whose model reads a
// 4 MiB file (a mesh of about 10^5 triangles), as the master's sendTask does.
void taskCost() {
  JobSpec j = job(kHeavyModel, 1024);
  ModelFile* f = j.add_model_files();
  f->set_path("part.stl");
  f->set_contents(std::string(4 << 20, 's'));
  f->set_hash(modelFileHash(f->contents()));
  const uint64_t jobId = jobIdOf(j);  // the master hashes its job once
  auto build = [&](bool withJob, std::string& bytes) {
    Envelope e;
    e.set_job_id(jobId);
    Task* t = e.mutable_task();
    t->set_brick_id(7);
    t->set_attempt(1);
    for (int a = 0; a < 3; ++a) t->add_lo(64), t->add_hi(128);
    e.SerializeToString(&bytes);
    if (withJob) {  // what tag 5 (Task.job, reserved since 2.0) added: the job, copied and serialized
      JobSpec copy = j;
      bytes += copy.SerializeAsString();
    }
  };
  double secs[2] = {0, 0};
  size_t size[2] = {0, 0};
  const int n = 50;
  for (int withJob = 0; withJob < 2; ++withJob) {
    std::string bytes;
    auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i) build(withJob == 1, bytes);
    secs[withJob] = seconds(t0) / n;
    size[withJob] = bytes.size();
  }
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 5; ++i)
    if (jobIdOf(j) != jobId) std::abort();  // what a 1.x worker did with every task's job
  const double hash = seconds(t0) / 5;
  std::printf("a task's envelope, job with a 4 MiB model file: protocol 1.x %zu bytes, %.0f us to build "
              "(and %.0f us for the worker to hash the job, per task); protocol 2 %zu bytes, %.2f us (%.0fx less; "
              "the job goes once per worker, in the welcome)\n\n",
              size[1], 1e6 * secs[1], 1e6 * hash, size[0], 1e6 * secs[0], secs[1] / secs[0]);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 6 && std::string(argv[1]) == "--fake-workers") {
    applyAllocatorPolicy();  // the fake workers stand in for frep-worker processes: its allocator policy
    return runFakeWorkers(std::atoi(argv[2]), std::atoi(argv[3]), std::atoi(argv[4]), std::atoi(argv[5]));
  }
  applyAllocatorPolicy();  // the master here stands in for frep sample's, which applies it too
  const bool masterOnly = argc >= 2 && std::string(argv[1]) == "--master-only";
  // --master-only --streaming: only the streamed runs (profiling the merge into a sink);
  // --master-only --building: only the runs that build the whole output (decoding on all cores).
  const bool streamingOnly = masterOnly && argc == 3 && std::string(argv[2]) == "--streaming";
  const bool buildingOnly = masterOnly && argc == 3 && std::string(argv[2]) == "--building";
  double brickSeconds = 0;
  if (!masterOnly) brickSeconds = workerSpeedUp();
  if (!streamingOnly && !buildingOnly) taskCost();

  // 3. The master's own ceiling: a 1024^3 grid in 64^3 bricks = 4096 bricks, each answered at
  //    once with 128 leaf blocks (a surface crossing a 64^3 brick, 150 kB), with a journal.
  const int leavesPerBrick = 128;
  std::printf("master against fake workers replaying pre-encoded results (their cost not measured; a child process),\n"
              "1024^3 in 64^3 bricks, %d leaves (150 kB) a brick, journal on; master CPU = the master's process\n"
              "(loop, decoders, ZeroMQ I/O thread), loop = its scheduling thread alone; \"all cores\" = the\n"
              "master's default decode threads (every core but two, at least one: %d here)\n",
              leavesPerBrick, defaultDecodeThreads());
  // Decoding on the scheduling loop alone (decodeThreads 1) against the default decode threads
  // (0: every core but two; the label keeps its name so that bench_farm_ab.sh compares with
  // older builds), building the output (result.leaves) or streaming it into a counting sink,
  // alternated, 3 runs each; medians. Peak RSS: each run's own (resetPeakRss).
  // The last mode streams with 64 fake workers: 8 with a credit of 4 bricks keep only 32 in
  // flight, and on 2 shared cores a brick's round trip (task, result, verification; every hop a
  // thread waiting for a core) alone then caps the rate (Little's law: 8 -> 16 -> 32 -> 64 fake
  // workers gave 9,495 -> 9,959 -> 10,142 -> 10,530 bricks/s, the master's CPU per brick 107 ->
  // 100 us). A farm of the 256 workers the goal names keeps 1,024 in flight.
  const int fakeCount[4] = {8, 8, 8, 64};
  const char* label[4] = {"decoding on the loop ", "decoding on all cores", "streaming into a sink",
                          "streaming into a sink, 256 in flight"};
  std::vector<double> rate[4], cpuPerBrick[4];
  for (int round = 0; round < 3; ++round)
    for (int mode = 0; mode < 4; ++mode) {
      if ((streamingOnly && mode < 2) || (buildingOnly && mode != 1)) continue;
      const int fakes = fakeCount[mode];
      MasterRun m = masterRun(fakes, 1024, 64, leavesPerBrick, mode == 0 ? 1 : 0, mode >= 2);
      rate[mode].push_back(double(m.bricks) / m.wall);
      cpuPerBrick[mode].push_back(m.processCpu / double(m.bricks));
      std::printf("  %d fake workers, %s: %llu bricks in %.2f s = %.0f bricks/s wall; master CPU %.0f us/brick, "
                  "loop %.0f us/brick; process peak RSS %.0f MiB; fake workers' CPU %.0f us/brick\n",
                  fakes, label[mode], (unsigned long long)m.bricks, m.wall, rate[mode].back(),
                  1e6 * m.processCpu / double(m.bricks), 1e6 * m.loopCpu / double(m.bricks), m.peakRssMb, 1e6 * m.fakesCpu / double(m.bricks));
    }
  if (streamingOnly || buildingOnly) return 0;
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf("median: %.0f bricks/s decoding on the loop, %.0f on all cores: %.2fx\n", median(rate[0]),
              median(rate[1]), median(rate[1]) / median(rate[0]));
  std::printf("master CPU per brick (median, all cores): %.0f us: %.0f bricks per second of master CPU\n",
              1e6 * median(cpuPerBrick[1]), 1 / median(cpuPerBrick[1]));
  std::printf("streaming into a sink (median): %.0f bricks/s wall (%.2fx), %.0f us of master CPU per brick (%.2fx "
              "fewer): %.0f bricks per second of master CPU\n",
              median(rate[2]), median(rate[2]) / median(rate[1]), 1e6 * median(cpuPerBrick[2]),
              median(cpuPerBrick[1]) / median(cpuPerBrick[2]), 1 / median(cpuPerBrick[2]));
  std::printf("streaming with 64 fake workers, 256 bricks in flight (median): %.0f bricks/s wall, %.0f us of master "
              "CPU per brick\n", median(rate[3]), 1e6 * median(cpuPerBrick[3]));
  if (brickSeconds > 0)
    std::printf("  -> at %.4f s per brick one master keeps %.0f workers busy (goal >= 256)\n", brickSeconds,
                median(rate[1]) * brickSeconds);
  return 0;
}
