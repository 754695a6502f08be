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
#include "frep/expressions/field_function.h"
#include "frep/extremum/extremum.h"

#include <malloc.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
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

namespace frep {

std::string closureDefect(const std::vector<std::array<uint32_t, 3>>& triangles, size_t numVertices,
                          uint64_t* unpaired) {
  std::string first;
  uint64_t bad = 0;
  std::vector<uint64_t> edges;  // (a << 32) | b per directed edge
  edges.reserve(3 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = triangles[t][size_t(c)], b = triangles[t][size_t((c + 1) % 3)];
      if (a >= numVertices || b >= numVertices || a == b) {
        if (first.empty())
          first = "triangle " + std::to_string(t) + (a == b ? " repeats a vertex" : " has a bad index");
        ++bad;
        continue;
      }
      edges.push_back((uint64_t(a) << 32) | b);
    }
  tbb::parallel_sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size(); ++i) {
    const uint32_t a = uint32_t(edges[i] >> 32), b = uint32_t(edges[i]);
    // The edge's name only for the first defect: every mesh written passes through here.
    auto name = [&] { return std::to_string(a) + "->" + std::to_string(b); };
    if (i + 1 < edges.size() && edges[i + 1] == edges[i]) {
      if (first.empty()) first = "directed edge " + name() + " occurs twice";
      ++bad;
      continue;
    }
    if (!std::binary_search(edges.begin(), edges.end(), (uint64_t(b) << 32) | a)) {
      if (first.empty()) first = "edge " + name() + " has no opposite";
      ++bad;
    }
  }
  if (unpaired) *unpaired = bad;
  return first;
}

double rawMeshErrorBound(const Mesh& mesh, const Tape& tape, const GridSpec& grid, double endGuard) {
  double longest2 = 0;
  // Triangles a collapse made (a farm brick's own simplification) are the simplifier's to bound.
  const std::vector<uint8_t>& made = mesh.carry.triangles;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (made.size() == mesh.triangles.size() && (made[i] & 0x80)) continue;
    const auto& t = mesh.triangles[i];
    for (int c = 0; c < 3; ++c) {
      const auto& a = mesh.positions[t[size_t(c)]];
      const auto& b = mesh.positions[t[size_t((c + 1) % 3)]];
      const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
      longest2 = std::max(longest2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
  }
  double search = 0;
  for (const ExtremumEntry& e : tape.extrema()) {
    const ExtremumSpec& s = *e.spec;
    search = std::max(search, s.method == ExtremumMethod::BranchAndBound
                                  ? s.tolerance
                                  : std::sqrt(double(s.numParams())) / 2.0 * s.eps);  // Pasko-Minkowski §4's d
  }
  double sampled = 0;  // sampled operands' own bounds (field_function.h)
  for (const auto& f : tape.fields()) sampled = std::max(sampled, f->setErrorBound());
  return std::sqrt(longest2 / 3.0) + endGuard * std::sqrt(3.0) * grid.voxel + search + sampled;
}

}  // namespace frep
