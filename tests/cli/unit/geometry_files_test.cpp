// Geometry files as model operands (io/geometry_files.h): the mesh readers (STL binary/ASCII,
// OBJ, PLY ASCII/binary) against the same cube, frMesh through the HyperFun front end (Steiner's
// volume of the cube's offset), frVolume on a .vdb that frep's own writer made and on a plain
// OpenVDB level set, and the errors (missing file, unknown grid, open mesh) at the call.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/geometry/distance_fields.h"
#include "frep/io/error.h"
#include "frep/io/geometry_files.h"
#include "frep/io/mesh_reader.h"
#include "frep/io/vdb_writer.h"
#include "frep/io/world_lattice.h"
#include "frep/lang/field.h"
#include "frep/lang/hyperfun.h"
#include "frep/sampling/sample.h"

using namespace frep;

namespace {

struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/frep_geometry_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { std::system(("rm -rf '" + path + "'").c_str()); }
  std::string file(const std::string& name, const std::string& bytes) const {
    std::ofstream(path + "/" + name, std::ios::binary) << bytes;
    return path + "/" + name;
  }
};

// The unit cube [0, 1]^3: 8 corners, 12 outward triangles.
const double kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
const int kTri[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                         {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};

std::string asciiStl(int drop = 0) {
  std::string s = "solid cube\n";
  for (int t = 0; t < 12 - drop; ++t) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (int c = 0; c < 3; ++c) {
      const double* p = kCorner[kTri[t][c]];
      s += "   vertex " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    }
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid cube\n";
}
std::string binaryStl() {
  std::string s(80, ' ');
  uint32_t n = 12;
  s.append(reinterpret_cast<char*>(&n), 4);
  for (auto& t : kTri) {
    float rec[12] = {0, 0, 0};
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) rec[3 + 3 * c + k] = float(kCorner[t[c]][k]);
    s.append(reinterpret_cast<char*>(rec), 48);
    s.append(2, '\0');
  }
  return s;
}
std::string obj() {
  std::string s = "# cube\n";
  for (auto& p : kCorner) s += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (auto& t : kTri) s += "f " + std::to_string(t[0] + 1) + "/1 " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] - 8) + "\n";
  return s;
}
std::string ply(bool binary) {
  std::string s = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") +
                  " 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                  "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (auto& p : kCorner) {
    if (binary) {
      for (int k = 0; k < 3; ++k) {
        float f = float(p[k]);
        s.append(reinterpret_cast<char*>(&f), 4);
      }
    } else {
      s += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    }
  }
  for (auto& t : kTri) {
    if (binary) {
      s += char(3);
      for (int c = 0; c < 3; ++c) {
        int32_t i = t[c];
        s.append(reinterpret_cast<char*>(&i), 4);
      }
    } else {
      s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    }
  }
  return s;
}

lang::CompileResult compileModel(const TempDir& d, const std::string& body, int dims = 3) {
  io::installGeometryLoader();
  const std::string path = d.file("model.hf", "m(x[" + std::to_string(dims) + "], a[1]) {\n" + body + "\n}\n");
  return lang::compileFile(path);
}

// A mesh file's vertices and triangles in MeshField's flat form.
struct FlatMesh {
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
};
FlatMesh readFlat(const std::string& path) {
  Mesh m = io::readMesh(path);
  FlatMesh f;
  for (const auto& p : m.positions) f.xyz.insert(f.xyz.end(), p.begin(), p.end());
  for (const auto& t : m.triangles) f.tris.insert(f.tris.end(), t.begin(), t.end());
  return f;
}

double sampledVolume(const Expr& f, double lo, double hi, int n) {
  auto tape = Tape::compile(f, 3);
  SampleResult r = sample(tape, GridSpec::fromBounds({lo, lo, lo}, {hi, hi, hi}, n));
  return insideVolume(r);
}

}  // namespace

TEST(GeometryFiles, EveryMeshFormatReadsTheSameClosedCube) {
  TempDir d;
  for (auto [name, bytes] : std::vector<std::pair<std::string, std::string>>{
           {"a.stl", asciiStl()}, {"b.stl", binaryStl()}, {"c.obj", obj()}, {"d.ply", ply(false)}, {"e.ply", ply(true)}}) {
    FlatMesh m = readFlat(d.file(name, bytes));
    MeshField f(m.xyz, m.tris, name);
    EXPECT_TRUE(f.check().closed()) << name;
    EXPECT_EQ(f.numTriangles(), 12u) << name;
    EXPECT_NEAR(f.volume(), 1.0, 1e-9) << name;
    const double p[3] = {0.5, 0.5, 0.75};
    EXPECT_NEAR(f.value(p), 0.25, 1e-9) << name;
  }
}

