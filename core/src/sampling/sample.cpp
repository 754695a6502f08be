// Sparse narrow-band sampling by recursive interval subdivision (see sample.h).
//
// The index space is covered by an octree of cubes whose sides are powers of two >= 8 voxels.
// A cube is classified with interval arithmetic over the box of grid points within bandVoxels
// of it (the "dilated" box): entirely positive -> inside tile, entirely negative -> outside
// tile, else it is split (its tape pruned to what the box decided). An 8^3 leaf is split once
// more into 4^3 and then (SampleOptions::leafBlock 2) 2^3 blocks; only points of the smallest
// blocks that stay ambiguous are evaluated (one batch per leaf, with the leaf's pruned tape).
// Values never depend on the pruning (a pruned tape is bit-identical to the full tape inside its
// box), and the leaf-level decisions only depend on the leaf's own boxes, so results are
// deterministic for any thread count.
#include "frep/sampling/sample.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "frep/evaluators/eval.h"
#include "sampling/parallel_chunks.h"

namespace frep {

GridSpec GridSpec::fromBounds(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int n) {
  if (n < 2) throw std::invalid_argument("grid resolution must be >= 2");
  double longest = 0;
  for (int a = 0; a < 3; ++a) {
    if (!(hi[a] > lo[a])) throw std::invalid_argument("bounds: max must exceed min on every axis");
    longest = std::max(longest, hi[a] - lo[a]);
  }
  GridSpec g;
  g.voxel = longest / double(n - 1);
  for (int a = 0; a < 3; ++a) {
    g.origin[a] = lo[a];
    g.dims[a] = static_cast<int32_t>(std::floor((hi[a] - lo[a]) / g.voxel + 1e-9)) + 1;
  }
  return g;
}

namespace {

using Box3 = std::array<int64_t, 6>;  // inclusive point-index box: lo x,y,z, hi x,y,z

struct Worker {
  IntervalEvaluator interval;
  BatchEvaluator<double> batch;
  std::vector<Interval> box;
  std::vector<LeafBlock> leaves;
  std::vector<Tile> tiles;
  SampleStats stats;
};

class Sampler {
 public:
  Sampler(const TapePtr& tape, const GridSpec& grid, const SampleOptions& opt)
      : tape_(tape), grid_(grid), opt_(opt), nvars_(tape->numVars()) {
    if (grid.dims[0] <= 0 || grid.dims[1] <= 0 || grid.dims[2] <= 0)
      throw std::invalid_argument("sample: grid dimensions must be positive");
    if (!(grid.voxel > 0)) throw std::invalid_argument("sample: voxel size must be positive");
    if (opt.bandVoxels < 0) throw std::invalid_argument("sample: band must be >= 0 voxels");
    if (opt.leafBlock != 2 && opt.leafBlock != 4)
      throw std::invalid_argument("sample: leafBlock must be 2 or 4 voxels, got " + std::to_string(opt.leafBlock));
    if (nvars_ > 3 && opt.fixedCoords.size() < nvars_ - 3)
      throw std::invalid_argument("sample: model has " + std::to_string(nvars_) +
                                  " coordinates; give values for x[4..] (fixedCoords)");
    for (int a = 0; a < 3; ++a) {
      lo_[a] = opt.regionLo[a];
      hi_[a] = opt.regionHi[a] < 0 ? grid.dims[a] : std::min(opt.regionHi[a], grid.dims[a]);
      if (lo_[a] % kLeafDim != 0) throw std::invalid_argument("sample: region must start on a multiple of 8");
      if (lo_[a] < 0 || lo_[a] >= hi_[a]) throw std::invalid_argument("sample: empty region");
    }
    background_ = float(opt.bandVoxels * grid.voxel);
    // Outside points the band decided: -background, or with a band of 0 the negative float
    // nearest 0 (-0 would read as inside: sample.h insideValue).
    outsideValue_ = background_ > 0 ? -background_ : -std::numeric_limits<float>::denorm_min();
  }

