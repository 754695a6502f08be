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
  double n[3], nn, na;  // its plane's normal (not unit), |n|^2 and n.v[0]: a cheaper lower bound
};

// The triangles of the cells that have some, and where each cell's are, by the cell's low
// corner's index in the halo field (-1: none). Thread's arrays, kept -1 between calls.
struct CellTriangles {
  std::vector<int32_t> first;  // index into range
  std::vector<uint64_t> rows;  // per row of cells along z (x, y), a bit per cell that has some
  struct Range {
    uint32_t first, count;
    double lo[3], hi[3];  // the box of its triangles
  };
  std::vector<Range> range;
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
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  t.n[0] = u[1] * w[2] - u[2] * w[1];
  t.n[1] = u[2] * w[0] - u[0] * w[2];
  t.n[2] = u[0] * w[1] - u[1] * w[0];
  t.nn = t.n[0] * t.n[0] + t.n[1] * t.n[1] + t.n[2] * t.n[2];
  t.na = t.n[0] * a[0] + t.n[1] * a[1] + t.n[2] * a[2];
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

// A row of cells along z at offset (x, y) from a voxel, and the squared distance from the voxel
// to the row's slab in x and y: a lower bound of its cells' triangles' distances.
struct RowOffset {
  int x, y, gap2;
};

int gap(int o) { return o > 0 ? o : (o + 1 < 0 ? -(o + 1) : 0); }  // to a cell at offset o

// The rows of the cells whose box lies within `band` voxels of a voxel, nearest first.
std::vector<RowOffset> rowOffsets(int band) {
  std::vector<RowOffset> out;
  for (int x = -band; x < band; ++x)
    for (int y = -band; y < band; ++y) {
      const int g2 = gap(x) * gap(x) + gap(y) * gap(y);
      if (g2 < band * band) out.push_back({x, y, g2});
    }
  std::stable_sort(out.begin(), out.end(), [](const RowOffset& a, const RowOffset& b) { return a.gap2 < b.gap2; });
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
  const int64_t words = (f.n[2] + 63) / 64;  // per row of cells along z: a bit per cell with triangles
  if (cells.first.size() < size) cells.first.resize(size, -1);
  if (cells.rows.size() < size_t(f.n[0] * f.n[1] * words)) cells.rows.resize(size_t(f.n[0] * f.n[1] * words), 0);
  cells.range.clear();
  cells.triangles.clear();
  std::vector<int64_t> built;  // cells.first's entries to clear
  struct Clean {
    CellTriangles& c;
    std::vector<int64_t>& built;
    int64_t s1, words;
    ~Clean() {
      for (int64_t p : built) {
        c.first[size_t(p)] = -1;
        c.rows[size_t(p / s1 * words + p % s1 / 64)] = 0;
      }
    }
  } clean{cells, built, f.s1, words};
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
    CellTriangles::Range range{uint32_t(before), uint32_t(cells.triangles.size() - before), {1, 1, 1}, {0, 0, 0}};
    for (size_t t = before; t < cells.triangles.size(); ++t)
      for (int a = 0; a < 3; ++a) {
        range.lo[a] = std::min(range.lo[a], cells.triangles[t].lo[a]);
        range.hi[a] = std::max(range.hi[a], cells.triangles[t].hi[a]);
      }
    cells.range.push_back(range);
    cells.rows[size_t(p / f.s1 * words + (p % f.s1) / 64)] |= uint64_t(1) << (p % f.s1 % 64);
    built.push_back(p);
  }

