#include "frep/io/mesh_reader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "frep/io/error.h"

namespace frep::io {
namespace {


[[noreturn]] void fail(const std::string& path, const std::string& why) { throw ioError(path + ": " + why); }

void addPolygon(Mesh& m, const std::vector<int64_t>& poly, const std::string& path, const std::string& where) {
  if (poly.size() < 3) fail(path, where + ": a face with fewer than 3 vertices");
  for (int64_t i : poly)
    if (i < 0 || uint64_t(i) >= m.positions.size()) fail(path, where + ": vertex index " + std::to_string(i) + " out of range");
  for (size_t k = 1; k + 1 < poly.size(); ++k)
    m.triangles.push_back({uint32_t(poly[0]), uint32_t(poly[k]), uint32_t(poly[k + 1])});
}

void checkPosition(const std::array<double, 3>& p, const std::string& path, const std::string& where) {
  for (double c : p)
    if (!std::isfinite(c)) fail(path, where + ": non-finite coordinate");
}

// ---- PLY ----

struct PlyProperty {
  std::string name, type, countType;  // countType: list properties only
};
struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> props;
};

size_t typeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

class PlyBinary {
 public:
  PlyBinary(std::istream& in, bool bigEndian, const std::string& path) : in_(in), big_(bigEndian), path_(path) {}
  double read(const std::string& type) {
    unsigned char b[8];
    const size_t n = typeSize(type);
    if (!in_.read(reinterpret_cast<char*>(b), std::streamsize(n))) fail(path_, "truncated binary data");
    if (big_) std::reverse(b, b + n);
    auto as = [&](auto v) { std::memcpy(&v, b, sizeof v); return double(v); };
    if (type == "char" || type == "int8") return as(int8_t());
    if (type == "uchar" || type == "uint8") return as(uint8_t());
    if (type == "short" || type == "int16") return as(int16_t());
    if (type == "ushort" || type == "uint16") return as(uint16_t());
    if (type == "int" || type == "int32") return as(int32_t());
    if (type == "uint" || type == "uint32") return as(uint32_t());
    if (type == "float" || type == "float32") return as(float());
    return as(double());
  }

 private:
  std::istream& in_;
  bool big_;
  const std::string& path_;
};

Mesh readPly(std::istream& in, const std::string& path) {
  std::string line, format;
  std::getline(in, line);
  if (line != "ply" && line != "ply\r") fail(path, "not a PLY file (no 'ply' magic)");
  std::vector<PlyElement> elements;
  for (int headerLine = 2;; ++headerLine) {
    if (!std::getline(in, line)) fail(path, "truncated header (no end_header)");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "end_header") break;
    if (word == "format") ls >> format;
    else if (word == "element") {
      PlyElement e;
      if (!(ls >> e.name >> e.count)) fail(path, "header line " + std::to_string(headerLine) + ": bad element line");
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) fail(path, "property before any element");
      PlyProperty p;
      ls >> p.type;
      if (p.type == "list") ls >> p.countType >> p.type;
      ls >> p.name;
      if (!typeSize(p.type) || (!p.countType.empty() && !typeSize(p.countType)))
        fail(path, "header line " + std::to_string(headerLine) + ": unknown property type");
      elements.back().props.push_back(p);
    }
  }
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    fail(path, "unknown PLY format (ascii, binary_little_endian, binary_big_endian)");
  Mesh m;
  PlyBinary bin(in, format == "binary_big_endian", path);
  std::string token;
  auto value = [&](const std::string& type) -> double {
    if (format != "ascii") return bin.read(type);
    if (!(in >> token)) fail(path, "truncated ascii data");
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (*end || end == token.c_str())
      fail(path, "not a number at byte " + std::to_string(int64_t(in.tellg()) - int64_t(token.size()) + 1));
    return v;
  };
  for (const PlyElement& e : elements) {
    const bool vertex = e.name == "vertex", face = e.name == "face";
    // Counts beyond what the file can hold are refused before allocating.
    if (e.count > (uint64_t(1) << 31)) fail(path, "element " + e.name + " count too large");
    for (uint64_t i = 0; i < e.count; ++i) {
      std::array<double, 3> p{0, 0, 0};
      for (const PlyProperty& pr : e.props) {
        if (!pr.countType.empty()) {
          const double n = value(pr.countType);
          if (!(n >= 0 && n <= 1e6)) fail(path, e.name + " " + std::to_string(i) + ": bad list length");
          std::vector<int64_t> poly(static_cast<size_t>(n));
          for (int64_t& k : poly) k = int64_t(value(pr.type));
          if (face && (pr.name == "vertex_indices" || pr.name == "vertex_index"))
            addPolygon(m, poly, path, "face " + std::to_string(i));
          continue;
        }
        const double v = value(pr.type);
        if (vertex && pr.name.size() == 1 && pr.name[0] >= 'x' && pr.name[0] <= 'z') p[size_t(pr.name[0] - 'x')] = v;
      }
      if (vertex) {
        checkPosition(p, path, "vertex " + std::to_string(i));
        m.positions.push_back(p);
      }
    }
  }
  return m;
}

