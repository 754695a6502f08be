// Quadtree evaluation of a plane lattice (see plane.h).
//
// The image is cut into fixed 128-pixel tiles (the parallel grain, independent of the thread
// count); each tile is classified by interval arithmetic over the box of its pixel centres,
// its tape pruned to what that box decided, and split in four until a tile holds at most one
// batch (16 x 16 pixels), which is evaluated with its pruned tape. Pixel coordinates are
// computed as origin + index * step, which is monotone in the index, so the box built from
// the first and last index contains every pixel's coordinate exactly.
#include "frep/sampling/plane.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "frep/evaluators/eval.h"
#include "sampling/parallel_chunks.h"

namespace frep {
namespace {

constexpr int kTopTile = 128;
// Tiles of at most kLeafTile^2 pixels are evaluated as one batch (8 x 8 leaves measured slower
// on Prospero, also with signOnly: the extra interval passes and prunes cost more than they save).
constexpr int kLeafTile = 16;
static_assert(kLeafTile * kLeafTile <= int(BatchEvaluator<double>::kBatch), "one batch per leaf tile");

struct PlaneWorker {
  IntervalEvaluator interval;
  BatchEvaluator<double> batch;
  std::vector<Interval> box;
  PlaneStats stats;
};

class PlaneEvaluator {
 public:
  PlaneEvaluator(const TapePtr& tape, const PlaneLattice& l, const PlaneOptions& opt, std::vector<double>& out)
      : l_(l), opt_(opt), out_(out), nvars_(std::max<uint32_t>(tape->numVars(), 1)) {}

  double colCoord(int c) const { return l_.origin[0] + double(c) * l_.step; }
  double rowCoord(int r) const { return l_.origin[1] + double(l_.height - 1 - r) * l_.step; }

  // Value of coordinate `var` other than u and v.
  double held(uint32_t var) const {
    if (int(var) == l_.normal) return l_.at;
    if (var >= 3 && var - 3 < l_.fixed.size()) return l_.fixed[var - 3];
    return 0.0;
  }

  // Pixels [c0, c1) x [r0, r1) with the tape that the enclosing tile decided.
  void tile(PlaneWorker& w, int c0, int c1, int r0, int r1, const TapePtr& tape) {
    w.box.resize(nvars_);
    for (uint32_t var = 0; var < nvars_; ++var) w.box[var] = Interval(held(var));
    if (l_.u < nvars_) w.box[l_.u] = Interval(colCoord(c0), colCoord(c1 - 1));
    if (l_.v < nvars_) w.box[l_.v] = Interval(rowCoord(r1 - 1), rowCoord(r0));
    ++w.stats.intervalEvals;
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
    TapePtr pruned = w.interval.pruned(tape);
    if (c1 - c0 <= kLeafTile && r1 - r0 <= kLeafTile) {
      leaf(w, c0, c1, r0, r1, *pruned);
      return;
    }
    const int cm = c1 - c0 > kLeafTile ? c0 + (c1 - c0 + 1) / 2 : c1;
    const int rm = r1 - r0 > kLeafTile ? r0 + (r1 - r0 + 1) / 2 : r1;
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
      std::fill(w.batch.in(var), w.batch.in(var) + n, held(var));
    }
    size_t k = 0;
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c, ++k) {
        if (l_.u < tape.numVars()) w.batch.in(l_.u)[k] = colCoord(c);
        if (l_.v < tape.numVars()) w.batch.in(l_.v)[k] = rowCoord(r);
      }
    const double* f = w.batch.eval(tape, n);
    k = 0;
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c, ++k) out_[index(c, r)] = f[k];
    w.stats.pointEvals += n;
    w.stats.tapeInstrs += tape.size();
    ++w.stats.tapeBatches;
  }

  size_t index(int c, int r) const { return size_t(r) * size_t(l_.width) + size_t(c); }

 private:
  const PlaneLattice& l_;
  const PlaneOptions& opt_;
  std::vector<double>& out_;
  uint32_t nvars_;
};

}  // namespace

std::vector<double> evaluatePlane(const TapePtr& tape, const PlaneLattice& l, const PlaneOptions& opt,
                                  PlaneStats* stats) {
  if (l.width <= 0 || l.height <= 0) throw std::invalid_argument("evaluatePlane: image size must be positive");
  if (!(l.step > 0) || !std::isfinite(l.step)) throw std::invalid_argument("evaluatePlane: pixel step must be positive");
  if (l.u == l.v) throw std::invalid_argument("evaluatePlane: the image axes must differ");
  std::vector<double> out(size_t(l.width) * size_t(l.height));
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
      stats->tapeInstrs += w.stats.tapeInstrs;
      stats->tapeBatches += w.stats.tapeBatches;
      stats->decidedPixels += w.stats.decidedPixels;
    }
  }
  return out;
}

}  // namespace frep
