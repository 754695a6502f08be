// Convex pieces covering a closed mesh (convex_cover.h).
#include "frep/minkowski_algebra/convex_cover.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

namespace frep::minkowski {
namespace {

using namespace vec3;
using Tri = std::array<uint32_t, 3>;

struct Plane {
  Vec3 n;    // unit
  double h;  // n . x <= h inside
};

bool planeOf(const Vec3& a, const Vec3& b, const Vec3& c, Plane* p) {
  const Vec3 n = cross(sub(b, a), sub(c, a));
  const double l = norm(n);
  if (!(l > 0)) return false;
  p->n = scale(n, 1 / l);
  p->h = dot(p->n, a);
  return true;
}

// The winding number of the closed outward mesh about p: the sum of its triangles' solid
// angles (Van Oosterom-Strackee's formula) over 4 pi; 1 inside, 0 outside.
double windingNumber(const std::vector<Vec3>& v, const std::vector<Tri>& t, const Vec3& p) {
  double w = 0;
  for (const Tri& f : t) {
    const Vec3 a = sub(v[f[0]], p), b = sub(v[f[1]], p), c = sub(v[f[2]], p);
    const double la = norm(a), lb = norm(b), lc = norm(c);
    const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    w += 2 * std::atan2(dot(a, cross(b, c)), den);
  }
  return w / (4 * M_PI);
}

struct Box {
  Vec3 lo, hi;
  bool touches(const Box& o, double tol) const {
    for (size_t a = 0; a < 3; ++a)
      if (o.lo[a] > hi[a] + tol || o.hi[a] < lo[a] - tol) return false;
    return true;
  }
};

Box boxOf(const std::vector<Vec3>& pts) {
  Box b{pts.at(0), pts.at(0)};
  for (const Vec3& p : pts)
    for (size_t a = 0; a < 3; ++a) b.lo[a] = std::min(b.lo[a], p[a]), b.hi[a] = std::max(b.hi[a], p[a]);
  return b;
}

double volumeOf(const PieceMesh& m) {
  double vol = 0;
  for (const Tri& f : m.t) vol += dot(m.v[f[0]], cross(m.v[f[1]], m.v[f[2]])) / 6;
  return vol;
}

Vec3 centroidOf(const std::vector<Vec3>& pts) {
  Vec3 c{0, 0, 0};
  for (const Vec3& p : pts) c = add(c, p);
  return scale(c, 1.0 / double(pts.size()));
}

// The tool: its triangles' planes and unique edges.
struct Tool {
  const std::vector<Vec3>& v;
  const std::vector<Tri>& t;
  std::vector<Plane> planes;
  std::vector<bool> ok;  // false: a degenerate triangle
  std::vector<std::array<uint32_t, 2>> edges;
};

// Where the segment pq meets the triangle f (closed, up to tol), if it crosses or touches its
// plane at one point.
bool segmentHitsTriangle(const Tool& P, size_t f, const Vec3& p, const Vec3& q, double tol, Vec3* x) {
  const Plane& pl = P.planes[f];
  const double dp = dot(pl.n, p) - pl.h, dq = dot(pl.n, q) - pl.h;
  if ((dp > tol && dq > tol) || (dp < -tol && dq < -tol)) return false;
  if (std::abs(dp) <= tol && std::abs(dq) <= tol) return false;  // in the plane: other rules
  *x = std::abs(dp) <= tol ? p : std::abs(dq) <= tol ? q : add(p, scale(sub(q, p), dp / (dp - dq)));
  for (int k = 0; k < 3; ++k) {
    const Vec3& a = P.v[P.t[f][size_t(k)]];
    const Vec3& b = P.v[P.t[f][size_t((k + 1) % 3)]];
    const Vec3 in = cross(pl.n, sub(b, a));  // points into the triangle
    const double l = norm(in);
    if (!(l > 0) || dot(in, sub(*x, a)) < -tol * l) return false;
  }
  return true;
}

// A cell's corners (feasible intersections of three of its planes) and edges (corners sharing
// two planes).
void cellCorners(const std::vector<Plane>& c, double tol, std::vector<Vec3>& corners,
                 std::vector<std::array<size_t, 2>>& edges) {
  std::vector<uint64_t> on;
  const size_t m = c.size();
  for (size_t i = 0; i < m; ++i)
    for (size_t j = i + 1; j < m; ++j)
      for (size_t k = j + 1; k < m; ++k) {
        const Vec3 jk = cross(c[j].n, c[k].n), ki = cross(c[k].n, c[i].n), ij = cross(c[i].n, c[j].n);
        const double det = dot(c[i].n, jk);
        if (std::abs(det) < 1e-9) continue;
        const Vec3 x = scale(add(add(scale(jk, c[i].h), scale(ki, c[j].h)), scale(ij, c[k].h)), 1 / det);
        uint64_t mask = 0;
        bool feasible = true;
        for (size_t q = 0; q < m && feasible; ++q) {
          const double d = dot(c[q].n, x) - c[q].h;
          feasible = d <= tol;
          if (std::abs(d) <= tol) mask |= uint64_t(1) << q;
        }
        if (!feasible) continue;
        bool known = false;
        for (size_t q = 0; q < corners.size() && !known; ++q) known = norm(sub(corners[q], x)) <= 10 * tol;
        if (!known) corners.push_back(x), on.push_back(mask);
      }
  for (size_t a = 0; a < corners.size(); ++a)
    for (size_t b = a + 1; b < corners.size(); ++b)
      if (__builtin_popcountll(on[a] & on[b]) >= 2) edges.push_back({a, b});
}

// Whether the triangle abc reaches the convex set {n . x <= h - tol} (Sutherland-Hodgman).
bool triangleEnters(const Vec3& a, const Vec3& b, const Vec3& c, const std::vector<Plane>& planes, double tol,
                    std::vector<Vec3>& poly, std::vector<Vec3>& next) {
  poly = {a, b, c};
  for (const Plane& pl : planes) {
    next.clear();
    for (size_t i = 0; i < poly.size(); ++i) {
      const Vec3 &p = poly[i], &q = poly[(i + 1) % poly.size()];
      const double dp = dot(pl.n, p) - pl.h + tol, dq = dot(pl.n, q) - pl.h + tol;
      if (dp <= 0) next.push_back(p);
      if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) next.push_back(add(p, scale(sub(q, p), dp / (dp - dq))));
    }
    poly.swap(next);
    if (poly.empty()) return false;
  }
  return true;
}

// Candidates for the corners of the tool's part in the cell: tool vertices in the cell, tool
// edges crossing a cell plane, cell edges meeting a tool triangle, cell corners inside the
// tool; those outside a bounding plane (a tool face reaching into the cell) are dropped. When
// the part is convex, it is the cell cut by those planes (each bounds it, and its facets inside
// the cell lie on them), so the rest are its corners; the part's faces lying on the cell's
// boundary with the tool on the far side (flat slivers) are dropped with them.
std::vector<Vec3> sectionPoints(const Tool& P, const std::vector<Plane>& cell, const std::vector<Vec3>& corners,
                                const std::vector<std::array<size_t, 2>>& edges, const std::vector<Plane>& bounding,
                                double tol) {
  auto keep = [&](const Vec3& x) {
    for (const Plane& pl : cell)
      if (dot(pl.n, x) > pl.h + tol) return false;
    for (const Plane& pl : bounding)
      if (dot(pl.n, x) > pl.h + tol) return false;
    return true;
  };
  std::vector<Vec3> pts;
  for (const Vec3& p : P.v)
    if (keep(p)) pts.push_back(p);
  for (const auto& e : P.edges) {
    const Vec3 &a = P.v[e[0]], &b = P.v[e[1]];
    for (const Plane& pl : cell) {
      const double da = dot(pl.n, a) - pl.h, db = dot(pl.n, b) - pl.h;
      if (!((da < -tol && db > tol) || (da > tol && db < -tol))) continue;
      const Vec3 x = add(a, scale(sub(b, a), da / (da - db)));
      if (keep(x)) pts.push_back(x);
    }
  }
  for (const auto& e : edges)
    for (size_t f = 0; f < P.t.size(); ++f) {
      Vec3 x;
      if (P.ok[f] && segmentHitsTriangle(P, f, corners[e[0]], corners[e[1]], tol, &x) && keep(x)) pts.push_back(x);
    }
  for (const Vec3& x : corners)
    if (keep(x) && windingNumber(P.v, P.t, x) > 0.5) pts.push_back(x);
  return pts;
}

// Whether every corner of `inner` lies within tol of `outer`'s planes (inner ⊆ outer).
bool hullHolds(const PieceMesh& outer, const PieceMesh& inner, double tol) {
  for (const Tri& f : outer.t) {
    Plane pl;
    if (!planeOf(outer.v[f[0]], outer.v[f[1]], outer.v[f[2]], &pl)) continue;
    for (const Vec3& p : inner.v)
      if (dot(pl.n, p) > pl.h + tol) return false;
  }
  return true;
}

}  // namespace

