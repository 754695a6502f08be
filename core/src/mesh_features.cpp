// Feature vertices by a QEF per cell, inserted as a fan (mesh_features.h).
//
// The triangles of one grid cell form a patch whose boundary lies on the cell's faces (every
// polygon edge inside the cell is shared by two of the cell's polygons). If the patch is a disc
// with one simple boundary loop and its vertex normals spread (a crease or a corner crosses the
// cell), the point minimising the sum of squared distances to the tangent planes at the cell's
// crossings (a QEF, solved about the mass point with small eigenvalues truncated; Ju et al.'s
// dual contouring uses the same estimate) is clamped strictly inside the cell, and the patch is
// replaced by the fan joining that point to the boundary loop, if the fan seen along the mean
// normal is star-shaped (every fan triangle turns positively, total angle 2 pi). The boundary
// is unchanged, so neighbours still match; the fan stays inside the cell and is a graph over
// the mean normal's plane, so the surface stays embedded (no self-intersection). The vertex on
// the cell's body diagonal, used only by this patch, disappears.
#include "mesh_features.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "frep/eval.h"

namespace frep {

namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations.
void symmetricEigen(double a[3][3], double vec[3][3], double val[3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) vec[i][j] = i == j;
  for (int sweep = 0; sweep < 32; ++sweep) {
    double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    if (off < 1e-30) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (std::abs(a[p][q]) < 1e-300) continue;
        double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          double vkp = vec[k][p], vkq = vec[k][q];
          vec[k][p] = c * vkp - s * vkq;
          vec[k][q] = s * vkp + c * vkq;
        }
      }
  }
  for (int i = 0; i < 3; ++i) val[i] = a[i][i];
}

struct CellPatch {
  uint64_t cell;
  std::vector<uint32_t> tris;  // indices into the triangle list
};

}  // namespace