  SampleResult run() {
    InterruptScope scope(InterruptScope::choose(opt_.interrupt));
    // Level 1 (serial): descend to cubes of at most 32^3, collecting the ambiguous ones.
    int64_t side = kLeafDim;
    while (side < std::max({hi_[0] - lo_[0], hi_[1] - lo_[1], hi_[2] - lo_[2]})) side *= 2;
    Worker top;
    std::vector<std::pair<std::array<int64_t, 3>, TapePtr>> work;
    descend(top, {lo_[0], lo_[1], lo_[2]}, side, tape_, work);

    // Level 2 (parallel): each work cube independently down to the voxels.
    tbb::enumerable_thread_specific<Worker> workers;
    std::atomic<uint64_t> cubesDone{0};
    parallelChunks(work.size(), 1, opt_.threads, [&](size_t b, size_t e) {
      Worker& w = workers.local();
      for (size_t i = b; i != e; ++i) {
        cube(w, work[i].first, kWorkSide, work[i].second);
        reportProgress("sample", ++cubesDone, work.size());  // a chunk is all cubes when serial
      }
    });

    SampleResult res;
    res.grid = grid_;
    res.bandVoxels = opt_.bandVoxels;
    auto addStats = [&](const SampleStats& s) {
      res.stats.pointEvals += s.pointEvals;
      res.stats.intervalEvals += s.intervalEvals;
      res.stats.nanValues += s.nanValues;
      res.stats.domainErrors.add(s.domainErrors);
      res.stats.tapeInstrs += s.tapeInstrs;
      res.stats.tapeBatches += s.tapeBatches;
    };
    addStats(top.stats);
    res.tiles = std::move(top.tiles);
    for (auto& w : workers) {
      addStats(w.stats);
      res.leaves.insert(res.leaves.end(), std::make_move_iterator(w.leaves.begin()),
                        std::make_move_iterator(w.leaves.end()));
      res.tiles.insert(res.tiles.end(), w.tiles.begin(), w.tiles.end());
    }
    res.stats.denseEvals = uint64_t(hi_[0] - lo_[0]) * uint64_t(hi_[1] - lo_[1]) * uint64_t(hi_[2] - lo_[2]);
    sortByOrigin(res.leaves, res.tiles);
    return res;
  }

 private:
  static constexpr int64_t kWorkSide = 32;

  // Interval of f over the grid points of box b (inclusive indices), dilated by the band. A
  // cube of a leaf or more (`cells`) also covers the far corners of its cells where the band
  // does not: with SampleOptions::tilesCoverCells a tile's sign then holds on every corner of
  // its cells, so a cell whose corners change sign always starts in a leaf (the mesher visits
  // the cells of leaves only; without this, two tiles of opposite signs left a hole between).
  Interval evalBox(Worker& w, const Box3& b, const Tape& tape, bool cells = true) {
    const int64_t d = opt_.bandVoxels;
    const int64_t dHi = cells && opt_.tilesCoverCells ? std::max<int64_t>(d, 1) : d;
    w.box.resize(std::max<size_t>(nvars_, 1));
    for (uint32_t v = 0; v < nvars_; ++v) {
      if (v < 3) {
        double l = grid_.origin[v] + double(b[v] - d) * grid_.voxel;
        double h = grid_.origin[v] + double(b[v + 3] + dHi) * grid_.voxel;
        w.box[v] = Interval(l, h);
      } else {
        w.box[v] = Interval(opt_.fixedCoords[v - 3]);
      }
    }
    ++w.stats.intervalEvals;
    // Signs only: a box an extremum bound leaves undecided within its budget has its points
    // searched (sign-only searches are cheap), with the same signs as a longer bound would give.
    w.interval.setExtremumBudgetOnly(opt_.pointwiseSearches && opt_.extremumSignsOnly);
    return w.interval.eval(tape, w.box.data());
  }

