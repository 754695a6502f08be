// evaluatePlane on a DenseTape (plane_dense.h), in Fidget's shape: the image split in four by
// four-box interval passes, each tile's tape simplified from its parent's in one backward pass
// (DenseSimplifier); tiles above kTaskTile split in tasks (any thread, work stealing), smaller
// ones on one thread into per-depth buffers of its worker (no allocation once warm), down to
// leaf tiles of one batch, whose pixels are evaluated with the
// leaf's short, densely numbered tape. Float leaves (signOnly + floatSigns) keep a pixel's float
// value where it exceeds the certified bound over the leaf's box (FloatErrorBound) and recompute
// the others in double on the same tape, so every sign is the double path's.
#include "sampling/plane_dense.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "frep/evaluators/dense_eval.h"
#include "frep/evaluators/float_error.h"
#include "frep/expressions/dense_tape.h"
#include "frep/interrupt/interrupter.h"

namespace frep {
namespace {

// Tiles of at most kTaskTile x kTaskTile pixels are split on one thread (in its per-depth
// buffers); larger ones split in tasks, each quadrant simplifying its own tape from its parent's
// (Prospero 1024^2 on two threads: 16 tasks of 256^2 were up to 4x apart in time, 64 of 128^2
// share the work evenly, and the root's and 512^2 tiles' simplifications run in parallel too).
constexpr int kTaskTile = 128;
// Leaves of at most 16 x 16 pixels, one batch (Prospero 1024^2, float signs: 8 x 8 and 32 x 32
// measured slower, by more interval passes and simplifications or by longer batch tapes).
constexpr int kLeafTile = 16;
// Buffers per depth: the top tile's, then one per halving down to the leaves.
constexpr int kMaxDepth = 16;
static_assert((kTaskTile >> (kMaxDepth - 2)) <= kLeafTile, "a depth's buffers for every halving");

struct Worker {
  DenseIntervalEvaluator interval;
  DenseSimplifier simplifier;
  DenseBatchEvaluator<float> fbatch;
  DenseBatchEvaluator<double> dbatch;
  FloatErrorBound error;
  // Per depth: the tapes, choices and boxes of the quadrants of the tile being split.
  std::vector<DenseTape> tapes = std::vector<DenseTape>(4 * kMaxDepth);
  std::vector<std::vector<uint8_t>> choices = std::vector<std::vector<uint8_t>>(kMaxDepth);
  std::vector<std::vector<Interval>> boxes = std::vector<std::vector<Interval>>(kMaxDepth);
  std::vector<uint32_t> redo;
  PlaneStats stats;
  bool ready = false;
};

class DensePlane {
 public:
  DensePlane(const TapePtr& tape, const PlaneLattice& l, const PlaneOptions& opt, std::vector<double>& out)
      : tape_(tape), l_(l), opt_(opt), out_(out), float_(opt.signOnly && opt.floatSigns) {
    root_.assign(*tape);
    nvb_ = std::max<uint32_t>(root_.numVars, 1);
    for (int c = 0; c < l.width; ++c) colD_.push_back(l_.colCoord(c)), colF_.push_back(float(l_.colCoord(c)));
  }

  size_t index(int c, int r) const { return size_t(r) * size_t(l_.width) + size_t(c); }

  // Per thread, once: the root's constants, and the lanes of the held coordinates (the tapes
  // never write a var's register, so they stay).
  void prepare(Worker& w) const {
    if (w.ready) return;
    w.interval.bind(*tape_);
    w.fbatch.bind(*tape_);
    w.dbatch.bind(*tape_);
    w.error.bind(*tape_);
    for (auto& boxes : w.boxes) {
      boxes.resize(4 * nvb_);
      for (size_t j = 0; j < 4; ++j)
        for (uint32_t var = 0; var < root_.numVars; ++var) boxes[j * nvb_ + var] = Interval(l_.held(var));
    }
    for (uint32_t var = 0; var < root_.numVars; ++var) {
      if (var == l_.u || var == l_.v) continue;
      std::fill(w.fbatch.in(var), w.fbatch.in(var) + DenseBatchEvaluator<float>::kBatch, float(l_.held(var)));
      std::fill(w.dbatch.in(var), w.dbatch.in(var) + DenseBatchEvaluator<double>::kBatch, l_.held(var));
    }
    w.ready = true;
  }

  struct Rect {
    int c0, c1, r0, r1;  // pixels [c0, c1) x [r0, r1)
  };

