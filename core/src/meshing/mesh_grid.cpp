// Marching tetrahedra on sampled values (see mesh_grid.h). Each leaf is meshed on its own from a
// 12^3 window of values (the leaf, one voxel before it and three after it: the corners of its
// cells and their central differences), so a vertex depends only on its edge's data and every
// leaf that uses an edge computes the same vertex; the pieces are then merged by edge key.
#include "frep/meshing/mesh_grid.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "meshing/kuhn_tables.h"
#include "sampling/parallel_chunks.h"

namespace frep {

namespace {

constexpr int W = 12;  // window: indices o - 1 .. o + 10 per axis

enum : uint8_t { kUnknown = 0, kSignOnly = 1, kActive = 2 };

struct Window {
  float v[W][W][W];
  uint8_t state[W][W][W];
};

struct ThreadOutput {
  std::vector<MeshVertex> vertices;  // per leaf sorted and unique; repeats across leaves
  std::vector<std::array<EdgeKey, 3>> tris;
  uint64_t cellsVisited = 0, cellsCrossed = 0, incomplete = 0;
  Window window;
  std::vector<std::array<EdgeKey, 4>> quads;  // scratch, per leaf
  std::vector<EdgeKey> edges;                 // scratch, per leaf
  std::vector<MeshVertex> leafVerts;          // scratch, per leaf
};

class SampledMesher {
 public:
  SampledMesher(const SampleResult& s, const SampledMeshOptions& opt) : s_(s), opt_(opt) {
    if (!(opt.endGuard >= 0 && opt.endGuard < 0.5)) throw std::invalid_argument("meshSamples: endGuard must be in [0, 0.5)");
    for (int a = 0; a < 3; ++a)
      if (s.grid.dims[a] >= kMaxMeshGridPoints)
        throw std::invalid_argument("meshSamples: grid too large (2^19 points per axis)");
    background_ = float(s.bandVoxels * s.grid.voxel);
    leafIndex_.reserve(s.leaves.size() * 2);
    for (const LeafBlock& l : s.leaves) {
      for (int a = 0; a < 3; ++a)
        if (l.origin[a] < 0 || l.origin[a] % kLeafDim != 0 || l.origin[a] >= kMaxMeshGridPoints)
          throw std::invalid_argument("meshSamples: leaf origins must be non-negative multiples of 8");
      if (!leafIndex_.emplace(blockKey(l.origin[0], l.origin[1], l.origin[2]), &l).second)
        throw std::invalid_argument("meshSamples: two leaves at the same origin");
    }
    for (const Tile& t : s.tiles) {
      if (t.origin[0] < 0 || t.origin[1] < 0 || t.origin[2] < 0 || t.size < kLeafDim) continue;
      tileSign_[tileKey(t.origin[0], t.origin[1], t.origin[2], t.size)] = t.inside;
      maxTile_ = std::max<int64_t>(maxTile_, t.size);
    }
  }

