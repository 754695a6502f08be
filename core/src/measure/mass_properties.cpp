// Certified mass properties by interval integration over an adaptive octree
// (mass_properties.h; docs/measure.md). Cells: inside/outside by interval evaluation (as frep
// relate and the mesher classify boxes), boundary leaves bounded between two polytopes
// box ∩ {L >= 0} ⊆ solid ∩ box ⊆ box ∩ {U >= 0} from a centred form (measure/cell_affine.h),
// surface area by the graph argument over the gradient cone. Refinement is global and
// greedy: each round splits the boundary leaves that contribute most to the widths.
#include "frep/measure/mass_properties.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "frep/evaluators/eval.h"
#include "measure/area_flux.h"
#include "measure/box_clip.h"
#include "measure/cell_affine.h"
#include "sampling/parallel_chunks.h"

namespace frep {

namespace {

using measure_detail::CellAffineEvaluator;
using measure_detail::HalfSpace;
using measure_detail::Moments;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kUlp = 0x1p-52;

enum : uint8_t { kUnknown = 0, kOutside = 1, kInside = 2, kBoundary = 3 };

struct Cell {
  double lo[3], hi[3];
  TapePtr tape;  // valid on the cell (pruned by its classification)
  int depth = 0;
  uint8_t cls = kUnknown;
  bool firstOrder = false;
  HalfSpace L, U;           // over y = x - centre: L(y) <= f(x) <= U(y)
  double vL = 0, vU = 0;    // volume of solid ∩ cell
  double n[3] = {0, 0, 0};  // unit mean gradient (0: none)
  double coneExcess = kInf; // (sec theta - 1) * shadow upper bound; +inf: no cone
  double shadowLo = 0;      // a lower bound of the area in the cell by itself
  double areaWidth = 0;     // the cell's share of the area bound's width (area_flux.h)
  double faceLo[6], faceHi[6];  // area of solid ∩ each face, from L and U (area_flux.h)