  // Each evaluated voxel of the region: the nearest triangle among the cells nearer than the
  // band, nearest cells first, stopping at the first cell whose box is no nearer than the best
  // triangle so far (a fixed order from the voxel's neighbourhood alone: the same bytes in any
  // brick; the minimum is exact in any order).
  const std::vector<RowOffset> offsets = rowOffsets(W);
  std::vector<int> zOrder;  // the offsets along z of the cells within the band, nearest first
  for (int k = 0; k < W; ++k) zOrder.insert(zOrder.end(), {k, -k - 1});
  const float background = float(W * grid.voxel);
  const double h = grid.voxel;
  const Triangle* triangles = cells.triangles.data();
  // The triangles of the cell at offset o from the voxel, against the best so far.
  auto cell = [&](int64_t p, const int* o, double& best) {
    const CellTriangles::Range& range = cells.range[size_t(cells.first[size_t(p)])];
    double cell2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double lo = o[a] + range.lo[a], hi = o[a] + range.hi[a];
      const double g = lo > 0 ? lo : (hi < 0 ? -hi : 0.0);
      cell2 += g * g;
    }
    if (cell2 >= best) return;
    for (uint32_t t = range.first; t < range.first + range.count; ++t) {
      const Triangle& tri = triangles[t];
      double box2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double lo = o[a] + tri.lo[a], hi = o[a] + tri.hi[a];
        const double g = lo > 0 ? lo : (hi < 0 ? -hi : 0.0);
        box2 += g * g;
      }
      if (box2 >= best) continue;
      // The distance to its plane, no more than to it (a degenerate triangle has none).
      const double plane = tri.n[0] * o[0] + tri.n[1] * o[1] + tri.n[2] * o[2] + tri.na;
      if (tri.nn > 0 && plane * plane >= best * tri.nn) continue;
      double v[3][3];
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) v[k][a] = o[a] + tri.v[k][a];
      best = std::min(best, triangle2(v[0], v[1], v[2]));
    }
  };
  auto leafDistance = [&](LeafBlock& l) {
    for (int n = 0; n < kLeafVoxels; ++n) {
      if (!l.isActive(n)) continue;
      const int64_t c[3] = {l.origin[0] + (n >> 6), l.origin[1] + ((n >> 3) & 7), l.origin[2] + (n & 7)};
      if (c[0] >= f.coreHi[0] || c[1] >= f.coreHi[1] || c[2] >= f.coreHi[2]) continue;
      double best = double(W) * double(W);
      // Rows nearest first; in a row, its cells with triangles nearest first.
      const int64_t zlo = std::max(c[2] - W, f.lo[2]) - f.lo[2], zhi = std::min(c[2] + W - 1, f.hi[2] - 2) - f.lo[2];
      const int64_t cz = c[2] - f.lo[2];
      for (const RowOffset& r : offsets) {
        if (double(r.gap2) >= best) break;
        const int64_t x = c[0] + r.x, y = c[1] + r.y;
        if (x < f.lo[0] || y < f.lo[1] || x + 1 >= f.hi[0] || y + 1 >= f.hi[1]) continue;
        const int64_t row = (x - f.lo[0]) * f.s0 + (y - f.lo[1]) * f.s1;
        const uint64_t* bits = cells.rows.data() + size_t(row / f.s1 * words);
        bool any = false;
        for (int64_t wz = zlo / 64; wz <= zhi / 64 && !any; ++wz) {
          uint64_t b = bits[wz];
          if (wz == zlo / 64) b &= ~uint64_t(0) << (zlo % 64);
          if (wz == zhi / 64 && zhi % 64 != 63) b &= (uint64_t(1) << (zhi % 64 + 1)) - 1;
          any = b != 0;
        }
        if (!any) continue;
        for (const int oz : zOrder) {  // gaps 0, 0, 1, 1, 2, 2, ...
          if (double(r.gap2 + gap(oz) * gap(oz)) >= best) break;
          const int64_t z = cz + oz;
          if (z < zlo || z > zhi || !((bits[z / 64] >> (z % 64)) & 1)) continue;
          const int o[3] = {r.x, r.y, oz};
          cell(row + z, o, best);
        }
      }
      const float d = float(std::sqrt(best) * h);
      const bool inside = insideValue(l.values[size_t(n)]);
      detail::storeBandDistance(l, n, d, inside, background);
    }
  };
  // Leaves in parallel (in-process runs sample a brick on every core): each writes only its own
  // values and reads the cells, so the result does not depend on the threads.
  parallelChunks(r.leaves.size(), 16, opt.threads, [&](size_t first, size_t last) {
    for (size_t li = first; li != last; ++li) leafDistance(r.leaves[li]);
  });
}

}  // namespace frep
