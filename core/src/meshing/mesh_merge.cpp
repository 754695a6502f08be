// mergePieces (mesh.h) and mergePiecesReleasing (mesh_merge.h): one merge, which the latter runs
// while freeing each piece once it has been consumed.
//
// (1) Only the keys are gathered and sorted; (2) the mesh's positions and normals are filled
// piece by piece and each piece's triangles remapped (mergePiecesReleasing then frees the piece,
// handing the memory back to the system every few pieces, so it holds about one copy of the
// output instead of three); (3) the triangles are sorted. Where two pieces disagree on a shared
// vertex (they never do: a vertex depends on its edge only) the smaller record (position, then
// normal) wins, so the result is the same whatever the order of the pieces.
#include "frep/meshing/mesh_merge.h"

#include <malloc.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <tuple>

namespace frep {

namespace {
// The merge of both entry points; `consumed(i)`, when given, is called once piece i has been
// stitched (it is not read again).
Mesh mergeKeyed(const std::vector<MeshPiece>& pieces, const std::function<void(size_t)>& consumed) {
  Mesh mesh;
  size_t nv = 0, nt = 0;
  bool withStates = false;  // some piece carries triangle states: they follow the sort
  for (const MeshPiece& p : pieces) {
    nv += p.vertices.size();
    nt += p.triangles.size();
    MeshStats& s = mesh.stats;
    s.cellsVisited += p.stats.cellsVisited;
    s.cellsCrossed += p.stats.cellsCrossed;
    s.rootEvals += p.stats.rootEvals;
    s.gradientEvals += p.stats.gradientEvals;
    s.samplePointEvals += p.stats.samplePointEvals;
    s.fallbackEdges += p.stats.fallbackEdges;
    s.sampleIntervalEvals += p.stats.sampleIntervalEvals;
    s.nanValues += p.stats.nanValues;
    s.domainErrors.add(p.stats.domainErrors);
    const SimplifyCarry& c = p.carry;
    mesh.carry.counters += c.counters;
    if (!c.triangles.empty() && c.triangles.size() != p.triangles.size())
      throw std::invalid_argument("mergePieces: a piece's triangle states do not match its triangles");
    withStates = withStates || !c.triangles.empty();
    for (size_t i = 1; i < p.vertices.size(); ++i)
      if (p.vertices[i].key <= p.vertices[i - 1].key)
        throw std::invalid_argument("mergePieces: piece vertices not sorted by key");
  }
  {
    std::vector<EdgeKey> keys;
    keys.reserve(nv);
    for (const MeshPiece& p : pieces)
      for (const MeshVertex& v : p.vertices) keys.push_back(v.key);
    tbb::parallel_sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    mesh.keys.assign(keys.begin(), keys.end());  // exact size
  }
  const size_t n = mesh.keys.size();
  mesh.positions.resize(n);
  mesh.normals.resize(n);
  std::vector<uint8_t> filled(n, 0);
  mesh.triangles.reserve(nt);
  struct Stated {
    std::array<uint32_t, 3> t;
    uint8_t state;
    bool operator<(const Stated& o) const { return t != o.t ? t < o.t : state < o.state; }
    bool operator==(const Stated& o) const { return t == o.t; }
  };
  std::vector<Stated> stated;
  if (withStates) stated.reserve(nt);
  std::vector<uint32_t> remap;
  for (size_t pi = 0; pi < pieces.size(); ++pi) {
    const MeshPiece& p = pieces[pi];
    remap.resize(p.vertices.size());
    size_t g = 0;
    if (!p.vertices.empty())
      g = size_t(std::lower_bound(mesh.keys.begin(), mesh.keys.end(), p.vertices[0].key) - mesh.keys.begin());
    for (size_t i = 0; i < p.vertices.size(); ++i) {
      const MeshVertex& v = p.vertices[i];
      while (mesh.keys[g] < v.key) ++g;
      remap[i] = uint32_t(g);
      if (!filled[g] || v.position < mesh.positions[g] || (v.position == mesh.positions[g] && v.normal < mesh.normals[g])) {
        mesh.positions[g] = v.position;
        mesh.normals[g] = v.normal;
        filled[g] = 1;
      }
    }
    for (const SimplifyCarry::Vertex& v : p.carry.vertices) {
      if (v.index >= remap.size()) throw std::invalid_argument("mergePieces: a carried vertex past its piece's vertices");
      mesh.carry.vertices.push_back(v);
      mesh.carry.vertices.back().index = remap[v.index];
    }
    for (size_t i = 0; i < p.triangles.size(); ++i) {
      const auto& t = p.triangles[i];
      if (t[0] >= remap.size() || t[1] >= remap.size() || t[2] >= remap.size())
        throw std::invalid_argument("mergePieces: a triangle indexes past its piece's vertices");
      std::array<uint32_t, 3> r{remap[t[0]], remap[t[1]], remap[t[2]]};
      canonicalRotate(r);
      if (withStates)
        stated.push_back({r, p.carry.triangles.empty() ? uint8_t(0) : p.carry.triangles[i]});
      else
        mesh.triangles.push_back(r);
    }
    if (consumed) consumed(pi);
  }
  if (withStates) {
    tbb::parallel_sort(stated.begin(), stated.end());
    stated.erase(std::unique(stated.begin(), stated.end()), stated.end());
    mesh.triangles.resize(stated.size());
    mesh.carry.triangles.resize(stated.size());
    for (size_t i = 0; i < stated.size(); ++i) mesh.triangles[i] = stated[i].t, mesh.carry.triangles[i] = stated[i].state;
  } else {
    tbb::parallel_sort(mesh.triangles.begin(), mesh.triangles.end());
    mesh.triangles.erase(std::unique(mesh.triangles.begin(), mesh.triangles.end()), mesh.triangles.end());
  }
  // A vertex is carried by the one piece whose block simplified it (seam vertices never are);
  // should two pieces carry it, the smaller record wins, whatever the order of the pieces.
  auto& cv = mesh.carry.vertices;
  std::sort(cv.begin(), cv.end(), [](const SimplifyCarry::Vertex& x, const SimplifyCarry::Vertex& y) {
    return std::tie(x.index, x.quadric, x.moved, x.settled) < std::tie(y.index, y.quadric, y.moved, y.settled);
  });
  cv.erase(std::unique(cv.begin(), cv.end(), [](const SimplifyCarry::Vertex& x, const SimplifyCarry::Vertex& y) {
             return x.index == y.index;
           }), cv.end());
  return mesh;
}

}  // namespace

Mesh mergePieces(const std::vector<MeshPiece>& pieces) { return mergeKeyed(pieces, nullptr); }

Mesh mergePiecesReleasing(std::vector<MeshPiece>& pieces, bool trimHeap) {
  size_t released = 0;
  Mesh mesh = mergeKeyed(pieces, [&](size_t i) {
    std::vector<MeshVertex>().swap(pieces[i].vertices);
    std::vector<std::array<uint32_t, 3>>().swap(pieces[i].triangles);
    pieces[i].carry = SimplifyCarry();
    // hand the freed pieces back (they are small heap blocks)
    if (trimHeap && ++released % 16 == 0) malloc_trim(0);
  });
  if (trimHeap) malloc_trim(0);
  return mesh;
}

}  // namespace frep