  // Clipped inclusive box of cube (o, s) against the region; false if empty.
  bool clip(const std::array<int64_t, 3>& o, int64_t s, Box3& b) const {
    for (int a = 0; a < 3; ++a) {
      b[a] = std::max<int64_t>(o[a], lo_[a]);
      b[a + 3] = std::min<int64_t>(o[a] + s, hi_[a]) - 1;
      if (b[a] > b[a + 3]) return false;
    }
    return true;
  }

  static int sideClass(const Interval& iv) {
    if (iv.lo > 0) return 1;
    if (iv.hi < 0) return -1;
    return 0;
  }

  void descend(Worker& w, const std::array<int64_t, 3>& o, int64_t s, const TapePtr& tape,
               std::vector<std::pair<std::array<int64_t, 3>, TapePtr>>& work) {
    Box3 b;
    if (!clip(o, s, b)) return;
    Interval iv = evalBox(w, b, *tape);
    int c = sideClass(iv);
    if (c != 0) {
      w.tiles.push_back(Tile{{int32_t(o[0]), int32_t(o[1]), int32_t(o[2])}, int32_t(s), c > 0});
      return;
    }
    TapePtr pruned = w.interval.pruned(tape);
    if (s <= kWorkSide) {
      work.emplace_back(o, pruned);
      return;
    }
    int64_t h = s / 2;
    for (int i = 0; i < 8; ++i)
      descend(w, {o[0] + ((i >> 2) & 1) * h, o[1] + ((i >> 1) & 1) * h, o[2] + (i & 1) * h}, h, pruned, work);
  }

  // Cube already known to be ambiguous at its parent; classify and recurse to leaves.
  void cube(Worker& w, const std::array<int64_t, 3>& o, int64_t s, const TapePtr& tape) {
    if (s == kLeafDim) {
      leaf(w, o, tape);
      return;
    }
    int64_t h = s / 2;
    for (int i = 0; i < 8; ++i) {
      std::array<int64_t, 3> co{o[0] + ((i >> 2) & 1) * h, o[1] + ((i >> 1) & 1) * h, o[2] + (i & 1) * h};
      Box3 b;
      if (!clip(co, h, b)) continue;
      Interval iv = evalBox(w, b, *tape);
      int c = sideClass(iv);
      if (c != 0) {
        w.tiles.push_back(Tile{{int32_t(co[0]), int32_t(co[1]), int32_t(co[2])}, int32_t(h), c > 0});
        continue;
      }
      cube(w, co, h, w.interval.pruned(tape));
    }
  }