  void half(double h[3]) const {
    for (int i = 0; i < 3; ++i) h[i] = 0.5 * (hi[i] - lo[i]);
  }
  void centre(double c[3]) const {
    for (int i = 0; i < 3; ++i) c[i] = 0.5 * (lo[i] + hi[i]);
  }
};

// The gradient set of a cell as boxes, one per vertex of the base switches' cube (cell_affine.h):
// every gradient is in one of them.
struct VBox {
  double lo[3], hi[3];
};

struct Worker {
  IntervalEvaluator ie;
  CellAffineEvaluator ca;
  std::vector<VBox> boxes;
};

// Faces of the outer box that the cell lies on: bit 2 * axis + side.
unsigned outerFaces(const Cell& c, const Interval box[3]) {
  unsigned m = 0;
  for (int a = 0; a < 3; ++a) {
    if (c.lo[a] == box[a].lo) m |= 1u << (2 * a);
    if (c.hi[a] == box[a].hi) m |= 1u << (2 * a + 1);
  }
  return m;
}

void gradientVertices(const measure_detail::Row& row, std::vector<VBox>& out) {
  out.clear();
  if (row.zero) {
    out.push_back(VBox{{0, 0, 0}, {0, 0, 0}});
    return;
  }
  int nb = row.nBase;
  uint32_t mask[measure_detail::kMaxSwitches];
  for (int j = 0; j < row.n; ++j) mask[j] = row.mask[j];
  if (nb > 12) {  // each term on its own: a superset, 2^n <= 256 vertices
    nb = row.n;
    for (int j = 0; j < row.n; ++j) mask[j] = 1u << j;
  }
  for (uint32_t b = 0; b < (1u << nb); ++b) {
    VBox v;
    for (int i = 0; i < 3; ++i) {
      double lo = row.g[i].lo, hi = row.g[i].hi;
      for (int j = 0; j < row.n; ++j)
        if ((mask[j] & b) == mask[j]) lo += row.s[j][i].lo, hi += row.s[j][i].hi;
      v.lo[i] = lo;
      v.hi[i] = hi;
    }
    out.push_back(v);
  }
  // The sums above round to nearest: widen every box by a few ulps of its terms.
  for (VBox& v : out)
    for (int i = 0; i < 3; ++i) {
      double mag = std::fabs(row.g[i].lo) + std::fabs(row.g[i].hi);
      for (int j = 0; j < row.n; ++j) mag += std::fabs(row.s[j][i].lo) + std::fabs(row.s[j][i].hi);
      v.lo[i] -= 16.0 * kUlp * mag;
      v.hi[i] += 16.0 * kUlp * mag;
    }
}

// The cell's share of the area machinery (area_flux.h): the unit mean gradient n, the cone
// excess (sec theta - 1) * (shadow of the slab {L <= 0 <= U} along n), and a lower bound of the
// area by itself (the lines along n that cross from {U < 0} to {L > 0} in the cell each meet the
// surface, at distinct points).
void areaData(Cell& c, const double h[3], const std::vector<VBox>& boxes) {
  const double g2 = c.L.g[0] * c.L.g[0] + c.L.g[1] * c.L.g[1] + c.L.g[2] * c.L.g[2];
  if (!(g2 > 0.0)) return;
  const double len = std::sqrt(g2);
  for (int i = 0; i < 3; ++i) c.n[i] = c.L.g[i] / len;
  const HalfSpace& L = c.L;
  const HalfSpace& U = c.U;
  HalfSpace notL{-L.c, {-L.g[0], -L.g[1], -L.g[2]}};  // f may be <= 0
  HalfSpace notU{-U.c, {-U.g[0], -U.g[1], -U.g[2]}};  // f <= 0 for sure
  c.shadowLo = measure_detail::projectedOverlap(h, notU, L, c.n) * (1.0 - 1e-12);
  // Cone. The gradients lie in R0 + sum_j t_j R_j, t_j in [0, 1] (switch symbols, cell_affine.h):
  // for fixed t, in an interval box V_t; g . n and |g x n| are extreme at a vertex t of the cube
  // for fixed R's, so both are bounded over the vertices. In each box g = mid + d with |d| <= |rad|,
  // so |g x n| <= |mid x n| + |rad| and g . n >= mid . n - |rad|: for a smooth cell n = mid and
  // tan theta = O(h), sec theta - 1 = O(h^2); at an edge of the solid the two faces' normals.
  struct Vertex {
    double mid[3], rad;
  };
  std::vector<Vertex> vs(boxes.size());
  const int nv = int(boxes.size());
  for (int t = 0; t < nv; ++t) {
    double rad2 = 0.0;
    for (int i = 0; i < 3; ++i) {
      vs[size_t(t)].mid[i] = 0.5 * (boxes[size_t(t)].lo[i] + boxes[size_t(t)].hi[i]);
      const double r = std::max(boxes[size_t(t)].hi[i] - vs[size_t(t)].mid[i], vs[size_t(t)].mid[i] - boxes[size_t(t)].lo[i]);
      rad2 += r * r;
    }
    vs[size_t(t)].rad = std::sqrt(rad2);
  }
  // tan theta for the direction u (unit), +inf when some gradient may be at 90 degrees or more.
  auto tanOf = [&](const double u[3], int* worst) {
    double minDot = kInf, maxPerp = 0.0, worstCos = kInf;
    for (int t = 0; t < nv; ++t) {
      const double* m = vs[size_t(t)].mid;
      const double dot = m[0] * u[0] + m[1] * u[1] + m[2] * u[2];
      const double cx = m[1] * u[2] - m[2] * u[1], cy = m[2] * u[0] - m[0] * u[2], cz = m[0] * u[1] - m[1] * u[0];
      const double perp = std::sqrt(cx * cx + cy * cy + cz * cz);
      minDot = std::min(minDot, dot - vs[size_t(t)].rad);
      maxPerp = std::max(maxPerp, perp + vs[size_t(t)].rad);
      const double cs = (dot - vs[size_t(t)].rad) / (std::hypot(dot, perp) + vs[size_t(t)].rad);
      if (worst && cs < worstCos) worstCos = cs, *worst = t;
    }
    minDot *= 1.0 - 1e-12;  // rounding of the products above, generously
    maxPerp = maxPerp * (1.0 + 1e-12) + 1e-15 * len;
    return minDot > 0.0 ? maxPerp / minDot : kInf;
  };
  // Directions tried: the mean gradient, then (at edges and corners of the solid, where the
  // normals spread) a few steps towards the worst normal from the mean of the unit normals.
  double best = tanOf(c.n, nullptr);
  if (nv > 1) {
    double u[3] = {0, 0, 0};
    for (int t = 0; t < nv; ++t) {
      const double* m = vs[size_t(t)].mid;
      const double l = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      if (l > 0.0)
        for (int i = 0; i < 3; ++i) u[i] += m[i] / l;
    }
    for (int it = 0; it < 24; ++it) {
      const double l = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      if (!(l > 0.0)) break;
      for (double& x : u) x /= l;
      int worst = 0;
      const double tu = tanOf(u, &worst);
      if (tu < best) {
        best = tu;
        for (int i = 0; i < 3; ++i) c.n[i] = u[i];
      }
      const double* m = vs[size_t(worst)].mid;
      const double lm = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      if (!(lm > 0.0)) break;
      for (int i = 0; i < 3; ++i) u[i] += m[i] / lm / (it + 2);
    }
  }
  if (!std::isfinite(best)) return;
  const double t = best;
  const double secMinus1 = t * t / (std::sqrt(1.0 + t * t) + 1.0);  // sqrt(1 + t^2) - 1, stably
  const HalfSpace slab[2] = {notL, U};
  c.coneExcess = measure_detail::projectedArea(h, slab, 2, c.n) * secMinus1 * (1.0 + 1e-9);
}

void evaluateCell(Cell& c, Worker& w, const Interval box[3]) {
  Interval cell[3];
  for (int i = 0; i < 3; ++i) cell[i] = Interval(c.lo[i], c.hi[i]);
  const Interval F = w.ie.eval(*c.tape, cell);
  if (F.lo > 0.0) {
    c.cls = kInside;
    c.tape.reset();
    return;
  }
  if (F.hi < 0.0) {
    c.cls = kOutside;
    c.tape.reset();
    return;
  }
  c.cls = kBoundary;
  c.tape = w.ie.pruned(c.tape);
  double h[3], ctr[3];
  c.half(h);
  c.centre(ctr);
  Interval G[3], Fcell;
  measure_detail::Row row;
  c.firstOrder = false;
  if (w.ca.gradient(*c.tape, cell, G, &Fcell, &row)) {
    // The gradient box from the vertices: tighter than the row's terms taken as independent.
    gradientVertices(row, w.boxes);
    for (int i = 0; i < 3; ++i) {
      double lo = kInf, hi = -kInf;
      for (const VBox& v : w.boxes) lo = std::min(lo, v.lo[i]), hi = std::max(hi, v.hi[i]);
      G[i] = Interval(std::max(lo, G[i].lo), std::min(hi, G[i].hi));
    }
    const Interval Fc = w.ca.valueAt(*c.tape, ctr);
    if (std::isfinite(Fc.lo) && std::isfinite(Fc.hi)) {
      double e = 0.0, scale = std::fabs(Fc.lo) + std::fabs(Fc.hi);
      for (int i = 0; i < 3; ++i) {
        const double g0 = G[i].mid();
        c.L.g[i] = c.U.g[i] = g0;
        e += std::max(G[i].hi - g0, g0 - G[i].lo) * h[i];
        scale += std::fabs(g0) * h[i];
      }
      // f(x) - f(c) - g0 . y = (G - g0) . y: at most e; the planes' own rounding on top.
      e = e * (1.0 + 1e-12) + 16.0 * kUlp * scale;
      c.L.c = Fc.lo - e;
      c.U.c = Fc.hi + e;
      c.firstOrder = true;
    }
  }
  if (!c.firstOrder) {  // zero order: the value interval over the cell
    c.L = HalfSpace{F.lo, {0, 0, 0}};
    c.U = HalfSpace{F.hi, {0, 0, 0}};
  }
  c.vL = measure_detail::clippedVolume(h, c.L);
  c.vU = measure_detail::clippedVolume(h, c.U);
  if (c.firstOrder) areaData(c, h, w.boxes);
  measure_detail::AreaCell a;
  for (int k = 0; k < 3; ++k) a.lo[k] = c.lo[k], a.hi[k] = c.hi[k];
  a.L = c.L;
  a.U = c.U;
  measure_detail::faceBounds(a);
  for (int k = 0; k < 6; ++k) c.faceLo[k] = a.faceLo[k], c.faceHi[k] = a.faceHi[k];
}

double faceAreaOf(const Cell& c, int b) {
  const int a = b / 2;
  return (c.hi[(a + 1) % 3] - c.lo[(a + 1) % 3]) * (c.hi[(a + 2) % 3] - c.lo[(a + 2) % 3]);
}

// Integrals of phi = 1, y_i, y_i y_j (y = x - p) over solid ∩ box, as bounds, summed in a fixed
// order. lo/hi: bounds; mag: sum of magnitudes for the rounding margin.
struct Acc {
  double lo[10] = {}, hi[10] = {}, mag[10] = {};
  uint64_t n = 0;
  void add(const Acc& o) {
    for (int k = 0; k < 10; ++k) {
      lo[k] += o.lo[k];
      hi[k] += o.hi[k];
      mag[k] += o.mag[k];
    }
    n += o.n;
  }
  MeasureBound bound(int k) const {
    const double margin = double(n + 64) * 4.0 * kUlp * mag[k];
    return {lo[k] - margin, hi[k] + margin};
  }
};

// Moments about the cell centre -> the ten integrals about p (d = centre - p).
void shifted(const Moments& m, const double d[3], double out[10]) {
  out[0] = m.v;
  for (int i = 0; i < 3; ++i) out[1 + i] = m.m1[i] + d[i] * m.v;
  const int I[6] = {0, 1, 2, 0, 1, 2}, J[6] = {0, 1, 2, 1, 2, 0};
  for (int k = 0; k < 6; ++k)
    out[4 + k] = m.m2[k] + d[I[k]] * m.m1[J[k]] + d[J[k]] * m.m1[I[k]] + d[I[k]] * d[J[k]] * m.v;
}

// Range of each phi over the cell.
void phiRanges(const double d[3], const double h[3], double pmin[10], double pmax[10]) {
  pmin[0] = pmax[0] = 1.0;
  for (int i = 0; i < 3; ++i) {
    pmin[1 + i] = d[i] - h[i];
    pmax[1 + i] = d[i] + h[i];
  }
  const int I[6] = {0, 1, 2, 0, 1, 2}, J[6] = {0, 1, 2, 1, 2, 0};
  for (int k = 0; k < 6; ++k) {
    const double a0 = d[I[k]] - h[I[k]], a1 = d[I[k]] + h[I[k]];
    const double b0 = d[J[k]] - h[J[k]], b1 = d[J[k]] + h[J[k]];
    const double p[4] = {a0 * b0, a0 * b1, a1 * b0, a1 * b1};
    pmin[4 + k] = *std::min_element(p, p + 4);
    pmax[4 + k] = *std::max_element(p, p + 4);
    if (I[k] == J[k] && a0 <= 0.0 && a1 >= 0.0) pmin[4 + k] = 0.0;
  }
}

void accumulateCell(const Cell& c, const double p[3], Acc& acc) {
  double h[3], ctr[3], d[3];
  c.half(h);
  c.centre(ctr);
  for (int i = 0; i < 3; ++i) d[i] = ctr[i] - p[i];
  double pmin[10], pmax[10];
  phiRanges(d, h, pmin, pmax);
  const double vol = 8.0 * h[0] * h[1] * h[2];
  ++acc.n;
  if (c.cls == kInside) {
    double m[10];
    shifted(measure_detail::boxMoments(h), d, m);
    for (int k = 0; k < 10; ++k) {
      acc.lo[k] += m[k];
      acc.hi[k] += m[k];
      acc.mag[k] += vol * std::max(std::fabs(pmin[k]), std::fabs(pmax[k]));
    }
    return;
  }
  double mL[10], mU[10];
  shifted(measure_detail::clippedMoments(h, c.L), d, mL);
  shifted(measure_detail::clippedMoments(h, c.U), d, mU);
  const double vd = mU[0] - mL[0];
  for (int k = 0; k < 10; ++k) {
    // solid ∩ cell = inner polytope + T with T inside the difference D of the polytopes.
    const double dk = mU[k] - mL[k];
    double tlo, thi;
    if (pmin[k] >= 0.0) tlo = 0.0, thi = dk;
    else if (pmax[k] <= 0.0) tlo = dk, thi = 0.0;
    else tlo = pmin[k] * vd, thi = pmax[k] * vd;
    acc.lo[k] += mL[k] + tlo;
    acc.hi[k] += mL[k] + thi;
    acc.mag[k] += vol * std::max(std::fabs(pmin[k]), std::fabs(pmax[k])) * 4.0;
  }
}

// Ordered, chunked sum of every cell's integrals about p (the same for any thread count).
Acc integrate(const std::vector<const Cell*>& cells, const double p[3], int threads) {
  constexpr size_t kChunk = 1024;
  const size_t chunks = (cells.size() + kChunk - 1) / kChunk;
  std::vector<Acc> part(chunks);
  parallelChunks(chunks, 1, threads, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k)
      for (size_t i = k * kChunk; i < std::min(cells.size(), (k + 1) * kChunk); ++i) accumulateCell(*cells[i], p, part[k]);
  });
  Acc total;
  for (const Acc& a : part) total.add(a);
  return total;
}

