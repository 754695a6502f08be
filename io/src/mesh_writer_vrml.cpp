// VRML 2.0 (VRML97) writer, the format of hfp's -wrl: one Shape with an IndexedFaceSet, per-vertex
// normals and, when the mesh has them, per-vertex colours (colorPerVertex). The faces are
// counter-clockwise seen from outside (ccw TRUE) and the surface is closed (solid TRUE: viewers
// may cull back faces).
#include <cctype>
#include <cstdio>
#include <cstring>

#include "byte_sink.h"
#include "mesh_writers.h"

namespace frep::io::detail {

namespace {

// A VRML node name: letters, digits and '_' (it may not start with a digit).
std::string vrmlName(const std::string& name) {
  std::string r;
  for (char c : name) r += (std::isalnum(static_cast<unsigned char>(c)) || c == '_') ? c : '_';
  if (r.empty() || std::isdigit(static_cast<unsigned char>(r[0]))) r = "m_" + r;
  return r;
}

void triples(Bytes& b, const std::vector<std::array<double, 3>>& v) {
  char line[128];
  for (const auto& p : v) {
    int n = std::snprintf(line, sizeof line, "          %.9g %.9g %.9g,\n", double(float(p[0])), double(float(p[1])),
                          double(float(p[2])));
    b.text(line, size_t(n));
  }
}

}  // namespace

void writeVrml(const std::string& path, const Mesh& m, const MeshWriteOptions& options) {
  Bytes b(path);
  const std::string name = vrmlName(options.name);
  b.text("#VRML V2.0 utf8\n");
  if (!options.comment.empty()) b.text("# " + oneLine(options.comment) + "\n");
  b.text("DEF " + name + " Transform {\n  children [\n    Shape {\n");
  b.text("      appearance Appearance { material Material { diffuseColor 0.8 0.8 0.8 } }\n");
  b.text("      geometry IndexedFaceSet {\n        ccw TRUE\n        solid TRUE\n");
  b.text("        coord Coordinate {\n          point [\n");
  triples(b, m.positions);
  b.text("          ]\n        }\n        normal Normal {\n          vector [\n");
  triples(b, m.normals);
  b.text("          ]\n        }\n        normalPerVertex TRUE\n");
  if (!m.colours.empty()) {
    b.text("        colorPerVertex TRUE\n        color Color {\n          color [\n");
    char line[128];
    for (const auto& c : m.colours) {
      int n = std::snprintf(line, sizeof line, "          %.9g %.9g %.9g,\n", double(c[0]), double(c[1]), double(c[2]));
      b.text(line, size_t(n));
    }
    b.text("          ]\n        }\n");
  }
  // Normals and colours are indexed like the coordinates (no normalIndex/colorIndex needed).
  b.text("        coordIndex [\n");
  char line[96];
  for (const auto& t : m.triangles) {
    int n = std::snprintf(line, sizeof line, "          %u, %u, %u, -1,\n", t[0], t[1], t[2]);
    b.text(line, size_t(n));
  }
  b.text("        ]\n      }\n    }\n  ]\n}\n");
  b.close();
}

}  // namespace frep::io::detail