std::optional<PieceMesh> convexHullMesh(const std::vector<Vec3>& pts, double tol) {
  const size_t n = pts.size();
  if (n < 4) return std::nullopt;
  // A first tetrahedron of far-apart points.
  size_t i0 = 0, i1 = 0, i2 = 0, i3 = 0;
  for (size_t i = 1; i < n; ++i)
    if (pts[i] < pts[i0]) i0 = i;
  double best = 0;
  for (size_t i = 0; i < n; ++i)
    if (const double d = norm(sub(pts[i], pts[i0])); d > best) best = d, i1 = i;
  if (!(best > tol)) return std::nullopt;
  const Vec3 dir = normalized(sub(pts[i1], pts[i0]));
  best = 0;
  for (size_t i = 0; i < n; ++i)
    if (const double d = norm(cross(dir, sub(pts[i], pts[i0]))); d > best) best = d, i2 = i;
  if (!(best > tol)) return std::nullopt;
  const Vec3 up = normalized(cross(sub(pts[i1], pts[i0]), sub(pts[i2], pts[i0])));
  best = 0;
  for (size_t i = 0; i < n; ++i)
    if (const double d = std::abs(dot(up, sub(pts[i], pts[i0]))); d > best) best = d, i3 = i;
  if (!(best > tol)) return std::nullopt;
  const Vec3 inner = centroidOf({pts[i0], pts[i1], pts[i2], pts[i3]});

  struct Face {
    Tri t;
    Plane p;
  };
  std::vector<Face> faces;
  auto addFace = [&](uint32_t a, uint32_t b, uint32_t c, bool orient) {
    Face f{{a, b, c}, {}};
    if (!planeOf(pts[a], pts[b], pts[c], &f.p)) return false;
    if (orient && dot(f.p.n, inner) > f.p.h) {
      std::swap(f.t[1], f.t[2]);
      f.p.n = scale(f.p.n, -1), f.p.h = -f.p.h;
    }
    faces.push_back(f);
    return true;
  };
  const uint32_t s[4] = {uint32_t(i0), uint32_t(i1), uint32_t(i2), uint32_t(i3)};
  for (int k = 0; k < 4; ++k) addFace(s[k], s[(k + 1) % 4], s[(k + 2) % 4], true);
  // Incremental: each point outside some faces (by more than tol) replaces them with the cone
  // from it over their horizon.
  for (size_t i = 0; i < n; ++i) {
    if (i == i0 || i == i1 || i == i2 || i == i3) continue;
    std::set<std::pair<uint32_t, uint32_t>> seen;
    std::vector<Face> kept;
    for (const Face& f : faces) {
      if (dot(f.p.n, pts[i]) - f.p.h > tol)
        for (int k = 0; k < 3; ++k) seen.insert({f.t[size_t(k)], f.t[size_t((k + 1) % 3)]});
      else kept.push_back(f);
    }
    if (seen.empty()) continue;
    faces.swap(kept);
    for (const auto& [a, b] : seen)
      if (!seen.count({b, a}) && !addFace(a, b, uint32_t(i), false)) return std::nullopt;
  }
  // Closed: every directed edge has its reverse (a rounding slip otherwise).
  std::set<std::pair<uint32_t, uint32_t>> directed;
  for (const Face& f : faces)
    for (int k = 0; k < 3; ++k) directed.insert({f.t[size_t(k)], f.t[size_t((k + 1) % 3)]});
  for (const auto& [a, b] : directed)
    if (!directed.count({b, a})) return std::nullopt;
  PieceMesh out;
  std::map<uint32_t, uint32_t> index;
  for (const Face& f : faces) {
    Tri t;
    for (int k = 0; k < 3; ++k) {
      auto [it, fresh] = index.insert({f.t[size_t(k)], uint32_t(out.v.size())});
      if (fresh) out.v.push_back(pts[f.t[size_t(k)]]);
      t[size_t(k)] = it->second;
    }
    out.t.push_back(t);
  }
  return out;
}