  SampledMesh run() {
    tbb::enumerable_thread_specific<ThreadOutput> outs;
    parallelChunks(s_.leaves.size(), 4, opt_.threads, [&](size_t b, size_t e) {
      ThreadOutput& out = outs.local();
      for (size_t i = b; i < e; ++i) meshLeaf(out, s_.leaves[i]);
    });

    SampledMesh result;
    MeshStats& st = result.mesh.stats;
    std::vector<MeshVertex> verts;
    size_t nv = 0, nt = 0;
    for (const ThreadOutput& o : outs) {
      nv += o.vertices.size();
      nt += o.tris.size();
    }
    verts.reserve(nv);
    for (ThreadOutput& o : outs) {
      st.cellsVisited += o.cellsVisited;
      st.cellsCrossed += o.cellsCrossed;
      result.incompleteCells += o.incomplete;
      verts.insert(verts.end(), o.vertices.begin(), o.vertices.end());
      std::vector<MeshVertex>().swap(o.vertices);
    }
    // Every copy of a vertex is the same record (it depends on its edge only): unique by key.
    tbb::parallel_sort(verts.begin(), verts.end(), [](const MeshVertex& a, const MeshVertex& b) { return a.key < b.key; });
    verts.erase(std::unique(verts.begin(), verts.end(),
                            [](const MeshVertex& a, const MeshVertex& b) { return a.key == b.key; }),
                verts.end());
    Mesh& mesh = result.mesh;
    mesh.positions.reserve(verts.size());
    mesh.normals.reserve(verts.size());
    mesh.keys.reserve(verts.size());
    for (const MeshVertex& v : verts) {
      mesh.positions.push_back(v.position);
      mesh.normals.push_back(v.normal);
      mesh.keys.push_back(v.key);
    }
    std::vector<MeshVertex>().swap(verts);

    // Key -> index (open addressing; keys never equal ~0).
    size_t cap = 16;
    while (cap < 2 * mesh.keys.size()) cap *= 2;
    const size_t mask = cap - 1;
    std::vector<uint64_t> slotKey(cap, ~uint64_t(0));
    std::vector<uint32_t> slotIndex(cap);
    auto slot = [&](uint64_t k) { return size_t((k * 0x9E3779B97F4A7C15ull) >> 20) & mask; };
    for (size_t i = 0; i < mesh.keys.size(); ++i) {
      size_t h = slot(mesh.keys[i]);
      while (slotKey[h] != ~uint64_t(0)) h = (h + 1) & mask;
      slotKey[h] = mesh.keys[i];
      slotIndex[h] = uint32_t(i);
    }
    auto indexOf = [&](EdgeKey k) {
      for (size_t h = slot(k);; h = (h + 1) & mask) {
        if (slotKey[h] == k) return slotIndex[h];
        if (slotKey[h] == ~uint64_t(0)) throw std::logic_error("meshSamples: a triangle's vertex is missing");
      }
    };
    mesh.triangles.reserve(nt);
    for (ThreadOutput& o : outs) {
      for (const auto& t : o.tris) {
        std::array<uint32_t, 3> r{indexOf(t[0]), indexOf(t[1]), indexOf(t[2])};
        canonicalRotate(r);
        mesh.triangles.push_back(r);
      }
      std::vector<std::array<EdgeKey, 3>>().swap(o.tris);
    }
    tbb::parallel_sort(mesh.triangles.begin(), mesh.triangles.end());
    mesh.triangles.erase(std::unique(mesh.triangles.begin(), mesh.triangles.end()), mesh.triangles.end());
    return result;
  }

 private:
  static uint64_t blockKey(int64_t i, int64_t j, int64_t k) { return edgeKey(i, j, k, 0); }
  static uint64_t tileKey(int64_t i, int64_t j, int64_t k, int64_t size) {
    int lg = 0;
    while ((int64_t(1) << lg) < size) ++lg;
    return edgeKey(i, j, k, 0) | uint64_t(lg);  // origins are multiples of 8: the low bits are free
  }

  // The 8^3 block at origin b: a leaf, a tile's sign (+1 / -1), or unknown (0).
  const LeafBlock* blockSource(int64_t bx, int64_t by, int64_t bz, int& tile) const {
    tile = 0;
    if (bx < 0 || by < 0 || bz < 0 || bx >= kMaxMeshGridPoints || by >= kMaxMeshGridPoints || bz >= kMaxMeshGridPoints)
      return nullptr;
    auto it = leafIndex_.find(blockKey(bx, by, bz));
    if (it != leafIndex_.end()) return it->second;
    for (int64_t size = kLeafDim; size <= maxTile_; size *= 2) {
      auto t = tileSign_.find(tileKey(bx / size * size, by / size * size, bz / size * size, size));
      if (t != tileSign_.end()) {
        tile = t->second ? 1 : -1;
        return nullptr;
      }
    }
    return nullptr;
  }

