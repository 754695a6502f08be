// Quadtree evaluation of a plane lattice (see plane.h): the general path, for every model;
// models of the arithmetic subset take plane_dense.cpp's (PlaneOptions::denseTapes).
//
// The image is cut into fixed 256-pixel tiles (the parallel grain, independent of the thread
// count); each tile is classified by interval arithmetic over the box of its pixel centres,
// its tape pruned to what that box decided, and split in four until a tile holds at most one
// batch (16 x 16 pixels), which is evaluated with its pruned tape. Pixel coordinates are
// computed as origin + index * step, which is monotone in the index, so the box built from
// the first and last index contains every pixel's coordinate exactly.
//
// floatSigns: a leaf runs in float, then its certified error bound over the leaf's box decides
// which lanes keep the float value (|f| > bound: the double value has the same sign) and which
// are gathered into one double batch. The bound is taken on the leaf's pruned tape (the tape
// both precisions evaluate there), so it is as tight as the leaf's box allows.
#include "frep/sampling/plane.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/float_error.h"
#include "frep/expressions/dense_tape.h"
#include "sampling/parallel_chunks.h"
#include "sampling/plane_dense.h"

namespace frep {
namespace {

// 256: on Prospero at 1024^2 the first interval passes over the whole tape are then 16, not 64,
// and their pruning shortens the next level's tapes: 19 % fewer interval instructions in all.
constexpr int kTopTile = 256;
// Tiles of at most kLeafTile^2 pixels are evaluated as one batch (8 x 8 leaves measured slower
// on Prospero, also with signOnly: the extra interval passes and prunes cost more than they save).
constexpr int kLeafTile = 16;
static_assert(kLeafTile * kLeafTile <= int(BatchEvaluator<double>::kBatch), "one batch per leaf tile");
// Float leaves are 32 x 32 pixels (four batches on one pruned tape): a float lane costs about half
// a double one, so one interval pass and prune fewer per 1,024 pixels is worth the longer tape
// and the pixels a finer tile would have decided (Prospero 1024^2: 0.91M interval plus batch
// instructions against 1.01M with 16 x 16 leaves).
constexpr int kFloatLeafTile = 32;

struct PlaneWorker {
  IntervalEvaluator interval;
  BatchEvaluator<double> batch;
  BatchEvaluator<float> fbatch;
  FloatErrorBound error;
  std::vector<uint32_t> redo;  // lanes of a float leaf recomputed in double
  std::vector<float> scratch = std::vector<float>(BatchEvaluator<float>::kBatch);
  std::vector<Interval> box;
  PlaneStats stats;
};

class PlaneEvaluator {
 public:
  PlaneEvaluator(const TapePtr& tape, const PlaneLattice& l, const PlaneOptions& opt, std::vector<double>& out)
      : l_(l), opt_(opt), out_(out), nvars_(std::max<uint32_t>(tape->numVars(), 1)),
        float_(opt.signOnly && opt.floatSigns && FloatErrorBound::supports(*tape)) {}

  // Pixels [c0, c1) x [r0, r1) with the tape that the enclosing tile decided.
  void tile(PlaneWorker& w, int c0, int c1, int r0, int r1, const TapePtr& tape) {
    w.box.resize(nvars_);
    for (uint32_t var = 0; var < nvars_; ++var) w.box[var] = Interval(l_.held(var));
    if (l_.u < nvars_) w.box[l_.u] = Interval(l_.colCoord(c0), l_.colCoord(c1 - 1));
    if (l_.v < nvars_) w.box[l_.v] = Interval(l_.rowCoord(r1 - 1), l_.rowCoord(r0));
    ++w.stats.intervalEvals;
    w.stats.intervalInstrs += tape->size();
    const Interval iv = w.interval.eval(*tape, w.box.data());
    const int side = iv.lo > 0 ? 1 : iv.hi < 0 ? -1 : 0;
    const uint64_t pixels = uint64_t(c1 - c0) * uint64_t(r1 - r0);
    if (side != 0) w.stats.decidedPixels += pixels;
    if (side != 0 && opt_.signOnly) {
      const double fill = side > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
      for (int r = r0; r < r1; ++r)
        std::fill(out_.begin() + index(c0, r), out_.begin() + index(c1, r), fill);
      return;
    }
    const bool isLeaf = c1 - c0 <= leafSide_ && r1 - r0 <= leafSide_;
    TapePtr pruned = w.interval.pruned(tape);
    if (isLeaf) {
      if (float_)
        floatLeaf(w, c0, c1, r0, r1, *pruned);
      else
        leaf(w, c0, c1, r0, r1, *pruned);
      return;
    }
    const int cm = c1 - c0 > leafSide_ ? c0 + (c1 - c0 + 1) / 2 : c1;
    const int rm = r1 - r0 > leafSide_ ? r0 + (r1 - r0 + 1) / 2 : r1;
    tile(w, c0, cm, r0, rm, pruned);
    if (cm < c1) tile(w, cm, c1, r0, rm, pruned);
    if (rm < r1) tile(w, c0, cm, rm, r1, pruned);
    if (cm < c1 && rm < r1) tile(w, cm, c1, rm, r1, pruned);
  }