uint64_t placeFeatureVertices(const FeatureContext& ctx, std::vector<MeshVertex>& verts,
                              std::vector<std::array<uint32_t, 3>>& tris) {
  // Group triangles by cell: the cell is the componentwise minimum of the edges' base points
  // (every Kuhn polygon, and each half of a split quad, has an edge based at the cell's corner).
  std::vector<std::pair<uint64_t, uint32_t>> byCell(tris.size());
  for (size_t t = 0; t < tris.size(); ++t) {
    std::array<int64_t, 3> lo{INT64_MAX, INT64_MAX, INT64_MAX};
    for (uint32_t v : tris[t]) {
      auto p = edgeKeyParts(verts[v].key);
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]);
    }
    byCell[t] = {edgeKey(lo[0], lo[1], lo[2], 0), uint32_t(t)};
  }
  std::sort(byCell.begin(), byCell.end());

  std::vector<char> dropTri(tris.size(), 0);
  std::vector<std::array<uint32_t, 3>> added;
  std::vector<MeshVertex> featureVerts;  // appended after verts (index verts.size() + i)
  GradientEvaluator grad;
  std::vector<double> x(std::max<uint32_t>(ctx.tape.numVars(), 3)), g(x.size());
  uint64_t changed = 0;
  const double h = ctx.grid.voxel;

  for (size_t s = 0; s < byCell.size();) {
    size_t e = s;
    while (e < byCell.size() && byCell[e].first == byCell[s].first) ++e;
    const uint64_t cell = byCell[s].first;
    std::vector<uint32_t> cellTris;
    for (size_t i = s; i < e; ++i) cellTris.push_back(byCell[i].second);
    s = e;

    // Vertices, normal spread.
    std::vector<uint32_t> vs;
    for (uint32_t t : cellTris)
      for (uint32_t v : tris[t]) vs.push_back(v);
    std::sort(vs.begin(), vs.end());
    vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    double minDot = 1;
    for (size_t i = 0; i < vs.size(); ++i)
      for (size_t j = i + 1; j < vs.size(); ++j) minDot = std::min(minDot, dot(verts[vs[i]].normal, verts[vs[j]].normal));
    if (minDot >= ctx.featureCos) continue;

    // Boundary loop: directed edges whose reverse is not in the patch; one simple cycle, and
    // the patch a disc (V - E + F = 1).
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (uint32_t t : cellTris)
      for (int c = 0; c < 3; ++c) directed[{tris[t][c], tris[t][(c + 1) % 3]}]++;
    std::map<uint32_t, uint32_t> next;
    size_t undirected = 0;
    bool ok = true;
    for (const auto& [d, n] : directed) {
      if (n != 1) ok = false;
      bool inner = directed.count({d.second, d.first}) > 0;
      undirected += inner ? (d.first < d.second) : 1;
      if (!inner) {
        if (next.count(d.first)) ok = false;
        next[d.first] = d.second;
      }
    }
    if (!ok || next.size() < 3) continue;
    if (long(vs.size()) - long(undirected) + long(cellTris.size()) != 1) continue;
    std::vector<uint32_t> loop{next.begin()->first};
    while (loop.size() <= next.size()) {
      auto it = next.find(loop.back());
      if (it == next.end()) break;
      if (it->second == loop.front()) break;
      loop.push_back(it->second);
    }
    if (loop.size() != next.size() || next.at(loop.back()) != loop.front()) continue;

    // QEF about the mass point.
    V3 mass{0, 0, 0}, nsum{0, 0, 0};
    for (uint32_t v : vs)
      for (int c = 0; c < 3; ++c) mass[c] += verts[v].position[c] / double(vs.size()), nsum[c] += verts[v].normal[c];
    double A[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, r[3] = {0, 0, 0};
    for (uint32_t v : vs) {
      const V3& n = verts[v].normal;
      double d = dot(n, sub(verts[v].position, mass));
      for (int i = 0; i < 3; ++i) {
        r[i] += n[i] * d;
        for (int j = 0; j < 3; ++j) A[i][j] += n[i] * n[j];
      }
    }
    double vec[3][3], val[3];
    symmetricEigen(A, vec, val);
    double vmax = std::max({std::abs(val[0]), std::abs(val[1]), std::abs(val[2])});
    V3 f = mass;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(val[k]) < 0.05 * vmax) continue;
      double proj = vec[0][k] * r[0] + vec[1][k] * r[1] + vec[2][k] * r[2];
      for (int c = 0; c < 3; ++c) f[c] += vec[c][k] * proj / val[k];
    }
    auto cp = edgeKeyParts(cell);
    for (int c = 0; c < 3; ++c) {
      double lo = ctx.grid.origin[c] + double(cp[c]) * h, margin = 0.01 * h;
      f[c] = std::min(std::max(f[c], lo + margin), lo + h - margin);
      if (!std::isfinite(f[c])) ok = false;
    }
    if (!ok) continue;
    // Star-shaped along some direction N: every fan triangle turns positively, total 2 pi.
    // Candidates: the mean vertex normal, the mean of the distinct normals (a corner seen from
    // its axis), the fan's own area-weighted normal.
    std::vector<V3> distinct;
    for (uint32_t v : vs) {
      bool seen = false;
      for (const V3& d : distinct) seen = seen || dot(d, verts[v].normal) > 0.99;
      if (!seen) distinct.push_back(verts[v].normal);
    }
    V3 dsum{0, 0, 0}, fsum{0, 0, 0};
    for (const V3& d : distinct)
      for (int c = 0; c < 3; ++c) dsum[c] += d[c];
    for (size_t i = 0; i < loop.size(); ++i) {
      V3 cr = cross(sub(verts[loop[i]].position, f), sub(verts[loop[(i + 1) % loop.size()]].position, f));
      for (int c = 0; c < 3; ++c) fsum[c] += cr[c];
    }
    auto starShaped = [&](V3 N) {
      double nlen = std::sqrt(dot(N, N));
      if (!(nlen > 1e-12)) return false;
      for (double& c : N) c /= nlen;
      V3 u = std::abs(N[0]) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0};
      u = cross(N, u);
      double ul = std::sqrt(dot(u, u));
      for (double& c : u) c /= ul;
      V3 w = cross(N, u);
      double total = 0;
      for (size_t i = 0; i < loop.size(); ++i) {
        V3 a = sub(verts[loop[i]].position, f), b = sub(verts[loop[(i + 1) % loop.size()]].position, f);
        double ax = dot(a, u), ay = dot(a, w), bx = dot(b, u), by = dot(b, w);
        double crs = ax * by - ay * bx;
        if (!(crs > 1e-9 * h * h)) return false;
        total += std::atan2(crs, ax * bx + ay * by);
      }
      return std::abs(total - 2 * M_PI) < 1e-6;
    };
    V3 N = nsum;
    if (!starShaped(N)) N = dsum;
    if (!starShaped(N)) N = fsum;
    if (!starShaped(N)) continue;
    {
      double nlen = std::sqrt(dot(N, N));
      for (double& c : N) c /= nlen;
    }
    for (size_t i = 0; i < loop.size() && ok; ++i) {
      V3 a = sub(verts[loop[i]].position, f), b = sub(verts[loop[(i + 1) % loop.size()]].position, f);
      double area = 0.5 * std::sqrt(dot(cross(a, b), cross(a, b)));
      if (!(area > 1e-7 * h * h)) ok = false;
    }
    if (!ok) continue;

    // Apply: the fan, the feature vertex (normal -grad f there, else N).
    MeshVertex fv;
    fv.key = cell;  // direction 0: the cell itself
    fv.position = f;
    for (size_t c = 0; c < x.size(); ++c) x[c] = c < 3 ? f[c] : ctx.fixedCoords[c - 3];
    std::fill(g.begin(), g.end(), 0.0);
    grad.eval(ctx.tape, x.data(), g.data());
    V3 gn{-g[0], -g[1], -g[2]};
    double gl = std::sqrt(dot(gn, gn));
    fv.normal = gl > 0 && std::isfinite(gl) ? V3{gn[0] / gl, gn[1] / gl, gn[2] / gl} : N;
    const uint32_t fi = uint32_t(verts.size() + featureVerts.size());
    featureVerts.push_back(fv);
    for (uint32_t t : cellTris) dropTri[t] = 1;
    for (size_t i = 0; i < loop.size(); ++i) added.push_back({fi, loop[i], loop[(i + 1) % loop.size()]});
    ++changed;
  }
  if (changed == 0) return 0;

  // Rebuild: keep used vertices, sorted by key.
  std::vector<std::array<uint32_t, 3>> out;
  out.reserve(tris.size() + added.size());
  for (size_t t = 0; t < tris.size(); ++t)
    if (!dropTri[t]) out.push_back(tris[t]);
  out.insert(out.end(), added.begin(), added.end());
  std::vector<MeshVertex> all = verts;
  all.insert(all.end(), featureVerts.begin(), featureVerts.end());
  std::vector<char> used(all.size(), 0);
  for (const auto& t : out)
    for (uint32_t v : t) used[v] = 1;
  std::vector<uint32_t> order;
  for (uint32_t i = 0; i < all.size(); ++i)
    if (used[i]) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return all[a].key < all[b].key; });
  std::vector<uint32_t> remap(all.size(), UINT32_MAX);
  verts.clear();
  for (uint32_t i = 0; i < order.size(); ++i) {
    remap[order[i]] = i;
    verts.push_back(all[order[i]]);
  }
  for (auto& t : out)
    for (uint32_t& v : t) v = remap[v];
  tris = std::move(out);
  return changed;
}

}  // namespace frep