  void fillWindow(Window& w, const LeafBlock& leaf) const {
    const int64_t o[3] = {leaf.origin[0], leaf.origin[1], leaf.origin[2]};
    // Per axis: block step d in {-1, 0, 1} covers window indices [wlo, whi) and block indices from blo.
    const int wlo[3] = {0, 1, 9}, whi[3] = {1, 9, 12}, blo[3] = {7, 0, 0};
    for (int dx = 0; dx < 3; ++dx)
      for (int dy = 0; dy < 3; ++dy)
        for (int dz = 0; dz < 3; ++dz) {
          const LeafBlock* src = &leaf;
          int tile = 0;
          if (dx != 1 || dy != 1 || dz != 1)
            src = blockSource(o[0] + 8 * (dx - 1), o[1] + 8 * (dy - 1), o[2] + 8 * (dz - 1), tile);
          for (int x = wlo[dx]; x < whi[dx]; ++x)
            for (int y = wlo[dy]; y < whi[dy]; ++y)
              for (int z = wlo[dz]; z < whi[dz]; ++z) {
                if (src) {
                  const int off = leafOffset(blo[dx] + x - wlo[dx], blo[dy] + y - wlo[dy], blo[dz] + z - wlo[dz]);
                  w.v[x][y][z] = src->values[size_t(off)];
                  w.state[x][y][z] = src->isActive(off) ? kActive : kSignOnly;
                } else {
                  w.v[x][y][z] = tile > 0 ? background_ : -background_;
                  w.state[x][y][z] = tile ? kSignOnly : kUnknown;
                }
              }
        }
  }

  // Central-difference gradient of f at window point (x, y, z), in index units; one-sided where
  // a neighbour is unknown (or NaN), 0 along an axis with neither.
  void gradient(const Window& w, int x, int y, int z, double g[3]) const {
    const int p[3] = {x, y, z};
    const double f0 = w.v[x][y][z];
    for (int a = 0; a < 3; ++a) {
      int q[3] = {p[0], p[1], p[2]}, r[3] = {p[0], p[1], p[2]};
      ++q[a];
      --r[a];
      const bool hasP = q[a] < W && w.state[q[0]][q[1]][q[2]] != kUnknown && !std::isnan(w.v[q[0]][q[1]][q[2]]);
      const bool hasM = r[a] >= 0 && w.state[r[0]][r[1]][r[2]] != kUnknown && !std::isnan(w.v[r[0]][r[1]][r[2]]);
      const double fp = hasP ? double(w.v[q[0]][q[1]][q[2]]) : 0.0, fm = hasM ? double(w.v[r[0]][r[1]][r[2]]) : 0.0;
      if (hasP && hasM) g[a] = 0.5 * (fp - fm);
      else if (hasP) g[a] = fp - f0;
      else if (hasM) g[a] = f0 - fm;
      else g[a] = 0.0;
    }
  }

  // The vertex of the crossed edge from window point b along dir (3-bit steps).
  MeshVertex vertex(const Window& w, const int64_t o[3], int bx, int by, int bz, int dir) const {
    const int d[3] = {dir & 1, (dir >> 1) & 1, (dir >> 2) & 1};
    const int ex = bx + d[0], ey = by + d[1], ez = bz + d[2];
    const double f0 = w.v[bx][by][bz], f1 = w.v[ex][ey][ez];
    double t = 0.5;
    if (std::isfinite(f0) && std::isfinite(f1) && f0 != f1) t = f0 / (f0 - f1);
    if (!(t >= opt_.endGuard)) t = opt_.endGuard;
    if (t > 1.0 - opt_.endGuard) t = 1.0 - opt_.endGuard;
    MeshVertex v;
    const int64_t base[3] = {o[0] + bx - 1, o[1] + by - 1, o[2] + bz - 1};
    v.key = edgeKey(base[0], base[1], base[2], dir);
    for (int a = 0; a < 3; ++a) v.position[a] = s_.grid.origin[a] + (double(base[a]) + t * d[a]) * s_.grid.voxel;
    double g0[3], g1[3], n[3];
    gradient(w, bx, by, bz, g0);
    gradient(w, ex, ey, ez, g1);
    for (int a = 0; a < 3; ++a) n[a] = -((1.0 - t) * g0[a] + t * g1[a]);
    double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0) || !std::isfinite(len)) {  // the edge's direction, inside -> outside
      const double s = insideValue(f0) ? 1.0 : -1.0;
      for (int a = 0; a < 3; ++a) n[a] = s * d[a];
      len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    for (int a = 0; a < 3; ++a) v.normal[a] = n[a] / len;
    return v;
  }

