// frPolygon, frBezierCurve, frBezierSurface in models (lang/src/library/fr_hybrid.cpp): values against the
// distance to the same geometry, areas by counting, and the errors at file:line:column. frMesh and
// frVolume read files through frep_io: tests/cli/unit/geometry_files_test.cpp.
#include <cmath>

#include "frep/geometry/distance_fields.h"
#include "frep/lang/library/library.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const char* kSquare =
    "m(x[2], a[1]) {\n"
    "  array v[8];\n"
    "  v = [0, 0, 2, 0, 2, 1, 0, 1];\n"
    "  m = frPolygon(x, v);\n"
    "}\n";

TEST(LibFrHybrid, PolygonIsTheSignedDistanceToTheRectangle) {
  Model m = compileOk(kSquare);
  EXPECT_CLOSE(evalModel(m, {1, 0.5}), 0.5);     // centre: 0.5 from the long sides
  EXPECT_CLOSE(evalModel(m, {0.2, 0.5}), 0.2);
  EXPECT_CLOSE(evalModel(m, {3, 0.5}), -1.0);    // outside: minus the distance
  EXPECT_CLOSE(evalModel(m, {3, 2}), -std::sqrt(2.0));
  EXPECT_CLOSE(evalModel(m, {2, 0.5}), 0.0);
}

TEST(LibFrHybrid, BezierCurveAreaMatchesTheClosedForm) {
  // Two cubic arcs approximating the unit circle's upper and lower halves would need 4 arcs; a
  // closed cubic arc pair with known area: by Green's theorem over the control polygon terms.
  // Here: the quadratic (degree 2) "lens" of two arcs (-1,0)-(0,1)-(1,0) and back via (0,-1):
  // each arc bounds 2/3 of its control triangle's area (1), so the lens has area 4/3.
  const char* src =
      "m(x[2], a[1]) {\n"
      "  array c[10];\n"
      "  c = [-1, 0, 0, 1, 1, 0, 0, -1, -1, 0];\n"
      "  m = frBezierCurve(x, c, 2, 9, 0.0005);\n"
      "}\n";
  Model m = compileOk(src);
  const int N = 600;
  const double h = 2.2 / N;
  size_t inside = 0;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) inside += evalModel(m, {-1.1 + (i + 0.5) * h, -1.1 + (j + 0.5) * h}) >= 0;
  EXPECT_NEAR(inside * h * h / (4.0 / 3.0), 1.0, 0.01);
  // The curve's midpoint (0, 0.5) lies on the boundary (within delta).
  EXPECT_NEAR(evalModel(m, {0, 0.5}), 0.0, 0.0005);
}

TEST(LibFrHybrid, BezierSurfaceOfFlatPatchesIsTheCube) {
  // Six flat bilinear patches on the faces of [0,1]^3, oriented outwards.
  const char* src =
      "m(x[3], a[1]) {\n"
      "  array c[72];\n"
      "  c = [0,0,0, 0,1,0, 1,0,0, 1,1,0,   0,0,1, 1,0,1, 0,1,1, 1,1,1,\n"
      "       0,0,0, 1,0,0, 0,0,1, 1,0,1,   0,1,0, 0,1,1, 1,1,0, 1,1,1,\n"
      "       0,0,0, 0,0,1, 0,1,0, 0,1,1,   1,0,0, 1,1,0, 1,0,1, 1,1,1];\n"
      "  m = frBezierSurface(x, c, 1, 1);\n"
      "}\n";
  Model m = compileOk(src);
  EXPECT_CLOSE(evalModel(m, {0.5, 0.5, 0.5}), 0.5);
  EXPECT_CLOSE(evalModel(m, {0.5, 0.5, 2}), -1.0);
  EXPECT_CLOSE(evalModel(m, {0.25, 0.6, 0.5}), 0.25);
}

struct ErrorCase {
  const char* src;
  int line, column;
  const char* message;
};

