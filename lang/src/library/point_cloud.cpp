// Point-cloud files for frVolumeSplineFile (format in point_cloud.h and docs/language.md).
#include "library/point_cloud.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>

namespace frep::lang {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& where, const std::string& what) {
  throw std::runtime_error(name + (where.empty() ? "" : ":" + where) + ": " + what);
}

bool parseDouble(const std::string& s, double& v) {
  const char* b = s.data();
  if (!s.empty() && *b == '+') ++b;
  auto r = std::from_chars(b, s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(v);
}

void add(PointCloud& pc, const std::vector<double>& row, int nxAt, int valueAt) {
  pc.points.push_back({row[0], row[1], row[2]});
  if (nxAt >= 0) pc.normals.push_back({row[size_t(nxAt)], row[size_t(nxAt) + 1], row[size_t(nxAt) + 2]});
  if (valueAt >= 0) pc.values.push_back(row[size_t(valueAt)]);
}

// Text: one point per line, numbers separated by blanks, '#' to the line's end a comment. A
// message names the line and the byte, never the file's text (a worker's --data-dir file).
PointCloud parseText(const std::string& contents, const std::string& name) {
  PointCloud pc;
  size_t columns = 0;
  size_t lineStart = 0;
  std::vector<double> row;
  for (int lineNo = 1; lineStart < contents.size(); ++lineNo) {
    size_t lineEnd = contents.find('\n', lineStart);
    if (lineEnd == std::string::npos) lineEnd = contents.size();
    const void* hash = std::memchr(contents.data() + lineStart, '#', lineEnd - lineStart);
    const size_t textEnd = hash ? size_t(static_cast<const char*>(hash) - contents.data()) : lineEnd;
    row.clear();
    for (size_t i = lineStart; i < textEnd;) {
      const unsigned char c = static_cast<unsigned char>(contents[i]);
      if (c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f') {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < textEnd && !std::strchr(" \t\r\v\f", contents[j])) ++j;
      double v;
      if (!parseDouble(contents.substr(i, j - i), v))
        fail(name, std::to_string(lineNo), "not a finite number at byte " + std::to_string(i + 1));
      row.push_back(v);
      i = j;
    }
    lineStart = lineEnd + 1;
    if (row.empty()) continue;
    if (columns == 0) {
      if (row.size() != 4 && row.size() != 6)
        fail(name, std::to_string(lineNo),
             "expected 'x y z value' or 'x y z nx ny nz' (surface points with normals), got " +
                 std::to_string(row.size()) + " numbers");
      columns = row.size();
    } else if (row.size() != columns) {
      fail(name, std::to_string(lineNo),
           "expected " + std::to_string(columns) + " numbers like the first line, got " + std::to_string(row.size()));
    }
    add(pc, row, columns == 6 ? 3 : -1, columns == 4 ? 3 : -1);
  }
  if (pc.points.empty()) fail(name, "", "no points");
  return pc;
}

int typeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double readBinary(const unsigned char* p, const std::string& t) {
  auto get = [&](auto v) {
    std::memcpy(&v, p, sizeof v);
    return double(v);
  };
  if (t == "char" || t == "int8") return get(int8_t());
  if (t == "uchar" || t == "uint8") return get(uint8_t());
  if (t == "short" || t == "int16") return get(int16_t());
  if (t == "ushort" || t == "uint16") return get(uint16_t());
  if (t == "int" || t == "int32") return get(int32_t());
  if (t == "uint" || t == "uint32") return get(uint32_t());
  if (t == "float" || t == "float32") return get(float());
  return get(double());
}

PointCloud parsePly(const std::string& contents, const std::string& name) {
  std::istringstream in(contents);
  std::string line, format;
  long vertices = -1;
  bool inVertex = false, vertexFirst = true, sawElement = false;
  std::vector<std::pair<std::string, std::string>> props;  // (type, name) of the vertex element
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (lineNo == 1) {
      if (key != "ply") fail(name, "1", "not a PLY file");
      continue;
    }
    if (key == "format") {
      ls >> format;
      if (format != "ascii" && format != "binary_little_endian")
        fail(name, std::to_string(lineNo), "this PLY format is not supported (ascii, binary_little_endian)");
    } else if (key == "element") {
      std::string el;
      long count = -1;
      ls >> el >> count;
      inVertex = el == "vertex";
      if (inVertex) {
        if (sawElement) vertexFirst = false;
        vertices = count;
      }
      sawElement = true;
    } else if (key == "property" && inVertex) {
      std::string type, pname;
      ls >> type;
      if (type == "list") fail(name, std::to_string(lineNo), "a list property in the vertex element");
      ls >> pname;
      if (!typeSize(type)) fail(name, std::to_string(lineNo), "unknown PLY property type");
      props.emplace_back(type, pname);
    } else if (key == "end_header") {
      break;
    }
  }
  if (vertices < 1) fail(name, "", "no vertex element (or no vertices)");
  if (format.empty()) fail(name, "", "no format line");
  if (!vertexFirst) fail(name, "", "the vertex element must be the first element");
  auto at = [&](const char* p) {
    for (size_t i = 0; i < props.size(); ++i)
      if (props[i].second == p) return int(i);
    return -1;
  };
  const int ix = at("x"), iy = at("y"), iz = at("z"), inx = at("nx"), iny = at("ny"), inz = at("nz"), iv = at("value");
  if (ix < 0 || iy < 0 || iz < 0) fail(name, "", "the vertices have no x, y, z");
  const bool hasNormals = inx >= 0 && iny >= 0 && inz >= 0;
  if (iv < 0 && !hasNormals) fail(name, "", "the vertices need a 'value' property or normals nx, ny, nz");
  PointCloud pc;
  std::vector<double> row(props.size());
  const std::streamoff dataStart = in.tellg();
  size_t stride = 0;
  for (const auto& p : props) stride += size_t(typeSize(p.first));
  // The vertices must fit in what follows the header (a binary vertex takes `stride` bytes, an
  // ascii value at least a character and a blank): checked before any is read.
  const uint64_t left = dataStart < 0 ? 0 : contents.size() - uint64_t(dataStart);
  const uint64_t least = format == "ascii" ? 2 * props.size() : stride;
  if (uint64_t(vertices) > (left + 1) / least)
    fail(name, "",
         "the header states " + std::to_string(vertices) + " vertices of at least " + std::to_string(least) +
             " bytes each, more than the " + std::to_string(left) + " bytes after it (truncated or damaged)");
  pc.points.reserve(size_t(vertices));
  for (long v = 0; v < vertices; ++v) {
    if (format == "ascii") {
      if (!std::getline(in, line)) fail(name, "", "the file ends at vertex " + std::to_string(v + 1));
      ++lineNo;
      std::istringstream ls(line);
      std::string word;
      for (size_t k = 0; k < props.size(); ++k)
        if (!(ls >> word) || !parseDouble(word, row[k]))
          fail(name, std::to_string(lineNo), "vertex " + std::to_string(v + 1) + ": bad or missing number");
    } else {
      const size_t off = size_t(dataStart) + size_t(v) * stride;
      if (dataStart < 0 || off + stride > contents.size())
        fail(name, "", "the file ends at vertex " + std::to_string(v + 1));
      const auto* p = reinterpret_cast<const unsigned char*>(contents.data()) + off;
      for (size_t k = 0; k < props.size(); ++k) {
        row[k] = readBinary(p, props[k].first);
        if (!std::isfinite(row[k])) fail(name, "", "vertex " + std::to_string(v + 1) + " has a non-finite number");
        p += typeSize(props[k].first);
      }
    }
    pc.points.push_back({row[size_t(ix)], row[size_t(iy)], row[size_t(iz)]});
    if (iv >= 0) pc.values.push_back(row[size_t(iv)]);
    else pc.normals.push_back({row[size_t(inx)], row[size_t(iny)], row[size_t(inz)]});
  }
  return pc;
}

}  // namespace

PointCloud parsePointCloud(const std::string& contents, const std::string& name) {
  if (contents.compare(0, 3, "ply") == 0) return parsePly(contents, name);
  return parseText(contents, name);
}

}  // namespace frep::lang
