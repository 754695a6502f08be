// frVolumeSpline / frVolumeSplineFile: interpolation through the language, the point-file
// formats (text with values, text with normals, PLY ascii and binary), paths relative to the
// model file, CompileOptions::files, and the errors.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

struct Data {
  std::vector<std::array<double, 3>> p;
  std::vector<double> v;
};

Data randomData(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Data d;
  for (size_t i = 0; i < n; ++i) {
    d.p.push_back({U(rng), U(rng), U(rng)});
    d.v.push_back(std::cos(d.p.back()[0]) + d.p.back()[1] * d.p.back()[2]);
  }
  return d;
}

std::string tempDir() {
  char tmpl[] = "/tmp/frep_vs_XXXXXX";
  const char* d = mkdtemp(tmpl);
  return d ? d : "/tmp";
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

TEST(LibFrVolumeSpline, ArraysInterpolateAtEveryCentre) {
  Data d = randomData(40, 1);
  std::ostringstream c, v;
  c.precision(17), v.precision(17);
  for (size_t i = 0; i < d.p.size(); ++i) {
    c << (i ? ", " : "") << d.p[i][0] << ", " << d.p[i][1] << ", " << d.p[i][2];
    v << (i ? ", " : "") << d.v[i];
  }
  Model m = compileOk("m(x[3], a[1]) { array c[120], v[40]; c = [" + c.str() + "]; v = [" + v.str() +
                      "]; m = frVolumeSpline(x, c, v); }");
  for (size_t i = 0; i < d.p.size(); ++i) EXPECT_NEAR(evalModel(m, {d.p[i][0], d.p[i][1], d.p[i][2]}), d.v[i], 1e-9);
}

TEST(LibFrVolumeSpline, FileWithValuesRelativeToTheModel) {
  const std::string dir = tempDir();
  Data d = randomData(300, 2);
  std::ostringstream t;
  t.precision(17);
  t << "# x y z value\n";
  for (size_t i = 0; i < d.p.size(); ++i) t << d.p[i][0] << " " << d.p[i][1] << " " << d.p[i][2] << " " << d.v[i] << "\n";
  writeFile(dir + "/pts.xyz", t.str());
  const std::string src = "m(x[3], a[1]) { m = frVolumeSplineFile(x, \"pts.xyz\", 0); }";
  writeFile(dir + "/m.hf", src);
  CompileResult r = compileFile(dir + "/m.hf");
  ASSERT_TRUE(r.ok) << allDiagnostics(r);
  ASSERT_EQ(r.files.size(), 1u);
  EXPECT_EQ(r.files[0].first, "pts.xyz");
  EXPECT_EQ(r.files[0].second, t.str());
  for (size_t i = 0; i < d.p.size(); i += 7)
    EXPECT_NEAR(evalModel(r.model, {d.p[i][0], d.p[i][1], d.p[i][2]}), d.v[i], 1e-9);
  // The same contents given in memory (as farm workers get them): the same field.
  CompileOptions opt;
  opt.files["pts.xyz"] = t.str();
  CompileResult mem = compile(src, "elsewhere/m.hf", opt);
  ASSERT_TRUE(mem.ok) << allDiagnostics(mem);
  EXPECT_TRUE(mem.model.field.same(r.model.field));
}

// The unit sphere from points with normals, as text and as PLY (ascii and binary): the three
// give the same field, positive inside, negative outside, zero on the points.
TEST(LibFrVolumeSpline, SurfacePointsWithNormalsTextAndPly) {
  const std::string dir = tempDir();
  const int n = 300;
  std::vector<std::array<double, 3>> p;
  std::ostringstream t, ply;
  t.precision(17), ply.precision(17);
  ply << "ply\nformat ascii 1.0\nelement vertex " << n
      << "\nproperty double x\nproperty double y\nproperty double z\nproperty double nx\nproperty double ny\n"
         "property double nz\nend_header\n";
  std::string bin = "ply\nformat binary_little_endian 1.0\ncomment sphere\nelement vertex " + std::to_string(n) +
                    "\nproperty double x\nproperty double y\nproperty double z\nproperty double nx\nproperty double "
                    "ny\nproperty double nz\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1 - z * z), a = 2.399963229728653 * i;
    const double q[3] = {r * std::cos(a), r * std::sin(a), z};
    p.push_back({q[0], q[1], q[2]});
    t << q[0] << " " << q[1] << " " << q[2] << " " << q[0] << " " << q[1] << " " << q[2] << "\n";
    ply << q[0] << " " << q[1] << " " << q[2] << " " << q[0] << " " << q[1] << " " << q[2] << "\n";
    for (int k = 0; k < 6; ++k) bin.append(reinterpret_cast<const char*>(&q[k % 3]), 8);
  }
  writeFile(dir + "/s.txt", t.str());
  writeFile(dir + "/s.ply", ply.str());
  writeFile(dir + "/sb.ply", bin);
  Expr fields[3];
  const char* names[3] = {"s.txt", "s.ply", "sb.ply"};
  for (int k = 0; k < 3; ++k) {
    writeFile(dir + "/m.hf", std::string("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"") + names[k] + "\", 0.05); }");
    CompileResult r = compileFile(dir + "/m.hf");
    ASSERT_TRUE(r.ok) << names[k] << "\n" << allDiagnostics(r);
    fields[k] = r.model.field;
    EXPECT_GT(evalModel(r.model, {0, 0, 0}), 0.0);
    EXPECT_LT(evalModel(r.model, {1.3, 0.2, 0}), 0.0);
    for (int i = 0; i < n; i += 17) EXPECT_NEAR(evalModel(r.model, {p[i][0], p[i][1], p[i][2]}), 0.0, 1e-9);
    // off-surface values: -eps outside, +eps inside
    EXPECT_NEAR(evalModel(r.model, {1.05 * p[5][0], 1.05 * p[5][1], 1.05 * p[5][2]}), -0.05, 1e-9);
  }
  EXPECT_TRUE(fields[0].same(fields[1]));
  EXPECT_TRUE(fields[0].same(fields[2]));
}

std::string errorOf(const std::string& src, const CompileOptions& opt = {}) {
  CompileResult r = compile(src, "/tmp/nowhere/m.hf", opt);
  EXPECT_FALSE(r.ok);
  return allDiagnostics(r);
}

TEST(LibFrVolumeSpline, Errors) {
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"no.xyz\", 0); }").find("m.hf:1:43: error: cannot open file '/tmp/nowhere/no.xyz'"),
            std::string::npos) << errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"no.xyz\", 0); }");
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, 3, 0); }").find("must be a file name"), std::string::npos);
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = \"a\" + 1; }").find("only allowed as a file name"), std::string::npos);
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"a, 0); }").find("unterminated string"), std::string::npos);
  CompileOptions opt;
  opt.files["p.xyz"] = "0 0 0 1\n1 0 0 1\n0 1 0\n";
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.xyz\", 0); }", opt).find("p.xyz:3: expected 4 numbers"),
            std::string::npos);
  opt.files["p.xyz"] = "0 0 0 1\n1 0 0 1\n0 1 0 1\n1 1 0 2\n";
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.xyz\", 0); }", opt).find("one plane"),
            std::string::npos);
  opt.files["p.xyz"] = "0 0 0 1\n0 0 0 2\n0 1 0 1\n1 1 1 2\n1 0 0 0\n";
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.xyz\", 0); }", opt).find("centre 1 and centre 2 coincide"),
            std::string::npos);
  opt.files["p.xyz"] = "0 0 0 nan\n";
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.xyz\", 0); }", opt).find("not a finite number"),
            std::string::npos);
  opt.files["p.ply"] = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 1 1\n";
  EXPECT_NE(errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.ply\", 0); }", opt).find("a 'value' property or normals"),
            std::string::npos);
  EXPECT_NE(errorOf("m(x[3], a[1]) { array c[4], v[2]; c = [0,0,0,1]; v = [1, 2]; m = frVolumeSpline(x, c, v); }")
                .find("expected 3 per value"),
            std::string::npos);
  EXPECT_NE(errorOf("m(x[3], a[1]) { array c[3], v[1]; c = [0,0,x[1]]; v = [1]; m = frVolumeSpline(x, c, v); }")
                .find("known at compile time"),
            std::string::npos);
}