bool convexInsideMesh(const PieceMesh& k, const std::vector<Vec3>& v, const std::vector<Tri>& t, double tol) {
  std::vector<Plane> kp;
  Vec3 lo = k.v.at(0), hi = k.v.at(0);
  for (const Vec3& p : k.v)
    for (size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  for (const Tri& f : k.t) {
    Plane pl;
    if (planeOf(k.v[f[0]], k.v[f[1]], k.v[f[2]], &pl)) kp.push_back(pl);
  }
  if (kp.size() < 4) return false;
  const Vec3 c = centroidOf(k.v);
  for (const Plane& pl : kp)
    if (pl.h - dot(pl.n, c) < 2 * tol) return false;  // too thin to tell
  std::vector<Vec3> poly, next;
  for (const Tri& f : t) {
    bool apart = false;
    for (size_t a = 0; a < 3 && !apart; ++a) {
      const double l = std::min({v[f[0]][a], v[f[1]][a], v[f[2]][a]});
      const double h = std::max({v[f[0]][a], v[f[1]][a], v[f[2]][a]});
      apart = l > hi[a] || h < lo[a];
    }
    if (apart) continue;
    if (triangleEnters(v[f[0]], v[f[1]], v[f[2]], kp, tol, poly, next)) return false;  // ∂P enters k
  }
  return windingNumber(v, t, c) > 0.5;
}

std::optional<std::vector<PieceMesh>> convexCover(const std::vector<Vec3>& v, const std::vector<Tri>& t,
                                                  size_t maxPieces, size_t maxCells) {
  if (v.empty() || t.size() < 4 || t.size() > 2048) return std::nullopt;
  Vec3 lo = v[0], hi = v[0];
  for (const Vec3& p : v)
    for (size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  const double diag = norm(sub(hi, lo));
  if (!(diag > 0)) return std::nullopt;
  // tol for the tests, a finer one for the hulls (convexOf checks its pieces at 1e-9 of the
  // operands' extent), a coarser one for cuts (no slivers).
  const double tol = 1e-9 * diag, hullTol = 1e-10 * diag, cutTol = 1e-7 * diag;

  Tool P{v, t, {}, {}, {}};
  P.planes.resize(t.size());
  P.ok.resize(t.size());
  for (size_t f = 0; f < t.size(); ++f) P.ok[f] = planeOf(v[t[f][0]], v[t[f][1]], v[t[f][2]], &P.planes[f]);
  // Edges, manifold and connected (Jordan-Brouwer: the inside of a connected closed surface is
  // connected, as the sum's b0 construction needs).
  std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> byEdge;
  for (size_t f = 0; f < t.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[f][size_t(k)], b = t[f][size_t((k + 1) % 3)];
      byEdge[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  std::vector<size_t> root(t.size());
  for (size_t f = 0; f < t.size(); ++f) root[f] = f;
  auto find = [&](size_t f) {
    while (root[f] != f) f = root[f] = root[root[f]];
    return f;
  };
  // Each reflex edge with the planes of its two faces.
  struct Reflex {
    Vec3 a, b;
    Plane plane;
  };
  std::vector<Reflex> reflex;
  double toolVolume = 0;
  for (const Tri& f : t) toolVolume += dot(v[f[0]], cross(v[f[1]], v[f[2]])) / 6;
  for (const auto& [e, fs] : byEdge) {
    if (fs.size() != 2) return std::nullopt;
    root[find(fs[0])] = find(fs[1]);
    P.edges.push_back({e.first, e.second});
    const size_t f = fs[0], g = fs[1];
    if (!P.ok[f] || !P.ok[g]) continue;
    uint32_t w = t[g][0];
    for (uint32_t x : t[g])
      if (x != e.first && x != e.second) w = x;
    // Reflex: g's far corner lies in front of f's plane.
    if (dot(P.planes[f].n, v[w]) - P.planes[f].h > tol)
      for (size_t h : {f, g}) reflex.push_back({v[e.first], v[e.second], P.planes[h]});
  }
  for (size_t f = 0; f < t.size(); ++f)
    if (find(f) != find(0)) return std::nullopt;
  if (reflex.empty() || !(toolVolume > 0)) return std::nullopt;  // convex: convexOf's case

  // Cells: the bounding box (grown by 1 %) cut by the face planes of the reflex edges that
  // meet it, then in half (at most 3 times) where the part is not one convex piece.
  struct Cell {
    PieceMesh hull;
    Vec3 centroid;
    double volume;
  };
  std::vector<Cell> cells;
  double cellsVolume = 0;
  std::vector<std::pair<std::vector<Plane>, int>> todo(1);
  for (size_t a = 0; a < 3; ++a) {
    Vec3 n{0, 0, 0};
    n[a] = 1;
    todo[0].first.push_back({n, hi[a] + 0.01 * diag});
    n[a] = -1;
    todo[0].first.push_back({n, -(lo[a] - 0.01 * diag)});
  }
  std::vector<Vec3> corners, poly, next;
  std::vector<std::array<size_t, 2>> cellEdges;
  std::vector<Plane> bounding;
  for (size_t visited = 0; !todo.empty(); ++visited) {
    if (visited > 4 * maxCells || cells.size() + todo.size() > maxCells) return std::nullopt;
    auto [cell, halvings] = std::move(todo.back());
    todo.pop_back();
    if (cell.size() >= 64) return std::nullopt;
    corners.clear(), cellEdges.clear(), bounding.clear();
    cellCorners(cell, tol, corners, cellEdges);
    if (corners.size() < 4) continue;
    auto keepCell = [&](PieceMesh hull) {
      const double vol = volumeOf(hull);
      const Vec3 mid = centroidOf(hull.v);
      cellsVolume += vol;
      cells.push_back({std::move(hull), mid, vol});
    };
    // The tool's faces reaching into the cell; none: the cell is all inside or all outside.
    for (size_t f = 0; f < t.size(); ++f)
      if (P.ok[f] && triangleEnters(v[t[f][0]], v[t[f][1]], v[t[f][2]], cell, tol, poly, next))
        bounding.push_back(P.planes[f]);
    if (bounding.empty()) {
      if (windingNumber(v, t, centroidOf(corners)) > 0.5)
        if (std::optional<PieceMesh> whole = convexHullMesh(corners, hullTol)) keepCell(std::move(*whole));
      continue;
    }
    // A reflex edge meeting the cell whose face plane crosses it: cut there.
    std::optional<Plane> cut;
    for (const Reflex& r : reflex) {
      double least = INFINITY, most = -INFINITY;
      for (const Vec3& p : corners)
        least = std::min(least, dot(r.plane.n, p) - r.plane.h), most = std::max(most, dot(r.plane.n, p) - r.plane.h);
      if (!(least < -cutTol && most > cutTol)) continue;
      double t0 = 0, t1 = 1;  // the edge clipped to the cell grown by tol
      for (const Plane& pl : cell) {
        const double da = dot(pl.n, r.a) - pl.h - tol, db = dot(pl.n, r.b) - pl.h - tol;
        if (da > 0 && db > 0) t0 = 1, t1 = 0;
        else if (da > 0) t0 = std::max(t0, da / (da - db));
        else if (db > 0) t1 = std::min(t1, da / (da - db));
      }
      if (t0 <= t1) {
        cut = r.plane;
        break;
      }
    }
    if (!cut) {
      std::optional<PieceMesh> hull =
          convexHullMesh(sectionPoints(P, cell, corners, cellEdges, bounding, tol), hullTol);
      if (hull && convexInsideMesh(*hull, v, t, tol)) {
        keepCell(std::move(*hull));
        continue;
      }
      // Several components (or none): halve the cell's longest side, a few times at most (the
      // volume check below catches what is dropped).
      if (halvings >= 3) continue;
      Vec3 clo = corners[0], chi = corners[0];
      for (const Vec3& p : corners)
        for (size_t a = 0; a < 3; ++a) clo[a] = std::min(clo[a], p[a]), chi[a] = std::max(chi[a], p[a]);
      size_t axis = 0;
      for (size_t a = 1; a < 3; ++a)
        if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
      Plane half{{0, 0, 0}, 0.5 * (clo[axis] + chi[axis])};
      half.n[axis] = 1;
      cut = half;
      ++halvings;
    }
    todo.push_back({cell, halvings});
    todo.back().first.push_back(*cut);
    cell.push_back({scale(cut->n, -1), -cut->h});
    todo.push_back({std::move(cell), halvings});
  }
  // The cells' parts have disjoint insides and lie in the tool: they cover it iff their volumes
  // add up to its volume.
  if (cells.empty() || std::abs(cellsVolume - toolVolume) > 1e-7 * toolVolume) return std::nullopt;

  // Pieces grown from each cell (nearest cells first) while the hull stays in the tool; with
  // many cells, only from cells no earlier piece took in.
  const size_t n = cells.size();
  struct Grown {
    std::vector<bool> has;
    PieceMesh mesh;
    double volume;
  };
  std::vector<Grown> grown;
  std::vector<bool> taken(n, false);
  for (size_t s = 0; s < n; ++s) {
    if (n > 24 && taken[s]) continue;
    Grown g{std::vector<bool>(n, false), cells[s].hull, cells[s].volume};
    g.has[s] = true;
    std::vector<size_t> order;
    for (size_t j = 0; j < n; ++j)
      if (j != s) order.push_back(j);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return norm(sub(cells[a].centroid, cells[s].centroid)) < norm(sub(cells[b].centroid, cells[s].centroid));
    });
    // Only cells touching the piece's box (a far one joins after those between).
    Box box = boxOf(g.mesh.v);
    bool grew = true;
    for (int pass = 0; pass < 2 && grew; ++pass) {
      grew = false;
      for (size_t j : order) {
        if (g.has[j] || !box.touches(boxOf(cells[j].hull.v), tol)) continue;
        if (hullHolds(g.mesh, cells[j].hull, tol)) {
          g.has[j] = true;
          continue;
        }
        std::vector<Vec3> pts = g.mesh.v;
        pts.insert(pts.end(), cells[j].hull.v.begin(), cells[j].hull.v.end());
        std::optional<PieceMesh> h = convexHullMesh(pts, hullTol);
        if (!h || !convexInsideMesh(*h, v, t, tol)) continue;
        g.mesh = std::move(*h);
        g.has[j] = true;
        box = boxOf(g.mesh.v);
        grew = true;
      }
    }
    g.volume = volumeOf(g.mesh);
    for (size_t j = 0; j < n; ++j) taken[j] = taken[j] || g.has[j];
    grown.push_back(std::move(g));
  }
  // Greedy set cover of the cells: most cells not yet covered, then the larger piece.
  std::vector<bool> covered(n, false);
  std::vector<size_t> chosen;
  for (size_t left = n; left > 0;) {
    size_t best = 0, bestCount = 0;
    for (size_t i = 0; i < grown.size(); ++i) {
      size_t count = 0;
      for (size_t j = 0; j < n; ++j) count += grown[i].has[j] && !covered[j];
      if (count > bestCount || (count == bestCount && count > 0 && grown[i].volume > grown[best].volume))
        best = i, bestCount = count;
    }
    if (bestCount == 0) return std::nullopt;
    chosen.push_back(best);
    for (size_t j = 0; j < n; ++j)
      if (grown[best].has[j] && !covered[j]) covered[j] = true, --left;
  }
  if (chosen.size() > maxPieces) return std::nullopt;
  std::vector<PieceMesh> out;
  for (size_t i : chosen) out.push_back(std::move(grown[i].mesh));
  return out;
}

}  // namespace frep::minkowski
