// HyperFun attributes: s[] at the end of the body as expressions, the compiled hfA_* functions
// against their formulas at points, and the diagnostics of wrong calls.
#include <cmath>
#include <cstdio>

#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

// s[i] of the model at x (parameters 0).
double attributeAt(const Model& m, size_t i, std::vector<double> x) {
  std::vector<Expr> params(static_cast<size_t>(m.aSize), Expr(0.0));
  Expr f = bindParams(m.attributes.at(i), params);
  x.resize(std::max<size_t>(x.size(), static_cast<size_t>(m.xSize)), 0.0);
  auto tape = Tape::compile(f, static_cast<uint32_t>(x.size()));
  PointEvaluator ev;
  return ev.eval(*tape, x.data());
}

TEST(LangAttributes, NoAttributesByDefault) {
  Model m = compileOk("my_model(x[3], a[1]) { my_model = 1 - x[1]*x[1]; }");
  EXPECT_FALSE(m.hasAttributes);
  ASSERT_EQ(m.attributes.size(), 1u);  // hfp's S_dim = 1
  EXPECT_TRUE(m.attributes[0].isConst(0.0));
}

TEST(LangAttributes, AssignedElementsAreExpressions) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    s[1] = 0.5 + 0.25 * x[1];  s[3] = x[2] * x[3];
    my_model = 1 - x[1]*x[1];
  })");
  EXPECT_TRUE(m.hasAttributes);
  ASSERT_EQ(m.attributes.size(), 3u);
  EXPECT_CLOSE(attributeAt(m, 0, {0.4, 2, 3}), 0.6);
  EXPECT_CLOSE(attributeAt(m, 1, {0.4, 2, 3}), 0.0);
  EXPECT_CLOSE(attributeAt(m, 2, {0.4, 2, 3}), 6.0);
}

TEST(LangAttributes, SetColorWhereTheSolidIs) {
  // Red where x[1] >= 0, then blue over it where x[2] >= 0; black elsewhere.
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    d = hfA_SetColor(x[1], s, 1, 0, 0);
    d = hfA_SetColor(x[2], s, 0, 0, 1);
    my_model = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3];
  })");
  EXPECT_TRUE(m.hasAttributes);
  auto rgb = [&](double px, double py) {
    return std::vector<double>{attributeAt(m, 0, {px, py, 0}), attributeAt(m, 1, {px, py, 0}),
                               attributeAt(m, 2, {px, py, 0})};
  };
  EXPECT_EQ(rgb(0.5, -0.5), (std::vector<double>{1, 0, 0}));
  EXPECT_EQ(rgb(0.5, 0.5), (std::vector<double>{0, 0, 1}));
  EXPECT_EQ(rgb(-0.5, -0.5), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(rgb(0.0, -0.5), (std::vector<double>{1, 0, 0}));  // f >= 0 colours, f = 0 included
}

TEST(LangAttributes, UnionTakesTheColourOfTheSolidThePointIsIn) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array c1[3], c2[3];
    c1 = [1, 0, 0];  c2 = [0, 1, 0];
    f1 = 1 - (x[1] + 1)^2 - x[2]^2 - x[3]^2;
    f2 = 1 - (x[1] - 1)^2 - x[2]^2 - x[3]^2;
    my_model = hfA_Union(f1, f2, s, c1, c2, 4);
  })");
  auto f1 = [](double x) { return 1 - (x + 1) * (x + 1); };
  auto f2 = [](double x) { return 1 - (x - 1) * (x - 1); };
  for (double px : {-1.5, -0.5, 0.0, 0.5, 1.5}) {
    double a = f1(px), b = f2(px);
    EXPECT_CLOSE(evalModel(m, {px, 0, 0}), a + b + std::sqrt(a * a + b * b));
  }
  EXPECT_CLOSE(attributeAt(m, 0, {-1.5, 0, 0}), 1.0);  // only in the first
  EXPECT_CLOSE(attributeAt(m, 1, {-1.5, 0, 0}), 0.0);
  EXPECT_CLOSE(attributeAt(m, 0, {1.5, 0, 0}), 0.0);   // only in the second
  EXPECT_CLOSE(attributeAt(m, 1, {1.5, 0, 0}), 1.0);
  EXPECT_CLOSE(attributeAt(m, 0, {0, 0, 0}), 1.0);     // in both (touching): maximum of each
  EXPECT_CLOSE(attributeAt(m, 1, {0, 0, 0}), 1.0);
  EXPECT_CLOSE(attributeAt(m, 0, {5, 0, 0}), 0.0);     // outside the union: s unchanged (0)
}

