// Convex pieces of a star-shaped closed mesh (star_pieces.h).
#include "frep/minkowski_algebra/star_pieces.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace frep::minkowski {
namespace {

using namespace vec3;

struct Plane {
  Vec3 n;
  double h;  // n . x <= h inside
  bool ok;   // false for a degenerate triangle
};

// The least margin h_i - n_i . c over the faces, and the face reaching it.
double leastMargin(const std::vector<Plane>& planes, const Vec3& c, size_t* which) {
  double m = INFINITY;
  for (size_t i = 0; i < planes.size(); ++i) {
    if (!planes[i].ok) continue;
    const double d = planes[i].h - dot(planes[i].n, c);
    if (d < m) m = d, *which = i;
  }
  return m;
}

// A point of the kernel with the largest margin found, and that margin.
std::pair<Vec3, double> kernelPoint(const std::vector<Vec3>& v, const std::vector<std::array<uint32_t, 3>>& t,
                                    const std::vector<Plane>& planes, double extent) {
  std::vector<Vec3> candidates;
  Vec3 centroid{0, 0, 0};
  for (const Vec3& p : v) centroid = add(centroid, p);
  candidates.push_back(scale(centroid, 1.0 / double(v.size())));
  const size_t stride = std::max<size_t>(1, t.size() / 32);
  for (size_t i = 0; i < t.size(); i += stride) {
    if (!planes[i].ok) continue;
    const Vec3 f = scale(add(add(v[t[i][0]], v[t[i][1]]), v[t[i][2]]), 1.0 / 3);
    for (double depth : {0.01, 0.1, 0.3}) candidates.push_back(sub(f, scale(planes[i].n, depth * extent)));
  }
  Vec3 best = candidates[0];
  size_t face = 0;
  double margin = -INFINITY;
  for (const Vec3& c : candidates) {
    const double m = leastMargin(planes, c, &face);
    if (m > margin) margin = m, best = c;
  }
  // Climb: step away from the nearest face's plane, halving the step when that does not help.
  double step = 0.05 * extent;
  for (int it = 0; it < 400 && step > 1e-9 * extent; ++it) {
    leastMargin(planes, best, &face);
    const Vec3 next = sub(best, scale(planes[face].n, step));
    size_t f2;
    const double m = leastMargin(planes, next, &f2);
    if (m > margin) margin = m, best = next;
    else step *= 0.5;
  }
  return {best, margin};
}

// The convex hull of coplanar points (normal n), counter-clockwise seen from the side n points
// to, and its area.
std::pair<std::vector<Vec3>, double> planarHull(std::vector<Vec3> pts, const Vec3& n) {
  const Vec3 e1 = normalized(std::abs(n[0]) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0}));
  const Vec3 e2 = cross(n, e1);
  auto uv = [&](const Vec3& p) { return std::array<double, 2>{dot(p, e1), dot(p, e2)}; };
  std::sort(pts.begin(), pts.end(), [&](const Vec3& a, const Vec3& b) { return uv(a) < uv(b); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  auto turn = [&](const Vec3& o, const Vec3& a, const Vec3& b) {
    const auto O = uv(o), A = uv(a), B = uv(b);
    return (A[0] - O[0]) * (B[1] - O[1]) - (A[1] - O[1]) * (B[0] - O[0]);
  };
  std::vector<Vec3> hull;
  for (int pass = 0; pass < 2; ++pass) {
    const size_t start = hull.size();
    for (size_t k = 0; k < pts.size(); ++k) {
      const Vec3& p = pts[pass == 0 ? k : pts.size() - 1 - k];
      while (hull.size() >= start + 2 && turn(hull[hull.size() - 2], hull.back(), p) <= 0) hull.pop_back();
      hull.push_back(p);
    }
    hull.pop_back();
  }
  double area = 0;
  for (size_t k = 1; k + 1 < hull.size(); ++k) area += 0.5 * turn(hull[0], hull[k], hull[k + 1]);
  return {hull, area};
}

double triangleArea(const Vec3& a, const Vec3& b, const Vec3& c) { return 0.5 * norm(cross(sub(b, a), sub(c, a))); }

}  // namespace

