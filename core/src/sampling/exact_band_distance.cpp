// The exact distance to the samples' piecewise-linear zero set in a sampled region's band (see
// exact_band_distance.h).
#include "frep/sampling/exact_band_distance.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "sampling/halo_field.h"
#include "sampling/parallel_chunks.h"

namespace frep {
namespace {

// A triangle of a cell's zero set in the cell's own coordinates ([0, 1]^3 from its low corner:
// the same numbers in whichever brick builds it), with its bounding box.
struct Triangle {
  double v[3][3];
  double lo[3], hi[3];
};

// The triangles of the cells that have some, and where each cell's are, by the cell's low
// corner's index in the halo field (-1: none). Thread's arrays, kept -1 between calls.
struct CellTriangles {
  std::vector<int32_t> first;  // index into range
  std::vector<std::array<uint32_t, 2>> range;
  std::vector<Triangle> triangles;
};

// Cell corner k sits at (k >> 2, (k >> 1) & 1, k & 1). Kuhn's tetrahedra: the paths from
// corner 0 to corner 7 along one axis at a time.
constexpr int kKuhn[6][4] = {{0, 4, 6, 7}, {0, 4, 5, 7}, {0, 2, 6, 7}, {0, 2, 3, 7}, {0, 1, 5, 7}, {0, 1, 3, 7}};

// The zero of the linear interpolant on the edge between corners a and b of opposite signs,
// always from the lower corner index: the same point from every tetrahedron sharing the edge.
void edgePoint(int a, int b, const float* q, double* p) {
  if (a > b) std::swap(a, b);
  const double qa = q[a], qb = q[b];
  const double t = qa / (qa - qb);  // in [0, 1]: qa, qb of opposite signs (insideValue)
  for (int ax = 0; ax < 3; ++ax) {
    const double ca = (a >> (2 - ax)) & 1, cb = (b >> (2 - ax)) & 1;
    p[ax] = ca + t * (cb - ca);
  }
}

void addTriangle(const double* a, const double* b, const double* c, std::vector<Triangle>& out) {
  Triangle t;
  for (int ax = 0; ax < 3; ++ax) {
    t.v[0][ax] = a[ax], t.v[1][ax] = b[ax], t.v[2][ax] = c[ax];
    t.lo[ax] = std::min(std::min(a[ax], b[ax]), c[ax]);
    t.hi[ax] = std::max(std::max(a[ax], b[ax]), c[ax]);
  }
  out.push_back(t);
}

// The zero set of f linear on each Kuhn tetrahedron of a cell with corner values q (no NaN):
// a triangle where one corner differs in sign from the other three, two where two do.
void triangulateCell(const float* q, std::vector<Triangle>& out) {
  for (const auto& tet : kKuhn) {
    int in[4], out_[4], nin = 0, nout = 0;
    for (int k : tet) {
      if (insideValue(q[k])) in[nin++] = k;
      else out_[nout++] = k;
    }
    double p[4][3];
    if (nin == 1 || nin == 3) {
      const int lone = nin == 1 ? in[0] : out_[0];
      const int* rest = nin == 1 ? out_ : in;
      for (int k = 0; k < 3; ++k) edgePoint(lone, rest[k], q, p[k]);
      addTriangle(p[0], p[1], p[2], out);
    } else if (nin == 2) {
      // The quadrilateral in[0]-out[0], in[0]-out[1], in[1]-out[1], in[1]-out[0], as two triangles.
      edgePoint(in[0], out_[0], q, p[0]);
      edgePoint(in[0], out_[1], q, p[1]);
      edgePoint(in[1], out_[1], q, p[2]);
      edgePoint(in[1], out_[0], q, p[3]);
      addTriangle(p[0], p[1], p[2], out);
      addTriangle(p[0], p[2], p[3], out);
    }
  }
}

double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Squared distance from the origin to segment ab.
double segment2(const double* a, const double* b) {
  const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double len2 = dot(ab, ab);
  double t = len2 > 0 ? -dot(a, ab) / len2 : 0.0;
  t = std::min(1.0, std::max(0.0, t));
  const double p[3] = {a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]};
  return dot(p, p);
}

// Squared distance from the origin to triangle abc: the closest point by the triangle's Voronoi
// regions (Ericson, Real-Time Collision Detection, 5.1.5), the edges for a degenerate triangle.
double triangle2(const double* a, const double* b, const double* c) {
  const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double d1 = -dot(ab, a), d2 = -dot(ac, a);
  if (d1 <= 0 && d2 <= 0) return dot(a, a);
  const double d3 = -dot(ab, b), d4 = -dot(ac, b);
  if (d3 >= 0 && d4 <= d3) return dot(b, b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return segment2(a, b);
  const double d5 = -dot(ab, c), d6 = -dot(ac, c);
  if (d6 >= 0 && d5 <= d6) return dot(c, c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return segment2(a, c);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return segment2(b, c);
  const double sum = va + vb + vc;
  if (!(sum > 0)) return std::min(std::min(segment2(a, b), segment2(a, c)), segment2(b, c));
  const double v = vb / sum, w = vc / sum;
  const double p[3] = {a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w};
  return dot(p, p);
}

// A cell at integer offset o from a voxel (its low corner minus the voxel), and the squared
// distance from the voxel to the cell's box: a lower bound of its triangles' distances.
struct CellOffset {
  int o[3];
  int gap2;
};

// The cells whose box lies within `band` voxels of a voxel, nearest first.
std::vector<CellOffset> cellOffsets(int band) {
  std::vector<CellOffset> out;
  for (int x = -band; x < band; ++x)
    for (int y = -band; y < band; ++y)
      for (int z = -band; z < band; ++z) {
        auto gap = [](int o) { return o > 0 ? o : (o + 1 < 0 ? -(o + 1) : 0); };
        const int g2 = gap(x) * gap(x) + gap(y) * gap(y) + gap(z) * gap(z);
        if (g2 < band * band) out.push_back({{x, y, z}, g2});
      }
  std::stable_sort(out.begin(), out.end(), [](const CellOffset& a, const CellOffset& b) { return a.gap2 < b.gap2; });
  return out;
}

}  // namespace

std::string exactBandDistanceBound() {
  return "exact distance to the piecewise-linear zero set of the samples (f linear on the 6 Kuhn tetrahedra of each "
         "lattice cell), up to rounding (double, stored as float); from the true surface f = 0 it differs by that "
         "interpolation's error: second order in the voxel where f is smooth, up to about a voxel at edges and "
         "corners sharper than the lattice";
}

void exactBandDistance(const TapePtr& tape, const GridSpec& grid, const SampleOptions& opt, SampleResult& r,
                       BandDistanceStats* stats) {
  if (opt.bandVoxels < 1) throw std::invalid_argument("exactBandDistance: the band must be at least 1 voxel");
  BandDistanceStats local;
  BandDistanceStats& st = stats ? *stats : local;
  if (r.leaves.empty()) return;  // tiles only: every point further than the band from a zero
  // Why a halo of the band's width W suffices: a point of the zero set nearer than W voxels to
  // a voxel v lies in a cell whose box is nearer than W, so its low corner is within [v - W,
  // v + W - 1] and all its corners within W voxels of v along each axis: inside the halo of
  // v's brick, sampled there as every brick samples it. So the minimum over the triangles of
  // those cells is the distance to the whole piecewise-linear zero set wherever that is below
  // W, and the stored value is the band's background wherever it is not. A cell with an
  // unevaluated corner has none: that corner's certified sign holds over its band, which holds
  // the cell's other corners, so the cell has no sign change (or a NaN sample, left out).
  const int W = opt.bandVoxels;
  const detail::HaloField f(tape, grid, opt, r, W, st);
  const float* value = f.values();

  thread_local CellTriangles threadCells;
  CellTriangles& cells = threadCells;  // this thread's, also in the loop below on TBB's threads
  const size_t size = size_t(f.n[0] * f.n[1] * f.n[2]);
  if (cells.first.size() < size) cells.first.resize(size, -1);
  cells.range.clear();
  cells.triangles.clear();
  std::vector<int64_t> built;  // cells.first's entries to clear
  struct Clean {
    CellTriangles& c;
    std::vector<int64_t>& built;
    ~Clean() {
      for (int64_t p : built) c.first[size_t(p)] = -1;
    }
  } clean{cells, built};
  const int64_t corner[8] = {0, 1, f.s1, f.s1 + 1, f.s0, f.s0 + 1, f.s0 + f.s1, f.s0 + f.s1 + 1};
  for (int64_t p : f.evaluated()) {
    const int64_t i = f.lo[0] + p / f.s0, j = f.lo[1] + (p % f.s0) / f.s1, k = f.lo[2] + p % f.s1;
    if (i + 1 >= f.hi[0] || j + 1 >= f.hi[1] || k + 1 >= f.hi[2]) continue;  // no cell in the box
    float q[8];
    bool complete = true;
    int inside = 0;
    for (int c = 0; c < 8; ++c) {
      q[c] = value[size_t(p + corner[c])];
      complete = complete && !std::isnan(q[c]);
      inside += insideValue(q[c]);
    }
    if (!complete || inside == 0 || inside == 8) continue;
    const size_t before = cells.triangles.size();
    triangulateCell(q, cells.triangles);
    cells.first[size_t(p)] = int32_t(cells.range.size());
    cells.range.push_back({uint32_t(before), uint32_t(cells.triangles.size() - before)});
    built.push_back(p);
  }

  // Each evaluated voxel of the region: the nearest triangle among the cells nearer than the
  // band, nearest cells first, stopping at the first cell whose box is no nearer than the best
  // triangle so far (a fixed order from the voxel's neighbourhood alone: the same bytes in any
  // brick; the minimum is exact in any order).
  const std::vector<CellOffset> offsets = cellOffsets(W);
  const float background = float(W * grid.voxel);
  const double h = grid.voxel;
  const Triangle* triangles = cells.triangles.data();
  auto leafDistance = [&](LeafBlock& l) {
    for (int n = 0; n < kLeafVoxels; ++n) {
      if (!l.isActive(n)) continue;
      const int64_t c[3] = {l.origin[0] + (n >> 6), l.origin[1] + ((n >> 3) & 7), l.origin[2] + (n & 7)};
      if (c[0] >= f.coreHi[0] || c[1] >= f.coreHi[1] || c[2] >= f.coreHi[2]) continue;
      double best = double(W) * double(W);
      for (const CellOffset& o : offsets) {
        if (double(o.gap2) >= best) break;
        const int64_t x = c[0] + o.o[0], y = c[1] + o.o[1], z = c[2] + o.o[2];
        if (x < f.lo[0] || y < f.lo[1] || z < f.lo[2] || x + 1 >= f.hi[0] || y + 1 >= f.hi[1] || z + 1 >= f.hi[2])
          continue;
        const int32_t id = cells.first[size_t(f.at(x, y, z))];
        if (id < 0) continue;
        const auto [first, count] = cells.range[size_t(id)];
        for (uint32_t t = first; t < first + count; ++t) {
          const Triangle& tri = triangles[t];
          double box2 = 0;
          for (int a = 0; a < 3; ++a) {
            const double lo = o.o[a] + tri.lo[a], hi = o.o[a] + tri.hi[a];
            const double g = lo > 0 ? lo : (hi < 0 ? -hi : 0.0);
            box2 += g * g;
          }
          if (box2 >= best) continue;
          double v[3][3];
          for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) v[k][a] = o.o[a] + tri.v[k][a];
          best = std::min(best, triangle2(v[0], v[1], v[2]));
        }
      }
      const uint64_t bit = uint64_t(1) << (n & 63);
      const float d = float(std::sqrt(best) * h);
      const bool inside = insideValue(l.values[size_t(n)]);
      if (d < background) {
        // An outside voxel keeps its sign (sample.h storedValue): never -0.
        l.values[size_t(n)] = inside ? d : (d > 0 ? -d : -std::numeric_limits<float>::denorm_min());
      } else {
        l.values[size_t(n)] = inside ? background : -background;
        l.active[size_t(n >> 6)] &= ~bit;
      }
    }
  };
  // Leaves in parallel (in-process runs sample a brick on every core): each writes only its own
  // values and reads the cells, so the result does not depend on the threads.
  parallelChunks(r.leaves.size(), 16, opt.threads, [&](size_t first, size_t last) {
    for (size_t li = first; li != last; ++li) leafDistance(r.leaves[li]);
  });
}

}  // namespace frep