TEST(LangAttributes, LerpAndCerpMixTwoColours) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array c1[3], c2[3];
    c1 = [1, 0, 0];  c2 = [0, 0, 1];
    t = hfA_Lerp(s, c1, c2, x[3], -1, 1);
    my_model = t;
  })");
  for (double z : {-2.0, -1.0, -0.5, 0.0, 0.3, 1.0, 3.0}) {
    double t = (z + 1) / 2, tc = std::min(1.0, std::max(0.0, t));
    EXPECT_CLOSE(evalModel(m, {0, 0, z}), t);
    EXPECT_CLOSE(attributeAt(m, 0, {0, 0, z}), 1 - tc);
    EXPECT_CLOSE(attributeAt(m, 2, {0, 0, z}), tc);
  }
  Model c = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array c1[3], c2[3];
    c1 = [0, 0, 0];  c2 = [1, 1, 1];
    my_model = hfA_Cerp(s, c1, c2, x[3], 0, 1);
  })");
  double t = 0.25, tc = t * t * (3 - 2 * t);
  EXPECT_CLOSE(attributeAt(c, 1, {0, 0, t}), tc);
  EXPECT_CLOSE(evalModel(c, {0, 0, t}), tc);
}

TEST(LangAttributes, ToolboxFunctionValues) {
  EXPECT_CLOSE(valueOf("hfA_Clamp(x[1], 0, 1)", {-0.5, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_Clamp(x[1], 0, 1)", {0.25, 0, 0}), 0.25);
  EXPECT_CLOSE(valueOf("hfA_Clamp(x[1], 0, 1)", {7, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Step(x[1], 2)", {1.9, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_Step(x[1], 2)", {2, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Pulse(x[1], 1, 2)", {0.5, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_Pulse(x[1], 1, 2)", {1.5, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Pulse(x[1], 1, 2)", {2.5, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_SmoothStep(x[1], 1, 3)", {2.5, 0, 0}), 0.75 * 0.75 * (3 - 1.5));
  EXPECT_CLOSE(valueOf("hfA_SmoothStep(x[1], 1, 3)", {0, 0, 0}), 0.0);
  EXPECT_CLOSE(valueOf("hfA_SmoothStep(x[1], 1, 3)", {4, 0, 0}), 1.0);
  EXPECT_CLOSE(valueOf("hfA_Modulo(x[1], 3)", {7.5, 0, 0}), 1.5);
  EXPECT_CLOSE(valueOf("hfA_Modulo(x[1], 3)", {-1, 0, 0}), 2.0);  // a modulo, not a remainder
  EXPECT_CLOSE(valueOf("hfA_Floor(x[1])", {-1.5, 0, 0}), -1.0);   // towards zero, as hfp
  EXPECT_CLOSE(valueOf("hfA_Floor(x[1])", {2.7, 0, 0}), 2.0);
}

TEST(LangAttributes, SetAttributesCopiesWhereInside) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[2]) {
    array v[3];
    v = [0.2, 0.4, 0.6];
    d = hfA_SetAttributes(x[1], s, v);
    my_model = 1;
  })");
  EXPECT_CLOSE(attributeAt(m, 0, {1, 0, 0}), 0.2);
  EXPECT_CLOSE(attributeAt(m, 1, {1, 0, 0}), 0.4);
  EXPECT_CLOSE(attributeAt(m, 1, {-1, 0, 0}), 0.0);
}

// Gardner's noise as in hfp's attribute library, written out here: scaled to [0, 1].
double gardner(double x, double y, double z, double phase, double freq) {
  const double sx = std::sin(freq * x), sy = std::sin(freq * y), sz = std::sin(freq * z);
  const double product = (sx + std::sin(freq * x / 1.35 + phase * sz) / 1.17) *
                         (sy + std::sin(freq * y / 1.35 + phase * sx) / 1.17) *
                         (sz + std::sin(freq * z / 1.35 + phase * sy) / 1.17);
  const double c3 = std::pow(2.17 / 1.17, 3);
  return (product + c3) / (2 * c3);
}

TEST(LangAttributes, WaveAndNoiseValues) {
  const double wave = 0.2 + 0.6 * (1 + std::sin(3 * 0.5)) / 2;
  EXPECT_CLOSE(valueOf("hfA_Wave(x[1], 0.2, 0.8, 3)", {0.5, 0, 0}), wave);
  EXPECT_CLOSE(valueOf("hfA_Wave(x[1], 0.8, 0.2, 3)", {0.5, 0, 0}), wave);  // bounds in either order
  EXPECT_CLOSE(valueOf("hfA_NoiseG(x, 0.7, 1.4)", {0.3, -2.2, 0.9}), gardner(0.3, -2.2, 0.9, 1.4, 0.7));
  EXPECT_CLOSE(valueOf("hfA_NoiseG(x, 2, 0.5)", {-1.1, 0.4, 3}), gardner(-1.1, 0.4, 3, 0.5, 2));
}

// Circles: |x| mod 1 picks a set by the map's intervals; Crackles: the cycled sum of three
// Gardner noises does. Outside every interval s keeps its value.
TEST(LangAttributes, CirclesAndCracklesPickAttributeSetsByTheMap) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array sets[6], map[3];
    sets = [1, 0, 0, 0, 0, 1];  map = [0, 0.5, 0.9];
    d = hfA_Circles(x, s, sets, map);
    my_model = 1;
  })");
  EXPECT_CLOSE(attributeAt(m, 0, {1.25, 0, 0}), 1.0);  // 0.25: first set
  EXPECT_CLOSE(attributeAt(m, 0, {0, -1, 0}), 1.0);    // |x| = 1: 0, first set
  EXPECT_CLOSE(attributeAt(m, 0, {0, 0, 1.7}), 0.0);    // 0.7: second set
  EXPECT_CLOSE(attributeAt(m, 2, {0, 0, 1.7}), 1.0);
  EXPECT_CLOSE(attributeAt(m, 0, {0, 0, 2.95}), 0.0);    // 0.95: no interval, s stays 0
  EXPECT_CLOSE(attributeAt(m, 2, {0, 0, 2.95}), 0.0);
  Model c = compileOk(R"(my_model(x[3], a[1], s[2]) {
    array sets[4], map[3];
    sets = [1, 2, 3, 4];  map = [0, 0.5, 1];
    d = hfA_Crackles(x, s, 1.5, sets, map);
    my_model = 1;
  })");
  for (const std::vector<double>& x : std::vector<std::vector<double>>{{0.3, -0.7, 1.1}, {2, 1, -0.5}, {-0.2, 0.1, 0.4}}) {
    const double phase = (std::fabs(x[0]) + std::fabs(x[1]) + std::fabs(x[2])) / 3;
    const double sum = -3 + 2 * (gardner(x[0], x[0], x[2], phase, 1.5) + gardner(x[1], x[1], x[0], phase, 1.5) +
                                 gardner(x[2], x[2], x[1], phase, 1.5));
    const double p = (1 + std::sin(std::trunc((sum - std::floor(sum)) * 1000) * 2 * M_PI / 1000)) / 2;
    const double first = p < 0.5 ? 1 : p < 1 ? 3 : 0;
    EXPECT_CLOSE(attributeAt(c, 0, x), first);
    EXPECT_CLOSE(attributeAt(c, 1, x), first == 0 ? 0 : first + 1);
  }
}