  // One 8^3 leaf: classify 4^3 blocks and (leafBlock 2) their 2^3 blocks, evaluate the points of
  // the smallest ambiguous ones.
  void leaf(Worker& w, const std::array<int64_t, 3>& o, const TapePtr& tape) {
    Box3 lb;
    if (!clip(o, kLeafDim, lb)) return;
    Interval liv = evalBox(w, lb, *tape);
    int lc = sideClass(liv);
    if (lc != 0) {
      w.tiles.push_back(Tile{{int32_t(o[0]), int32_t(o[1]), int32_t(o[2])}, kLeafDim, lc > 0});
      return;
    }
    TapePtr leafTape = w.interval.pruned(tape);

    LeafBlock blk;
    blk.origin = {int32_t(o[0]), int32_t(o[1]), int32_t(o[2])};
    blk.active.fill(0);
    // Sign of each voxel as decided by a sub-block (+1/-1), 0 = evaluate.
    std::array<int8_t, kLeafVoxels> sign;
    sign.fill(-1);
    std::array<uint16_t, kLeafVoxels> todo;
    size_t ntodo = 0;
    auto fillSign = [&](int x0, int y0, int z0, int n, int8_t sg) {
      for (int x = x0; x < x0 + n; ++x)
        for (int y = y0; y < y0 + n; ++y)
          for (int z = z0; z < z0 + n; ++z) sign[leafOffset(x, y, z)] = sg;
    };
    for (int q = 0; q < 8; ++q) {
      int qx = ((q >> 2) & 1) * 4, qy = ((q >> 1) & 1) * 4, qz = (q & 1) * 4;
      Box3 qb;
      if (!clip({o[0] + qx, o[1] + qy, o[2] + qz}, 4, qb)) continue;
      int qc = sideClass(evalBox(w, qb, *leafTape, false));  // point signs only
      if (qc != 0) {
        fillSign(qx, qy, qz, 4, int8_t(qc));
        continue;
      }
      if (opt_.leafBlock == 4) {
        addPoints(o, qb, sign, todo.data(), ntodo);
        continue;
      }
      for (int e = 0; e < 8; ++e) {
        int ex = qx + ((e >> 2) & 1) * 2, ey = qy + ((e >> 1) & 1) * 2, ez = qz + (e & 1) * 2;
        Box3 eb;
        if (!clip({o[0] + ex, o[1] + ey, o[2] + ez}, 2, eb)) continue;
        int ec = sideClass(evalBox(w, eb, *leafTape, false));
        if (ec != 0) {
          fillSign(ex, ey, ez, 2, int8_t(ec));
          continue;
        }
        addPoints(o, eb, sign, todo.data(), ntodo);
      }
    }
    for (int i = 0; i < kLeafVoxels; ++i) blk.values[i] = sign[i] > 0 ? background_ : outsideValue_;
    evaluatePoints(w, blk, *leafTape, todo.data(), ntodo);
    w.leaves.push_back(blk);
  }

  // The points of block b (inclusive indices) of the leaf at o, to be evaluated.
  static void addPoints(const std::array<int64_t, 3>& o, const Box3& b, std::array<int8_t, kLeafVoxels>& sign,
                        uint16_t* todo, size_t& ntodo) {
    for (int64_t x = b[0]; x <= b[3]; ++x)
      for (int64_t y = b[1]; y <= b[4]; ++y)
        for (int64_t z = b[2]; z <= b[5]; ++z) {
          const int off = leafOffset(int(x - o[0]), int(y - o[1]), int(z - o[2]));
          sign[size_t(off)] = 0;
          todo[ntodo++] = uint16_t(off);
        }
  }

  void evaluatePoints(Worker& w, LeafBlock& blk, const Tape& tape, const uint16_t* todo, size_t n) {
    constexpr size_t B = BatchEvaluator<double>::kBatch;
    w.batch.reserve(tape);
    w.batch.countDomainErrors(&w.stats.domainErrors);
    w.batch.setExtremumWarmStarts(!opt_.pointwiseSearches);
    w.batch.setExtremumSignsOnly(opt_.pointwiseSearches && opt_.extremumSignsOnly);
    w.batch.setFieldSignsOnly(opt_.fieldSignsOnly);
    for (size_t start = 0; start < n; start += B) {
      size_t count = std::min(B, n - start);
      for (size_t k = 0; k < count; ++k) {
        int off = todo[start + k];
        int64_t ijk[3] = {blk.origin[0] + (off >> 6), blk.origin[1] + ((off >> 3) & 7), blk.origin[2] + (off & 7)};
        for (uint32_t v = 0; v < nvars_; ++v)
          w.batch.in(v)[k] = v < 3 ? grid_.origin[v] + double(ijk[v]) * grid_.voxel : opt_.fixedCoords[v - 3];
      }
      const double* out = w.batch.eval(tape, count);
      for (size_t k = 0; k < count; ++k) {
        int off = todo[start + k];
        double f = out[k];
        if (std::isnan(f)) {
          ++w.stats.nanValues;
          blk.values[off] = outsideValue_;
          continue;
        }
        blk.values[off] = storedValue(f);  // the class of f, also for tiny negatives
        blk.active[off >> 6] |= uint64_t(1) << (off & 63);
      }
      w.stats.pointEvals += count;
      w.stats.tapeInstrs += tape.size();
      ++w.stats.tapeBatches;
    }
  }

