// Reading back the mesh files frep mesh writes (binary PLY, OBJ, binary STL), for the tests that
// run the binary (frep_mesh_test.cpp, frep_mesh_vdb_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "core/mesh_checks.h"

namespace frep_cli_test {

struct ReadMesh {
  std::vector<mesh_checks::Vec3> positions, normals;  // float values, widened
  std::vector<mesh_checks::Tri> triangles;
  std::vector<mesh_checks::Vec3> facetNormals;  // STL only
};

inline uint32_t u32(const std::string& b, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(b[at + i])) << (8 * i);
  return v;
}
inline float f32(const std::string& b, size_t at) {
  uint32_t v = u32(b, at);
  float f;
  std::memcpy(&f, &v, 4);
  return f;
}

inline ReadMesh readPly(const std::string& bytes) {
  ReadMesh m;
  size_t end = bytes.find("end_header\n");
  EXPECT_NE(end, std::string::npos);
  if (end == std::string::npos) return m;
  std::istringstream header(bytes.substr(0, end));
  std::string line;
  size_t nv = 0, nf = 0;
  std::vector<std::string> props;
  while (std::getline(header, line)) {
    std::istringstream ls(line);
    std::string w, what;
    ls >> w;
    if (w == "element") {
      ls >> what;
      (what == "vertex" ? nv : nf) = std::stoul(line.substr(line.rfind(' ') + 1));
    } else if (w == "property") {
      props.push_back(line);
    } else if (w == "format") {
      EXPECT_EQ(line, "format binary_little_endian 1.0");
    }
  }
  // x y z nx ny nz [red green blue: per-vertex colours of models that set s[]] and the faces.
  const bool coloured = props.size() == 10;
  EXPECT_TRUE(props.size() == 7u || coloured) << props.size();
  if (coloured) EXPECT_EQ(props[6], "property uchar red");
  EXPECT_EQ(props.back(), "property list uchar uint vertex_indices");
  const size_t stride = coloured ? 27 : 24;
  size_t at = end + 11;
  EXPECT_EQ(bytes.size(), at + nv * stride + nf * 13);
  if (bytes.size() != at + nv * stride + nf * 13) return m;
  for (size_t i = 0; i < nv; ++i, at += stride) {
    m.positions.push_back({f32(bytes, at), f32(bytes, at + 4), f32(bytes, at + 8)});
    m.normals.push_back({f32(bytes, at + 12), f32(bytes, at + 16), f32(bytes, at + 20)});
  }
  for (size_t i = 0; i < nf; ++i, at += 13) {
    EXPECT_EQ(uint8_t(bytes[at]), 3u);
    m.triangles.push_back({u32(bytes, at + 1), u32(bytes, at + 5), u32(bytes, at + 9)});
  }
  return m;
}

inline ReadMesh readObj(const std::string& text) {
  ReadMesh m;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v" || tag == "vn") {
      float x, y, z;  // the writer prints floats with 9 digits: read back exactly
      ls >> x >> y >> z;
      (tag == "v" ? m.positions : m.normals).push_back({x, y, z});
    } else if (tag == "f") {
      mesh_checks::Tri t;
      for (int c = 0; c < 3; ++c) {
        std::string item;
        ls >> item;
        size_t s = item.find("//");
        EXPECT_NE(s, std::string::npos);
        EXPECT_EQ(item.substr(0, s), item.substr(s + 2));  // normal index = vertex index
        t[c] = uint32_t(std::stoul(item.substr(0, s)) - 1);
      }
      m.triangles.push_back(t);
    }
  }
  return m;
}

inline ReadMesh readStl(const std::string& bytes) {
  ReadMesh m;
  EXPECT_GE(bytes.size(), 84u);
  if (bytes.size() < 84) return m;
  EXPECT_NE(bytes.substr(0, 5), "solid");
  uint32_t n = u32(bytes, 80);
  EXPECT_EQ(bytes.size(), 84 + size_t(n) * 50);
  if (bytes.size() != 84 + size_t(n) * 50) return m;
  for (size_t i = 0, at = 84; i < n; ++i, at += 50) {
    m.facetNormals.push_back({f32(bytes, at), f32(bytes, at + 4), f32(bytes, at + 8)});
    mesh_checks::Tri t;
    for (int v = 0; v < 3; ++v) {
      size_t p = at + 12 + size_t(v) * 12;
      t[v] = uint32_t(m.positions.size());
      m.positions.push_back({f32(bytes, p), f32(bytes, p + 4), f32(bytes, p + 8)});
    }
    m.triangles.push_back(t);
  }
  return m;
}

}  // namespace frep_cli_test
