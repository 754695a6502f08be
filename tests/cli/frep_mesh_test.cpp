// frep mesh end to end: the files it writes are read back here (binary PLY, OBJ, binary STL)
// and checked: watertight and oriented, Euler characteristic, volume, outward normals, the three
// formats agreeing, and the same bytes whatever --brick and --threads (farm options: see
// frep_mesh_farm_test.cpp).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/mesh_checks.h"
#include "frep_runner.h"

using namespace frep_cli_test;
namespace mc = mesh_checks;

namespace {

constexpr double kPi = 3.14159265358979323846;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

struct ReadMesh {
  std::vector<mc::Vec3> positions, normals;  // float values, widened
  std::vector<mc::Tri> triangles;
  std::vector<mc::Vec3> facetNormals;  // STL only
};

uint32_t u32(const std::string& b, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(b[at + i])) << (8 * i);
  return v;
}
float f32(const std::string& b, size_t at) {
  uint32_t v = u32(b, at);
  float f;
  std::memcpy(&f, &v, 4);
  return f;
}

ReadMesh readPly(const std::string& bytes) {
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
  EXPECT_EQ(props.size(), 7u);
  EXPECT_EQ(props.back(), "property list uchar uint vertex_indices");
  size_t at = end + 11;
  EXPECT_EQ(bytes.size(), at + nv * 24 + nf * 13);
  if (bytes.size() != at + nv * 24 + nf * 13) return m;
  for (size_t i = 0; i < nv; ++i, at += 24) {
    m.positions.push_back({f32(bytes, at), f32(bytes, at + 4), f32(bytes, at + 8)});
    m.normals.push_back({f32(bytes, at + 12), f32(bytes, at + 16), f32(bytes, at + 20)});
  }
  for (size_t i = 0; i < nf; ++i, at += 13) {
    EXPECT_EQ(uint8_t(bytes[at]), 3u);
    m.triangles.push_back({u32(bytes, at + 1), u32(bytes, at + 5), u32(bytes, at + 9)});
  }
  return m;
}

ReadMesh readObj(const std::string& text) {
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
      mc::Tri t;
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

ReadMesh readStl(const std::string& bytes) {
  ReadMesh m;
  EXPECT_GE(bytes.size(), 84u);
  if (bytes.size() < 84) return m;
  EXPECT_NE(bytes.substr(0, 5), "solid");
  uint32_t n = u32(bytes, 80);
  EXPECT_EQ(bytes.size(), 84 + size_t(n) * 50);
  if (bytes.size() != 84 + size_t(n) * 50) return m;
  for (size_t i = 0, at = 84; i < n; ++i, at += 50) {
    m.facetNormals.push_back({f32(bytes, at), f32(bytes, at + 4), f32(bytes, at + 8)});
    mc::Tri t;
    for (int v = 0; v < 3; ++v) {
      size_t p = at + 12 + size_t(v) * 12;
      t[v] = uint32_t(m.positions.size());
      m.positions.push_back({f32(bytes, p), f32(bytes, p + 4), f32(bytes, p + 8)});
    }
    m.triangles.push_back(t);
  }
  return m;
}

}  // namespace