TEST(GeometryFiles, MalformedMeshFilesAreErrorsNamingTheFile) {
  TempDir d;
  auto code = [&](const std::string& name, const std::string& bytes) {
    try {
      io::readMesh(d.file(name, bytes));
    } catch (const io::Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      return e.code;
    }
    return -1;
  };
  EXPECT_EQ(code("t.stl", binaryStl().substr(0, 200)), io::kExitIoError);  // truncated
  EXPECT_EQ(code("t.obj", "v 0 0 0\nf 1 2 3\n"), io::kExitIoError);       // index out of range
  EXPECT_EQ(code("t.ply", ply(true).substr(0, 250)), io::kExitIoError);     // truncated
  EXPECT_EQ(code("t.xyz", "1 2 3"), io::kExitIoError);                      // unknown format
  EXPECT_THROW(io::readMesh(d.path + "/none.stl"), io::Error);
}

TEST(GeometryFiles, MeshOffsetByABallHasSteinersVolume) {
  // The cube's signed distance + r is the Minkowski sum cube + ball(r): V = 1 + 6r + 3 pi r^2 + 4/3 pi r^3.
  TempDir d;
  d.file("cube.stl", binaryStl());
  lang::CompileResult r = compileModel(d, "  m = frMesh(x, \"cube.stl\") + 0.25;");
  ASSERT_TRUE(r.ok) << (r.diagnostics.empty() ? "" : r.diagnostics[0].format());
  ASSERT_EQ(r.files.size(), 1u);  // shipped in farm jobs by the path as written
  EXPECT_EQ(r.files[0].first, "cube.stl");
  EXPECT_EQ(io::contentHash(r.files[0].second), io::contentHash(binaryStl()));
  const double rr = 0.25, steiner = 1 + 6 * rr + 3 * M_PI * rr * rr + 4.0 / 3.0 * M_PI * rr * rr * rr;
  EXPECT_NEAR(sampledVolume(r.model.field, -0.4, 1.4, 160) / steiner, 1.0, 0.01);
}

// frMinkowski of a file operand and frBall: a closed mesh is an exact signed distance, so the
// sum is its offset (no extremum node, Steiner's volume); an open mesh (winding-number solid)
// and a trilinear .vdb volume are not exact distances and keep the certified search.
TEST(GeometryFiles, MinkowskiSumWithABallIsAnOffsetOnlyForExactDistances) {
  TempDir d;
  d.file("cube.stl", binaryStl());
  d.file("open.stl", asciiStl(1));
  io::installGeometryLoader();
  auto compileSum = [&](const std::string& part) {
    const std::string path = d.file("sum.hf", "p(x[3], a[1]) { p = " + part + "; }\n"
                                              "b(x[3], a[1]) { b = frBall(x, 0.25); }\n"
                                              "my_model(x[3], a[1]) { my_model = frMinkowski(x, p, b); }\n");
    return lang::compileFile(path);
  };
  auto hasExtremum = [](const Expr& f) {
    bool found = false;
    forEachNode(f, [&](const Node& n) { found = found || n.op == Op::Extremum; });
    return found;
  };
  lang::CompileResult closed = compileSum("frMesh(x, \"cube.stl\")");
  ASSERT_TRUE(closed.ok) << (closed.diagnostics.empty() ? "" : closed.diagnostics[0].format());
  EXPECT_FALSE(hasExtremum(closed.model.field));
  const double rr = 0.25, steiner = 1 + 6 * rr + 3 * M_PI * rr * rr + 4.0 / 3.0 * M_PI * rr * rr * rr;
  EXPECT_NEAR(sampledVolume(closed.model.field, -0.4, 1.4, 160) / steiner, 1.0, 0.01);

  lang::CompileResult open = compileSum("frMesh(x, \"open.stl\")");
  ASSERT_TRUE(open.ok);
  EXPECT_TRUE(hasExtremum(open.model.field));

  openvdb::initialize();
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.5f, openvdb::Vec3f(0, 0, 0), 0.05f);
  grid->setName("sphere");
  openvdb::io::File(d.path + "/s.vdb").write({grid});
  lang::CompileResult vol = compileSum("frVolume(x, \"s.vdb\")");
  ASSERT_TRUE(vol.ok) << (vol.diagnostics.empty() ? "" : vol.diagnostics[0].format());
  EXPECT_TRUE(hasExtremum(vol.model.field));
}

TEST(GeometryFiles, OpenMeshWarnsAndMissingFileIsAnErrorAtTheCall) {
  TempDir d;
  d.file("open.stl", asciiStl(1));
  lang::CompileResult r = compileModel(d, "  m = frMesh(x, \"open.stl\");");
  ASSERT_TRUE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_NE(r.diagnostics[0].message.find("3 open edges"), std::string::npos) << r.diagnostics[0].message;
  EXPECT_NE(r.diagnostics[0].message.find("winding number"), std::string::npos);
  EXPECT_EQ(r.diagnostics[0].line, 2);

  lang::CompileResult missing = compileModel(d, "  m = frMesh(x, \"nothing.stl\");");
  ASSERT_FALSE(missing.ok);
  EXPECT_EQ(missing.diagnostics[0].line, 2);
  EXPECT_EQ(missing.diagnostics[0].column, 17);
  EXPECT_NE(missing.diagnostics[0].message.find("cannot open file '" + d.path + "/nothing.stl'"), std::string::npos)
      << missing.diagnostics[0].message;
}