  void leaf(PlaneWorker& w, int c0, int c1, int r0, int r1, const Tape& tape) {
    const size_t n = size_t(c1 - c0) * size_t(r1 - r0);
    w.batch.reserve(tape);
    for (uint32_t var = 0; var < tape.numVars(); ++var) {
      if (var == l_.u || var == l_.v) continue;
      std::fill(w.batch.in(var), w.batch.in(var) + n, l_.held(var));
    }
    size_t k = 0;
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c, ++k) {
        if (l_.u < tape.numVars()) w.batch.in(l_.u)[k] = l_.colCoord(c);
        if (l_.v < tape.numVars()) w.batch.in(l_.v)[k] = l_.rowCoord(r);
      }
    const double* f = w.batch.eval(tape, n);
    k = 0;
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c, ++k) out_[index(c, r)] = f[k];
    w.stats.pointEvals += n;
    w.stats.tapeInstrs += tape.size();
    ++w.stats.tapeBatches;
    if (opt_.signOnly && opt_.floatSigns) w.stats.doublePixels += n;  // not certified in float
  }

  // The leaf in float, by batches of whole rows; w.box still holds its box.
  void floatLeaf(PlaneWorker& w, int c0, int c1, int r0, int r1, const Tape& tape) {
    const double bound = w.error.bound(tape, w.box.data());
    const int rows = std::max(1, int(BatchEvaluator<float>::kBatch) / (c1 - c0));
    for (int ra = r0; ra < r1; ra += rows) {
      const int rb = std::min(r1, ra + rows);
      if (std::isfinite(bound)) {
        floatBatch(w, c0, c1, ra, rb, tape, bound);
      } else {
        leaf(w, c0, c1, ra, rb, tape);
      }
    }
  }

