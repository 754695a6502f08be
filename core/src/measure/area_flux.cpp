// Surface area bounds by the flux form of the divergence theorem (area_flux.h).
#include "measure/area_flux.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sampling/parallel_chunks.h"

namespace frep::measure_detail {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kUlp = 0x1p-52;

struct Face {
  uint32_t cell;
  uint8_t axis, side;  // side 1: the face at the cell's hi (outward normal +e_axis)
  bool outer;
  double coord, u0, u1, v0, v1;
  double lo, hi;  // this cell's bounds on a_F (the whole face), then on its remainder
};

// Bounds from cell c's planes on the area of solid ∩ (rectangle [u0,u1] x [v0,v1] of its face).
void pieceBounds(const AreaCell& c, int axis, int side, double u0, double u1, double v0, double v1, double& lo,
                 double& hi) {
  double h[3], ctr[3];
  for (int i = 0; i < 3; ++i) {
    h[i] = 0.5 * (c.hi[i] - c.lo[i]);
    ctr[i] = 0.5 * (c.lo[i] + c.hi[i]);
  }
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  const double u[2] = {u0 - ctr[a], u1 - ctr[a]}, v[2] = {v0 - ctr[b], v1 - ctr[b]};
  const double full = (u1 - u0) * (v1 - v0);
  // Most pieces lie wholly on one side of a plane: no clipping then.
  auto area = [&](const HalfSpace& s) {
    const double mid = s.c + s.g[axis] * (side ? h[axis] : -h[axis]) + s.g[a] * 0.5 * (u[0] + u[1]) +
                       s.g[b] * 0.5 * (v[0] + v[1]);
    const double r = (std::fabs(s.g[a]) * (u[1] - u[0]) + std::fabs(s.g[b]) * (v[1] - v[0])) * 0.5;
    const double slack = 1e-12 * (std::fabs(mid) + r);
    if (mid - r > slack) return full;
    if (mid + r < -slack) return 0.0;
    return rectArea(h, axis, side, u, v, s);
  };
  lo = area(c.L);
  hi = area(c.U);
}

struct Sum {
  double lo = 0, hi = 0, mag = 0;
  uint64_t n = 0;
  void atom(double k, double alo, double ahi) {
    const double p = k * alo, q = k * ahi;
    lo += std::min(p, q);
    hi += std::max(p, q);
    mag += std::fabs(p) + std::fabs(q);
    ++n;
  }
};

}  // namespace

void faceBounds(AreaCell& c) {
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side)
      pieceBounds(c, axis, side, c.lo[a], c.hi[a], c.lo[b], c.hi[b], c.faceLo[axis * 2 + side], c.faceHi[axis * 2 + side]);
  }
}