// Messages name the line and byte of a bad number, never the text (a worker's --data-dir file
// would otherwise come back to the master in the error).
TEST(LibFrVolumeSpline, ErrorsNeverQuoteTheFile) {
  CompileOptions opt;
  opt.files["p.xyz"] = "0 0 0 1\n1 0 0 1 # fine\n  1 SECRET 0 1\n";
  const std::string err = errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.xyz\", 0); }", opt);
  EXPECT_NE(err.find("p.xyz:3: not a finite number at byte 28"), std::string::npos) << err;
  EXPECT_EQ(err.find("SECRET"), std::string::npos) << err;
  opt.files["p.ply"] = "ply\nformat SECRET 1.0\nelement vertex 1\nproperty SECRET2 x\nend_header\n";
  const std::string ply = errorOf("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.ply\", 0); }", opt);
  EXPECT_EQ(ply.find("SECRET"), std::string::npos) << ply;
}

// On the user's own machine (FileAccess::Local, frep) files are read from the disk, but only
// regular files of bounded size: a FIFO is refused at once instead of parking the compile,
// /dev/zero instead of read to the end of memory; JobOnly (a farm worker) opens nothing.
TEST(LibFrVolumeSpline, TheDiskGivesRegularFilesOfBoundedSizeOnly) {
  const std::string dir = tempDir();
  const std::string fifo = dir + "/fifo.xyz";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  writeFile(dir + "/p.xyz", "0 0 0 1\n1 0 0 -1\n0 1 0 -1\n0 0 1 -1\n-1 -1 -1 -1\n");
  auto compileReading = [&](const std::string& path, const CompileOptions& opt) {
    return compile("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"" + path + "\", 0); }", dir + "/m.hf", opt);
  };
  const auto t0 = std::chrono::steady_clock::now();
  CompileResult r = compileReading(fifo, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(allDiagnostics(r).find("is not a regular file"), std::string::npos) << allDiagnostics(r);
  r = compileReading("/dev/zero", {});
  EXPECT_NE(allDiagnostics(r).find("is not a regular file"), std::string::npos) << allDiagnostics(r);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_TRUE(compileReading("p.xyz", {}).ok);
  CompileOptions small;
  small.maxFileBytes = 16;
  r = compileReading("p.xyz", small);
  EXPECT_NE(allDiagnostics(r).find("more than the limit of 16 bytes"), std::string::npos) << allDiagnostics(r);
  CompileOptions jobOnly;
  jobOnly.fileAccess = CompileOptions::FileAccess::JobOnly;
  r = compileReading("p.xyz", jobOnly);
  EXPECT_NE(allDiagnostics(r).find("'p.xyz': is not among the files the job ships"), std::string::npos) << allDiagnostics(r);
  jobOnly.files["p.xyz"] = "0 0 0 1\n1 0 0 -1\n0 1 0 -1\n0 0 1 -1\n-1 -1 -1 -1\n";
  EXPECT_TRUE(compileReading("p.xyz", jobOnly).ok);
  // compileFile reads the model itself the same way.
  r = compileFile(fifo);
  EXPECT_NE(allDiagnostics(r).find("is not a regular file"), std::string::npos) << allDiagnostics(r);
  std::system(("rm -rf '" + dir + "'").c_str());
}

}  // namespace
}  // namespace frep::lang::testing