  void floatBatch(PlaneWorker& w, int c0, int c1, int r0, int r1, const Tape& tape, double bound) {
    const int cols = c1 - c0;
    const size_t n = size_t(cols) * size_t(r1 - r0);
    BatchEvaluator<float>& fb = w.fbatch;
    fb.reserve(tape);
    for (uint32_t var = 0; var < tape.numVars(); ++var) {
      if (var == l_.u || var == l_.v) continue;
      std::fill(fb.in(var), fb.in(var) + n, float(l_.held(var)));
    }
    // Coordinates rounded to float (the error bound counts that rounding); the lanes of a
    // var the tape does not read go to a scratch row.
    float* us = l_.u < tape.numVars() ? fb.in(l_.u) : w.scratch.data();
    float* vs = l_.v < tape.numVars() ? fb.in(l_.v) : w.scratch.data();
    size_t k = 0;
    for (int r = r0; r < r1; ++r) {
      const float v = float(l_.rowCoord(r));
      for (int c = c0; c < c1; ++c, ++k) us[k] = float(l_.colCoord(c)), vs[k] = v;
    }
    const float* f = fb.eval(tape, n);
    w.redo.clear();
    k = 0;
    for (int r = r0; r < r1; ++r) {
      double* row = &out_[index(c0, r)];
      for (int c = 0; c < cols; ++c, ++k) {
        if (std::fabs(double(f[k])) > bound)
          row[c] = double(f[k]);
        else
          w.redo.push_back(uint32_t(k));
      }
    }
    w.stats.pointEvals += n;
    w.stats.tapeInstrs += tape.size();
    ++w.stats.tapeBatches;
    w.stats.floatPixels += n - w.redo.size();
    if (w.redo.empty()) return;
    // The uncertain lanes, packed into one double batch.
    const size_t m = w.redo.size();
    w.batch.reserve(tape);
    for (uint32_t var = 0; var < tape.numVars(); ++var) {
      if (var == l_.u || var == l_.v) continue;
      std::fill(w.batch.in(var), w.batch.in(var) + m, l_.held(var));
    }
    for (size_t j = 0; j < m; ++j) {
      const int c = c0 + int(w.redo[j] % uint32_t(cols)), r = r0 + int(w.redo[j] / uint32_t(cols));
      if (l_.u < tape.numVars()) w.batch.in(l_.u)[j] = l_.colCoord(c);
      if (l_.v < tape.numVars()) w.batch.in(l_.v)[j] = l_.rowCoord(r);
    }
    const double* g = w.batch.eval(tape, m);
    for (size_t j = 0; j < m; ++j) {
      const int c = c0 + int(w.redo[j] % uint32_t(cols)), r = r0 + int(w.redo[j] / uint32_t(cols));
      out_[index(c, r)] = g[j];
    }
    w.stats.doublePixels += m;
  }

  size_t index(int c, int r) const { return size_t(r) * size_t(l_.width) + size_t(c); }

 private:
  const PlaneLattice& l_;
  const PlaneOptions& opt_;
  std::vector<double>& out_;
  uint32_t nvars_;
  bool float_;
  int leafSide_ = float_ ? kFloatLeafTile : kLeafTile;
};

}  // namespace

std::vector<double> evaluatePlane(const TapePtr& tape, const PlaneLattice& l, const PlaneOptions& opt,
                                  PlaneStats* stats) {
  if (l.width <= 0 || l.height <= 0) throw std::invalid_argument("evaluatePlane: image size must be positive");
  if (!(l.step > 0) || !std::isfinite(l.step)) throw std::invalid_argument("evaluatePlane: pixel step must be positive");
  if (l.u == l.v) throw std::invalid_argument("evaluatePlane: the image axes must differ");
  std::vector<double> out(size_t(l.width) * size_t(l.height));
  if (opt.denseTapes && DenseTape::supports(*tape)) {
    PlaneStats st;
    evaluatePlaneDense(tape, l, opt, out, st);
    if (stats) *stats = st;
    return out;
  }
  PlaneEvaluator pe(tape, l, opt, out);
  const int tilesX = (l.width + kTopTile - 1) / kTopTile, tilesY = (l.height + kTopTile - 1) / kTopTile;
  tbb::enumerable_thread_specific<PlaneWorker> workers;
  parallelChunks(size_t(tilesX) * size_t(tilesY), 1, opt.threads, [&](size_t b, size_t e) {
    PlaneWorker& w = workers.local();
    for (size_t t = b; t < e; ++t) {
      const int tx = int(t % size_t(tilesX)), ty = int(t / size_t(tilesX));
      const int c0 = tx * kTopTile, r0 = ty * kTopTile;
      pe.tile(w, c0, std::min(c0 + kTopTile, l.width), r0, std::min(r0 + kTopTile, l.height), tape);
    }
  });
  if (stats) {
    *stats = {};
    for (const PlaneWorker& w : workers) {
      stats->pointEvals += w.stats.pointEvals;
      stats->intervalEvals += w.stats.intervalEvals;
      stats->intervalInstrs += w.stats.intervalInstrs;
      stats->tapeInstrs += w.stats.tapeInstrs;
      stats->tapeBatches += w.stats.tapeBatches;
      stats->decidedPixels += w.stats.decidedPixels;
      stats->floatPixels += w.stats.floatPixels;
      stats->doublePixels += w.stats.doublePixels;
    }
  }
  return out;
}

}  // namespace frep