MeasureBound quotient(const MeasureBound& a, const MeasureBound& v) {
  // a / v with v > 0, outward.
  const double q[4] = {a.lower / v.lower, a.lower / v.upper, a.upper / v.lower, a.upper / v.upper};
  const double lo = *std::min_element(q, q + 4), hi = *std::max_element(q, q + 4);
  return {lo - 4.0 * kUlp * std::fabs(lo), hi + 4.0 * kUlp * std::fabs(hi)};
}
MeasureBound productB(const MeasureBound& a, const MeasureBound& b) {
  const double q[4] = {a.lower * b.lower, a.lower * b.upper, a.upper * b.lower, a.upper * b.upper};
  const double lo = *std::min_element(q, q + 4), hi = *std::max_element(q, q + 4);
  return {lo - 4.0 * kUlp * std::fabs(lo), hi + 4.0 * kUlp * std::fabs(hi)};
}
MeasureBound sumB(const MeasureBound& a, const MeasureBound& b, double sb = 1.0) {
  const double lo = sb > 0 ? a.lower + b.lower : a.lower - b.upper;
  const double hi = sb > 0 ? a.upper + b.upper : a.upper - b.lower;
  return {lo - 2.0 * kUlp * std::fabs(lo), hi + 2.0 * kUlp * std::fabs(hi)};
}

