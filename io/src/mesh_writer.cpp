// PLY, OBJ, STL (binary and ASCII) and POV-Ray writers, and the dispatch to the others (see
// mesh_writer.h). Binary formats are little-endian whatever the host, so the bytes are the same
// on every machine.
#include "frep/io/mesh_writer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <array>
#include <vector>

#include "byte_sink.h"
#include "mesh_writers.h"
#include "frep/io/error.h"

namespace frep::io {

namespace {

using detail::Bytes;
using detail::oneLine;

void ply(Bytes& b, const Mesh& m, const std::string& comment) {
  b.text("ply\nformat binary_little_endian 1.0\n");
  if (!comment.empty()) b.text("comment " + oneLine(comment) + "\n");
  b.text("element vertex " + std::to_string(m.positions.size()) + "\n");
  b.text("property float x\nproperty float y\nproperty float z\n");
  b.text("property float nx\nproperty float ny\nproperty float nz\n");
  const bool colours = !m.colours.empty();
  if (colours) b.text("property uchar red\nproperty uchar green\nproperty uchar blue\n");
  b.text("element face " + std::to_string(m.triangles.size()) + "\n");
  b.text("property list uchar uint vertex_indices\nend_header\n");
  for (size_t i = 0; i < m.positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) b.f32(float(m.positions[i][c]));
    for (int c = 0; c < 3; ++c) b.f32(float(m.normals[i][c]));
    if (colours)
      for (int c = 0; c < 3; ++c) b.u8(detail::channelByte(m.colours[i][c]));
  }
  for (const auto& t : m.triangles) {
    b.u8(3);
    for (uint32_t v : t) b.u32(v);
  }
}

void obj(Bytes& b, const Mesh& m, const std::string& comment) {
  if (!comment.empty()) b.text("# " + oneLine(comment) + "\n");
  char line[160];
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const auto& p = m.positions[i];
    int n = std::snprintf(line, sizeof line, "v %.9g %.9g %.9g", double(float(p[0])), double(float(p[1])), double(float(p[2])));
    if (!m.colours.empty()) {  // the vertex-colour extension read by MeshLab, Blender, assimp, trimesh
      const auto& c = m.colours[i];
      n += std::snprintf(line + n, sizeof line - size_t(n), " %.9g %.9g %.9g", double(c[0]), double(c[1]), double(c[2]));
    }
    line[n++] = '\n';
    b.text(line, size_t(n));
  }
  for (const auto& n : m.normals) {
    std::snprintf(line, sizeof line, "vn %.9g %.9g %.9g\n", double(float(n[0])), double(float(n[1])), double(float(n[2])));
    b.text(line, std::strlen(line));
  }
  for (const auto& t : m.triangles) {  // OBJ indices are 1-based
    std::snprintf(line, sizeof line, "f %u//%u %u//%u %u//%u\n", t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1,
                  t[2] + 1);
    b.text(line, std::strlen(line));
  }
}

// A triangle's unit normal from its float corners (what a reader recomputes), or the mean of
// the vertex normals where the float triangle is degenerate.
std::array<float, 3> facetNormal(const Mesh& m, const std::array<uint32_t, 3>& t, const float (&p)[3][3]) {
  double u[3], w[3], n[3];
  for (int c = 0; c < 3; ++c) {
    u[c] = double(p[1][c]) - p[0][c];
    w[c] = double(p[2][c]) - p[0][c];
  }
  n[0] = u[1] * w[2] - u[2] * w[1];
  n[1] = u[2] * w[0] - u[0] * w[2];
  n[2] = u[0] * w[1] - u[1] * w[0];
  double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(len > 0)) {
    for (int c = 0; c < 3; ++c) n[c] = m.normals[t[0]][c] + m.normals[t[1]][c] + m.normals[t[2]][c];
    len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  std::array<float, 3> r;
  for (int c = 0; c < 3; ++c) r[c] = len > 0 ? float(n[c] / len) : 0.0f;
  return r;
}

void corners(const Mesh& m, const std::array<uint32_t, 3>& t, float (&p)[3][3]) {
  for (int v = 0; v < 3; ++v)
    for (int c = 0; c < 3; ++c) p[v][c] = float(m.positions[t[v]][c]);
}

