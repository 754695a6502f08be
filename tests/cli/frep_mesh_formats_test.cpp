// frep mesh's file formats read back by readers independent of its writers: tests/cli/tools/
// read_mesh.py (Python's standard library; numpy-stl for STL), lib3mf's reader for 3MF and
// assimp's `assimp info`.
// Counts, closed and consistently oriented triangles, per-vertex colours against the model's
// s[] formula at the vertices, the same bytes for any worker count, glTF's Y-up, CLI slices of
// a sphere against the disc areas, and hfp's command line.
#include <Model/COM/NMR_DLLInterfaces.h>

#include <cmath>
#include <map>
#include <regex>
#include <sstream>

#include "frep_runner.h"

namespace frep_cli_test {
namespace {

const char* kReader = FREP_SOURCE_DIR "/tests/cli/tools/read_mesh.py";

// Unit sphere coloured by position: s = (0.5 + x/2, 0.5 + y/2, 0.5 + z/2).
const char* kColoured = R"(my_model(x[3], a[1], s[3]) {
  s[1] = 0.5 + 0.5*x[1];  s[2] = 0.5 + 0.5*x[2];  s[3] = 0.5 + 0.5*x[3];
  my_model = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3];
}
)";
const double kVoxel = 0.15;  // -b 1.5 -g 20

struct Read {
  size_t vertices = 0, triangles = 0;
  bool closedOriented = false, normals = false, colours = false;
  std::vector<std::vector<double>> rows;  // x y z [nx ny nz] [r g b]
};

class MeshFormatsTest : public FrepTest {
 protected:
  Read readBack(const std::string& file, const std::string& format = "") {
    RunResult r = capture("/usr/bin/python3 '" + std::string(kReader) + "' '" + path(file) + "' " + format + " --text");
    EXPECT_EQ(r.code, 0) << r.err;
    Read m;
    std::istringstream in(r.out);
    std::string key;
    int flag = 0;
    in >> key >> m.vertices >> key >> m.triangles >> key >> flag;
    m.closedOriented = flag;
    in >> key >> flag;
    m.normals = flag;
    in >> key >> flag;
    m.colours = flag;
    const size_t width = 3 + (m.normals ? 3 : 0) + (m.colours ? 3 : 0);
    for (size_t i = 0; i < m.vertices; ++i) {
      std::vector<double> row(width);
      for (double& v : row) in >> v;
      m.rows.push_back(row);
    }
    return m;
  }
  void mesh(const std::string& out, const std::string& extra = "", const std::string& model = kColoured) {
    write("m.hf", model);
    RunResult r = run("mesh m.hf -b 1.5 -g 20 --workers 0 -O " + out + " " + extra);
    ASSERT_EQ(r.code, 0) << r.err;
  }
};

// The colour formula half a voxel inside the vertex (docs/language.md, "Attributes").
double expected(double p, double n) { return std::min(1.0, std::max(0.0, 0.5 + 0.5 * (p - 0.5 * kVoxel * n))); }

TEST_F(MeshFormatsTest, EveryWriterReadsBackWithColours) {
  mesh("ref.ply");
  Read ref = readBack("ref.ply");
  ASSERT_GT(ref.triangles, 300u);
  ASSERT_TRUE(ref.closedOriented);
  ASSERT_TRUE(ref.normals && ref.colours);
  struct Case {
    std::string file, format;
    bool colours;
    double tolerance;  // of a colour channel: bytes are rounded to 1/255
  };
  const Case cases[] = {{"a.ply", "", true, 0.5 / 255 + 1e-6}, {"a.obj", "", true, 1e-6},
                        {"a.wrl", "", true, 1e-6},             {"a.pov", "", true, 1e-6},
                        {"a.3mf", "", true, 0.5 / 255 + 1e-6}, {"a.glb", "--up z", true, 1e-6},
                        {"a.stl", "", false, 0},               {"b.stl", "--format stl-ascii", false, 0}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file + " " + c.format);
    mesh(c.file, c.format);
    Read m = readBack(c.file, c.file == "b.stl" ? "stl" : "");
    EXPECT_EQ(m.triangles, ref.triangles);
    EXPECT_EQ(m.vertices, ref.vertices);  // STL: vertices merged by position, so none coincide
    EXPECT_TRUE(m.closedOriented);
    EXPECT_EQ(m.colours, c.colours);
    if (!m.colours || c.file.find("stl") != std::string::npos) continue;
    double worst = 0;
    for (size_t i = 0; i < m.vertices; ++i) {
      const auto& row = m.rows[i];
      const auto& r = ref.rows[i];  // normals from the PLY (same vertex order in every format)
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(row[k], r[k], 1e-6);
        worst = std::max(worst, std::fabs(row[row.size() - 3 + k] - expected(r[k], r[3 + k])));
      }
    }
    EXPECT_LE(worst, c.tolerance);
  }
}