AreaTotals surfaceArea(const std::vector<AreaCell>& cells, const Interval box[3], std::vector<double>* widths,
                       int threads) {
  AreaTotals out;
  if (widths) widths->assign(cells.size(), 0.0);
  std::vector<Face> faces(cells.size() * 6);
  for (size_t i = 0; i < cells.size(); ++i) {
    const AreaCell& c = cells[i];
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        Face& f = faces[i * 6 + size_t(axis * 2 + side)];
        const int a = (axis + 1) % 3, bb = (axis + 2) % 3;
        f.cell = uint32_t(i);
        f.axis = uint8_t(axis);
        f.side = uint8_t(side);
        f.coord = side ? c.hi[axis] : c.lo[axis];
        f.outer = side ? f.coord == box[axis].hi : f.coord == box[axis].lo;
        f.u0 = c.lo[a], f.u1 = c.hi[a], f.v0 = c.lo[bb], f.v1 = c.hi[bb];
        f.lo = c.faceLo[axis * 2 + side];
        f.hi = c.faceHi[axis * 2 + side];
      }
  }

  Sum flux, cap;
  auto coef = [&](const Face& f) { return cells[f.cell].n[f.axis] * (f.side ? 1.0 : -1.0); };
  auto attribute = [&](uint32_t cell, double w) {
    if (widths) (*widths)[cell] += w;
  };

  // Pieces shared by two boundary leaves: the faces on one plane, cells below (side 1) against
  // cells above (side 0). Faces on one side of a plane never overlap each other.
  struct Key {
    double coord, u0, v0;
    uint32_t idx;
    uint8_t axis, side;
  };
  std::vector<Key> keys(faces.size());
  for (uint32_t i = 0; i < faces.size(); ++i)
    keys[i] = Key{faces[i].coord, faces[i].u0, faces[i].v0, i, faces[i].axis, faces[i].side};
  parallelSort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    if (a.axis != b.axis) return a.axis < b.axis;
    if (a.coord != b.coord) return a.coord < b.coord;
    if (a.side != b.side) return a.side < b.side;
    if (a.u0 != b.u0) return a.u0 < b.u0;
    if (a.v0 != b.v0) return a.v0 < b.v0;
    return a.idx < b.idx;
  }, threads);
  std::vector<uint32_t> order(faces.size());
  for (size_t i = 0; i < keys.size(); ++i) order[i] = keys[i].idx;
  keys = {};
  std::vector<double> remLo(faces.size()), remHi(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) remLo[i] = faces[i].lo, remHi[i] = faces[i].hi;
  for (size_t g = 0; g < order.size();) {
    const Face& first = faces[order[g]];
    size_t end = g;
    while (end < order.size() && faces[order[end]].axis == first.axis && faces[order[end]].coord == first.coord) ++end;
    // order[g, mid): side 0 (cells above the plane), sorted by u0; order[mid, end): side 1.
    size_t mid = g;
    while (mid < end && faces[order[mid]].side == 0) ++mid;
    double maxWidth = 0.0;
    for (size_t k = g; k < mid; ++k) maxWidth = std::max(maxWidth, faces[order[k]].u1 - faces[order[k]].u0);
    for (size_t k = mid; k < end && mid > g; ++k) {
      const uint32_t ia = order[k];
      const Face& A = faces[ia];
      if (A.outer) continue;
      // Side-0 faces with u0 in (A.u0 - maxWidth, A.u1).
      size_t j = size_t(std::lower_bound(order.begin() + long(g), order.begin() + long(mid), A.u0 - maxWidth,
                                         [&](uint32_t x, double v) { return faces[x].u0 < v; }) -
                        order.begin());
      for (; j < mid && faces[order[j]].u0 < A.u1; ++j) {
        const uint32_t ib = order[j];
        const Face& B = faces[ib];
        const double u0 = std::max(A.u0, B.u0), u1 = std::min(A.u1, B.u1);
        const double v0 = std::max(A.v0, B.v0), v1 = std::min(A.v1, B.v1);
        if (!(u1 > u0) || !(v1 > v0)) continue;
        double la = A.lo, ha = A.hi, lb = B.lo, hb = B.hi;  // a whole face: as computed once
        if (!(u0 == A.u0 && u1 == A.u1 && v0 == A.v0 && v1 == A.v1))
          pieceBounds(cells[A.cell], A.axis, 1, u0, u1, v0, v1, la, ha);
        if (!(u0 == B.u0 && u1 == B.u1 && v0 == B.v0 && v1 == B.v1))
          pieceBounds(cells[B.cell], B.axis, 0, u0, u1, v0, v1, lb, hb);
        remLo[ia] -= la, remHi[ia] -= ha;
        remLo[ib] -= lb, remHi[ib] -= hb;
        double lo = std::max(la, lb), hi = std::min(ha, hb);
        if (lo > hi) lo = std::min(la, lb), hi = std::max(ha, hb);  // rounding only
        const double k = coef(A) + coef(B);
        flux.atom(k, lo, hi);
        attribute(A.cell, 0.5 * std::fabs(k) * (hi - lo));
        attribute(B.cell, 0.5 * std::fabs(k) * (hi - lo));
      }
    }
    g = end;
  }
  // What is left of every face: touching the box, an inside or an outside cell.
  for (size_t i = 0; i < faces.size(); ++i) {
    const Face& f = faces[i];
    const double slack = 64.0 * kUlp * (f.u1 - f.u0) * (f.v1 - f.v0);
    const double lo = std::max(0.0, remLo[i] - slack), hi = std::max(lo, remHi[i] + slack);
    const double k = coef(f);
    flux.atom(k, lo, hi);
    attribute(f.cell, std::fabs(k) * (hi - lo));
    if (f.outer) {
      cap.atom(1.0, f.lo, f.hi);
      if (f.hi > 0.0) out.capMask |= 1u << (2 * f.axis + f.side);
    }
  }
  double excess = 0.0, shadow = 0.0;
  for (size_t i = 0; i < cells.size(); ++i) {
    excess += cells[i].coneExcess;
    shadow += cells[i].shadowLo;
    attribute(uint32_t(i), cells[i].coneExcess);
  }
  const double fm = double(flux.n + 64) * 4.0 * kUlp * flux.mag;
  out.lower = std::max({0.0, flux.lo - fm, shadow * (1.0 - double(cells.size() + 64) * 4.0 * kUlp)});
  out.upper = flux.hi + fm + excess * (1.0 + 1e-12);
  const double cm = double(cap.n + 64) * 4.0 * kUlp * cap.mag;
  out.capLower = std::max(0.0, cap.lo - cm);
  out.capUpper = cap.hi + cm;
  return out;
}

}  // namespace frep::measure_detail