void stl(Bytes& b, const Mesh& m, const std::string& comment) {
  // 80-byte header; it must not start with "solid" (readers would take the file for ASCII).
  std::string header = "binary STL " + oneLine(comment);
  header.resize(80, ' ');
  b.text(header);
  b.u32(uint32_t(m.triangles.size()));
  for (const auto& t : m.triangles) {
    float p[3][3];
    corners(m, t, p);
    for (float c : facetNormal(m, t, p)) b.f32(c);
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) b.f32(p[v][c]);
    b.u16(0);
  }
}

// ASCII STL (hfp's -stl): the same floats as the binary form, printed with 9 digits.
void stlAscii(Bytes& b, const Mesh& m, const std::string& name, const std::string& comment) {
  std::string solid = oneLine(name);
  for (char& c : solid)
    if (c == ' ') c = '_';
  b.text("solid " + solid + (comment.empty() ? "" : " " + oneLine(comment)) + "\n");
  char line[200];
  for (const auto& t : m.triangles) {
    float p[3][3];
    corners(m, t, p);
    auto n = facetNormal(m, t, p);
    int k = std::snprintf(line, sizeof line, "  facet normal %.9g %.9g %.9g\n    outer loop\n", double(n[0]),
                          double(n[1]), double(n[2]));
    b.text(line, size_t(k));
    for (int v = 0; v < 3; ++v) {
      k = std::snprintf(line, sizeof line, "      vertex %.9g %.9g %.9g\n", double(p[v][0]), double(p[v][1]), double(p[v][2]));
      b.text(line, size_t(k));
    }
    b.text("    endloop\n  endfacet\n");
  }
  b.text("endsolid " + solid + "\n");
}

// POV-Ray mesh2 (the fallback of `frep pov` for models that are not reducible): declares
// frep_mesh; include it and write `object { frep_mesh ... }`.
void pov(Bytes& b, const Mesh& m, const std::string& comment) {
  if (!comment.empty()) b.text("// " + oneLine(comment) + "\n");
  b.text(povMesh2(m, "frep_mesh"));
}

// The mesh in the file's axes: (x, y, z) -> (x, z, -y) for Y-up (a rotation: windings kept).
Mesh yUp(const Mesh& m) {
  Mesh r;
  r.positions.reserve(m.positions.size());
  r.normals.reserve(m.normals.size());
  for (const auto& p : m.positions) r.positions.push_back({p[0], p[2], -p[1]});
  for (const auto& n : m.normals) r.normals.push_back({n[0], n[2], -n[1]});
  r.triangles = m.triangles;
  r.colours = m.colours;
  return r;
}

}  // namespace

std::string povMesh2(const Mesh& m, const std::string& name) {
  char line[160];
  std::string b;
  auto text = [&b](const std::string& t) { b += t; };
  text("#declare " + name + " = mesh2 {\n  vertex_vectors { " + std::to_string(m.positions.size()) + "\n");
  for (const auto& p : m.positions) {
    std::snprintf(line, sizeof line, "    <%.9g, %.9g, %.9g>\n", double(float(p[0])), double(float(p[1])), double(float(p[2])));
    b.append(line, std::strlen(line));
  }
  text("  }\n  normal_vectors { " + std::to_string(m.normals.size()) + "\n");
  for (const auto& n : m.normals) {
    std::snprintf(line, sizeof line, "    <%.9g, %.9g, %.9g>\n", double(float(n[0])), double(float(n[1])), double(float(n[2])));
    b.append(line, std::strlen(line));
  }
  const bool colours = !m.colours.empty();
  if (colours) {  // one texture per vertex; mesh2 interpolates them across each triangle
    text("  }\n  texture_list { " + std::to_string(m.colours.size()) + "\n");
    for (const auto& c : m.colours) {
      std::snprintf(line, sizeof line, "    texture { pigment { rgb <%.9g, %.9g, %.9g> } }\n", double(c[0]), double(c[1]),
                    double(c[2]));
      b.append(line, std::strlen(line));
    }
  }
  text("  }\n  face_indices { " + std::to_string(m.triangles.size()) + "\n");
  for (const auto& t : m.triangles) {
    if (colours)
      std::snprintf(line, sizeof line, "    <%u, %u, %u>, %u, %u, %u\n", t[0], t[1], t[2], t[0], t[1], t[2]);
    else
      std::snprintf(line, sizeof line, "    <%u, %u, %u>\n", t[0], t[1], t[2]);
    b.append(line, std::strlen(line));
  }
  text("  }\n  inside_vector <0, 0, 1>\n}\n");
  return b;
}


