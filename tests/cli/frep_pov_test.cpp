// frep pov (Roerdink's preprocessor): the written POV-Ray scene, rendered by povray, against
// frepfarm's own silhouette of the model in the same orthographic camera (rays cast through
// the compiled field by sphere tracing: the field is minus a distance, or an a = 0 R-union of
// such, which never exceeds the distance, so steps of |f| never cross the surface); the
// `$ ... $` scene syntax and its errors.
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <vector>

#include "cli/frep_runner.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "frep/lang/hyperfun.h"

namespace frep_cli_test {
namespace {

struct Camera {
  double loc[3], dir[3], up[3], right[3];  // orthographic: up/right are the image's full extent
};

const int kW = 120, kH = 90;

std::string povCamera(const Camera& c) {
  char b[512];
  std::snprintf(b, sizeof b,
                "camera { orthographic location <%g,%g,%g> direction <%g,%g,%g> up <%g,%g,%g> right <%g,%g,%g> }\n",
                c.loc[0], c.loc[1], c.loc[2], c.dir[0], c.dir[1], c.dir[2], c.up[0], c.up[1], c.up[2], c.right[0],
                c.right[1], c.right[2]);
  return b;
}

// Binary PPM (P6, header comments allowed) of povray's +FP output -> mask of bright pixels.
std::vector<bool> readMask(const std::string& path) {
  std::string s = readText(path);
  size_t at = 0;
  auto token = [&]() {
    for (;;) {
      while (at < s.size() && std::isspace(static_cast<unsigned char>(s[at]))) ++at;
      if (at < s.size() && s[at] == '#') {
        while (at < s.size() && s[at] != '\n') ++at;
        continue;
      }
      break;
    }
    size_t b = at;
    while (at < s.size() && !std::isspace(static_cast<unsigned char>(s[at]))) ++at;
    return s.substr(b, at - b);
  };
  if (token() != "P6") return {};
  int w = std::atoi(token().c_str()), h = std::atoi(token().c_str()), maxv = std::atoi(token().c_str());
  size_t off = at + 1;
  if (w != kW || h != kH) return {};
  const size_t bpp = maxv > 255 ? 6 : 3;
  if (s.size() < off + size_t(w) * h * bpp) return {};
  std::vector<bool> m(size_t(w) * h);
  for (size_t i = 0; i < m.size(); ++i) m[i] = static_cast<unsigned char>(s[off + i * bpp]) > 127;
  return m;
}

std::vector<bool> frepSilhouette(const std::string& model, const Camera& c) {
  frep::lang::CompileResult r = frep::lang::compileFile(model);
  EXPECT_TRUE(r.ok);
  frep::TapePtr tape = frep::Tape::compile(r.model.field, 3);
  frep::PointEvaluator pe;
  double dn = std::sqrt(c.dir[0] * c.dir[0] + c.dir[1] * c.dir[1] + c.dir[2] * c.dir[2]);
  std::vector<bool> m(size_t(kW) * kH);
  for (int j = 0; j < kH; ++j)
    for (int i = 0; i < kW; ++i) {
      // POV's pixel (i, j): right grows with i, up shrinks with j; pixel centres.
      double u = (i + 0.5) / kW - 0.5, v = 0.5 - (j + 0.5) / kH;
      double p[3];
      for (int k = 0; k < 3; ++k) p[k] = c.loc[k] + u * c.right[k] + v * c.up[k];
      bool hit = false;
      for (int step = 0; step < 4000 && !hit; ++step) {
        double f = pe.eval(*tape, p);
        if (f >= -1e-4) {
          hit = true;
          break;
        }
        double t = std::max(-f, 1e-4);
        for (int k = 0; k < 3; ++k) p[k] += t * c.dir[k] / dn;
        if (std::fabs(p[0]) > 20 || std::fabs(p[1]) > 20 || std::fabs(p[2]) > 20) break;
      }
      m[size_t(j) * kW + i] = hit;
    }
  return m;
}

class FrepPov : public FrepTest {
 protected:
  // Writes model.inc with frep pov, renders it in camera c, compares with frepfarm's silhouette.
  void compare(const std::string& model, const Camera& c, const char* what) {
    if (std::system("command -v povray >/dev/null 2>&1") != 0)
      GTEST_SKIP() << "povray is not installed (apt-get install povray; deploy/install-deps.sh installs it)";
    RunResult r = run("pov '" + model + "' -O model.inc");
    ASSERT_EQ(r.code, 0) << r.err;
    write("scene.pov", "#version 3.7;\n#include \"model.inc\"\nglobal_settings { ambient_light 1 }\n"
                       "background { rgb 0 }\n" + povCamera(c) +
                           "object { frep_model pigment { rgb 1 } finish { ambient 1 diffuse 0 } }\n");
    std::string cmd = "cd '" + dir_ + "' && povray +Iscene.pov +Oimage.ppm +FP +W" + std::to_string(kW) + " +H" +
                      std::to_string(kH) + " -A -D -V >/dev/null 2>povray.log";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << readText(path("povray.log"));
    std::vector<bool> pov = readMask(path("image.ppm")), frep = frepSilhouette(model, c);
    ASSERT_EQ(pov.size(), frep.size()) << "unreadable povray output";
    size_t agree = 0, inPov = 0, inFrep = 0, either = 0;
    for (size_t i = 0; i < pov.size(); ++i) {
      agree += pov[i] == frep[i];
      inPov += pov[i];
      inFrep += frep[i];
      either += pov[i] || frep[i];
    }
    const double all = double(agree) / pov.size(), onMask = 1.0 - double(pov.size() - agree) / either;
    std::printf("%s: %zu povray / %zu frepfarm pixels of %zu, agreement %.4f of all pixels, %.4f on the union mask\n",
                what, inPov, inFrep, pov.size(), all, onMask);
    EXPECT_GT(inPov, pov.size() / 20);  // not a blank image
    EXPECT_GE(onMask, 0.99);
  }
};

TEST_F(FrepPov, TableSceneMatchesFrepfarmsSilhouette) {
  // An oblique view (not symmetric: a mirrored image would not match).
  Camera c{{4, -3, 2.6}, {-4, 3, -2.2}, {0, 0, 2.2}, {3.6, 4.8, 0}};
  double s = 0.5;
  for (double& v : c.right) v *= s;
  compare(std::string(FREP_EXAMPLES_DIR) + "/roerdink/table.hf", c, "table (Fig. 9)");
}

TEST_F(FrepPov, RotatedSumsMatchFrepfarmsSilhouette) {
  write("rot.hf",
        "b(x[3], a[1]) { array c[3], r[3]; c = [-0.6, -0.3, -0.2]; r = [0.3, 0.5, 0.2];\n"
        "  b = frBlock(x, 1.0, 0.6, 0.4, c, r); }\n"
        "d(x[3], a[1]) { array c[3], r[3]; c = [0, 0, 0]; r = [0.3, 0.5, 0.2]; d = frZDisc(x, 0.25, c, r); }\n"
        "sb(x[3], a[1]) { sb = frBall(x, 0.12); }\n"
        "l(x[3], a[1]) { array c[3], r[3]; c = [1.2, 0.5, -0.5]; r = [1, 0, 0.4]; l = frYLine(x, 0.9, c, r); }\n"
        "e(x[3], a[1]) { array c[3], r[3]; c = [0, 0, 0]; r = [1, 0, 0.4]; e = frYDisc(x, 0.3, c, r); }\n"
        "one(x[3], a[1]) { one = frMinkowskiSum(x, b, d, sb); }\n"
        "two(x[3], a[1]) { two = frMinkowskiSum(x, l, e, sb); }\n"
        "my_model(x[3], a[1]) { my_model = one(x, a) | two(x, a); }\n");
  Camera c{{3, 4, 2}, {-3, -4, -2}, {0, 0, 3.2}, {-3.4, 2.55, 0}};
  compare(path("rot.hf"), c, "rotated block+zdisc+sphere and yline+ydisc+sphere");
}

// Discs on two axes: bicircle quartics, cylinders and blocks in POV against the closed-form
// bidisc gauge (1-Lipschitz, so sphere tracing it is safe) in frepfarm.
TEST_F(FrepPov, TwoAxisSumsMatchFrepfarmsSilhouette) {
  write("bi.hf",
        "b(x[3], a[1]) { array c[3], r[3]; c = [-0.5, -0.3, -0.2]; r = [0.3, 0.5, 0.2];\n"
        "  b = frBlock(x, 0.8, 0.5, 0.3, c, r); }\n"
        "dx(x[3], a[1]) { array c[3], r[3]; c = [0, 0, 0]; r = [0.3, 0.5, 0.2]; dx = frXDisc(x, 0.35, c, r); }\n"
        "dz(x[3], a[1]) { array c[3], r[3]; c = [0, 0, 0]; r = [0.3, 0.5, 0.2]; dz = frZDisc(x, 0.2, c, r); }\n"
        "ex(x[3], a[1]) { array c[3]; c = [1.3, 0.9, -0.6]; ex = frXDisc(x, 0.3, c); }\n"
        "ey(x[3], a[1]) { array c[3]; c = [0, 0, 0]; ey = frYDisc(x, 0.4, c); }\n"
        "one(x[3], a[1]) { one = frMinkowskiSum(x, b, dx, dz); }\n"
        "two(x[3], a[1]) { two = frMinkowskiSum(x, ex, ey); }\n"
        "my_model(x[3], a[1]) { my_model = one(x, a) | two(x, a); }\n");
  Camera c{{3, 4, 2}, {-3, -4, -2}, {0, 0, 3.2}, {-3.4, 2.55, 0}};
  compare(path("bi.hf"), c, "rotated block+xdisc+zdisc and a bidisc");
}

// Discs on three axes with a sphere (Appendix B's B*, tricircle-sphere corners) and discs on two
// axes with a sphere (bicircle-sphere): blocks, cylinders and tridiscsphere mesh2 pieces in POV
// against the convex-projection field (the exact distance outside) in frepfarm.
TEST_F(FrepPov, HigherSurfaceSumsMatchFrepfarmsSilhouette) {
  write("tri.hf",
        "b(x[3], a[1]) { array c[3], r[3]; c = [-0.6, -0.3, -0.2]; r = [0.3, 0.5, 0.2];\n"
        "  b = frBlock(x, 0.8, 0.5, 0.3, c, r); }\n"
        "dx(x[3], a[1]) { array c[3], r[3]; c = [0, 0, 0]; r = [0.3, 0.5, 0.2]; dx = frXDisc(x, 0.3, c, r); }\n"
        "dy(x[3], a[1]) { array c[3], r[3]; c = [0, 0, 0]; r = [0.3, 0.5, 0.2]; dy = frYDisc(x, 0.2, c, r); }\n"
        "dz(x[3], a[1]) { array c[3], r[3]; c = [0, 0, 0]; r = [0.3, 0.5, 0.2]; dz = frZDisc(x, 0.25, c, r); }\n"
        "sb(x[3], a[1]) { sb = frBall(x, 0.1); }\n"
        "ex(x[3], a[1]) { array c[3]; c = [1.3, 0.9, -0.6]; ex = frXDisc(x, 0.3, c); }\n"
        "ez(x[3], a[1]) { array c[3]; c = [0, 0, 0]; ez = frZDisc(x, 0.4, c); }\n"
        "one(x[3], a[1]) { one = frMinkowskiSum(x, b, dx, dy, dz, sb); }\n"
        "two(x[3], a[1]) { two = frMinkowskiSum(x, ex, ez, sb); }\n"
        "my_model(x[3], a[1]) { my_model = one(x, a) | two(x, a); }\n");
  Camera c{{3, 4, 2}, {-3, -4, -2}, {0, 0, 3.2}, {-3.4, 2.55, 0}};
  compare(path("tri.hf"), c, "rotated block+xdisc+ydisc+zdisc+sphere and xdisc+zdisc+sphere");
}

TEST_F(FrepPov, SceneTermsAreTranslatedAndErrorsNamed) {
  write("scene.pov", "#version 3.7;\n// eq. 22\nobject { $ xline(5) <+> zline(5) <+> yline(100) <+> ydisc(2) $ }\n"
                     "object { $ block(4, 4, 4, -2, -2, -2) <-> sphere(0.5) $ }\n");
  RunResult r = run("pov scene.pov -O out.pov");
  ASSERT_EQ(r.code, 0) << r.err;
  std::string out = readText(path("out.pov"));
  EXPECT_EQ(out.find('$'), std::string::npos);
  EXPECT_NE(out.find("box { <0.5, 0.5, 0.5>, <3.5, 3.5, 3.5> translate <-2, -2, -2> }"), std::string::npos) << out;
  EXPECT_NE(out.find("6 primitives"), std::string::npos) << out;  // block ⊕ ydisc: 2 blocks, 4 cylinders
  // A bicircle-sphere (R12) is one tridiscsphere: a mesh2 declared once, used as an object.
  write("tds.pov", "object {\n  $ xdisc(1) <+>   ydisc(1) <+> sphere(1) $ }\n");
  r = run("pov tds.pov -O tds_out.pov");
  ASSERT_EQ(r.code, 0) << r.err;
  out = readText(path("tds_out.pov"));
  EXPECT_NE(out.find("#declare frep_tridiscsphere_"), std::string::npos);
  EXPECT_NE(out.find("1 primitives"), std::string::npos);
  EXPECT_NE(out.find("object { frep_tridiscsphere_"), std::string::npos);
  write("bad2.pov", "$ xline(1) <+> cone(2) $");
  r = run("pov bad2.pov -O bad_out.pov");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("bad2.pov:1:16: 'cone' is not in the basic set"), std::string::npos) << r.err;
  // Sizes that overflow once summed (1e308 + 1e308) were written as `inf` with exit 0: refused,
  // naming the term, nothing written.
  write("big.pov", "object { $ block(1e308, 1, 1) <+> block(1e308, 1, 1) $ }\n");
  r = run("pov big.pov -O big_out.pov");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("big.pov:1:12: a size or placement is not a finite number once the terms are summed (inf)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fileExists(path("big_out.pov")));
  write("big.hf", "blk(x[3], a[1]) { blk = frBlock(x, 1e308, 1, 1); }\n"
                  "my_model(x[3], a[1]) { my_model = frMinkowskiSum(x, blk, blk); }\n");
  r = run("pov big.hf -O big.inc");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("big.hf: a size or placement is not a finite number"), std::string::npos) << r.err;
  EXPECT_FALSE(fileExists(path("big.inc")));
  // A .hf model with a part outside the basic set: named by its object.
  write("m.hf", "ball(x[3], a[1]) { ball = frBall(x, 1); }\nother(x[3], a[1]) { other = 1 - x[1]^2; }\n"
                "my_model(x[3], a[1]) { my_model = ball(x, a) | other(x, a); }\n");
  r = run("pov m.hf -O m.inc");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("m.hf:2:1: object 'other' is not reducible"), std::string::npos) << r.err;
  EXPECT_FALSE(fileExists(path("m.inc")));
  // The fallback: frep mesh writes a POV mesh2.
  r = run("mesh m.hf -O m.inc -b 2 --res 16 --workers 0 --no-progress");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(readText(path("m.inc")).find("#declare frep_mesh = mesh2"), std::string::npos);
}

}  // namespace
}  // namespace frep_cli_test
