// Mesh slicing and the CLI writer (cli_slices.h). A plane z = h cuts a triangle whose corners are
// on both sides (a corner counts as above when z >= h, so no corner lies on the plane) in one
// segment between two of its edges. The crossing point of an edge is computed from its two
// vertices in index order, so both triangles of the edge get the same point, and the segment
// runs from the edge its winding crosses downwards to the one it crosses upwards: along z × n,
// counter-clockwise around material seen from +z. Segments chain by their edges into contours.
#include "frep/io/cli_slices.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_map>

#include "byte_sink.h"

namespace frep::io {

namespace {

using EdgeId = uint64_t;  // (smaller vertex index << 32) | larger
EdgeId edgeOf(uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a; }

std::array<double, 2> crossing(const Mesh& m, EdgeId e, double h) {
  const auto& p = m.positions[e >> 32];
  const auto& q = m.positions[e & 0xffffffffu];
  const double t = (h - p[2]) / (q[2] - p[2]);
  return {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
}

SliceLayer cut(const Mesh& m, double h) {
  SliceLayer layer;
  std::unordered_map<EdgeId, EdgeId> next;  // segment start edge -> end edge
  std::unordered_map<EdgeId, int> ends;     // how many segments end at an edge
  for (const auto& t : m.triangles) {
    bool above[3];
    for (int v = 0; v < 3; ++v) above[v] = m.positions[t[v]][2] >= h;
    if (above[0] == above[1] && above[1] == above[2]) continue;
    EdgeId down = 0, up = 0;
    for (int v = 0; v < 3; ++v) {
      const uint32_t a = t[v], b = t[(v + 1) % 3];
      if (above[v] && !above[(v + 1) % 3]) down = edgeOf(a, b);
      if (!above[v] && above[(v + 1) % 3]) up = edgeOf(a, b);
    }
    next[down] = up;
    ++ends[up];
  }
  // Starts: open chains first (a start no segment ends at), then the rest of the closed loops,
  // each from its smallest edge (std::map keeps the order).
  std::map<EdgeId, EdgeId> ordered(next.begin(), next.end());
  std::unordered_map<EdgeId, bool> used;
  auto walk = [&](EdgeId start, bool open) {
    SliceContour c;
    c.direction = open ? 2 : 1;
    EdgeId e = start;
    c.points.push_back(crossing(m, e, h));
    while (true) {
      used[e] = true;
      auto it = next.find(e);
      if (it == next.end()) break;  // an open chain ends
      e = it->second;
      c.points.push_back(crossing(m, e, h));
      if (e == start || used.count(e)) break;
    }
    if (!open) {
      double area = 0;  // shoelace: positive when counter-clockwise
      for (size_t i = 0; i + 1 < c.points.size(); ++i)
        area += c.points[i][0] * c.points[i + 1][1] - c.points[i + 1][0] * c.points[i][1];
      c.direction = area >= 0 ? 1 : 0;
    }
    layer.contours.push_back(std::move(c));
  };
  for (const auto& [start, end] : ordered)
    if (!ends.count(start) && !used.count(start)) walk(start, true);
  for (const auto& [start, end] : ordered) {
    // The smallest edge of an unvisited loop is the first one met in key order.
    if (!used.count(start)) walk(start, false);
  }
  return layer;
}

}  // namespace

std::vector<SliceLayer> sliceMesh(const Mesh& mesh, double zMin, double zMax, double thickness) {
  std::vector<SliceLayer> layers;
  if (!(thickness > 0) || !(zMax > zMin)) return layers;
  const long n = long(std::floor((zMax - zMin) / thickness + 1e-9));
  for (long k = 1; k <= n; ++k) {
    const double top = zMin + double(k) * thickness;
    SliceLayer layer = cut(mesh, top - thickness / 2);
    layer.top = top;
    layer.cut = top - thickness / 2;
    layers.push_back(std::move(layer));
  }
  return layers;
}

void writeCli(const std::string& path, const std::vector<SliceLayer>& layers, const CliOptions& o) {
  detail::Bytes b(path);
  char buf[256];
  auto num = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return std::string(buf);
  };
  b.text("$$HEADERSTART\n");
  b.text(o.binary ? "$$BINARY\n" : "$$ASCII\n");
  b.text("$$UNITS/" + num(o.units) + "\n$$VERSION/200\n");
  if (!o.label.empty()) b.text("$$LABEL/1," + detail::oneLine(o.label) + "\n");
  b.text("$$DIMENSION/");
  for (int i = 0; i < 6; ++i) b.text((i ? "," : "") + num(o.dimension[i]));
  b.text("\n$$LAYERS/" + std::to_string(layers.size()) + "\n$$HEADEREND");
  if (o.binary) {
    // Long-form binary commands (little-endian): 127 start layer (real32 z), 130 polyline
    // (int32 id, int32 direction, int32 n, then n x/y pairs as real32).
    for (const auto& layer : layers) {
      b.u16(127);
      b.f32(float(layer.top));
      for (const auto& c : layer.contours) {
        b.u16(130);
        b.u32(1);
        b.u32(uint32_t(c.direction));
        b.u32(uint32_t(c.points.size()));
        for (const auto& p : c.points) {
          b.f32(float(p[0]));
          b.f32(float(p[1]));
        }
      }
    }
  } else {
    b.text("\n$$GEOMETRYSTART\n");
    for (const auto& layer : layers) {
      b.text("$$LAYER/" + num(layer.top) + "\n");
      for (const auto& c : layer.contours) {
        b.text("$$POLYLINE/1," + std::to_string(c.direction) + "," + std::to_string(c.points.size()));
        for (const auto& p : c.points) b.text("," + num(p[0]) + "," + num(p[1]));
        b.text("\n");
      }
    }
    b.text("$$GEOMETRYEND\n");
  }
  b.close();
}

}  // namespace frep::io