  void meshLeaf(ThreadOutput& out, const LeafBlock& leaf) {
    const int64_t o[3] = {leaf.origin[0], leaf.origin[1], leaf.origin[2]};
    int end[3];  // cells [0, end) of the leaf, local
    for (int a = 0; a < 3; ++a) end[a] = int(std::min<int64_t>(kLeafDim, int64_t(s_.grid.dims[a]) - 1 - o[a]));
    if (end[0] <= 0 || end[1] <= 0 || end[2] <= 0) return;
    Window& w = out.window;
    fillWindow(w, leaf);
    out.edges.clear();
    out.quads.clear();
    out.leafVerts.clear();
    for (int x = 0; x < end[0]; ++x)
      for (int y = 0; y < end[1]; ++y)
        for (int z = 0; z < end[2]; ++z) {
          ++out.cellsVisited;
          unsigned mask = 0, known = 0;
          bool complete = true;
          for (int c = 0; c < 8; ++c) {
            const int cx = x + 1 + (c & 1), cy = y + 1 + ((c >> 1) & 1), cz = z + 1 + ((c >> 2) & 1);
            const uint8_t st = w.state[cx][cy][cz];
            if (st != kActive) complete = false;
            if (st != kUnknown) {
              known |= 1u << c;
              mask |= unsigned(insideValue(w.v[cx][cy][cz])) << c;
            }
          }
          if (!complete) {
            if ((mask & known) != 0 && (mask & known) != known) ++out.incomplete;
            continue;
          }
          if (mask == 0 || mask == 255) continue;
          ++out.cellsCrossed;
          // The same cell polygons as the model mesher's (kuhn_tables.h).
          forCellPolygons(
              mask, o[0] + x, o[1] + y, o[2] + z, edgeKey, [&](EdgeKey k, bool) { out.edges.push_back(k); },
              [&](const EdgeKey* k, int n) {
                if (n == 3) out.tris.push_back({k[0], k[1], k[2]});
                else out.quads.push_back({k[0], k[1], k[2], k[3]});
              });
        }
    if (out.edges.empty()) return;
    std::sort(out.edges.begin(), out.edges.end());
    out.edges.erase(std::unique(out.edges.begin(), out.edges.end()), out.edges.end());
    for (EdgeKey k : out.edges) {
      auto p = edgeKeyParts(k);
      out.leafVerts.push_back(vertex(w, o, int(p[0] - o[0] + 1), int(p[1] - o[1] + 1), int(p[2] - o[2] + 1), int(p[3])));
    }
    // Quads: split along the shorter diagonal (ties: 0-2), from the quad alone (as meshGrid).
    for (const auto& q : out.quads) {
      const std::array<double, 3>* p[4];
      for (int c = 0; c < 4; ++c) {
        size_t i = size_t(std::lower_bound(out.edges.begin(), out.edges.end(), q[c]) - out.edges.begin());
        p[c] = &out.leafVerts[i].position;
      }
      splitKuhnQuad(q, p, out.tris);
    }
    out.vertices.insert(out.vertices.end(), out.leafVerts.begin(), out.leafVerts.end());
  }

  const SampleResult& s_;
  SampledMeshOptions opt_;
  float background_ = 0;
  std::unordered_map<uint64_t, const LeafBlock*> leafIndex_;
  std::unordered_map<uint64_t, bool> tileSign_;
  int64_t maxTile_ = kLeafDim;
};

}  // namespace

SampledMesh meshSamples(const SampleResult& samples, const SampledMeshOptions& options) {
  return SampledMesher(samples, options).run();
}

}  // namespace frep