TEST(LangAttributes, CheckerBoardBlocksRepeatFromTheOrigin) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array block[3], gap[3], on[3], off[3];
    block = [1, 1, 2];  gap = [0.5, 0.5, 0];  on = [1, 1, 1];  off = [0, 0, 0.5];
    d = hfA_CheckerBoard(x, block, gap, s, on, off);
    my_model = 1;
  })");
  // Blocks on (1.5k, 1.5k + 1) in x and y, (2k, 2k + 2) in z: strictly inside on every axis.
  EXPECT_CLOSE(attributeAt(m, 0, {0.5, 0.5, 0.5}), 1.0);
  EXPECT_CLOSE(attributeAt(m, 2, {1.2, 0.5, 0.5}), 0.5);   // in the gap along x
  EXPECT_CLOSE(attributeAt(m, 0, {-1, 1.7, -3}), 1.0);     // blocks (-1.5, -0.5), (1.5, 2.5), (-4, -2)
  EXPECT_CLOSE(attributeAt(m, 0, {1, 0.5, 0.5}), 0.0);     // on a block's face: outside
  EXPECT_CLOSE(attributeAt(m, 0, {0.5, 0.5, 2}), 0.0);
}

TEST(LangAttributes, HsvAndRgbConversions) {
  Model m = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array hsv[3];
    hsv = [x[1], 0.5, 0.8];
    d = hfA_HSVToRGB(hsv, s);
    my_model = 1;
  })");
  for (double h : {210.0, -150.0, 570.0}) {  // hue taken modulo 360
    EXPECT_CLOSE(attributeAt(m, 0, {h, 0, 0}), 0.4);
    EXPECT_CLOSE(attributeAt(m, 1, {h, 0, 0}), 0.6);
    EXPECT_CLOSE(attributeAt(m, 2, {h, 0, 0}), 0.8);
  }
  EXPECT_CLOSE(attributeAt(m, 0, {0, 0, 0}), 0.8);  // red: (1, 0.5, 0.5) * 0.8
  EXPECT_CLOSE(attributeAt(m, 1, {0, 0, 0}), 0.4);
  Model r = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array rgb[3];
    rgb = [x[1], x[2], x[3]];
    d = hfA_RGBToHSV(rgb, s);
    my_model = 1;
  })");
  auto hsv = [&](std::vector<double> c) {
    return std::vector<double>{attributeAt(r, 0, c), attributeAt(r, 1, c), attributeAt(r, 2, c)};
  };
  const std::vector<double> blue = hsv({0.4, 0.6, 0.8}), grey = hsv({0.3, 0.3, 0.3}), pink = hsv({0.8, 0.2, 0.4});
  EXPECT_CLOSE(blue[0], 210.0);
  EXPECT_CLOSE(blue[1], 0.5);
  EXPECT_CLOSE(blue[2], 0.8);
  EXPECT_EQ(grey, (std::vector<double>{0, 0, 0.3}));
  EXPECT_CLOSE(pink[0], -20.0);  // not wrapped, as hfp
  EXPECT_CLOSE(pink[1], 0.75);
}