TEST(GeometryFiles, VdbFromTheSamplerReadsBackWithinHalfAVoxel) {
  TempDir d;
  // Sample a ball's signed distance, write it as frep sample does, read it back with frVolume.
  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr ball = 0.8 - sqrt(square(X - 0.1) + square(Y) + square(Z + 0.05));
  // On the world lattice, as frep sample samples (the file's transform is a pure scale).
  GridSpec g = io::worldLatticeGrid("test", {-1, -1, -1}, {1, 1, 1}, 2.0 / 63);
  SampleResult s = sample(Tape::compile(ball, 3), g);
  io::VdbMetadata meta;
  meta.gridName = "ball";
  io::writeLevelSet(d.file("ball.vdb", ""), s, meta);  // the writer fills an existing (temporary) file

  lang::CompileResult r = compileModel(d, "  m = frVolume(x, \"ball.vdb\", \"ball\");");
  ASSERT_TRUE(r.ok) << (r.diagnostics.empty() ? "" : r.diagnostics[0].format());
  auto vol = Tape::compile(r.model.field, 3), exact = Tape::compile(ball, 3);
  PointEvaluator pv, pe;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.95, 0.95);
  double worst = 0;
  int inBand = 0;
  for (int i = 0; i < 20000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    const double fe = pe.eval(*exact, p), fv = pv.eval(*vol, p);
    if (std::fabs(fe) < 2 * g.voxel) worst = std::max(worst, std::fabs(fe - fv)), ++inBand;
    else EXPECT_EQ(fe > 0, fv > 0);  // away from the surface: the same side (tiles, background)
  }
  EXPECT_GT(inBand, 300);
  EXPECT_LT(worst, 0.5 * g.voxel);  // 1-Lipschitz field: the zero set moves less than half a voxel
  // Re-sampled on the same lattice: the same zero set within half a voxel (the same side at
  // every lattice point farther than that from the surface), and the same volume within 1%.
  SampleResult again = sample(vol, g);
  EXPECT_NEAR(insideVolume(again) / insideVolume(s), 1.0, 0.01);
  int flipped = 0;
  for (int i = 0; i < g.dims[0]; i += 2)
    for (int j = 0; j < g.dims[1]; j += 2)
      for (int k = 0; k < g.dims[2]; k += 2) {
        const double p[3] = {g.origin[0] + i * g.voxel, g.origin[1] + j * g.voxel, g.origin[2] + k * g.voxel};
        const double fe = pe.eval(*exact, p);
        if (std::fabs(fe) > 0.5 * g.voxel && (fe > 0) != (pv.eval(*vol, p) > 0)) ++flipped;
      }
  EXPECT_EQ(flipped, 0);
  // Outside the grid's extent: the background, outside.
  const double far[3] = {5, 5, 5};
  EXPECT_LT(pv.eval(*vol, far), 0.0);

  lang::CompileResult bad = compileModel(d, "  m = frVolume(x, \"ball.vdb\", \"nope\");");
  ASSERT_FALSE(bad.ok);
  EXPECT_EQ(bad.diagnostics[0].column, 31);
  EXPECT_NE(bad.diagnostics[0].message.find("no grid named 'nope' (frVolume's grid argument); it holds 'ball' (float)"), std::string::npos)
      << bad.diagnostics[0].message;
}

TEST(GeometryFiles, PlainOpenVdbLevelSetIsNegativeInside) {
  TempDir d;
  openvdb::initialize();
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.5f, openvdb::Vec3f(0.2f, 0, 0), 0.02f);
  grid->setName("sphere");
  openvdb::io::File(d.path + "/s.vdb").write({grid});
  lang::CompileResult r = compileModel(d, "  m = frVolume(x, \"s.vdb\");");
  ASSERT_TRUE(r.ok) << (r.diagnostics.empty() ? "" : r.diagnostics[0].format());
  auto t = Tape::compile(r.model.field, 3);
  PointEvaluator pe;
  const double centre[3] = {0.2, 0, 0}, near[3] = {0.2, 0.45, 0}, out[3] = {0.2, 0.9, 0};
  EXPECT_GT(pe.eval(*t, centre), 0.0);  // deep inside: the inside tile value, positive
  EXPECT_NEAR(pe.eval(*t, near), 0.05, 0.01);
  EXPECT_LT(pe.eval(*t, out), 0.0);
}