MeshFormat meshFormatFromPath(const std::string& field, const std::string& path) {
  auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == "ply") return MeshFormat::Ply;
  if (ext == "obj") return MeshFormat::Obj;
  if (ext == "stl") return MeshFormat::Stl;
  if (ext == "inc" || ext == "pov") return MeshFormat::Pov;
  if (ext == "wrl") return MeshFormat::Wrl;
  if (ext == "3mf") return MeshFormat::ThreeMf;
  if (ext == "glb") return MeshFormat::Glb;
  throw badArgs(field + ": '" + path +
                "' has no mesh extension; use .ply (binary PLY), .obj, .stl (binary STL; --format stl-ascii for "
                "ASCII), .wrl (VRML 2.0), .inc/.pov (POV-Ray mesh2), .3mf or .glb (glTF 2.0 binary)");
}

MeshFormat meshFormatFromName(const std::string& field, const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (n == "ply") return MeshFormat::Ply;
  if (n == "obj") return MeshFormat::Obj;
  if (n == "stl" || n == "stlb" || n == "stl-binary") return MeshFormat::Stl;
  if (n == "stl-ascii" || n == "stla") return MeshFormat::StlAscii;
  if (n == "pov" || n == "inc") return MeshFormat::Pov;
  if (n == "wrl" || n == "vrml") return MeshFormat::Wrl;
  if (n == "3mf") return MeshFormat::ThreeMf;
  if (n == "glb" || n == "gltf") return MeshFormat::Glb;
  throw badArgs(field + ": unknown mesh format '" + name + "'; the formats are ply, obj, stl, stl-ascii, wrl, pov, 3mf and glb");
}

const char* meshFormatName(MeshFormat format) {
  switch (format) {
    case MeshFormat::Ply: return "binary PLY";
    case MeshFormat::Obj: return "OBJ";
    case MeshFormat::Stl: return "binary STL";
    case MeshFormat::StlAscii: return "ASCII STL";
    case MeshFormat::Pov: return "POV-Ray mesh2";
    case MeshFormat::Wrl: return "VRML 2.0";
    case MeshFormat::ThreeMf: return "3MF";
    case MeshFormat::Glb: return "glTF 2.0 binary";
  }
  return "?";
}

bool formatHoldsColours(MeshFormat format) { return format != MeshFormat::Stl && format != MeshFormat::StlAscii; }

UpAxis resolvedUpAxis(MeshFormat format, UpAxis up) {
  if (up != UpAxis::Default) return up;
  return format == MeshFormat::Glb ? UpAxis::Y : UpAxis::Z;
}

void requireMeshWriter(MeshFormat format) {
  if (format == MeshFormat::ThreeMf || format == MeshFormat::Glb) (void)detail::meshFilesBackend();
}

void writeMesh(const std::string& path, const Mesh& input, MeshFormat format, const MeshWriteOptions& options) {
  Mesh rotated;
  const bool toY = resolvedUpAxis(format, options.up) == UpAxis::Y;
  if (toY) rotated = yUp(input);
  const Mesh& mesh = toY ? rotated : input;
  switch (format) {
    case MeshFormat::Wrl: return detail::writeVrml(path, mesh, options);
    case MeshFormat::ThreeMf: return detail::meshFilesBackend().write3mf(path, mesh, options);
    case MeshFormat::Glb: return detail::meshFilesBackend().writeGlb(path, mesh, options);
    default: break;
  }
  Bytes b(path);
  switch (format) {
    case MeshFormat::Ply: ply(b, mesh, options.comment); break;
    case MeshFormat::Obj: obj(b, mesh, options.comment); break;
    case MeshFormat::Stl: stl(b, mesh, options.comment); break;
    case MeshFormat::StlAscii: stlAscii(b, mesh, options.name, options.comment); break;
    case MeshFormat::Pov: pov(b, mesh, options.comment); break;
    default: break;
  }
  b.close();
}

}  // namespace frep::io