// Look-up tables: set k belongs to map[k]; below map[1] the first set, at or past the last entry
// the last set. LookUpTable picks set k on [map[k], map[k+1]); SmoothLookUpTable mixes k and k+1.
TEST(LangAttributes, LookUpTablesPickOrMixTheSetsOfTheMap) {
  const char* table = R"(my_model(x[3], a[1], s[2]) {
    array sets[6], map[3];
    sets = [1, 2, 3, 4, 5, 6];  map = [0.2, 0.5, 0.9];
    d = %s(x[1], s, sets, map);
    my_model = 1;
  })";
  char text[512];
  std::snprintf(text, sizeof text, table, "hfA_LookUpTable");
  Model m = compileOk(text);
  EXPECT_TRUE(m.hasAttributes);
  auto pair = [](const Model& model, double t) {
    return std::vector<double>{attributeAt(model, 0, {t, 0, 0}), attributeAt(model, 1, {t, 0, 0})};
  };
  EXPECT_EQ(pair(m, -3), (std::vector<double>{1, 2}));  // below the map: the first set
  EXPECT_EQ(pair(m, 0.2), (std::vector<double>{1, 2}));
  EXPECT_EQ(pair(m, 0.49), (std::vector<double>{1, 2}));
  EXPECT_EQ(pair(m, 0.5), (std::vector<double>{3, 4}));
  EXPECT_EQ(pair(m, 0.89), (std::vector<double>{3, 4}));
  EXPECT_EQ(pair(m, 0.9), (std::vector<double>{5, 6}));  // at or past the last entry: its set
  EXPECT_EQ(pair(m, 7), (std::vector<double>{5, 6}));
  std::snprintf(text, sizeof text, table, "hfA_SmoothLookUpTable");
  Model smooth = compileOk(text);
  auto mix = [](double a, double b, double l) { return (1 - l) * a + l * b; };
  EXPECT_EQ(pair(smooth, 0.1), (std::vector<double>{1, 2}));
  for (double t : {0.2, 0.3, 0.45}) {
    const double l = (t - 0.2) / 0.3;
    EXPECT_CLOSE(pair(smooth, t)[0], mix(1, 3, l));
    EXPECT_CLOSE(pair(smooth, t)[1], mix(2, 4, l));
  }
  for (double t : {0.5, 0.8}) {
    const double l = (t - 0.5) / 0.4;
    EXPECT_CLOSE(pair(smooth, t)[0], mix(3, 5, l));
    EXPECT_CLOSE(pair(smooth, t)[1], mix(4, 6, l));
  }
  EXPECT_EQ(pair(smooth, 0.9), (std::vector<double>{5, 6}));
  EXPECT_EQ(pair(smooth, 4), (std::vector<double>{5, 6}));
  // One set fewer than the map's entries (hfp's documented example): the last set is held from
  // the last interval on; the smooth table mixes towards it and holds it.
  Model short_ = compileOk(R"(my_model(x[3], a[1], s[2]) {
    array sets[4], map[3];
    sets = [1, 2, 3, 4];  map = [0.2, 0.5, 0.9];
    d = hfA_LookUpTable(x[1], s, sets, map);
    my_model = 1;
  })");
  EXPECT_EQ(pair(short_, 0.3), (std::vector<double>{1, 2}));
  EXPECT_EQ(pair(short_, 0.6), (std::vector<double>{3, 4}));
  EXPECT_EQ(pair(short_, 0.95), (std::vector<double>{3, 4}));
  Model shortSmooth = compileOk(R"(my_model(x[3], a[1], s[2]) {
    array sets[4], map[3];
    sets = [1, 2, 3, 4];  map = [0.2, 0.5, 0.9];
    d = hfA_SmoothLookUpTable(x[1], s, sets, map);
    my_model = 1;
  })");
  EXPECT_CLOSE(pair(shortSmooth, 0.35)[0], mix(1, 3, 0.5));
  EXPECT_EQ(pair(shortSmooth, 0.6), (std::vector<double>{3, 4}));
  EXPECT_EQ(pair(shortSmooth, 2), (std::vector<double>{3, 4}));
}

