// Farm figures, all measured in this run:
//  1. speed-up of a compute-heavy job from 1 to 2 local workers (this machine has 2 cores);
//  2. the master's own throughput against instant fake workers (bricks and leaf blocks merged
//     per second), and from it how many real workers one master keeps busy at the brick time
//     measured in 1.
#include <chrono>
#include <cstring>
#include <future>
#include <cstdio>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include "brick.h"
#include "farm_master.h"
#include "wire.h"

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

// A fake worker: answers every task at once with a canned payload of `leaves` leaf blocks.
void fakeWorker(const std::string& ep, int leaves, std::atomic<bool>& stop) {
  zmq::context_t ctx(1);
  zmq::socket_t s(ctx, zmq::socket_type::dealer);
  s.set(zmq::sockopt::linger, 0);
  s.connect(ep);
  Envelope hello;
  hello.mutable_hello()->set_worker_id("fake");
  send(s, "", hello);
  std::string payloadCache;
  std::vector<size_t> leafOffsets;
  while (!stop) {
    zmq::pollitem_t item{static_cast<void*>(s), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, std::chrono::milliseconds(50));
    Incoming in;
    while (receive(s, false, in, nullptr)) {
      if (in.envelope.body_case() == Envelope::kBye) return;
      if (in.envelope.body_case() != Envelope::kTask) continue;
      const Task& t = in.envelope.task();
      // The payload is encoded once; per task only the leaf origins are patched, so that the
      // fake workers cost the shared cores as little as possible.
      if (payloadCache.empty()) {
        BrickOutput b;
        for (int i = 0; i < leaves; ++i) {
          LeafBlock l{};
          l.origin = {8 * (i % 8), 8 * ((i / 8) % 8), 8 * (i / 64)};
          // a typical surface leaf: about half its voxels in the band
          for (int v = 0; v < kLeafVoxels; ++v) {
            bool active = (v / 8) % 2 == 0;
            l.values[size_t(v)] = active ? 0.01f * float(v % 7) : (v < 256 ? 0.3f : -0.3f);
            if (active) l.active[size_t(v >> 6)] |= uint64_t(1) << (v & 63);
          }
          b.leaves.push_back(l);
        }
        payloadCache = encodeBrick(b);
        leafOffsets.clear();
        for (size_t pos = 12, i = 0; i < size_t(leaves); ++i) {
          leafOffsets.push_back(pos);
          pos += 12 + 4 + 64 + 64 + 4 + 4 * 256;
        }
      }
      std::string payload = payloadCache;
      for (int i = 0; i < leaves; ++i) {
        int32_t origin[3] = {t.lo(0) + 8 * (i % 8), t.lo(1) + 8 * ((i / 8) % 8), t.lo(2) + 8 * (i / 64)};
        std::memcpy(payload.data() + leafOffsets[size_t(i)], origin, sizeof origin);
      }
      Envelope r;
      r.set_job_id(in.envelope.job_id());
      Result* res = r.mutable_result();
      res->set_brick_id(t.brick_id());
      res->set_attempt(t.attempt());
      res->set_leaves(uint32_t(leaves));
      res->set_payload_crc32(crc32Of(payload.data(), payload.size()));
      send(s, "", r, &payload);
    }
  }
}

}  // namespace

int main() {
  // 1. Speed-up, 1 -> 2 local workers.
  JobSpec heavy = job(kHeavyModel, 192);
  double t[3] = {0, 0, 0};
  uint64_t bricks = 0;
  double brickSeconds = 0;
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

  // 2. Master throughput with instant fake workers: a 1024^3 grid in 64^3 bricks = 4096
  //    bricks, each answered with 128 leaf blocks (a surface crossing a 64^3 brick).
  JobSpec big = job("my_model(x[3], a[1]) { my_model = 1; }", 1024);
  const int leavesPerBrick = 128;
  for (int fakes : {2, 8}) {
    FarmOptions o;
    o.listen = "tcp://127.0.0.1:*";
    std::promise<std::string> bound;
    o.onListening = [&](const std::string& ep) { bound.set_value(ep); };
    o.brickVoxels = 64;
    o.heartbeatMs = 500;
    std::atomic<bool> stop{false};
    std::vector<std::thread> ws;
    auto t0 = std::chrono::steady_clock::now();
    std::thread master([&] {
      FarmOutcome out = runJob(big, o);
      double s = seconds(t0);
      double rate = double(out.report.bricks) / s;
      std::printf("master with %2d instant fake workers: %llu bricks, %llu leaves in %.2f s = %.0f bricks/s, %.0f leaves/s\n",
                  fakes, (unsigned long long)out.report.bricks, (unsigned long long)out.report.leaves, s, rate,
                  double(out.report.leaves) / s);
      std::printf("  -> at %.4f s per brick one master keeps %.0f workers busy (goal >= 256)\n", brickSeconds,
                  rate * brickSeconds);
    });
    const std::string endpoint = bound.get_future().get();
    for (int i = 0; i < fakes; ++i) ws.emplace_back(fakeWorker, endpoint, leavesPerBrick, std::ref(stop));
    master.join();
    stop = true;
    for (auto& w : ws) w.join();
  }
  return 0;
}