// Inertia tensor (row-major) from the integrals of y_i y_j about p.
std::array<MeasureBound, 9> inertiaOf(const Acc& a) {
  MeasureBound s[6];
  for (int k = 0; k < 6; ++k) s[k] = a.bound(4 + k);
  std::array<MeasureBound, 9> t;
  t[0] = sumB(s[1], s[2]);
  t[4] = sumB(s[2], s[0]);
  t[8] = sumB(s[0], s[1]);
  const int off[3][2] = {{0, 1}, {1, 2}, {2, 0}};
  for (int k = 0; k < 3; ++k) {
    const MeasureBound v{-s[3 + k].upper, -s[3 + k].lower};
    t[size_t(off[k][0] * 3 + off[k][1])] = v;
    t[size_t(off[k][1] * 3 + off[k][0])] = v;
  }
  return t;
}

// Area bounds of the boundary leaves (area_flux.h); with `shares`, each cell's areaWidth too.
measure_detail::AreaTotals areaOf(std::vector<Cell>& cells, const Interval box[3], int threads, bool shares) {
  std::vector<measure_detail::AreaCell> ac(cells.size());
  for (size_t i = 0; i < cells.size(); ++i) {
    const Cell& c = cells[i];
    measure_detail::AreaCell& a = ac[i];
    for (int k = 0; k < 3; ++k) {
      a.lo[k] = c.lo[k];
      a.hi[k] = c.hi[k];
      a.n[k] = c.n[k];
    }
    a.L = c.L;
    a.U = c.U;
    a.coneExcess = c.coneExcess;
    a.shadowLo = c.shadowLo;
    for (int k = 0; k < 6; ++k) a.faceLo[k] = c.faceLo[k], a.faceHi[k] = c.faceHi[k];
  }
  std::vector<double> widths;
  measure_detail::AreaTotals t = measure_detail::surfaceArea(ac, box, shares ? &widths : nullptr, threads);
  if (shares)
    for (size_t i = 0; i < cells.size(); ++i) cells[i].areaWidth = widths[i];
  return t;
}

}  // namespace