// Catmull-Rom through p1, p2 with p0 and p3 steering the tangents, in its textbook form.
double catmullRom(double p0, double p1, double p2, double p3, double r) {
  return 0.5 * (2 * p1 + (p2 - p0) * r + (2 * p0 - 5 * p1 + 4 * p2 - p3) * r * r + (3 * p1 - p0 - 3 * p2 + p3) * r * r * r);
}

TEST(LangAttributes, SplineIsCatmullRomThroughTheInnerKnots) {
  // Five knots of one element (two spans) and of two elements; t = x[1] over [1, 3].
  Model m = compileOk(R"(my_model(x[3], a[1], s[2]) {
    array knots[10];
    knots = [0, 5, 1, 6, 4, 2, 2, 8, 3, 1];
    d = hfA_Spline(s, knots, x[1], 1, 3);
    my_model = 1;
  })");
  EXPECT_TRUE(m.hasAttributes);
  const double k[2][5] = {{0, 1, 4, 2, 3}, {5, 6, 2, 8, 1}};
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_CLOSE(attributeAt(m, j, {0.5, 0, 0}), k[j][0]);  // below tmin: the first knot
    EXPECT_CLOSE(attributeAt(m, j, {3.5, 0, 0}), k[j][4]);  // above tmax: the last
    EXPECT_CLOSE(attributeAt(m, j, {1, 0, 0}), k[j][1]);    // the curve runs from the second knot
    EXPECT_CLOSE(attributeAt(m, j, {2, 0, 0}), k[j][2]);
    EXPECT_CLOSE(attributeAt(m, j, {3, 0, 0}), k[j][3]);    // to the last but one (u = 1 included)
    for (double t : {1.3, 1.5, 1.9}) {
      const double r = (t - 1) / 2 * 2;
      EXPECT_CLOSE(attributeAt(m, j, {t, 0, 0}), catmullRom(k[j][0], k[j][1], k[j][2], k[j][3], r));
    }
    for (double t : {2.1, 2.6, 2.99}) {
      const double r = (t - 1) / 2 * 2 - 1;
      EXPECT_CLOSE(attributeAt(m, j, {t, 0, 0}), catmullRom(k[j][1], k[j][2], k[j][3], k[j][4], r));
    }
  }
  // Four knots: one span; the colour array as in hfp's documentation.
  Model rgb = compileOk(R"(my_model(x[3], a[1], s[3]) {
    array colours[12];
    colours = [0, 0, 0,  1, 0, 0,  0, 0, 1,  1, 1, 1];
    d = hfA_Spline(s, colours, x[3], -1, 1);
    my_model = 1;
  })");
  EXPECT_CLOSE(attributeAt(rgb, 0, {0, 0, 0}), catmullRom(0, 1, 0, 1, 0.5));
  EXPECT_CLOSE(attributeAt(rgb, 2, {0, 0, 0}), catmullRom(0, 0, 1, 1, 0.5));
  EXPECT_CLOSE(attributeAt(rgb, 2, {0, 0, 1}), 1.0);
}