TEST_F(MeshFormatsTest, SetColorColoursTheSurfaceOfItsOwnSolid) {
  // hfA_SetColor(f, ...) tests f >= 0: evaluated half a voxel inside, every vertex gets it.
  mesh("red.ply", "", R"(my_model(x[3], a[1], s[3]) {
    r = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3];
    d = hfA_SetColor(r, s, 1, 0, 0.5);
    my_model = r;
  })");
  Read m = readBack("red.ply");
  ASSERT_TRUE(m.colours);
  for (const auto& row : m.rows) {
    EXPECT_EQ(row[6], 1.0);
    EXPECT_EQ(row[7], 0.0);
    EXPECT_NEAR(row[8], 128.0 / 255, 1e-9);
  }
}

TEST_F(MeshFormatsTest, AssimpReadsTheCommonFormats) {
  if (capture("command -v assimp").code != 0) GTEST_SKIP() << "assimp-utils not installed";
  mesh("ref.ply");
  const size_t triangles = readBack("ref.ply").triangles;
  for (std::string file : {"a.ply", "a.obj", "a.stl", "a.glb"}) {
    SCOPED_TRACE(file);
    mesh(file);
    RunResult r = capture("assimp info " + file);
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("Faces:              " + std::to_string(triangles) + "\n"), std::string::npos) << r.out;
  }
  // assimp 5.2 cannot open the ZIP64 container lib3mf writes (docs/cli.md, "Mesh formats"); the
  // same entries repacked by Python's zipfile without ZIP64 are read with every face.
  mesh("a.3mf");
  ASSERT_EQ(capture("/usr/bin/python3 -c \"import zipfile; s = zipfile.ZipFile('a.3mf'); "
                    "z = zipfile.ZipFile('b.3mf', 'w', zipfile.ZIP_DEFLATED); "
                    "[z.writestr(n, s.read(n)) for n in s.namelist()]; z.close()\"").code, 0);
  RunResult r = capture("assimp info b.3mf");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Faces:              " + std::to_string(triangles) + "\n"), std::string::npos) << r.out;
}