MassProperties measureMassProperties(const TapePtr& tape, const Interval box[3], const MeasureOptions& opt) {
  if (!tape || tape->numVars() > 3) throw std::invalid_argument("measureMassProperties: the tape must have at most 3 coordinates");
  for (int i = 0; i < 3; ++i)
    if (!(box[i].hi > box[i].lo) || !std::isfinite(box[i].lo) || !std::isfinite(box[i].hi))
      throw std::invalid_argument("measureMassProperties: the box must be finite with hi > lo on every axis");
  if (!(opt.tolerance > 0.0)) throw std::invalid_argument("measureMassProperties: tolerance must be > 0");
  MassProperties out;
  tbb::enumerable_thread_specific<Worker> workers;

  // Initial grid: about initialCells along the longest edge, cells close to cubes.
  double longest = 0.0;
  for (int i = 0; i < 3; ++i) longest = std::max(longest, box[i].width());
  int n[3];
  for (int i = 0; i < 3; ++i)
    n[i] = std::max(1, int(std::lround(box[i].width() / longest * std::max(1, opt.initialCells))));
  std::vector<Cell> pending;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        Cell c;
        const int idx[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          c.lo[a] = idx[a] == 0 ? box[a].lo : box[a].lo + box[a].width() * idx[a] / n[a];
          c.hi[a] = idx[a] + 1 == n[a] ? box[a].hi : box[a].lo + box[a].width() * (idx[a] + 1) / n[a];
        }
        c.tape = tape;
        pending.push_back(std::move(c));
      }

  std::vector<Cell> inside, boundary;
  std::vector<Cell> splitParents;  // the boundary leaves the last round split: its fallback
  double insideVolume = 0.0, insideCap = 0.0;
  unsigned insideCapMask = 0;
  const Interrupter* run = InterruptScope::choose(opt.interrupt);
  InterruptScope quiet(nullptr);  // checked only where a cancel leaves valid bounds (below)
  auto stop = [&](const char* reason) {
    out.stopped = true;
    out.stopReason = reason;
  };
  for (int round = 0;; ++round) {
    try {
      InterruptScope scope(run);
      parallelChunks(pending.size(), 8, opt.threads, [&](size_t b, size_t e) {
        Worker& w = workers.local();
        for (size_t i = b; i < e; ++i) evaluateCell(pending[i], w, box);
      });
    } catch (const Interrupted&) {
      // Cancelled inside a round: its children are half evaluated, so the leaves of the last
      // whole round stand (their bounds hold). In the first round there are none.
      if (round == 0) throw;
      for (Cell& c : splitParents) boundary.push_back(std::move(c));
      pending.clear();
      stop("cancelled");
      break;
    }
    splitParents.clear();
    for (Cell& c : pending) {
      if (c.cls == kInside) {
        double h[3];
        c.half(h);
        insideVolume += 8.0 * h[0] * h[1] * h[2];
        const unsigned faces = outerFaces(c, box);
        for (int b = 0; b < 6; ++b)
          if (faces & (1u << b)) insideCap += faceAreaOf(c, b);
        insideCapMask |= faces;
        inside.push_back(std::move(c));
      } else if (c.cls == kBoundary) {
        out.depth = std::max(out.depth, c.depth);
        boundary.push_back(std::move(c));
      }
    }
    pending.clear();
    out.rounds = round + 1;

    // Widths now (the final bounds get rounding margins below).
    double vL = insideVolume, vU = insideVolume;
    for (const Cell& c : boundary) {
      vL += c.vL;
      vU += c.vU;
    }
    double aL = insideCap, aU = insideCap, aWidthFinite = 0.0;
    bool areaSplittableInf = false;
    if (opt.areaTolerance) {
      const measure_detail::AreaTotals at = areaOf(boundary, box, opt.threads, true);
      aL += at.lower + at.capLower;
      aU += at.upper + at.capUpper;
      for (const Cell& c : boundary) {
        if (std::isfinite(c.areaWidth)) aWidthFinite += c.areaWidth;
        else if (c.depth < opt.maxDepth) areaSplittableInf = true;
      }
    }
    const double tV = opt.tolerance * (vL > 0.0 ? vL : vU);
    const double tA = opt.tolerance * (aL > 0.0 ? aL : (std::isfinite(aU) ? aU : 0.0));
    const bool volumeMet = vU - vL <= tV;
    const bool areaMet = !opt.areaTolerance || (!areaSplittableInf && aWidthFinite <= tA);
    MeasureProgress pr;
    pr.round = out.rounds;
    pr.boundaryCells = boundary.size();
    pr.volumeWidth = vL > 0.0 ? (vU - vL) / vL : kInf;
    pr.areaWidth = aL > 0.0 ? (aU - aL) / aL : kInf;
    if (volumeMet && areaMet) {
      out.toleranceReached = true;
      out.stopReason = "tolerance reached";
      break;
    }
    if ((opt.cancel && opt.cancel->load()) || (run && run->cancelled())) {
      stop("cancelled");
      break;
    }
    if (run) {
      try {
        run->progress("measure", uint64_t(out.rounds), 0);  // total unknown: rounds until the tolerance
      } catch (const Interrupted&) {
        stop("cancelled");
        break;
      }
    }
    if (opt.progress && !opt.progress(pr)) {
      stop("stopped by the caller");
      break;
    }

    // Split the leaves that contribute most until the predicted widths are 0.8 of the targets
    // (a split leaf keeps about a quarter of its width: second order).
    std::vector<uint32_t> order;
    std::vector<double> score(boundary.size(), 0.0);
    for (uint32_t i = 0; i < boundary.size(); ++i) {
      const Cell& c = boundary[i];
      if (c.depth >= opt.maxDepth) continue;
      const double wv = c.vU - c.vL, wa = c.areaWidth;
      score[i] = (tV > 0 ? wv / tV : (wv > 0 ? kInf : 0.0)) +
                 (opt.areaTolerance ? (std::isfinite(wa) ? (tA > 0 ? wa / tA : (wa > 0 ? kInf : 0.0)) : kInf) : 0.0);
      order.push_back(i);
    }
    if (order.empty()) {
      out.stopReason = "maximum depth reached";
      break;
    }
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
      return score[a] != score[b] ? score[a] > score[b] : a < b;
    });
    // Only cells within a factor 16 of the widest share go this round (the rest may not need it:
    // splitting every cell with some width refines flat faces next to an edge for nothing).
    double topScore = 0.0;
    for (uint32_t i : order)
      if (std::isfinite(score[i])) topScore = std::max(topScore, score[i]);
    double predV = vU - vL, predA = aWidthFinite;
    const uint64_t room = opt.maxBoundaryCells > boundary.size() ? (opt.maxBoundaryCells - boundary.size()) / 7 : 0;
    std::vector<char> split(boundary.size(), 0);
    uint64_t nsplit = 0;
    for (uint32_t i : order) {
      const Cell& c = boundary[i];
      const bool needed = predV > 0.8 * tV || (opt.areaTolerance && (predA > 0.8 * tA || !std::isfinite(c.areaWidth)));
      if (!needed || nsplit >= room || score[i] < topScore / 16.0) break;
      split[i] = 1;
      ++nsplit;
      predV -= 0.75 * (c.vU - c.vL);
      if (std::isfinite(c.areaWidth)) predA -= 0.75 * c.areaWidth;
    }
    if (nsplit == 0) {
      out.stopReason = room == 0 ? "cell budget reached" : "maximum depth reached";
      break;
    }
    std::vector<Cell> kept;
    kept.reserve(boundary.size() - nsplit);
    for (uint32_t i = 0; i < boundary.size(); ++i) {
      Cell& c = boundary[i];
      if (!split[i]) {
        kept.push_back(std::move(c));
        continue;
      }
      double mid[3];
      for (int a = 0; a < 3; ++a) mid[a] = 0.5 * (c.lo[a] + c.hi[a]);
      for (int k = 0; k < 8; ++k) {
        Cell ch;
        for (int a = 0; a < 3; ++a) {
          const bool upper = (k >> a) & 1;
          ch.lo[a] = upper ? mid[a] : c.lo[a];
          ch.hi[a] = upper ? c.hi[a] : mid[a];
        }
        ch.tape = c.tape;
        ch.depth = c.depth + 1;
        pending.push_back(std::move(ch));
      }
      splitParents.push_back(std::move(c));
    }
    boundary = std::move(kept);
  }

  // Final sums, in a fixed order: inside cells, then boundary leaves.
  std::vector<const Cell*> cells;
  cells.reserve(inside.size() + boundary.size());
  for (const Cell& c : inside) cells.push_back(&c);
  for (const Cell& c : boundary) cells.push_back(&c);
  out.insideCells = inside.size();
  out.boundaryCells = boundary.size();
  for (const Cell& c : boundary) out.firstOrderCells += c.firstOrder ? 1 : 0;

  // Area: the surface in the cells and the cut faces.
  const measure_detail::AreaTotals at = areaOf(boundary, box, opt.threads, false);
  const double capMargin = double(inside.size() + 64) * 4.0 * kUlp * insideCap;
  out.cutArea = {std::max(0.0, insideCap + at.capLower - capMargin), insideCap + at.capUpper + capMargin};
  out.area = {out.cutArea.lower + at.lower, out.cutArea.upper + at.upper};
  out.areaBounded = std::isfinite(out.area.upper);
  out.cutFaces = insideCapMask | at.capMask;

  // Volume and centroid about the box centre first, then everything about that centroid
  // estimate (small first moments: tight centroid bounds), then about the origin.
  double p0[3];
  for (int i = 0; i < 3; ++i) p0[i] = box[i].mid();
  const Acc a0 = integrate(cells, p0, opt.threads);
  out.volume = a0.bound(0);
  out.volume.lower = std::max(out.volume.lower, 0.0);
  if (!(out.volume.lower > 0.0)) {
    // No certified interior: centroid and inertia about it are undefined.
    for (auto& c : out.centroid) c = {-kInf, kInf};
    for (auto& t : out.inertia) t = {-kInf, kInf};
  } else {
    double p1[3];
    for (int i = 0; i < 3; ++i) p1[i] = p0[i] + quotient(a0.bound(1 + i), out.volume).mid();
    const Acc a1 = integrate(cells, p1, opt.threads);
    MeasureBound delta[3];  // centroid - p1
    for (int i = 0; i < 3; ++i) {
      delta[i] = quotient(a1.bound(1 + i), out.volume);
      out.centroid[size_t(i)] = sumB(MeasureBound{p1[i], p1[i]}, delta[i]);
    }
    // I_c = I_p - V (|delta|^2 E - delta delta^T).
    std::array<MeasureBound, 9> ip = inertiaOf(a1);
    MeasureBound dd[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        dd[i][j] = i == j ? MeasureBound{0.0, std::max(delta[i].lower * delta[i].lower, delta[i].upper * delta[i].upper)}
                          : productB(delta[i], delta[j]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        MeasureBound corr;
        if (i == j) corr = sumB(dd[(i + 1) % 3][(i + 1) % 3], dd[(i + 2) % 3][(i + 2) % 3]);
        else corr = MeasureBound{-dd[i][j].upper, -dd[i][j].lower};
        out.inertia[size_t(i * 3 + j)] = sumB(ip[size_t(i * 3 + j)], productB(out.volume, corr), -1.0);
      }
  }
  const double origin[3] = {0.0, 0.0, 0.0};
  out.inertiaOrigin = inertiaOf(integrate(cells, origin, opt.threads));
  return out;
}

}  // namespace frep
