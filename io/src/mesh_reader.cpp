// Mesh files for frep render and frMesh (mesh_reader.h). Every count a file states is checked
// against the bytes the file really has before anything is allocated or looped over, every
// coordinate and index must be a finite number, and a message names the file and the line or
// byte at fault, never the file's text (a worker's --data-dir file must not travel back to its
// master in an error).
#include "frep/io/mesh_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>

#include "frep/io/error.h"
#include "frep/io/file_kind.h"
#include "frep/io/input_file.h"

namespace frep::io {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& why) { throw ioError(path + ": " + why); }

std::string byteText(size_t at) { return "byte " + std::to_string(at + 1); }

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

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

// A number token: the whole token, finite.
bool parseNumber(const char* b, const char* e, double& v) {
  if (b < e && *b == '+') ++b;
  const auto r = std::from_chars(b, e, v);
  return r.ec == std::errc() && r.ptr == e && std::isfinite(v);
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

// How a message names an element: its name if it is one this reader knows, else its rank.
std::string elementText(const PlyElement& e, size_t rank) {
  if (e.name == "vertex" || e.name == "face") return "element '" + e.name + "'";
  return "element " + std::to_string(rank + 1);
}

class PlyData {
 public:
  PlyData(const std::string& bytes, size_t pos, int format, const std::string& path)
      : b_(bytes), pos_(pos), format_(format), path_(path) {}

  double value(const std::string& type) {
    if (format_ == 0) return asciiValue();
    unsigned char b[8];
    const size_t n = typeSize(type);
    if (b_.size() - pos_ < n) fail(path_, "truncated binary data at " + byteText(pos_));
    std::memcpy(b, b_.data() + pos_, n);
    pos_ += n;
    if (format_ == 2) std::reverse(b, b + n);
    auto as = [&](auto v) {
      std::memcpy(&v, b, sizeof v);
      return double(v);
    };
    if (type == "char" || type == "int8") return as(int8_t());
    if (type == "uchar" || type == "uint8") return as(uint8_t());
    if (type == "short" || type == "int16") return as(int16_t());
    if (type == "ushort" || type == "uint16") return as(uint16_t());
    if (type == "int" || type == "int32") return as(int32_t());
    if (type == "uint" || type == "uint32") return as(uint32_t());
    if (type == "float" || type == "float32") return as(float());
    return as(double());
  }
  size_t pos() const { return pos_; }
  size_t left() const { return b_.size() - pos_; }

 private:
  double asciiValue() {
    while (pos_ < b_.size() && isBlank(b_[pos_])) ++pos_;
    if (pos_ >= b_.size()) fail(path_, "truncated ascii data (the file ends at " + byteText(b_.size() - 1) + ")");
    const size_t start = pos_;
    while (pos_ < b_.size() && !isBlank(b_[pos_])) ++pos_;
    double v;
    if (!parseNumber(b_.data() + start, b_.data() + pos_, v)) fail(path_, "not a finite number at " + byteText(start));
    return v;
  }

  const std::string& b_;
  size_t pos_;
  int format_;  // 0 ascii, 1 binary little endian, 2 binary big endian
  const std::string& path_;
};

Mesh readPly(const std::string& bytes, const std::string& path) {
  size_t pos = 0;
  int lineNo = 0;
  std::string line;
  auto nextLine = [&]() {
    if (pos >= bytes.size()) return false;
    size_t e = bytes.find('\n', pos);
    if (e == std::string::npos) e = bytes.size();
    line.assign(bytes, pos, e - pos);
    pos = std::min(bytes.size(), e + 1);
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!nextLine() || line != "ply") fail(path, "not a PLY file (no 'ply' magic)");
  std::vector<PlyElement> elements;
  int format = -1;
  for (;;) {
    if (!nextLine()) fail(path, "truncated header (no end_header)");
    const std::string where = "header line " + std::to_string(lineNo);
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "end_header") break;
    if (word == "format") {
      std::string f;
      ls >> f;
      format = f == "ascii" ? 0 : f == "binary_little_endian" ? 1 : f == "binary_big_endian" ? 2 : -2;
      if (format == -2) fail(path, where + ": unknown PLY format (ascii, binary_little_endian, binary_big_endian)");
    } else if (word == "element") {
      PlyElement e;
      std::string count;
      if (!(ls >> e.name >> count)) fail(path, where + ": expected 'element NAME COUNT'");
      const auto r = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (r.ec != std::errc() || r.ptr != count.data() + count.size())
        fail(path, where + ": the element count is not a whole number of at most 2^64 - 1");
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) fail(path, where + ": property before any element");
      PlyProperty p;
      ls >> p.type;
      if (p.type == "list") ls >> p.countType >> p.type;
      ls >> p.name;
      if (!typeSize(p.type) || (p.type == "list") || (!p.countType.empty() && !typeSize(p.countType)))
        fail(path, where + ": unknown property type");
      if (p.name.empty()) fail(path, where + ": a property without a name");
      elements.back().props.push_back(p);
    } else if (word != "comment" && word != "obj_info" && !word.empty()) {
      fail(path, where + ": not a PLY header line (format, element, property, comment, end_header)");
    }
  }
  if (format < 0) fail(path, "no format line in the header");
  // Every element's entries must fit in what follows the header, at their smallest: a binary
  // entry takes its scalars' and list counts' bytes, an ascii value at least a character and a
  // blank. Checked before anything is read or allocated, so a header that states 2^31 or 2^64
  // entries fails here at once (before: a 48 GB allocation, or 2.2 s spinning a header line).
  const size_t left = bytes.size() - pos;
  unsigned __int128 need = 0;
  for (size_t k = 0; k < elements.size(); ++k) {
    const PlyElement& e = elements[k];
    uint64_t least = 0;
    for (const PlyProperty& p : e.props) least += format == 0 ? 2 : typeSize(p.countType.empty() ? p.type : p.countType);
    if (e.name == "vertex") {
      for (const char* axis : {"x", "y", "z"})
        if (std::none_of(e.props.begin(), e.props.end(), [&](const PlyProperty& p) { return p.name == axis && p.countType.empty(); }))
          fail(path, "the vertex element has no scalar property '" + std::string(axis) + "'");
    }
    if (e.count > 0 && least == 0)
      fail(path, elementText(e, k) + " has " + std::to_string(e.count) + " entries but no properties");
    need += static_cast<unsigned __int128>(e.count) * least;
    if (need > static_cast<unsigned __int128>(left) + 1)
      fail(path, elementText(e, k) + " states " + std::to_string(e.count) + " entries of at least " +
                     std::to_string(least) + " bytes each, more than the " + std::to_string(left) +
                     " bytes after the header (truncated or damaged)");
  }
  Mesh m;
  PlyData data(bytes, pos, format, path);
  for (const PlyElement& e : elements) {
    const bool vertex = e.name == "vertex", face = e.name == "face";
    if (vertex) m.positions.reserve(m.positions.size() + size_t(std::min<uint64_t>(e.count, 1 << 20)));
    for (uint64_t i = 0; i < e.count; ++i) {
      std::array<double, 3> p{0, 0, 0};
      for (const PlyProperty& pr : e.props) {
        if (!pr.countType.empty()) {
          const size_t at = data.pos();
          const double n = data.value(pr.countType);
          // A list's entries take at least a byte each (two in ascii): its length is bounded by
          // what is left before it is allocated.
          if (!(n >= 0 && n == std::floor(n) && n <= double(data.left())))
            fail(path, e.name == "face" ? "face " + std::to_string(i) + ": bad list length at " + byteText(at)
                                        : "bad list length at " + byteText(at));
          std::vector<int64_t> poly(static_cast<size_t>(n));
          for (int64_t& k : poly) {
            const size_t vat = data.pos();
            const double v = data.value(pr.type);
            if (!(v == std::floor(v) && std::fabs(v) <= 9.0e15)) fail(path, "not a whole number at " + byteText(vat));
            k = int64_t(v);
          }
          if (face && (pr.name == "vertex_indices" || pr.name == "vertex_index"))
            addPolygon(m, poly, path, "face " + std::to_string(i));
          continue;
        }
        const double v = data.value(pr.type);
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

Mesh readObj(const std::string& bytes, const std::string& path) {
  Mesh m;
  size_t pos = 0;
  std::vector<int64_t> poly;
  for (size_t lineNo = 1; pos < bytes.size(); ++lineNo) {
    size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    const size_t lineStart = pos;
    pos = end + 1;
    // The line's blank-separated tokens, one at a time.
    size_t at = lineStart;
    auto token = [&](const char*& b, const char*& e) {
      while (at < end && isBlank(bytes[at])) ++at;
      if (at >= end) return false;
      b = bytes.data() + at;
      while (at < end && !isBlank(bytes[at])) ++at;
      e = bytes.data() + at;
      return true;
    };
    const std::string where = "line " + std::to_string(lineNo);
    const char *b, *e;
    if (!token(b, e)) continue;
    const std::string word(b, e);
    if (word == "v") {
      std::array<double, 3> p{};
      for (double& c : p) {
        if (!token(b, e)) fail(path, where + ": expected v x y z");
        if (!parseNumber(b, e, c)) fail(path, where + ": not a finite number at " + byteText(size_t(b - bytes.data())));
      }
      m.positions.push_back(p);
    } else if (word == "f") {
      poly.clear();
      while (token(b, e)) {
        int64_t k = 0;
        const auto r = std::from_chars(b, e, k);
        if (r.ec != std::errc() || (r.ptr != e && *r.ptr != '/') || k == 0)
          fail(path, where + ": bad face vertex at " + byteText(size_t(b - bytes.data())));
        poly.push_back(k > 0 ? k - 1 : int64_t(m.positions.size()) + k);
      }
      addPolygon(m, poly, path, where);
    }
  }
  return m;
}

// ---- STL ----

// ASCII STL, strictly: solid NAME, then facets (facet normal nx ny nz / outer loop / three
// vertex x y z / endloop / endfacet), then endsolid; several solids may follow one another. A
// file that ends before endsolid is truncated and refused, naming its last line (before: it was
// accepted, its open edges only warned about).
Mesh readAsciiStl(const std::string& bytes, const std::string& path) {
  Mesh m;
  size_t pos = 0;
  size_t lineNo = 1, tokenLine = 1;  // the line of the last token read
  const char *b = nullptr, *e = nullptr;
  auto token = [&]() {
    for (; pos < bytes.size() && isBlank(bytes[pos]); ++pos)
      if (bytes[pos] == '\n') ++lineNo;
    if (pos >= bytes.size()) return false;
    tokenLine = lineNo;
    b = bytes.data() + pos;
    while (pos < bytes.size() && !isBlank(bytes[pos])) ++pos;
    e = bytes.data() + pos;
    return true;
  };
  auto where = [&]() { return path + ":" + std::to_string(tokenLine); };
  auto is = [&](const char* w) { return size_t(e - b) == std::strlen(w) && std::memcmp(b, w, size_t(e - b)) == 0; };
  auto expect = [&](const char* w, const char* inside) {
    if (!token()) throw ioError(where() + ": truncated ASCII STL (the file ends inside " + inside + ")");
    if (!is(w)) throw ioError(where() + ": expected '" + w + "' in " + inside);
  };
  auto number = [&](const char* inside) {
    if (!token()) throw ioError(where() + ": truncated ASCII STL (the file ends inside " + inside + ")");
    double v;
    if (!parseNumber(b, e, v)) throw ioError(where() + ": not a finite number in " + inside);
    return v;
  };
  bool inSolid = false;
  while (token()) {
    if (!inSolid) {
      if (!is("solid")) throw ioError(where() + ": expected 'solid'");
      inSolid = true;
      // The solid's name: the rest of the line.
      while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
      continue;
    }
    if (is("endsolid")) {
      inSolid = false;
      while (pos < bytes.size() && bytes[pos] != '\n') ++pos;  // its name
      continue;
    }
    if (!is("facet")) throw ioError(where() + ": expected 'facet' or 'endsolid'");
    expect("normal", "a facet");
    for (int k = 0; k < 3; ++k) number("a facet's normal");
    expect("outer", "a facet");
    expect("loop", "a facet");
    std::array<std::array<double, 3>, 3> t{};
    for (int v = 0; v < 3; ++v) {
      if (!token()) throw ioError(where() + ": truncated ASCII STL (the file ends inside a facet)");
      if (is("endloop")) throw ioError(where() + ": a facet with fewer than 3 vertices");
      if (!is("vertex")) throw ioError(where() + ": expected 'vertex' in a facet");
      for (double& c : t[size_t(v)]) c = number("a vertex");
    }
    if (!token()) throw ioError(where() + ": truncated ASCII STL (the file ends inside a facet)");
    if (is("vertex")) throw ioError(where() + ": a facet with more than 3 vertices");
    if (!is("endloop")) throw ioError(where() + ": expected 'endloop' in a facet");
    expect("endfacet", "a facet");
    for (const auto& p : t) m.positions.push_back(p);
    const uint32_t first = uint32_t(m.positions.size() - 3);
    m.triangles.push_back({first, first + 1, first + 2});
  }
  if (inSolid) throw ioError(where() + ": truncated ASCII STL (no endsolid)");
  return m;
}

Mesh readStl(const std::string& bytes, const std::string& path) {
  // Binary when the size is exactly what its facet count says (a binary header may well start
  // with "solid"), ASCII when it starts with "solid" otherwise.
  uint32_t n = 0;
  if (bytes.size() >= 84) std::memcpy(&n, bytes.data() + 80, 4);
  const bool binarySize = bytes.size() >= 84 && bytes.size() == 84 + uint64_t(n) * 50;
  if (!binarySize && bytes.compare(0, 5, "solid") == 0) return readAsciiStl(bytes, path);
  if (bytes.size() < 84) fail(path, "truncated binary STL (no header)");
  if (bytes.size() < 84 + uint64_t(n) * 50)
    fail(path, "truncated binary STL (" + std::to_string(n) + " facets announced, " +
                   std::to_string((bytes.size() - 84) / 50) + " in the file)");
  Mesh m;
  m.positions.reserve(size_t(n) * 3);
  m.triangles.reserve(n);
  for (uint32_t i = 0; i < n; ++i) {
    std::array<std::array<double, 3>, 3> t{};
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) {
        float f = 0;
        std::memcpy(&f, bytes.data() + 84 + size_t(i) * 50 + 12 + size_t(v) * 12 + size_t(c) * 4, 4);
        t[size_t(v)][size_t(c)] = f;
      }
    for (const auto& p : t) {
      checkPosition(p, path, "facet " + std::to_string(i));
      m.positions.push_back(p);
    }
    const uint32_t first = uint32_t(m.positions.size() - 3);
    m.triangles.push_back({first, first + 1, first + 2});
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
  // The format by the file's bytes where they tell it (PLY, binary STL), else by its extension.
  const FileKind kind = sniffFileKind(bytes.substr(0, 512), bytes.size());
  std::string ext = kind == FileKind::Ply ? "ply" : kind == FileKind::StlBinary ? "stl" : lowerExtension(path);
  if (kind != FileKind::Text && !isMeshKind(kind))
    throw ioError(path + ": " + describeFileKind(kind) + ", not a mesh file (expected PLY, OBJ or STL)");
  if (ext != "ply" && ext != "obj" && ext != "stl") throw ioError(path + ": not a mesh file (expected .ply, .obj or .stl)");
  Mesh m = ext == "stl" ? readStl(bytes, path) : ext == "ply" ? readPly(bytes, path) : readObj(bytes, path);
  if (m.triangles.empty()) fail(path, "no triangles");
  return m;
}

Mesh readMesh(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext != "ply" && ext != "obj" && ext != "stl" && !isMeshKind(sniffFile(path)))
    throw ioError(path + ": not a mesh file (expected .ply, .obj or .stl)");
  return parseMesh(path, readInputFile(path));
}

}  // namespace frep::io