std::optional<std::vector<PieceMesh>> starConvexPieces(const std::vector<Vec3>& v,
                                                       const std::vector<std::array<uint32_t, 3>>& t, double tol,
                                                       size_t maxPieces) {
  if (v.empty() || t.size() < 4) return std::nullopt;
  double extent = 0;
  Vec3 lo = v[0], hi = v[0];
  for (const Vec3& p : v)
    for (int k = 0; k < 3; ++k)
      lo[size_t(k)] = std::min(lo[size_t(k)], p[size_t(k)]), hi[size_t(k)] = std::max(hi[size_t(k)], p[size_t(k)]);
  extent = norm(sub(hi, lo));
  std::vector<Plane> planes(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    const Vec3 n = cross(sub(v[t[i][1]], v[t[i][0]]), sub(v[t[i][2]], v[t[i][0]]));
    const double l = norm(n);
    planes[i].ok = l > 1e-12 * extent * extent;
    if (planes[i].ok) planes[i].n = scale(n, 1 / l), planes[i].h = dot(planes[i].n, v[t[i][0]]);
  }
  const auto [c, margin] = kernelPoint(v, t, planes, extent);
  if (!(margin > tol)) return std::nullopt;

  // Faces: coplanar triangles joined across shared edges while the union's hull has their
  // total area (the union is then that convex polygon).
  std::map<std::pair<uint32_t, uint32_t>, size_t> byEdge;  // directed edge -> triangle
  for (size_t i = 0; i < t.size(); ++i)
    for (int k = 0; k < 3; ++k) byEdge[{t[i][size_t(k)], t[i][size_t((k + 1) % 3)]}] = i;
  std::vector<int> group(t.size(), -1);
  std::vector<PieceMesh> pieces;
  for (size_t seed = 0; seed < t.size(); ++seed) {
    if (group[seed] >= 0 || !planes[seed].ok) continue;
    const int g = int(pieces.size());
    if (pieces.size() >= maxPieces) return std::nullopt;
    std::vector<Vec3> pts{v[t[seed][0]], v[t[seed][1]], v[t[seed][2]]};
    double area = triangleArea(pts[0], pts[1], pts[2]);
    std::vector<size_t> queue{seed};
    group[seed] = g;
    for (size_t q = 0; q < queue.size(); ++q) {
      const auto& tri = t[queue[q]];
      for (int k = 0; k < 3; ++k) {
        auto it = byEdge.find({tri[size_t((k + 1) % 3)], tri[size_t(k)]});
        if (it == byEdge.end()) continue;
        const size_t j = it->second;
        if (group[j] >= 0 || !planes[j].ok) continue;
        if (dot(planes[j].n, planes[seed].n) < 1 - 1e-12 || std::abs(planes[j].h - planes[seed].h) > tol) continue;
        std::vector<Vec3> more = pts;
        for (uint32_t x : t[j]) more.push_back(v[x]);
        const double joined = area + triangleArea(v[t[j][0]], v[t[j][1]], v[t[j][2]]);
        const double hullArea = planarHull(more, planes[seed].n).second;
        if (std::abs(hullArea - joined) > 1e-9 * std::max(joined, extent * extent * 1e-6)) continue;
        pts.swap(more);
        area = joined;
        group[j] = g;
        queue.push_back(j);
      }
    }
    // The pyramid from c over the polygon, each triangle turned outward (away from its centroid).
    const std::vector<Vec3> base = planarHull(pts, planes[seed].n).first;
    if (base.size() < 3) return std::nullopt;
    PieceMesh piece;
    piece.v.push_back(c);
    piece.v.insert(piece.v.end(), base.begin(), base.end());
    Vec3 mid{0, 0, 0};
    for (const Vec3& p : piece.v) mid = add(mid, p);
    mid = scale(mid, 1.0 / double(piece.v.size()));
    auto emit = [&](uint32_t a, uint32_t b, uint32_t d) {
      const Vec3 n = cross(sub(piece.v[b], piece.v[a]), sub(piece.v[d], piece.v[a]));
      if (dot(n, sub(piece.v[a], mid)) < 0) std::swap(b, d);
      piece.t.push_back({a, b, d});
    };
    const uint32_t m = uint32_t(base.size());
    for (uint32_t k = 1; k + 1 < m; ++k) emit(1, 1 + k, 2 + k);
    for (uint32_t k = 0; k < m; ++k) emit(0, 1 + k, 1 + (k + 1) % m);
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

}  // namespace frep::minkowski