  TapePtr tape_;
  GridSpec grid_;
  SampleOptions opt_;
  uint32_t nvars_;
  int64_t lo_[3], hi_[3];
  float background_, outsideValue_;
};

}  // namespace

void sortByOrigin(std::vector<LeafBlock>& leaves, std::vector<Tile>& tiles) {
  std::vector<uint32_t> order(leaves.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return leaves[a].origin < leaves[b].origin; });
  std::vector<LeafBlock> sorted;
  sorted.reserve(leaves.size());
  for (uint32_t i : order) sorted.push_back(leaves[i]);
  leaves.swap(sorted);
  std::sort(tiles.begin(), tiles.end(), [](const Tile& a, const Tile& b) { return a.origin < b.origin; });
}

SampleResult sample(const TapePtr& tape, const GridSpec& grid, const SampleOptions& options) {
  return Sampler(tape, grid, options).run();
}

double insideVolume(const SampleResult& r) {
  const GridSpec& g = r.grid;
  uint64_t inside = 0;
  for (const Tile& t : r.tiles) {
    if (!t.inside) continue;
    uint64_t n = 1;
    for (int a = 0; a < 3; ++a) n *= uint64_t(std::max(0, std::min(t.origin[a] + t.size, g.dims[a]) - t.origin[a]));
    inside += n;
  }
  for (const LeafBlock& l : r.leaves)
    for (int x = 0; x < 8; ++x)
      for (int y = 0; y < 8; ++y)
        for (int z = 0; z < 8; ++z)
          if (l.origin[0] + x < g.dims[0] && l.origin[1] + y < g.dims[1] && l.origin[2] + z < g.dims[2] &&
              l.values[leafOffset(x, y, z)] >= 0)
            ++inside;
  return double(inside) * g.voxel * g.voxel * g.voxel;
}

unsigned facesReached(const TapePtr& tape, const GridSpec& grid, const std::vector<double>& fixedCoords,
                      int threads) {
  unsigned faces = 0;
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const int32_t layer = side ? grid.dims[a] - 1 : 0;
      SampleOptions opt;
      opt.bandVoxels = 0;
      opt.pointwiseSearches = true;  // a sign per point, as the mesher's
      opt.extremumSignsOnly = true;
      opt.fixedCoords = fixedCoords;
      opt.threads = threads;
      opt.regionLo[a] = layer - layer % kLeafDim;
      opt.regionHi[a] = layer + 1;
      const SampleResult r = sample(tape, grid, opt);
      bool reached = false;
      for (const Tile& t : r.tiles) reached = reached || (t.inside && t.origin[a] <= layer && layer < t.origin[a] + t.size);
      for (const LeafBlock& l : r.leaves) {
        if (reached || layer < l.origin[a] || layer >= l.origin[a] + kLeafDim) continue;
        for (int i = 0; i < kLeafVoxels && !reached; ++i) {
          const int local[3] = {i >> 6, (i >> 3) & 7, i & 7};
          bool inGrid = local[a] == layer - l.origin[a];
          for (int b = 0; b < 3; ++b) inGrid = inGrid && l.origin[b] + local[b] < grid.dims[b];
          reached = inGrid && insideValue(l.values[size_t(i)]);
        }
      }
      if (reached) faces |= 1u << (2 * a + side);
    }
  return faces;
}

double latticeVolume(const GridSpec& g, const std::function<bool(const std::array<double, 3>&)>& inside) {
  uint64_t count = 0;
  for (int i = 0; i < g.dims[0]; ++i)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int k = 0; k < g.dims[2]; ++k) count += inside(g.world(i, j, k));
  return double(count) * g.voxel * g.voxel * g.voxel;
}

}  // namespace frep
