// Slice images by quadtree interval subdivision with tape pruning (frep/sampling/plane.h)
// against every pixel evaluated with the full tape (what `frep slice` did before), in one run,
// on the Prospero challenge text (Fidget's 7,866-op model, ../shared/corpus/fidget/prospero.hf)
// at 1024^2: wall and CPU milliseconds (best of 5), the ratios, and that the values agree bit
// for bit; then sign images in double and in float with the certified double fallback
// (PlaneOptions::floatSigns), whose signs must all be the baseline's; each by the general path and
// by dense tapes (PlaneOptions::denseTapes). Usage: bench_slice [model.hf] [side]
// With --mask-runs N first: the dense float sign image (`frep slice --mask`) alone, N runs at
// one thread and N at two, alternated, their median and best CPU and wall times, and that every
// run's signs are the double sign path's.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/lang/hyperfun.h"
#include "frep/sampling/plane.h"

using namespace frep;

namespace {

double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Timing {
  double wallMs = INFINITY, cpuMs = INFINITY;
};

Timing best(int repeats, const std::function<void()>& fn) {
  Timing t;
  for (int i = 0; i < repeats; ++i) {
    const double c0 = cpuSeconds();
    const auto w0 = std::chrono::steady_clock::now();
    fn();
    t.wallMs =
        std::min(t.wallMs, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count());
    t.cpuMs = std::min(t.cpuMs, 1e3 * (cpuSeconds() - c0));
  }
  return t;
}

// Every pixel with the full tape, one thread: the baseline.
std::vector<double> bruteForce(const TapePtr& tape, const PlaneLattice& l) {
  std::vector<double> out(size_t(l.width) * size_t(l.height));
  BatchEvaluator<double> eval;
  eval.reserve(*tape);
  const int kBatch = int(BatchEvaluator<double>::kBatch);
  for (int row = 0; row < l.height; ++row) {
    const double v = l.origin[1] + double(l.height - 1 - row) * l.step;
    for (int c0 = 0; c0 < l.width; c0 += kBatch) {
      const int n = std::min(kBatch, l.width - c0);
      for (int k = 0; k < n; ++k) {
        eval.in(0)[k] = l.origin[0] + double(c0 + k) * l.step;
        eval.in(1)[k] = v;
        if (tape->numVars() > 2) eval.in(2)[k] = 0.0;
      }
      const double* f = eval.eval(*tape, size_t(n));
      std::copy(f, f + n, out.begin() + long(size_t(row) * size_t(l.width) + size_t(c0)));
    }
  }
  return out;
}

}  // namespace

// Medians and minima of n samples.
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

int signClass(double f) { return std::isnan(f) ? 2 : f >= 0 ? 1 : 0; }

// --mask-runs: the float sign image, runs alternated between one and two threads.
int maskRuns(const TapePtr& tape, const PlaneLattice& l, int runs) {
  PlaneOptions dbl;
  dbl.signOnly = true;
  dbl.threads = 1;
  const std::vector<double> ref = evaluatePlane(tape, l, dbl);
  std::vector<double> cpu[3], wall[3];
  size_t wrong = 0;
  PlaneStats st;
  for (int i = 0; i < runs; ++i)
    for (int threads : {1, 2}) {
      PlaneOptions o;
      o.signOnly = o.floatSigns = true;
      o.threads = threads;
      std::vector<double> got;
      st = PlaneStats();
      const Timing t = best(1, [&] { got = evaluatePlane(tape, l, o, &st); });
      cpu[threads].push_back(t.cpuMs);
      wall[threads].push_back(t.wallMs);
      for (size_t k = 0; k < ref.size(); ++k) wrong += signClass(ref[k]) != signClass(got[k]);
    }
  for (int threads : {1, 2})
    std::printf("float mask, dense, %d thr, %d runs: CPU ms median %.2f best %.2f; wall ms median %.2f best %.2f\n",
                threads, runs, median(cpu[threads]), *std::min_element(cpu[threads].begin(), cpu[threads].end()),
                median(wall[threads]), *std::min_element(wall[threads].begin(), wall[threads].end()));
  std::printf("%.2fM interval instructions, %.2fM batch instructions in %llu batches, %llu pixels in double, "
              "%llu in float; pixels of another sign than the double path's: %zu\n",
              1e-6 * double(st.intervalInstrs), 1e-6 * double(st.tapeInstrs), (unsigned long long)st.tapeBatches,
              (unsigned long long)st.doublePixels, (unsigned long long)st.floatPixels, wrong);
  return wrong ? 1 : 0;
}