TEST(LibFrHybrid, BadInputIsAnErrorAtTheCall) {
  const ErrorCase cases[] = {
      {"m(x[2], a[1]) {\n  array v[4];\n  v = [0, 0, 1, 1];\n  m = frPolygon(x, v);\n}\n", 4, 20,
       "frPolygon: a polygon needs at least 3 distinct vertices"},
      {"m(x[2], a[1]) {\n  array c[8];\n  c = [0, 0, 0, 0, 0, 0, 0, 0];\n  m = frBezierCurve(x, c, 3);\n}\n", 4, 24,
       "frBezierCurve: arc 1 is degenerate: all its control points are equal"},
      {"m(x[2], a[1]) {\n  array c[8];\n  c = [0, 0, 1, 0, 1, 1, 0, 1];\n  m = frBezierCurve(x, c, 3);\n}\n", 4, 24,
       "frBezierCurve: the curve is not closed: the last control point must equal the first"},
      {"m(x[2], a[1]) {\n  array c[8];\n  c = [0, 0, 1, 0, 1, x[1], 0, 0];\n  m = frBezierCurve(x, c, 3);\n}\n", 4, 24,
       "frBezierCurve: element 6 of c must be a constant known at compile time (the geometry is built once)"},
      {"m(x[3], a[1]) {\n  m = frMesh(x, 3);\n}\n", 2, 17, "argument 2 of frMesh must be a file name in double quotes"},
      // A surface finer than 2^20 triangles: refused at once, not tessellated for minutes (a
      // fuzzed aircraft with a control point at -3e8). The cube's corner (1, 1, 1) moved far
      // twists its three patches; n past the cap for six patches.
      {"m(x[3], a[1]) {\n  array c[72];\n"
       "  c = [0,0,0, 0,1,0, 1,0,0, 1,1,0,   0,0,1, 1,0,1, 0,1,1, 1e6,1e6,1e6,\n"
       "       0,0,0, 1,0,0, 0,0,1, 1,0,1,   0,1,0, 0,1,1, 1,1,0, 1e6,1e6,1e6,\n"
       "       0,0,0, 0,0,1, 0,1,0, 0,1,1,   1,0,0, 1,1,0, 1,0,1, 1e6,1e6,1e6];\n"
       "  m = frBezierSurface(x, c, 1, 1, 2, 0.001);\n}\n",
       6, 26, ""},
      {"m(x[3], a[1]) {\n  array c[72];\n"
       "  c = [0,0,0, 0,1,0, 1,0,0, 1,1,0,   0,0,1, 1,0,1, 0,1,1, 1,1,1,\n"
       "       0,0,0, 1,0,0, 0,0,1, 1,0,1,   0,1,0, 0,1,1, 1,1,0, 1,1,1,\n"
       "       0,0,0, 0,0,1, 0,1,0, 0,1,1,   1,0,0, 1,1,0, 1,0,1, 1,1,1];\n"
       "  m = frBezierSurface(x, c, 1, 1, 300);\n}\n",
       6, 26,
       "frBezierSurface: n = 300 cells a side on each of the 6 patches is more than the 295 allowed (2^20 "
       "triangles in all)"},
  };
  for (const auto& c : cases) {
    CompileResult r = compile(c.src, "test.hf");
    ASSERT_FALSE(r.ok) << c.src;
    ASSERT_FALSE(r.diagnostics.empty());
    EXPECT_EQ(r.diagnostics[0].line, c.line) << c.src;
    EXPECT_EQ(r.diagnostics[0].column, c.column) << c.src;
    if (*c.message) EXPECT_EQ(r.diagnostics[0].message, c.message);
    else
      EXPECT_EQ(r.diagnostics[0].message.rfind("frBezierSurface: delta 0.001 needs about ", 0), 0u)
          << r.diagnostics[0].message;
  }
}

TEST(LibFrHybrid, FilesComeFromTheCompileOptionsOrTheDiskAndAreRecordedForJobs) {
  FileFieldLoader saved = fileFieldLoader();
  std::string seenPath, seenBytes;
  setFileFieldLoader([&](const FileFieldRequest& req) {
    seenPath = req.path;
    seenBytes = *req.bytes;
    if (seenBytes == "bad") throw std::runtime_error(req.path + ": no triangles");
    LoadedFileField l;
    l.field = std::make_shared<PolygonField>(std::vector<double>{0, 0, 1, 0, 0, 1}, "tri");
    l.fileHash = 42;
    l.warnings.push_back("not closed");
    return l;
  });
  // A farm worker: the bytes come with the job (CompileOptions::files), by the path as written.
  CompileOptions opt;
  opt.files["parts/a.stl"] = "mesh bytes";
  CompileResult r = compile("m(x[3], a[1]) {\n  m = frMesh(x, \"parts/a.stl\");\n}\n", "/models/m.hf", opt);
  EXPECT_TRUE(r.ok) << allDiagnostics(r);
  EXPECT_EQ(seenPath, "parts/a.stl");
  EXPECT_EQ(seenBytes, "mesh bytes");
  ASSERT_EQ(r.files.size(), 1u);  // what the master ships (JobSpec.model_files)
  EXPECT_EQ(r.files[0].first, "parts/a.stl");
  EXPECT_EQ(r.files[0].second, "mesh bytes");
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].message, "frMesh: not closed");
  EXPECT_EQ(r.diagnostics[0].line, 2);

  // Not given and not on disk: an error at the file argument.
  CompileResult missing = compile("m(x[3], a[1]) {\n  m = frMesh(x, \"missing.stl\");\n}\n", "m.hf");
  ASSERT_FALSE(missing.ok);
  EXPECT_EQ(missing.diagnostics[0].format().substr(0, 10), "m.hf:2:17:");
  EXPECT_NE(missing.diagnostics[0].message.find("missing.stl"), std::string::npos);

  // The loader's error: at the file argument, naming the file.
  opt.files["parts/a.stl"] = "bad";
  CompileResult bad = compile("m(x[3], a[1]) {\n  m = frMesh(x, \"parts/a.stl\");\n}\n", "m.hf", opt);
  ASSERT_FALSE(bad.ok);
  EXPECT_EQ(bad.diagnostics[0].format().substr(0, 10), "m.hf:2:17:");
  EXPECT_EQ(bad.diagnostics[0].message, "frMesh: parts/a.stl: no triangles");

  // A grid name is text, and only frVolume's third argument.
  CompileResult text = compile("m(x[3], a[1]) {\n  m = frMesh(x, \"parts/a.stl\", \"g\");\n}\n", "m.hf", opt);
  ASSERT_FALSE(text.ok);
  setFileFieldLoader(saved);
}

}  // namespace
}  // namespace frep::lang::testing
