// PLY, OBJ and STL writers (see mesh_writer.h). Binary formats are little-endian whatever the
// host, so the bytes are the same on every machine.
#include "frep/io/mesh_writer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "frep/io/error.h"

namespace frep::io {

namespace {

// Little-endian bytes streamed to the file through a 1 MiB buffer: the file is never held in
// memory whole (a 512^3 mesh's PLY is ~0.4 GB), so writing adds nothing proportional to it.
class Bytes {
 public:
  explicit Bytes(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "wb")) {
    if (!file_) throw ioError("cannot write " + path);
    buf_.reserve(kChunk + 256);
  }
  ~Bytes() {
    if (file_) std::fclose(file_);
  }
  Bytes(const Bytes&) = delete;
  Bytes& operator=(const Bytes&) = delete;

  void u8(uint8_t v) { put(char(v)); }
  void u16(uint16_t v) {
    for (int i = 0; i < 2; ++i) put(char((v >> (8 * i)) & 0xff));
  }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) put(char((v >> (8 * i)) & 0xff));
  }
  void f32(float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    u32(v);
  }
  void text(const std::string& s) { text(s.data(), s.size()); }
  void text(const char* s, size_t n) {
    buf_.insert(buf_.end(), s, s + n);
    if (buf_.size() >= kChunk) drain();
  }
  void close() {
    drain();
    FILE* f = file_;
    file_ = nullptr;
    if (!ok_ || std::fclose(f) != 0) throw ioError("cannot write " + path_);
  }

 private:
  static constexpr size_t kChunk = size_t(1) << 20;
  void put(char c) {
    buf_.push_back(c);
    if (buf_.size() >= kChunk) drain();
  }
  void drain() {
    if (!buf_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), file_) != buf_.size()) ok_ = false;
    buf_.clear();
  }
  std::string path_;
  FILE* file_;
  std::vector<char> buf_;
  bool ok_ = true;
};

// One line, no control characters (headers are line-based).
std::string oneLine(const std::string& s) {
  std::string r = s;
  for (char& c : r)
    if (c == '\n' || c == '\r') c = ' ';
  return r;
}

void ply(Bytes& b, const Mesh& m, const std::string& comment) {
  b.text("ply\nformat binary_little_endian 1.0\n");
  if (!comment.empty()) b.text("comment " + oneLine(comment) + "\n");
  b.text("element vertex " + std::to_string(m.positions.size()) + "\n");
  b.text("property float x\nproperty float y\nproperty float z\n");
  b.text("property float nx\nproperty float ny\nproperty float nz\n");
  b.text("element face " + std::to_string(m.triangles.size()) + "\n");
  b.text("property list uchar uint vertex_indices\nend_header\n");
  for (size_t i = 0; i < m.positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) b.f32(float(m.positions[i][c]));
    for (int c = 0; c < 3; ++c) b.f32(float(m.normals[i][c]));
  }
  for (const auto& t : m.triangles) {
    b.u8(3);
    for (uint32_t v : t) b.u32(v);
  }
}

void obj(Bytes& b, const Mesh& m, const std::string& comment) {
  if (!comment.empty()) b.text("# " + oneLine(comment) + "\n");
  char line[160];
  for (const auto& p : m.positions) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", double(float(p[0])), double(float(p[1])), double(float(p[2])));
    b.text(line, std::strlen(line));
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

void stl(Bytes& b, const Mesh& m, const std::string& comment) {
  // 80-byte header; it must not start with "solid" (readers would take the file for ASCII).
  std::string header = "binary STL " + oneLine(comment);
  header.resize(80, ' ');
  b.text(header);
  b.u32(uint32_t(m.triangles.size()));
  for (const auto& t : m.triangles) {
    float p[3][3];
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) p[v][c] = float(m.positions[t[v]][c]);
    double u[3], w[3], n[3];
    for (int c = 0; c < 3; ++c) {
      u[c] = double(p[1][c]) - p[0][c];
      w[c] = double(p[2][c]) - p[0][c];
    }
    n[0] = u[1] * w[2] - u[2] * w[1];
    n[1] = u[2] * w[0] - u[0] * w[2];
    n[2] = u[0] * w[1] - u[1] * w[0];
    double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) {  // degenerate in float: the mean of the vertex normals
      for (int c = 0; c < 3; ++c) n[c] = m.normals[t[0]][c] + m.normals[t[1]][c] + m.normals[t[2]][c];
      len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    for (int c = 0; c < 3; ++c) b.f32(len > 0 ? float(n[c] / len) : 0.0f);
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) b.f32(p[v][c]);
    b.u16(0);
  }
}

// POV-Ray mesh2 (the fallback of `frep pov` for models that are not reducible): declares
// frep_mesh; include it and write `object { frep_mesh ... }`.
void pov(Bytes& b, const Mesh& m, const std::string& comment) {
  if (!comment.empty()) b.text("// " + oneLine(comment) + "\n");
  char line[160];
  b.text("#declare frep_mesh = mesh2 {\n  vertex_vectors { " + std::to_string(m.positions.size()) + "\n");
  for (const auto& p : m.positions) {
    std::snprintf(line, sizeof line, "    <%.9g, %.9g, %.9g>\n", double(float(p[0])), double(float(p[1])), double(float(p[2])));
    b.text(line, std::strlen(line));
  }
  b.text("  }\n  normal_vectors { " + std::to_string(m.normals.size()) + "\n");
  for (const auto& n : m.normals) {
    std::snprintf(line, sizeof line, "    <%.9g, %.9g, %.9g>\n", double(float(n[0])), double(float(n[1])), double(float(n[2])));
    b.text(line, std::strlen(line));
  }
  b.text("  }\n  face_indices { " + std::to_string(m.triangles.size()) + "\n");
  for (const auto& t : m.triangles) {
    std::snprintf(line, sizeof line, "    <%u, %u, %u>\n", t[0], t[1], t[2]);
    b.text(line, std::strlen(line));
  }
  b.text("  }\n  inside_vector <0, 0, 1>\n}\n");
}

}  // namespace

MeshFormat meshFormatFromPath(const std::string& field, const std::string& path) {
  auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == "ply") return MeshFormat::Ply;
  if (ext == "obj") return MeshFormat::Obj;
  if (ext == "stl") return MeshFormat::Stl;
  if (ext == "inc" || ext == "pov") return MeshFormat::Pov;
  throw badArgs(field + ": '" + path + "' has no mesh extension; use .ply (binary PLY), .obj, .stl (binary STL) or .inc/.pov (POV-Ray mesh2)");
}

const char* meshFormatName(MeshFormat format) {
  switch (format) {
    case MeshFormat::Ply: return "binary PLY";
    case MeshFormat::Obj: return "OBJ";
    case MeshFormat::Stl: return "binary STL";
    case MeshFormat::Pov: return "POV-Ray mesh2";
  }
  return "?";
}

void writeMesh(const std::string& path, const Mesh& mesh, MeshFormat format, const std::string& comment) {
  Bytes b(path);
  switch (format) {
    case MeshFormat::Ply: ply(b, mesh, comment); break;
    case MeshFormat::Obj: obj(b, mesh, comment); break;
    case MeshFormat::Stl: stl(b, mesh, comment); break;
    case MeshFormat::Pov: pov(b, mesh, comment); break;
  }
  b.close();
}

}  // namespace frep::io
