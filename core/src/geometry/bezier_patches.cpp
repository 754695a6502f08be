// Tensor-product Bezier patches -> a watertight triangle mesh (distance_fields.h), adapting the
// cell count to the chord deviation delta (Choporov-Hybrid, nonuniform-surface-mesh, eq. 8-9).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "frep/geometry/distance_fields.h"

namespace frep {
namespace {

struct Patches {
  const std::vector<double>& ctrl;
  int du, dv;
  size_t perPatch() const { return size_t(du + 1) * size_t(dv + 1); }
  const double* at(size_t patch, int i, int j) const { return &ctrl[3 * (patch * perPatch() + size_t(i) * (dv + 1) + j)]; }

  // S(u, v): de Casteljau along u for each column j, then along v.
  void point(size_t patch, double u, double v, double* out) const {
    double col[3 * 64], row[3 * 64];
    for (int j = 0; j <= dv; ++j) {
      for (int i = 0; i <= du; ++i)
        for (int k = 0; k < 3; ++k) row[3 * i + k] = at(patch, i, j)[k];
      bezierPoint(row, du, 3, u, &col[3 * j]);
    }
    bezierPoint(col, dv, 3, v, out);
  }
  // A boundary curve (side 0: v = 0, 1: u = 1, 2: v = 1, 3: u = 0) at step s of m, evaluated
  // from the lexicographically smaller end so that neighbours sharing it get the same bits.
  void boundary(size_t patch, int side, int s, int m, double* out) const {
    const int deg = side % 2 == 0 ? du : dv;
    double c[3 * 64];
    for (int q = 0; q <= deg; ++q) {
      const double* p = side == 0 ? at(patch, q, 0) : side == 1 ? at(patch, du, q) : side == 2 ? at(patch, q, dv) : at(patch, 0, q);
      for (int k = 0; k < 3; ++k) c[3 * q + k] = p[k];
    }
    bool reverse = false;
    for (int q = 0; q <= deg; ++q) {
      const int r = deg - q;
      if (c[3 * r] != c[3 * q] || c[3 * r + 1] != c[3 * q + 1] || c[3 * r + 2] != c[3 * q + 2]) {
        reverse = std::lexicographical_compare(&c[3 * r], &c[3 * r + 3], &c[3 * q], &c[3 * q + 3]);
        break;
      }
    }
    if (reverse) {
      for (int q = 0; q < (deg + 1) / 2; ++q) std::swap_ranges(&c[3 * q], &c[3 * q + 3], &c[3 * (deg - q)]);
      bezierPoint(c, deg, 3, double(m - s) / m, out);
    } else {
      bezierPoint(c, deg, 3, double(s) / m, out);
    }
  }
  // Grid vertex (i, j) of an m x m parameter grid, boundaries canonical.
  void gridPoint(size_t patch, int i, int j, int m, double* out) const {
    if (j == 0) return boundary(patch, 0, i, m, out);
    if (i == m) return boundary(patch, 1, j, m, out);
    if (j == m) return boundary(patch, 2, i, m, out);
    if (i == 0) return boundary(patch, 3, j, m, out);
    point(patch, double(i) / m, double(j) / m, out);
  }
};

double dist3(const double* a, const double* b) { return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2])); }

// Largest distance between the surface and the linear interpolation of the grid triangles at
// edge midpoints and centroids, in parameter space (an upper bound of the geometric deviation
// at those points).
double deviation(const Patches& P, size_t patch, int m) {
  std::vector<double> g(3 * size_t(m + 1) * (m + 1));
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= m; ++j) P.gridPoint(patch, i, j, m, &g[3 * (size_t(i) * (m + 1) + j)]);
  auto G = [&](int i, int j) { return &g[3 * (size_t(i) * (m + 1) + j)]; };
  double worst = 0.0;
  const double h = 1.0 / m;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      // Triangles (i,j)-(i+1,j)-(i+1,j+1) and (i,j)-(i+1,j+1)-(i,j+1): their edge midpoints and
      // centroids as weights of the cell's corners w00, w10, w11, w01.
      static const double pts[][4] = {{0.5, 0, 0.5, 0}, {0.5, 0, 0, 0.5}, {0.5, 0.5, 0, 0}, {0, 0, 0.5, 0.5},
                                      {0, 0.5, 0.5, 0}, {1 / 3., 1 / 3., 1 / 3., 0}, {1 / 3., 0, 1 / 3., 1 / 3.}};
      for (const auto& w0 : pts) {
        const double w00 = w0[0], w10 = w0[1], w11 = w0[2], w01 = w0[3];
        const double u = i * h + h * (w10 + w11), v = j * h + h * (w11 + w01);
        double s[3], l[3];
        P.point(patch, u, v, s);
        for (int k = 0; k < 3; ++k) l[k] = w00 * G(i, j)[k] + w10 * G(i + 1, j)[k] + w11 * G(i + 1, j + 1)[k] + w01 * G(i, j + 1)[k];
        worst = std::max(worst, dist3(s, l));
      }
    }
  return worst;
}

}  // namespace