// The .3mf through lib3mf's own reader (not our writer's code path): one build item naming a
// mesh object of type "model", the PLY's vertices and triangles, each triangle's corner colours
// the PLY's vertex colours (both bytes of the same s[] value), and every edge in exactly two
// triangles, once each way (closed and consistently oriented) — besides lib3mf's own check.
TEST_F(MeshFormatsTest, Lib3mfReadsThe3mf) {
  using namespace NMR;
  mesh("ref.ply");
  mesh("a.3mf");
  const Read ref = readBack("ref.ply");
  struct Handle {
    PLib3MFBase* p = nullptr;
    ~Handle() {
      if (p) lib3mf_release(p);
    }
  } model, reader, items, item, object, properties;
  ASSERT_EQ(lib3mf_createmodel(&model.p), LIB3MF_OK);
  ASSERT_EQ(lib3mf_model_queryreader(model.p, "3mf", &reader.p), LIB3MF_OK);
  ASSERT_EQ(lib3mf_reader_setstrictmodeactive(reader.p, true), LIB3MF_OK);
  ASSERT_EQ(lib3mf_reader_readfromfileutf8(reader.p, path("a.3mf").c_str()), LIB3MF_OK);
  DWORD warnings = 1;
  ASSERT_EQ(lib3mf_reader_getwarningcount(reader.p, &warnings), LIB3MF_OK);
  EXPECT_EQ(warnings, 0u);
  ASSERT_EQ(lib3mf_model_getbuilditems(model.p, &items.p), LIB3MF_OK);
  BOOL more = false;
  ASSERT_EQ(lib3mf_builditemiterator_movenext(items.p, &more), LIB3MF_OK);
  ASSERT_TRUE(more);
  ASSERT_EQ(lib3mf_builditemiterator_getcurrent(items.p, &item.p), LIB3MF_OK);
  ASSERT_EQ(lib3mf_builditem_getobjectresource(item.p, &object.p), LIB3MF_OK);
  ASSERT_EQ(lib3mf_builditemiterator_movenext(items.p, &more), LIB3MF_OK);
  EXPECT_FALSE(more);  // one item
  BOOL isMesh = false, valid = false, manifold = false;
  DWORD type = 99;
  ASSERT_EQ(lib3mf_object_ismeshobject(object.p, &isMesh), LIB3MF_OK);
  ASSERT_TRUE(isMesh);
  ASSERT_EQ(lib3mf_object_gettype(object.p, &type), LIB3MF_OK);
  EXPECT_EQ(type, DWORD(MODELOBJECTTYPE_MODEL));
  ASSERT_EQ(lib3mf_object_isvalidobject(object.p, &valid), LIB3MF_OK);
  EXPECT_TRUE(valid);
  ASSERT_EQ(lib3mf_meshobject_ismanifoldandoriented(object.p, &manifold), LIB3MF_OK);
  EXPECT_TRUE(manifold);
  DWORD nv = 0, nt = 0;
  ASSERT_EQ(lib3mf_meshobject_getvertexcount(object.p, &nv), LIB3MF_OK);
  ASSERT_EQ(lib3mf_meshobject_gettrianglecount(object.p, &nt), LIB3MF_OK);
  ASSERT_EQ(nv, ref.vertices);
  ASSERT_EQ(nt, ref.triangles);
  std::vector<MODELMESHVERTEX> vertices(nv);
  std::vector<MODELMESHTRIANGLE> triangles(nt);
  ASSERT_EQ(lib3mf_meshobject_getvertices(object.p, vertices.data(), nv, nullptr), LIB3MF_OK);
  ASSERT_EQ(lib3mf_meshobject_gettriangleindices(object.p, triangles.data(), nt, nullptr), LIB3MF_OK);
  for (size_t i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(vertices[i].m_fPosition[k], ref.rows[i][k], 1e-6);  // lib3mf writes 6 decimals
  // Directed edges: each must occur once, and its reverse once.
  std::map<std::pair<DWORD, DWORD>, int> edges;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) ++edges[{t.m_nIndices[k], t.m_nIndices[(k + 1) % 3]}];
  size_t bad = 0;
  for (const auto& [e, n] : edges) bad += n != 1 || edges.count({e.second, e.first}) != 1 || edges.at({e.second, e.first}) != 1;
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(edges.size(), 3 * size_t(nt));
  ASSERT_EQ(lib3mf_meshobject_createpropertyhandler(object.p, &properties.p), LIB3MF_OK);
  std::vector<MODELMESH_TRIANGLECOLOR_SRGB> colours(nt);
  ASSERT_EQ(lib3mf_propertyhandler_getcolorarray(properties.p, colours.data()), LIB3MF_OK);
  size_t wrong = 0;
  double worst = 0;
  for (size_t i = 0; i < nt; ++i)
    for (int v = 0; v < 3; ++v) {
      const auto& c = colours[i].m_Colors[v];
      const auto& r = ref.rows[triangles[i].m_nIndices[v]];  // x y z nx ny nz r g b (bytes / 255)
      const uint8_t rgba[4] = {c.m_Red, c.m_Green, c.m_Blue, c.m_Alpha};
      for (int k = 0; k < 3; ++k) {
        wrong += rgba[k] != std::lround(r[6 + k] * 255);
        worst = std::max(worst, std::fabs(rgba[k] / 255.0 - expected(r[k], r[3 + k])));
      }
      wrong += rgba[3] != 255;
    }
  EXPECT_EQ(wrong, 0u);
  EXPECT_LE(worst, 0.5 / 255 + 1e-6);
}