  // Tile p with its tape: split on this thread when it is at most a task tile, else its
  // quadrants classified in one pass, their tapes simplified, and each undecided one run as a
  // task (through `spawn`) that recurses.
  template <typename Spawn>
  void descend(Worker& w, const Rect& p, const DenseTape& tape, Spawn&& spawn) {
    if (isTask(p)) {
      if (isLeaf(p)) {
        Interval* box = w.boxes[0].data();
        setBox(box, p);
        leaf(w, p.c0, p.c1, p.r0, p.r1, tape, box);
      } else {
        group(w, p, tape, 0);
      }
      return;
    }
    Rect kids[4];
    uint32_t decided[4];
    Interval iv[4];
    const int n = quadrants(w, p, tape, 0, kids, decided, iv);
    // The quadrants' tapes, simplified here in one simplify4 into tapes of this frame (the
    // tasks may run on other threads, or on this one after it took other work).
    DenseTape subs[4];
    DenseTape* bufs[4] = {&subs[0], &subs[1], &subs[2], &subs[3]};
    const DenseTape* own[4];
    unsigned wanted = 0;
    for (int j = 0; j < 4; ++j) {
      own[j] = nullptr;
      if (j >= n || decide(w, kids[j], iv[j], tape.size())) continue;
      if (decided[j]) wanted |= 1u << j, own[j] = &subs[j];
      else own[j] = &tape;
    }
    if (wanted) w.simplifier.simplify4(tape, w.choices[1].data(), wanted, bufs);
    spawn([&](auto&& fork) {
      for (int j = 0; j < n; ++j) {
        if (!own[j]) continue;
        const Rect t = kids[j];
        const DenseTape* sub = own[j];
        fork([this, t, sub, &spawn](Worker& worker) { descend(worker, t, *sub, spawn); });
      }
    });
  }
  // The whole image from the root's tape.
  template <typename Spawn>
  void run(Worker& w, Spawn&& spawn) {
    descend(w, Rect{0, l_.width, 0, l_.height}, root_, spawn);
  }

 private:
  bool isTask(const Rect& t) const { return t.c1 - t.c0 <= kTaskTile && t.r1 - t.r0 <= kTaskTile; }
  bool isLeaf(const Rect& t) const { return t.c1 - t.c0 <= leafSide_ && t.r1 - t.r0 <= leafSide_; }
  void setBox(Interval* b, const Rect& t) const {
    if (l_.u < root_.numVars) b[l_.u] = Interval(l_.colCoord(t.c0), l_.colCoord(t.c1 - 1));
    if (l_.v < root_.numVars) b[l_.v] = Interval(l_.rowCoord(t.r1 - 1), l_.rowCoord(t.r0));
  }

  // Counts tile t's interval pass (over a tape of `size` instructions); with signOnly, fills it
  // when the interval decides its sign and says so.
  bool decide(Worker& w, const Rect& t, const Interval& iv, size_t size) {
    ++w.stats.intervalEvals;
    w.stats.intervalInstrs += size;
    const int side = iv.lo > 0 ? 1 : iv.hi < 0 ? -1 : 0;
    if (side != 0) w.stats.decidedPixels += uint64_t(t.c1 - t.c0) * uint64_t(t.r1 - t.r0);
    if (side == 0 || !opt_.signOnly) return false;
    const double fill = side > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
    for (int r = t.r0; r < t.r1; ++r)
      std::fill(out_.begin() + long(index(t.c0, r)), out_.begin() + long(index(t.c1, r)), fill);
    return true;
  }