TEST_F(FrepTest, MeshWritesPlyObjStlThatReadBackWatertight) {
  write("s.hf", kSphere);
  RunResult r = run("mesh s.hf -b 1.5 --res 48 -O s.ply");
  ASSERT_EQ(r.code, 0) << r.err;
  ReadMesh ply = readPly(readText(path("s.ply")));
  ASSERT_GT(ply.triangles.size(), 1000u);
  EXPECT_TRUE(contains(r.out, "wrote s.ply (binary PLY): " + std::to_string(ply.positions.size()) + " vertices, " +
                                  std::to_string(ply.triangles.size()) + " triangles"))
      << r.out;
  EXPECT_TRUE(contains(r.out, " s meshing")) << r.out;
  EXPECT_EQ(mc::checkEdgePairs(ply.triangles, ply.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(ply.triangles, ply.positions.size()), 2);
  EXPECT_EQ(mc::selfIntersections(ply.positions, ply.triangles), 0u);  // after rounding to float
  const double volume = 4.0 / 3.0 * kPi;
  EXPECT_NEAR(mc::enclosedVolume(ply.positions, ply.triangles), volume, 0.01 * volume);
  EXPECT_NEAR(mc::surfaceArea(ply.positions, ply.triangles), 4 * kPi, 0.01 * 4 * kPi);
  for (size_t i = 0; i < ply.positions.size(); ++i) {
    const mc::Vec3& p = ply.positions[i];
    ASSERT_GT(mc::dot(ply.normals[i], p) / mc::norm(p), 0.9) << "vertex " << i;
    ASSERT_NEAR(mc::norm(p), 1.0, 0.5 * 3.0 / 47);  // within half a voxel of the unit sphere
  }

  // OBJ: the same float values and the same triangles.
  r = run("mesh s.hf -b 1.5 --res 48 -O s.obj");
  ASSERT_EQ(r.code, 0) << r.err;
  ReadMesh obj = readObj(readText(path("s.obj")));
  EXPECT_TRUE(obj.positions == ply.positions);
  EXPECT_TRUE(obj.normals == ply.normals);
  EXPECT_TRUE(obj.triangles == ply.triangles);

  // STL: the same triangles as vertex triples, facet normals outward.
  r = run("mesh s.hf -b 1.5 --res 48 -O S.STL");
  ASSERT_EQ(r.code, 0) << r.err;
  ReadMesh stl = readStl(readText(path("S.STL")));
  ASSERT_EQ(stl.triangles.size(), ply.triangles.size());
  for (size_t t = 0; t < ply.triangles.size(); ++t) {
    for (int v = 0; v < 3; ++v) ASSERT_TRUE(stl.positions[3 * t + v] == ply.positions[ply.triangles[t][v]]) << t;
    ASSERT_NEAR(mc::norm(stl.facetNormals[t]), 1.0, 1e-6);
    ASSERT_GT(mc::dot(stl.facetNormals[t], stl.positions[3 * t]), 0.0) << "facet " << t;
  }
  // No temporary files or journals left; each output has its farm report beside it.
  EXPECT_EQ(listing(), "S.STL S.STL.report.json s.hf s.obj s.obj.report.json s.ply s.ply.report.json");
}

TEST_F(FrepTest, MeshBytesDoNotDependOnBrickOrThreads) {
  std::string model = readText(FREP_EXAMPLES_DIR "/twisted_block.hf");
  write("t.hf", model);
  ASSERT_EQ(run("mesh t.hf -b 1.2 --res 56 -O a.ply").code, 0);
  const std::string ref = readText(path("a.ply"));
  ReadMesh m = readPly(ref);
  EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(m.triangles, m.positions.size()), 2);
  for (const char* opts : {"--brick 8", "--brick 16 --threads 1", "--brick 24 --threads 2", "--brick 512"}) {
    RunResult r = run(std::string("mesh t.hf -b 1.2 --res 56 -O b.ply ") + opts);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(readText(path("b.ply")) == ref) << opts;
  }
}

TEST_F(FrepTest, MeshSharpFeaturesStayWatertightAndSplitInvariant) {
  write("b.hf",
        "my_model(x[3], a[1]) {\n  array c[3];\n  c = [-0.61, -0.52, -0.43];\n"
        "  my_model = hfBlock(x, c, 1.2, 1.0, 0.8);\n}\n");
  RunResult r = run("mesh b.hf -b 1 --res 40 --sharp -O s.ply");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "feature vertices ")) << r.out;
  ReadMesh m = readPly(readText(path("s.ply")));
  EXPECT_EQ(mc::checkEdgePairs(m.triangles, m.positions.size()), "");
  EXPECT_EQ(mc::eulerCharacteristic(m.triangles, m.positions.size()), 2);
  EXPECT_EQ(mc::selfIntersections(m.positions, m.triangles), 0u);
  EXPECT_NEAR(mc::enclosedVolume(m.positions, m.triangles), 0.96, 0.005 * 0.96);
  ASSERT_EQ(run("mesh b.hf -b 1 --res 40 --sharp --brick 8 -O t.ply").code, 0);
  EXPECT_TRUE(readText(path("s.ply")) == readText(path("t.ply")));
}

TEST_F(FrepTest, MeshRejectsBadArguments) {
  write("s.hf", kSphere);
  write("flat.hf", "my_model(x[2], a[1]) { my_model = 1 - x[1]*x[1] - x[2]*x[2]; }\n");
  struct Case {
    const char* args;
    const char* message;
  } cases[] = {
      {"mesh s.hf --res 16", "-O/--out: the output mesh path"},
      {"mesh s.hf --res 16 -O s.vdb", "-O/--out: 's.vdb' has no mesh extension; use .ply"},
      {"mesh s.hf --res 16 -O s.ply --brick 12", "--brick: expected a positive multiple of 8"},
      {"mesh flat.hf --res 16 -O f.ply", "frep mesh needs a three-dimensional object"},
      {"mesh s.hf --res 16 -O nodir/s.ply", "-O/--out"},
  };
  for (const Case& c : cases) {
    RunResult r = run(c.args);
    EXPECT_NE(r.code, 0) << c.args;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
  }
  EXPECT_EQ(run("mesh s.hf --res 16 -O s.vdb").code, 2);
  EXPECT_EQ(run("mesh s.hf --res 16 -O nodir/s.ply").code, 3);
  EXPECT_EQ(listing(), "flat.hf s.hf");
}