TEST(LangAttributes, WrongCallsAreErrorsAtTheirPlace) {
  CompileResult r = compile("my_model(x[3], a[1]) {\n  d = hfA_SetColor(x[1], s, 1, 0, 0);\n  my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_EQ(r.diagnostics[0].line, 2);
  EXPECT_EQ(r.diagnostics[0].column, 26);
  EXPECT_EQ(r.diagnostics[0].message, "hfA_SetColor: 's' needs at least 3 elements, it has 1");
  r = compile("my_model(x[3], a[1], s[3]) {\n  d = hfA_SetColor(x[1], s, 1);\n  my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "hfA_SetColor takes 5 arguments, hfA_SetColor(f, s, r, g, b); got 3");
  r = compile("my_model(x[3], a[1], s[3]) {\n array c[3];\n c = [1,1,1];\n"
              " d = hfA_Union(x[1], x[2], s, c, c, x[3]);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "hfA_Union: the operation must be a constant 0 to 4");
  r = compile("my_model(x[3], a[1], s[3]) {\n array b[3], on[3], off[2];\n b = [1,1,1]; on = [1,1,1]; off = [0,0];\n"
              " d = hfA_CheckerBoard(x, b, b, s, on, off);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "hfA_CheckerBoard: s_block and s_gap need the same number of elements (3 and 2)");
  r = compile("my_model(x[3], a[1], s[3]) {\n array sets[3], map[3];\n sets = [1,1,1]; map = [0,0.5,1];\n"
              " d = hfA_Circles(x, s, sets, map);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message,
            "hfA_Circles: the attribute sets need 6 elements (2 intervals of the map × 3 of s), they have 3");
  r = compile("my_model(x[3], a[1], s[3]) {\n array sets[3], map[3];\n sets = [1,1,1]; map = [0,0.5,1];\n"
              " d = hfA_SmoothLookUpTable(x[1], s, sets, map);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).line, 4);
  EXPECT_EQ(r.diagnostics.at(0).column, 37);
  EXPECT_EQ(r.diagnostics.at(0).message,
            "hfA_SmoothLookUpTable: the attribute sets need 6 elements (a set of 3 for each of the map's 3 entries, "
            "the last one may be left out), they have 3");
  r = compile("my_model(x[3], a[1], s[3]) {\n array sets[3], map[1];\n sets = [1,1,1]; map = [0];\n"
              " d = hfA_LookUpTable(x[1], s, sets, map);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "hfA_LookUpTable: 'map' needs at least 2 elements, it has 1");
  r = compile("my_model(x[3], a[1], s[3]) {\n d = hfA_LookUpTable(x[1], s, s);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "hfA_LookUpTable takes 4 arguments, hfA_LookUpTable(t, s, sets, map); got 3");
  r = compile("my_model(x[3], a[1], s[3]) {\n array k[11];\n k = [1,1,1,1,1,1,1,1,1,1,1];\n"
              " d = hfA_Spline(s, k, x[1], 0, 1);\n my_model = 1;\n}\n", "c.hf");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message,
            "hfA_Spline: the knots need at least 4 sets of 3 (the size of s), 12 elements; they have 11");
}

}  // namespace
}  // namespace frep::lang::testing