  // The quadrants of tile p (p itself when it is a leaf already) in kids, classified in one
  // four-lane pass of p's tape over their boxes (depth + 1's buffers; depth 0's box is a leaf
  // task's); returns how many.
  int quadrants(Worker& w, const Rect& p, const DenseTape& tape, int depth, Rect* kids, uint32_t* decided,
                Interval* iv) {
    int n = 0;
    if (isLeaf(p)) {
      kids[n++] = p;
    } else {
      const int cm = p.c1 - p.c0 > leafSide_ ? p.c0 + (p.c1 - p.c0 + 1) / 2 : p.c1;
      const int rm = p.r1 - p.r0 > leafSide_ ? p.r0 + (p.r1 - p.r0 + 1) / 2 : p.r1;
      kids[n++] = Rect{p.c0, cm, p.r0, rm};
      if (cm < p.c1) kids[n++] = Rect{cm, p.c1, p.r0, rm};
      if (rm < p.r1) kids[n++] = Rect{p.c0, cm, rm, p.r1};
      if (cm < p.c1 && rm < p.r1) kids[n++] = Rect{cm, p.c1, rm, p.r1};
    }
    // Lanes past n repeat the last tile (computed and ignored).
    Interval* boxes = w.boxes[size_t(depth + 1)].data();
    for (int j = 0; j < 4; ++j) setBox(boxes + size_t(j) * nvb_, kids[std::min(j, n - 1)]);
    std::vector<uint8_t>& choices = w.choices[size_t(depth + 1)];
    if (choices.size() < 4 * tape.size()) choices.resize(4 * tape.size());
    w.interval.eval4(tape, boxes, choices.data(), decided, iv);
    return n;
  }
  // The quadrants' tapes (own[j]; null for a quadrant whose sign is filled): tape simplified by
  // each quadrant's choices into depth + 1's buffers in one simplify4, or tape itself where
  // nothing was decided. Counts and fills the quadrants decide first.
  void simplified(Worker& w, const DenseTape& tape, int depth, int n, const Rect* kids, const uint32_t* decided,
                  const Interval* iv, const DenseTape** own) {
    unsigned wanted = 0;
    DenseTape* bufs[4];
    for (int j = 0; j < 4; ++j) {
      bufs[j] = &w.tapes[4 * size_t(depth + 1) + size_t(j)];
      own[j] = nullptr;
      if (j >= n || decide(w, kids[j], iv[j], tape.size())) continue;
      if (decided[j]) wanted |= 1u << j, own[j] = bufs[j];
      else own[j] = &tape;
    }
    if (wanted) w.simplifier.simplify4(tape, w.choices[size_t(depth + 1)].data(), wanted, bufs);
  }

  // Each quadrant of tile p is filled (signOnly, decided), evaluated as a leaf, or split in
  // turn, with the tape simplified by its own choices.
  void group(Worker& w, const Rect& p, const DenseTape& tape, int depth) {
    Rect kids[4];
    uint32_t decided[4];
    Interval iv[4];
    const int n = quadrants(w, p, tape, depth, kids, decided, iv);
    const Interval* boxes = w.boxes[size_t(depth + 1)].data();
    const DenseTape* own[4];
    simplified(w, tape, depth, n, kids, decided, iv, own);
    for (int j = 0; j < n; ++j) {
      const Rect& t = kids[j];
      if (!own[j]) continue;
      if (isLeaf(t)) leaf(w, t.c0, t.c1, t.r0, t.r1, *own[j], boxes + size_t(j) * nvb_);
      else group(w, t, *own[j], depth + 1);
    }
  }

  // Fills the u and v lanes of a batch with the pixels of the tile, row by row.
  template <typename T>
  void coordinates(DenseBatchEvaluator<T>& b, int c0, int c1, int r0, int r1) const {
    const size_t cols = size_t(c1 - c0);
    const T* cs = columns<T>() + c0;
    if (l_.u < root_.numVars)
      for (size_t k = 0, r = size_t(r0); r < size_t(r1); ++r, k += cols) std::copy(cs, cs + cols, b.in(l_.u) + k);
    if (l_.v < root_.numVars)
      for (size_t k = 0, r = size_t(r0); r < size_t(r1); ++r, k += cols)
        std::fill(b.in(l_.v) + k, b.in(l_.v) + k + cols, T(l_.rowCoord(int(r))));
  }
  // Every column's u, in double and rounded to float (the leaves' coordinates, computed once).
  template <typename T>
  const T* columns() const {
    if constexpr (sizeof(T) == sizeof(float)) return colF_.data();
    else return colD_.data();
  }

  // A leaf tile over the given box, by batches of whole rows.
  void leaf(Worker& w, int c0, int c1, int r0, int r1, const DenseTape& tape, const Interval* box) {
    const double bound = float_ ? w.error.bound(tape, box) : std::numeric_limits<double>::infinity();
    const int rows = std::max(1, int(DenseBatchEvaluator<float>::kBatch) / (c1 - c0));
    for (int ra = r0; ra < r1; ra += rows) batch(w, c0, c1, ra, std::min(r1, ra + rows), tape, bound);
  }