TEST_F(MeshFormatsTest, ColouredBytesAreTheSameForAnyWorkerCount) {
  write("m.hf", kColoured);
  for (std::string ext : {"ply", "obj", "wrl", "3mf", "glb", "pov", "cli"}) {
    SCOPED_TRACE(ext);
    std::string first;
    for (std::string workers : {"0", "1", "2"}) {
      RunResult r = run("mesh m.hf -b 1.5 -g 24 --brick 8 --workers " + workers + " -O w" + workers + "." + ext);
      ASSERT_EQ(r.code, 0) << r.err;
      std::string bytes = readText(path("w" + workers + "." + ext));
      ASSERT_FALSE(bytes.empty());
      if (first.empty()) first = bytes;
      EXPECT_TRUE(bytes == first) << "--workers " << workers;
    }
  }
}

TEST_F(MeshFormatsTest, GlbIsYUpUnlessAskedOtherwise) {
  mesh("z.ply");
  mesh("y.glb");
  mesh("z.glb", "--up z");
  mesh("y.obj", "--up y");
  Read z = readBack("z.ply"), y = readBack("y.glb"), zg = readBack("z.glb"), yo = readBack("y.obj");
  ASSERT_EQ(y.vertices, z.vertices);
  for (size_t i = 0; i < z.vertices; ++i) {
    const auto &p = z.rows[i], &q = y.rows[i];
    EXPECT_NEAR(q[0], p[0], 1e-7);  // (x, y, z) -> (x, z, -y)
    EXPECT_NEAR(q[1], p[2], 1e-7);
    EXPECT_NEAR(q[2], -p[1], 1e-7);
    EXPECT_NEAR(q[4], p[5], 1e-7);  // normals turn with it
    EXPECT_NEAR(zg.rows[i][1], p[1], 1e-7);
    EXPECT_NEAR(yo.rows[i][1], p[2], 1e-6);
  }
  EXPECT_TRUE(y.closedOriented);  // a rotation keeps the winding outward
}

TEST_F(MeshFormatsTest, CliSlicesOfASphereAreItsDiscs) {
  write("m.hf", kColoured);
  ASSERT_EQ(run("mesh m.hf -b 1.5 -g 60 --tolerance 0 --workers 0 -O s.cli --gs 0.1").code, 0);
  ASSERT_EQ(run("mesh m.hf -b 1.5 -g 60 --tolerance 0 --workers 0 -O b.cli --format cli-binary --gs 0.1").code, 0);
  for (std::string file : {"s.cli", "b.cli"}) {
    SCOPED_TRACE(file);
    RunResult r = capture("/usr/bin/python3 '" + std::string(kReader) + "' " + file + " --text");
    ASSERT_EQ(r.code, 0) << r.err;
    std::istringstream in(r.out);
    std::string key;
    int layers = 0, declared = 0, withContour = 0;
    in >> key >> layers >> declared;
    EXPECT_EQ(layers, 30);  // 3 / 0.1
    EXPECT_EQ(declared, layers);
    for (int l = 0; l < layers; ++l) {
      double top = 0;
      int polylines = 0;
      in >> key >> top >> polylines;
      const double cut = top - 0.05;
      const double disc = M_PI * (1 - cut * cut);
      if (std::fabs(cut) < 0.95) EXPECT_EQ(polylines, 1) << "layer " << top;
      for (int k = 0; k < polylines; ++k) {
        int dir = 0, n = 0, closed = 0;
        double area = 0;
        in >> key >> dir >> n >> area >> closed;
        EXPECT_EQ(dir, 1);  // counter-clockwise around material
        EXPECT_EQ(closed, 1);
        // Vertices on the sphere, contour points on chords: inscribed, within a few % of the disc.
        EXPECT_LE(area, disc * (1 + 1e-6));
        EXPECT_GE(area, disc * 0.97 - 0.01) << "layer " << top;
        ++withContour;
      }
    }
    EXPECT_GE(withContour, 19);
  }
}