// ---- OBJ ----

Mesh readObj(std::istream& in, const std::string& path) {
  Mesh m;
  std::string line;
  for (size_t lineNo = 1; std::getline(in, line); ++lineNo) {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    const std::string where = "line " + std::to_string(lineNo);
    if (word == "v") {
      std::array<double, 3> p{};
      if (!(ls >> p[0] >> p[1] >> p[2])) fail(path, where + ": expected v x y z");
      checkPosition(p, path, where);
      m.positions.push_back(p);
    } else if (word == "f") {
      std::vector<int64_t> poly;
      std::string item;
      while (ls >> item) {
        char* end = nullptr;
        const long long k = std::strtoll(item.c_str(), &end, 10);
        if (end == item.c_str() || (*end && *end != '/') || k == 0) fail(path, where + ": bad face vertex");
        poly.push_back(k > 0 ? k - 1 : int64_t(m.positions.size()) + k);
      }
      addPolygon(m, poly, path, where);
    }
  }
  return m;
}

// ---- STL ----

Mesh readStl(const std::string& bytes, const std::string& path) {
  Mesh m;
  auto addTriangle = [&](const std::array<std::array<double, 3>, 3>& t, const std::string& where) {
    for (const auto& p : t) {
      checkPosition(p, path, where);
      m.positions.push_back(p);
    }
    const uint32_t b = uint32_t(m.positions.size() - 3);
    m.triangles.push_back({b, b + 1, b + 2});
  };
  const bool ascii = bytes.compare(0, 5, "solid") == 0 && bytes.find("facet") != std::string::npos;
  if (ascii) {
    std::istringstream ls(bytes);
    std::string word;
    std::array<std::array<double, 3>, 3> t{};
    int k = 0;
    size_t facet = 0;
    while (ls >> word) {
      if (word != "vertex") continue;
      if (!(ls >> t[size_t(k)][0] >> t[size_t(k)][1] >> t[size_t(k)][2])) fail(path, "facet " + std::to_string(facet) + ": bad vertex");
      if (++k == 3) addTriangle(t, "facet " + std::to_string(facet++)), k = 0;
    }
    if (k != 0) fail(path, "a facet with fewer than 3 vertices");
    return m;
  }
  if (bytes.size() < 84) fail(path, "truncated binary STL (no header)");
  uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);
  if (bytes.size() < 84 + uint64_t(n) * 50) fail(path, "truncated binary STL (" + std::to_string(n) + " facets announced)");
  for (uint32_t i = 0; i < n; ++i) {
    std::array<std::array<double, 3>, 3> t{};
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) {
        float f = 0;
        std::memcpy(&f, bytes.data() + 84 + size_t(i) * 50 + 12 + size_t(v) * 12 + size_t(c) * 4, 4);
        t[size_t(v)][size_t(c)] = f;
      }
    addTriangle(t, "facet " + std::to_string(i));
  }
  return m;
}

}  // namespace

std::string lowerExtension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Mesh parseMesh(const std::string& path, const std::string& bytes) {
  const std::string ext = lowerExtension(path);
  if (ext != "ply" && ext != "obj" && ext != "stl") throw ioError(path + ": not a mesh file (expected .ply, .obj or .stl)");
  Mesh m;
  if (ext == "stl") {
    m = readStl(bytes, path);
  } else {
    std::istringstream in(bytes, std::ios::binary);
    m = ext == "ply" ? readPly(in, path) : readObj(in, path);
  }
  if (m.triangles.empty()) fail(path, "no triangles");
  return m;
}

Mesh readMesh(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext != "ply" && ext != "obj" && ext != "stl") throw ioError(path + ": not a mesh file (expected .ply, .obj or .stl)");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open the file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail(path, "cannot read the file");
  return parseMesh(path, bytes);
}

}  // namespace frep::io