TriangleMesh tessellateBezierPatches(const std::vector<double>& ctrl, int du, int dv, int n, double delta) {
  if (du < 1 || dv < 1 || du > 63 || dv > 63) throw std::invalid_argument("the degrees must be 1 to 63");
  if (n < 1) throw std::invalid_argument("n (initial cells per patch side) must be at least 1");
  if (!(delta > 0.0)) throw std::invalid_argument("delta (chord deviation) must be positive");
  Patches P{ctrl, du, dv};
  const size_t per = 3 * P.perPatch();
  if (ctrl.empty() || ctrl.size() % per != 0)
    throw std::invalid_argument("the control array must hold patches of " + std::to_string(P.perPatch()) +
                                " points (3 numbers each) for degrees " + std::to_string(du) + " x " +
                                std::to_string(dv) + "; got " + std::to_string(ctrl.size()) + " numbers");
  const size_t patches = ctrl.size() / per;
  for (size_t p = 0; p < patches; ++p) {
    bool allSame = true;
    for (size_t k = 3; k < per; ++k) allSame = allSame && ctrl[p * per + k] == ctrl[p * per + k % 3];
    if (allSame) throw std::invalid_argument("patch " + std::to_string(p + 1) + " is degenerate: all its control points are equal");
  }
  // At most about 2^20 triangles in all (and 512 cells a side): a surface whose delta asks for
  // more (a far control point, a delta tiny against the extent) is an error, not hours of work.
  const int mMax = int(std::min(512.0, std::floor(std::sqrt(double(1 << 19) / double(patches)))));
  auto tooFine = [&](double needed) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "delta %g needs about %.3g cells a side on each of the %zu patches, more than the %d allowed "
                  "(2^20 triangles in all): give a larger delta",
                  delta, needed, patches, mMax);
    return std::invalid_argument(buf);
  };
  if (n > mMax)
    throw std::invalid_argument("n = " + std::to_string(n) + " cells a side on each of the " + std::to_string(patches) +
                                " patches is more than the " + std::to_string(mMax) +
                                " allowed (2^20 triangles in all)");
  int m = n;
  for (;;) {
    double dev = 0.0;
    for (size_t p = 0; p < patches; ++p) dev = std::max(dev, deviation(P, p, m));
    if (dev <= delta) break;
    if (m >= mMax) throw tooFine(m * std::sqrt(dev / delta) * 1.05);  // not within delta at the cap
    // The interpolation error falls as m^-2: jump close to the needed count in one step; one
    // far past the cap is refused before the cap's costly check.
    const double needed = m * std::sqrt(dev / delta) * 1.05;
    if (!(needed <= 4.0 * mMax)) throw tooFine(needed);
    m = std::min(mMax, std::max(m + 1, int(std::ceil(needed))));
  }
  TriangleMesh out;
  out.cells = m;
  for (size_t p = 0; p < patches; ++p) {
    const uint32_t base = uint32_t(out.xyz.size() / 3);
    for (int i = 0; i <= m; ++i)
      for (int j = 0; j <= m; ++j) {
        double q[3];
        P.gridPoint(p, i, j, m, q);
        out.xyz.insert(out.xyz.end(), q, q + 3);
      }
    auto id = [&](int i, int j) { return base + uint32_t(i * (m + 1) + j); };
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        out.tris.insert(out.tris.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        out.tris.insert(out.tris.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  }
  return out;
}

}  // namespace frep