TEST_F(MeshFormatsTest, HfpCommandLine) {
  write("m.hf", kColoured);
  RunResult r = run("m.hf -b 1.5 -g 20 -stl a.stl -wrl a.wrl -stlb b.stl -pov a.pov -cli a.cli -gs 0.3 -t -d 5 --workers 0");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("-d 5 ignored"), std::string::npos) << r.err;
  // -t: hfp's timing line (frep prints it always).
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  time [0-9.]+ s meshing, [0-9.]+ s in all\n"))) << r.out;
  EXPECT_EQ(readText(path("a.stl")).rfind("solid my_model", 0), 0u);
  mesh("ref.ply");
  const size_t triangles = readBack("ref.ply").triangles;
  EXPECT_EQ(readBack("a.stl").triangles, triangles);
  EXPECT_EQ(readBack("b.stl").triangles, triangles);
  EXPECT_EQ(readBack("a.wrl").triangles, triangles);
  EXPECT_EQ(readBack("a.pov").triangles, triangles);
  EXPECT_TRUE(fileExists(path("a.cli")));
  // hfp's default grid is -g 30.
  ASSERT_EQ(run("m.hf -b 1.5 -stlb d.stl --workers 0").code, 0);
  ASSERT_EQ(run("mesh m.hf -b 1.5 -g 30 --workers 0 -O e.stl").code, 0);
  EXPECT_TRUE(readText(path("d.stl")) == readText(path("e.stl")));
  r = run("m.hf -g 20 -foo 3 -stl x.stl");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown hfp option '-foo'; hfp's options are"), std::string::npos) << r.err;
  r = run("m.hf -g 20");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no output"), std::string::npos) << r.err;
  r = run("m.hf -h");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("-stlb FILE"), std::string::npos);
  r = run("mesh m.hf -O a.glb --up x");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--up: expected z or y"), std::string::npos) << r.err;
}

// A full disk under every output kind (issue 31: .3mf ended in std::terminate, exit 134, its
// temporary left behind: lib3mf threw from its own destructor). `ulimit -f` makes every write
// past 8 KiB fail (EFBIG) as a full disk does; meshing a .vdb writes no journal, so the output
// is the first file to hit it. Each kind: exit 3 naming the write, no output, no temporary.
TEST_F(MeshFormatsTest, AFullDiskUnderEveryOutputKindIsAnIoError) {
  write("ball.hf", "my_model(x[3], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2; }\n");
  ASSERT_EQ(run("sample ball.hf -b 1.5 --res 64 --workers 0 --no-progress -O s.vdb").code, 0);
  for (const char* ext : {"ply", "obj", "stl", "wrl", "inc", "3mf", "glb", "cli"}) {
    const std::string out = std::string("full.") + ext;
    RunResult r = capture("(trap '' XFSZ; ulimit -f 8; '" FREP_BINARY "' mesh s.vdb -O " + out + ")");
    EXPECT_EQ(r.code, 3) << ext << ": " << r.err;
    EXPECT_NE(r.err.find("cannot write"), std::string::npos) << ext << ": " << r.err;
    EXPECT_FALSE(fileExists(path(out))) << ext;
    EXPECT_EQ(listing().find(".tmp"), std::string::npos) << ext << ": " << listing();
  }
  // Without the limit the same .3mf is written (through lib3mf's callbacks, the same bytes as
  // before: Lib3mfReadsThe3mf and ColouredBytesAreTheSameForAnyWorkerCount read it).
  ASSERT_EQ(run("mesh s.vdb -O ok.3mf").code, 0);
  EXPECT_GT(readText(path("ok.3mf")).size(), 8u * 1024);
}

}  // namespace
}  // namespace frep_cli_test