int main(int argc, char** argv) {
  int maskRunCount = 0;
  if (argc > 2 && std::strcmp(argv[1], "--mask-runs") == 0) {
    maskRunCount = std::max(1, std::atoi(argv[2]));
    argc -= 2, argv += 2;
  }
  const std::string path = argc > 1 ? argv[1] : FREP_SHARED_DIR "/corpus/fidget/prospero.hf";
  const int side = argc > 2 ? std::atoi(argv[2]) : 1024;
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "bench_slice: cannot read %s\n", path.c_str());
    return 1;
  }
  std::stringstream text;
  text << in.rdbuf();
  lang::CompileResult r = lang::compile(text.str(), path);
  if (!r.ok) {
    for (auto& d : r.diagnostics) std::fprintf(stderr, "%s\n", d.format().c_str());
    return 1;
  }
  TapePtr tape = Tape::compile(bindParams(r.model.field, {Expr(0.0)}), 3);
  PlaneLattice l;
  l.normal = 2;
  l.origin[0] = l.origin[1] = -1.0;
  l.step = 2.0 / double(side - 1);
  l.width = l.height = side;
  if (maskRunCount) return maskRuns(tape, l, maskRunCount);

  std::vector<double> ref, fast, mask, fmask;
  const Timing tb = best(3, [&] { ref = bruteForce(tape, l); });
  std::printf("%s at %dx%d: %zu instructions, %u registers\n", path.c_str(), side, side, tape->size(), tape->numRegs());
  std::printf("%-52s %10s %10s %9s %9s\n", "", "wall ms", "CPU ms", "vs base", "vs general");
  std::printf("%-52s %10.1f %10.1f %9s\n", "every pixel, full tape, 1 thread (baseline)", tb.wallMs, tb.cpuMs, "1.0x");
  // Rows: values in double, signs in double, signs in float with the double fallback, each by
  // the general path (pruned Tapes, one tile per interval pass: "before") and by dense tapes
  // (PlaneOptions::denseTapes, the default); "vs general" compares with the general path's row
  // of the same mode and thread count.
  PlaneStats floatStats, work[3][2];
  const char* name[3] = {"values", "signs (--mask), double", "signs, float + fallback"};
  for (int mode = 0; mode < 3; ++mode) {
    Timing general[3] = {};
    for (int dense : {0, 1}) {
      for (int threads : {1, 2}) {
        PlaneOptions o;
        o.signOnly = mode > 0;
        o.floatSigns = mode == 2;
        o.threads = threads;
        o.denseTapes = dense == 1;
        PlaneStats st;
        std::vector<double>& out = mode == 0 ? fast : mode == 1 ? mask : fmask;
        std::vector<double> got;
        const Timing t = best(dense ? 15 : 5, [&] { got = evaluatePlane(tape, l, o, &st); });
        // the dense rows' images are the ones checked against the baseline below
        if (dense) out = got;
        if (!dense) general[threads] = t;
        if (mode == 2 && dense) floatStats = st;
        work[mode][dense] = st;
        char label[96];
        std::snprintf(label, sizeof label, "%s, %s, %d thr (tape %.0f)", name[mode], dense ? "dense" : "general",
                      threads, st.tapeBatches ? double(st.tapeInstrs) / double(st.tapeBatches) : 0.0);
        // CPU time is the figure on a shared machine (wall time includes other processes' turns)
        std::printf("%-52s %10.1f %10.1f %8.1fx %8.2fx\n", label, t.wallMs, t.cpuMs, tb.cpuMs / t.cpuMs,
                    general[threads].cpuMs / t.cpuMs);
      }
    }
  }
  // Work that does not depend on the machine's load: tape instructions run by the interval
  // passes (one per tile; each also prunes a tape that long) and by the batches (one per
  // 256 lanes).
  for (int mode = 0; mode < 3; ++mode)
    for (int dense : {0, 1})
      std::printf("work, %s, %s: %.2fM interval instructions, %.2fM batch instructions, %llu pixels in double\n",
                  name[mode], dense ? "dense" : "general", 1e-6 * double(work[mode][dense].intervalInstrs),
                  1e-6 * double(work[mode][dense].tapeInstrs),
                  (unsigned long long)(mode == 2 ? work[mode][dense].doublePixels : work[mode][dense].pointEvals));
  std::printf("%-52s %10.1f\n", "Fidget, published (VM interpreter)", 6.0);
  std::printf("%-52s %10.1f\n", "Fidget, published (JIT)", 4.6);
  std::printf("float sign path: %llu pixels certified in float, %llu recomputed in double, %llu decided by tiles\n",
              (unsigned long long)floatStats.floatPixels, (unsigned long long)floatStats.doublePixels,
              (unsigned long long)floatStats.decidedPixels);
  // Sign classes of the image: NaN, f >= 0, f < 0.
  auto cls = signClass;
  size_t differ = 0, signs = 0, floatSigns = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (std::memcmp(&ref[i], &fast[i], sizeof(double)) != 0) ++differ;
    if (cls(ref[i]) != cls(mask[i])) ++signs;
    if (cls(ref[i]) != cls(fmask[i])) ++floatSigns;
  }
  std::printf(
      "pruned values differing from the baseline's bits: %zu; pixels of another sign than the baseline's: "
      "%zu sign-only, %zu float\n",
      differ, signs, floatSigns);
  return differ || signs || floatSigns ? 1 : 0;
}