  void batch(Worker& w, int c0, int c1, int r0, int r1, const DenseTape& tape, double bound) {
    const int cols = c1 - c0;
    const size_t n = size_t(cols) * size_t(r1 - r0);
    w.stats.pointEvals += n;
    w.stats.tapeInstrs += tape.size();
    ++w.stats.tapeBatches;
    if (!std::isfinite(bound)) {
      w.dbatch.reserve(tape);
      coordinates(w.dbatch, c0, c1, r0, r1);
      const double* f = w.dbatch.eval(tape, n);
      size_t k = 0;
      for (int r = r0; r < r1; ++r, k += size_t(cols)) std::copy(f + k, f + k + size_t(cols), &out_[index(c0, r)]);
      if (float_) w.stats.doublePixels += n;  // not certified in float
      return;
    }
    w.fbatch.reserve(tape);
    coordinates(w.fbatch, c0, c1, r0, r1);
    const float* f = w.fbatch.eval(tape, n);
    // Every float value out, then the uncertain lanes' indices appended without a branch.
    size_t k = 0;
    for (int r = r0; r < r1; ++r, k += size_t(cols)) {
      double* row = &out_[index(c0, r)];
      for (int c = 0; c < cols; ++c) row[c] = double(f[k + size_t(c)]);
    }
    // The uncertain lanes counted in float lanes first (most batches have none): |f| > fb is
    // |f| > bound, fb being the largest float <= bound (a float above fb is above bound).
    float fb = float(bound);
    if (double(fb) > bound) fb = std::nextafter(fb, 0.0f);
    uint32_t uncertain = 0;
    for (size_t i = 0; i < n; ++i) uncertain += !(std::fabs(f[i]) > fb);
    w.stats.floatPixels += n - uncertain;
    if (uncertain == 0) return;
    w.redo.resize(n + 1);
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
      w.redo[m] = uint32_t(i);
      m += !(std::fabs(f[i]) > fb);
    }
    // The uncertain pixels, packed into one double batch on the same tape.
    w.dbatch.reserve(tape);
    double* us = l_.u < root_.numVars ? w.dbatch.in(l_.u) : nullptr;
    double* vs = l_.v < root_.numVars ? w.dbatch.in(l_.v) : nullptr;
    for (size_t j = 0; j < m; ++j) {
      const int c = c0 + int(w.redo[j] % uint32_t(cols)), r = r0 + int(w.redo[j] / uint32_t(cols));
      if (us) us[j] = l_.colCoord(c);
      if (vs) vs[j] = l_.rowCoord(r);
    }
    const double* g = w.dbatch.eval(tape, m);
    for (size_t j = 0; j < m; ++j) {
      const int c = c0 + int(w.redo[j] % uint32_t(cols)), r = r0 + int(w.redo[j] / uint32_t(cols));
      out_[index(c, r)] = g[j];
    }
    w.stats.doublePixels += m;
  }

  const TapePtr& tape_;
  const PlaneLattice& l_;
  const PlaneOptions& opt_;
  std::vector<double>& out_;
  bool float_;
  int leafSide_ = kLeafTile;
  std::vector<double> colD_;
  std::vector<float> colF_;
  size_t nvb_ = 1;  // Intervals per box: max(numVars, 1)
  DenseTape root_;
};

}  // namespace

void evaluatePlaneDense(const TapePtr& tape, const PlaneLattice& l, const PlaneOptions& opt, std::vector<double>& out,
                        PlaneStats& stats) {
  DensePlane plane(tape, l, opt, out);
  tbb::enumerable_thread_specific<Worker> workers;
  const Interrupter* interrupt = currentInterrupter();
  auto local = [&]() -> Worker& {
    Worker& w = workers.local();
    plane.prepare(w);
    return w;
  };
  if (opt.threads == 1) {
    // Serial: each quadrant's task runs at once, on this thread.
    auto spawn = [&](auto&& body) {
      body([&](auto&& task) {
        if (interrupt) interrupt->check();
        task(local());
      });
    };
    plane.run(local(), spawn);
  } else {
    // A task group per split tile; a task may run on any thread, with that thread's worker.
    auto spawn = [&](auto&& body) {
      tbb::task_group g;
      body([&](auto task) {
        g.run([&, task] {
          InterruptScope scope(interrupt);
          if (interrupt) interrupt->check();
          task(local());
        });
      });
      g.wait();
    };
    if (opt.threads > 1) {
      tbb::task_arena arena(opt.threads);
      arena.execute([&] { plane.run(local(), spawn); });
    } else {
      plane.run(local(), spawn);
    }
  }
  for (const Worker& w : workers) {
    stats.pointEvals += w.stats.pointEvals;
    stats.intervalEvals += w.stats.intervalEvals;
    stats.intervalInstrs += w.stats.intervalInstrs;
    stats.tapeInstrs += w.stats.tapeInstrs;
    stats.tapeBatches += w.stats.tapeBatches;
    stats.decidedPixels += w.stats.decidedPixels;
    stats.floatPixels += w.stats.floatPixels;
    stats.doublePixels += w.stats.doublePixels;
  }
}

}  // namespace frep
