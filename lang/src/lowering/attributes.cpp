// HyperFun's attribute functions (hfA_*): they write the attribute array s[] (colour: s[1..3] as
// red, green, blue in [0, 1]) and return a value, and never change the geometry unless the
// model uses that value. Compiled like every other statement: a write that depends on f
// (hfA_SetColor colours where f >= 0) is a select() on the old value, so s[] ends the body as
// one expression per element over x and a (docs/language.md, "Attributes"). Semantics re-derived
// from HyperFun's attribute library documentation (hfA_* in hfp); arguments are in call order.
#include <algorithm>
#include <cmath>

#include "lowering/object_lowering.h"

namespace frep::lang::detail {

namespace {

// The attribute functions compiled here; the others (hfp's Perlin-noise textures, whose code has
// no definite value: docs/language.md) are accepted with a warning and return 1.
enum class Attr {
  SetColor, SetAttributes, Union, Lerp, Cerp, Clamp, Pulse, Step, SmoothStep, Modulo, Floor,
  Wave, NoiseG, Crackles, Circles, CheckerBoard, HSVToRGB, RGBToHSV, LookUpTable, SmoothLookUpTable,
  Spline, Ignored
};

struct AttrSpec {
  Attr kind;
  const char* signature;  // 'A' array, 'S' scalar, '*' anything (ignored functions)
};

AttrSpec specOf(const std::string& name) {
  if (name == "hfa_setcolor") return {Attr::SetColor, "SASSS"};
  if (name == "hfa_setattributes") return {Attr::SetAttributes, "SAA"};
  if (name == "hfa_union") return {Attr::Union, "SSAAAS"};
  if (name == "hfa_lerp") return {Attr::Lerp, "AAASSS"};
  if (name == "hfa_cerp") return {Attr::Cerp, "AAASSS"};
  if (name == "hfa_clamp") return {Attr::Clamp, "SSS"};
  if (name == "hfa_pulse") return {Attr::Pulse, "SSS"};
  if (name == "hfa_step") return {Attr::Step, "SS"};
  if (name == "hfa_smoothstep") return {Attr::SmoothStep, "SSS"};
  if (name == "hfa_modulo") return {Attr::Modulo, "SS"};
  if (name == "hfa_floor") return {Attr::Floor, "S"};
  if (name == "hfa_wave") return {Attr::Wave, "SSSS"};
  if (name == "hfa_noiseg") return {Attr::NoiseG, "ASS"};
  if (name == "hfa_crackles") return {Attr::Crackles, "AASAA"};
  if (name == "hfa_circles") return {Attr::Circles, "AAAA"};
  if (name == "hfa_checkerboard") return {Attr::CheckerBoard, "AAAAAA"};
  if (name == "hfa_hsvtorgb") return {Attr::HSVToRGB, "AA"};
  if (name == "hfa_rgbtohsv") return {Attr::RGBToHSV, "AA"};
  if (name == "hfa_lookuptable") return {Attr::LookUpTable, "SAAA"};
  if (name == "hfa_smoothlookuptable") return {Attr::SmoothLookUpTable, "SAAA"};
  if (name == "hfa_spline") return {Attr::Spline, "AASSS"};
  return {Attr::Ignored, "*"};
}

const char* usage(Attr kind) {
  switch (kind) {
    case Attr::SetColor: return "hfA_SetColor(f, s, r, g, b)";
    case Attr::SetAttributes: return "hfA_SetAttributes(f, s, s1)";
    case Attr::Union: return "hfA_Union(f1, f2, s, s1, s2, operation)";
    case Attr::Lerp: return "hfA_Lerp(s, s1, s2, f, fmin, fmax)";
    case Attr::Cerp: return "hfA_Cerp(s, s1, s2, f, fmin, fmax)";
    case Attr::Clamp: return "hfA_Clamp(f, a, b)";
    case Attr::Pulse: return "hfA_Pulse(f, a, b)";
    case Attr::Step: return "hfA_Step(f, a)";
    case Attr::SmoothStep: return "hfA_SmoothStep(f, a, b)";
    case Attr::Modulo: return "hfA_Modulo(a, b)";
    case Attr::Floor: return "hfA_Floor(a)";
    case Attr::Wave: return "hfA_Wave(t, c1, c2, freq)";
    case Attr::NoiseG: return "hfA_NoiseG(x, freq, phase)";
    case Attr::Crackles: return "hfA_Crackles(x, s, freq, attributes, map)";
    case Attr::Circles: return "hfA_Circles(x, s, attributes, map)";
    case Attr::CheckerBoard: return "hfA_CheckerBoard(x, block, gap, s, s_block, s_gap)";
    case Attr::HSVToRGB: return "hfA_HSVToRGB(hsv, rgb)";
    case Attr::RGBToHSV: return "hfA_RGBToHSV(rgb, hsv)";
    case Attr::LookUpTable: return "hfA_LookUpTable(t, s, sets, map)";
    case Attr::SmoothLookUpTable: return "hfA_SmoothLookUpTable(t, s, sets, map)";
    case Attr::Spline: return "hfA_Spline(s, knots, t, tmin, tmax)";
    case Attr::Ignored: break;
  }
  return "";
}

// Gardner's solid noise as hfp's attribute library computes it (amplitude 1), scaled from
// [-c^3, c^3], c = 2.17/1.17, to [0, 1]: a product of three sine series, each axis's second
// term phase-shifted by the sine of another axis.
Expr gardnerNoise(const Expr& x, const Expr& y, const Expr& z, const Expr& phase, const Expr& freq) {
  const Expr sx = sin(freq * x), sy = sin(freq * y), sz = sin(freq * z);
  const Expr serx = sx + sin(freq * x / Expr(1.35) + phase * sz) / Expr(1.17);
  const Expr sery = sy + sin(freq * y / Expr(1.35) + phase * sx) / Expr(1.17);
  const Expr serz = sz + sin(freq * z / Expr(1.35) + phase * sy) / Expr(1.17);
  const double c = 2.17 / 1.17, cMin = std::pow(-c, 3);
  return (serx * sery * serz - Expr(cMin)) / Expr(-cMin - cMin);
}

}  // namespace

Value& ObjectLowering::attributeArray(const AstExpr& e, size_t index, size_t minSize) {
  Value& arr = arrayArgument(*e.args[index], e.spelling, index);
  if (arr.elems.size() < minSize)
    throw CompileError{e.args[index]->loc, e.spelling + ": '" + arr.spelling + "' needs at least " +
                                               plural(minSize, "element") + ", it has " +
                                               std::to_string(arr.elems.size())};
  return arr;
}

Expr ObjectLowering::callAttribute(const AstExpr& e) {
  const AttrSpec spec = specOf(e.name);
  if (spec.kind == Attr::Ignored) {
    if (!sh_.warnedAttributes) {
      sh_.warnedAttributes = true;
      sh_.diags.warning(e.loc, e.spelling + " (a procedural attribute texture) is accepted but not computed: "
                                            "s[] is left as it is and the call's value is 1");
    }
    for (const auto& a : e.args) {  // checked for errors; their values are not used
      if (a->kind == AstExpr::Kind::Name) {
        auto it = env_.find(a->name);
        if (it != env_.end() && it->second.isArray) continue;
      }
      lower(*a);
    }
    return Expr(1.0);
  }
  const std::string sig = spec.signature;
  if (e.args.size() != sig.size())
    throw CompileError{e.loc, e.spelling + " takes " + plural(sig.size(), "argument") + ", " + usage(spec.kind) +
                                  "; got " + std::to_string(e.args.size())};
  // Scalars are lowered right to left, as hfp evaluates arguments.
  std::vector<Expr> v(sig.size());
  for (size_t i = sig.size(); i-- > 0;)
    if (sig[i] == 'S') v[i] = lower(*e.args[i]);
  // The writes: s[i] = select(cond, new, old); the array's own name decides what is written.
  auto write = [&](Value& target, size_t i, const Expr& cond, const Expr& value) {
    target.elems[i] = cond.isConst() ? (cond.constValue() != 0 ? value : target.elems[i])
                                     : select(cond, value, target.elems[i]);
    target.elemState[i] = Def::Defined;
    if (&target == &env_.at("s")) attributesWritten_ = true;
  };
  switch (spec.kind) {
    case Attr::SetColor: {  // where f >= 0: s[1..3] = (r, g, b)
      Value& s = attributeArray(e, 1, 3);
      Expr inside = ge(v[0], Expr(0.0));
      for (size_t c = 0; c < 3; ++c) write(s, c, inside, v[2 + c]);
      return Expr(1.0);
    }
    case Attr::SetAttributes: {  // where f >= 0: s[i] = s1[i] over the shorter of the two
      Value& s1 = attributeArray(e, 2, 1);
      std::vector<Expr> from = s1.elems;
      Value& s = attributeArray(e, 1, 1);
      Expr inside = ge(v[0], Expr(0.0));
      for (size_t i = 0; i < std::min(s.elems.size(), from.size()); ++i) write(s, i, inside, from[i]);
      return Expr(1.0);
    }
    case Attr::Union: {  // the union f1 | f2; s takes the attributes of the solid the point is in
      if (!v[5].isConst())
        throw CompileError{e.args[5]->loc, e.spelling + ": the operation must be a constant 0 to 4"};
      const double op = v[5].constValue();
      if (!(op == 0 || op == 1 || op == 2 || op == 3 || op == 4))
        throw CompileError{e.args[5]->loc, e.spelling + ": the operation must be 0 (s1), 1 (s2), 2 (sum), "
                                                        "3 (minimum) or 4 (maximum), got " + fmtNumber(op)};
      std::vector<Expr> c1 = attributeArray(e, 3, 1).elems, c2 = attributeArray(e, 4, 1).elems;
      Value& s = attributeArray(e, 2, 1);
      if (c1.size() < s.elems.size() || c2.size() < s.elems.size())
        throw CompileError{e.loc, e.spelling + ": s1 and s2 need at least as many elements as s (" +
                                      std::to_string(s.elems.size()) + ")"};
      const Expr& f1 = v[0];
      const Expr& f2 = v[1];
      Expr u = f1 + f2 + sqrt(f1 * f1 + f2 * f2);
      Expr in1 = ge(f1, Expr(0.0)), in2 = ge(f2, Expr(0.0));
      Expr only1 = logicalAnd(in1, logicalNot(in2)), only2 = logicalAnd(in2, logicalNot(in1));
      for (size_t i = 0; i < s.elems.size(); ++i) {
        Expr both = op == 0 ? c1[i] : op == 1 ? c2[i] : op == 2 ? c1[i] + c2[i] : op == 3 ? min(c1[i], c2[i]) : max(c1[i], c2[i]);
        Expr value = select(only1, c1[i], select(only2, c2[i], both));
        write(s, i, gt(u, Expr(-1e-6)), value);
      }
      return u;
    }
    case Attr::Lerp:
    case Attr::Cerp: {  // t = (f - fmin)/(fmax - fmin); s = s1 below 0, s2 above 1, else mixed
      std::vector<Expr> c1 = attributeArray(e, 1, 1).elems, c2 = attributeArray(e, 2, 1).elems;
      Value& s = attributeArray(e, 0, 1);
      if (c1.size() < s.elems.size() || c2.size() < s.elems.size())
        throw CompileError{e.loc, e.spelling + ": s1 and s2 need at least as many elements as s (" +
                                      std::to_string(s.elems.size()) + ")"};
      Expr t = (v[3] - v[4]) / (v[5] - v[4]);
      if (spec.kind == Attr::Cerp) t = t * t * (Expr(3.0) - Expr(2.0) * t);  // cubic, as hfp: before the tests
      for (size_t i = 0; i < s.elems.size(); ++i) {
        Expr mixed = (Expr(1.0) - t) * c1[i] + t * c2[i];
        Expr value = select(lt(t, Expr(0.0)), c1[i], select(gt(t, Expr(1.0)), c2[i], mixed));
        write(s, i, Expr(1.0), value);
      }
      return t;
    }
    case Attr::Clamp: return select(lt(v[0], v[1]), v[1], select(gt(v[0], v[2]), v[2], v[0]));
    case Attr::Pulse: return logicalAnd(ge(v[0], v[1]), le(v[0], v[2]));
    case Attr::Step: return ge(v[0], v[1]);
    case Attr::SmoothStep: {
      Expr t = (v[0] - v[1]) / (v[2] - v[1]);
      return select(gt(v[0], v[2]), Expr(1.0), select(lt(v[0], v[1]), Expr(0.0), t * t * (Expr(3.0) - Expr(2.0) * t)));
    }
    case Attr::Modulo: {  // a - trunc(a/b)·b, moved into [0, b) when negative
      Expr r = v[0] - trunc(v[0] / v[1]) * v[1];
      return select(lt(r, Expr(0.0)), r + v[1], r);
    }
    case Attr::Floor: return trunc(v[0]);  // hfp's (int) cast: towards zero
    case Attr::Wave: {  // (1 + sin(freq·t))/2 spread over [min(c1, c2), max(c1, c2)]
      const Expr w = (Expr(1.0) + sin(v[3] * v[0])) / Expr(2.0);
      return select(gt(v[1], v[2]), w * (v[1] - v[2]) + v[2], w * (v[2] - v[1]) + v[1]);
    }
    case Attr::NoiseG: {
      const std::vector<Expr> x = attributeArray(e, 0, 3).elems;
      return gardnerNoise(x[0], x[1], x[2], v[2], v[1]);
    }
    case Attr::Crackles:
    case Attr::Circles: {
      // A value p in [0, 1) picks attribute set k (attributes[k·n + 1 .. k·n + n], n the size of
      // s) where map[k+1] <= p < map[k+2]; no interval: s unchanged. Circles: p = |x| mod 1 and
      // the first interval wins; Crackles: p from Gardner noise, cycled, and the last one wins
      // (hfp's loop has no break there).
      const bool circles = spec.kind == Attr::Circles;
      const size_t mapArg = circles ? 3 : 4, setsArg = circles ? 2 : 3;
      const std::vector<Expr> x = attributeArray(e, 0, 3).elems, map = attributeArray(e, mapArg, 2).elems,
                              sets = attributeArray(e, setsArg, 1).elems;
      Value& s = attributeArray(e, 1, 1);
      const size_t n = s.elems.size(), intervals = map.size() - 1;
      if (sets.size() < n * intervals)
        throw CompileError{e.args[setsArg]->loc, e.spelling + ": the attribute sets need " + std::to_string(n * intervals) +
                                                     " elements (" + std::to_string(intervals) + " intervals of the map × " +
                                                     std::to_string(n) + " of s), they have " + std::to_string(sets.size())};
      Expr p;
      if (circles) {
        p = fmod(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), Expr(1.0));
      } else {
        const Expr phase = (abs(x[0]) + abs(x[1]) + abs(x[2])) / Expr(3.0);
        const Expr sum = Expr(-3.0) + Expr(2.0) * (gardnerNoise(x[0], x[0], x[2], phase, v[2]) +
                                                   gardnerNoise(x[1], x[1], x[0], phase, v[2]) +
                                                   gardnerNoise(x[2], x[2], x[1], phase, v[2]));
        // hfp's cycle(): the fraction quantised to thousandths (an int cast), through a sine.
        const Expr thousandths = trunc((sum - floor(sum)) * Expr(1000.0));
        p = (Expr(1.0) + sin(thousandths * Expr(2.0 * M_PI / 1000.0))) / Expr(2.0);
      }
      std::vector<Expr> out = s.elems;
      for (size_t step = 0; step < intervals; ++step) {
        const size_t k = circles ? intervals - 1 - step : step;  // the winner is applied last
        const Expr in = logicalAnd(ge(p, map[k]), lt(p, map[k + 1]));
        for (size_t j = 0; j < n; ++j) out[j] = select(in, sets[n * k + j], out[j]);
      }
      for (size_t j = 0; j < n; ++j) write(s, j, Expr(1.0), out[j]);
      return Expr(1.0);
    }
    case Attr::CheckerBoard: {
      // Blocks of size block[i] repeating every block[i] + gap[i] from the origin: strictly inside
      // one on all three axes, s = s_block, else s = s_gap.
      const std::vector<Expr> x = attributeArray(e, 0, 3).elems, block = attributeArray(e, 1, 3).elems,
                              gap = attributeArray(e, 2, 3).elems, inBlock = attributeArray(e, 4, 1).elems,
                              inGap = attributeArray(e, 5, 1).elems;
      if (inBlock.size() != inGap.size())  // hfp then writes nothing; an error says why
        throw CompileError{e.loc, e.spelling + ": s_block and s_gap need the same number of elements (" +
                                      std::to_string(inBlock.size()) + " and " + std::to_string(inGap.size()) + ")"};
      Value& s = attributeArray(e, 3, inBlock.size());
      Expr inside(1.0);
      for (size_t i = 0; i < 3; ++i) {
        const Expr period = gap[i] + block[i], start = period * floor(x[i] / period);
        inside = logicalAnd(inside, logicalAnd(gt(x[i], start), lt(x[i], start + block[i])));
      }
      for (size_t j = 0; j < inBlock.size(); ++j) write(s, j, Expr(1.0), select(inside, inBlock[j], inGap[j]));
      return Expr(1.0);
    }
    case Attr::HSVToRGB: {  // hue in degrees (any, taken mod 360), saturation and value in [0, 1]
      const std::vector<Expr> hsv = attributeArray(e, 0, 3).elems;
      Value& rgb = attributeArray(e, 1, 3);
      const Expr h = hsv[0] - Expr(360.0) * floor(hsv[0] / Expr(360.0));
      const Expr below120 = lt(h, Expr(120.0)), below240 = lt(h, Expr(240.0));
      const Expr r = select(below120, (Expr(120.0) - h) / Expr(60.0), select(below240, Expr(0.0), (h - Expr(240.0)) / Expr(60.0)));
      const Expr g = select(below120, h / Expr(60.0), select(below240, (Expr(240.0) - h) / Expr(60.0), Expr(0.0)));
      const Expr b = select(below120, Expr(0.0), select(below240, (h - Expr(120.0)) / Expr(60.0), (Expr(360.0) - h) / Expr(60.0)));
      const Expr channel[3] = {r, g, b};
      for (size_t c = 0; c < 3; ++c)
        write(rgb, c, Expr(1.0), (Expr(1.0) - hsv[1] + hsv[1] * min(channel[c], Expr(1.0))) * hsv[2]);
      return Expr(1.0);
    }
    case Attr::RGBToHSV: {  // hue in degrees, -60 to 300 as hfp leaves it, 0 for greys
      const std::vector<Expr> rgb = attributeArray(e, 0, 3).elems;
      Value& hsv = attributeArray(e, 1, 3);
      const Expr &r = rgb[0], &g = rgb[1], &b = rgb[2];
      const Expr hi = max(r, max(g, b)), spread = hi - min(r, min(g, b));
      // Divisors kept off 0 where their quotient is not used (no spurious domain errors).
      const Expr delta = select(gt(spread, Expr(0.0)), spread, Expr(1.0)), top = select(gt(hi, Expr(0.0)), hi, Expr(1.0));
      // hfp adds the term of each channel equal to the maximum unless the next one ties it.
      const Expr h = select(logicalAnd(eq(hi, r), ne(hi, g)), (g - b) / delta, Expr(0.0)) +
                     select(logicalAnd(eq(hi, g), ne(hi, b)), Expr(2.0) + (b - r) / delta, Expr(0.0)) +
                     select(logicalAnd(eq(hi, b), ne(hi, r)), Expr(4.0) + (r - g) / delta, Expr(0.0));
      write(hsv, 0, Expr(1.0), select(gt(spread, Expr(0.0)), Expr(60.0) * h, Expr(0.0)));
      write(hsv, 1, Expr(1.0), select(gt(hi, Expr(0.0)), spread / top, Expr(0.0)));
      write(hsv, 2, Expr(1.0), hi);
      return Expr(1.0);
    }
    case Attr::LookUpTable:
    case Attr::SmoothLookUpTable: {
      // A table of attribute sets indexed by t through the map m[1..M] (increasing): set k
      // (sets[(k-1)·n + 1 .. k·n], n the size of s) belongs to m[k]. LookUpTable: s = set k
      // for m[k] <= t < m[k+1]; SmoothLookUpTable: the linear mix of sets k and k+1 there.
      // Below m[1]: the first set; at or past m[M] (or in no interval of an unordered map):
      // set M. With M - 1 sets (hfp's documented example) set M is the last one given.
      // The first matching interval wins (hfp stops there).
      const bool smooth = spec.kind == Attr::SmoothLookUpTable;
      const std::vector<Expr> map = attributeArray(e, 3, 2).elems, sets = attributeArray(e, 2, 1).elems;
      Value& s = attributeArray(e, 1, 1);
      const size_t n = s.elems.size(), entries = map.size();
      if (sets.size() < n * (entries - 1))
        throw CompileError{e.args[2]->loc, e.spelling + ": the attribute sets need " + std::to_string(n * (entries - 1)) +
                                               " elements (a set of " + std::to_string(n) + " for each of the map's " +
                                               std::to_string(entries) + " entries, the last one may be left out), they have " +
                                               std::to_string(sets.size())};
      const size_t given = std::min(entries, sets.size() / n);
      auto set = [&](size_t k, size_t j) { return sets[n * std::min(k, given - 1) + j]; };
      const Expr& t = v[0];
      std::vector<Expr> out(n);
      for (size_t j = 0; j < n; ++j) out[j] = set(entries - 1, j);
      for (size_t k = entries - 1; k-- > 0;) {
        const Expr in = logicalAnd(ge(t, map[k]), lt(t, map[k + 1]));
        // The width kept off 0 where the interval is empty (its mix is then never used).
        const Expr width = map[k + 1] - map[k], l = (t - map[k]) / select(gt(width, Expr(0.0)), width, Expr(1.0));
        const bool mixes = smooth && std::min(k + 1, given - 1) != std::min(k, given - 1);
        for (size_t j = 0; j < n; ++j)
          out[j] = select(in, mixes ? (Expr(1.0) - l) * set(k, j) + l * set(k + 1, j) : set(k, j), out[j]);
      }
      for (size_t j = 0; j < n; ++j) write(s, j, Expr(1.0), select(lt(t, map[0]), set(0, j), out[j]));
      return Expr(1.0);
    }
    case Attr::Spline: {
      // Catmull-Rom through knots 2 .. K-1 of the K sets of n (the size of s) in knots, knots 1
      // and K only steering the end tangents: u = (t - tmin)/(tmax - tmin) spread over the K - 3
      // spans. u < 0: s = knot 1; u > 1: s = knot K (as hfp, a step at either end).
      const std::vector<Expr> knots = attributeArray(e, 1, 1).elems;
      Value& s = attributeArray(e, 0, 1);
      const size_t n = s.elems.size(), count = knots.size() / n;
      if (count < 4)
        throw CompileError{e.args[1]->loc, e.spelling + ": the knots need at least 4 sets of " + std::to_string(n) +
                                               " (the size of s), " + std::to_string(4 * n) + " elements; they have " +
                                               std::to_string(knots.size())};
      const size_t spans = count - 3;
      const Expr u = (v[2] - v[3]) / (v[4] - v[3]);
      const Expr w = u * Expr(double(spans));
      // Span i covers i <= w < i + 1, the last one also w = spans (u = 1).
      auto segment = [&](size_t i, size_t j) {
        const Expr &k0 = knots[(i + 0) * n + j], &k1 = knots[(i + 1) * n + j], &k2 = knots[(i + 2) * n + j],
                   &k3 = knots[(i + 3) * n + j];
        const Expr c3 = Expr(-0.5) * k0 + Expr(1.5) * k1 - Expr(1.5) * k2 + Expr(0.5) * k3;
        const Expr c2 = k0 - Expr(2.5) * k1 + Expr(2.0) * k2 - Expr(0.5) * k3;
        const Expr c1 = Expr(0.5) * (k2 - k0);
        const Expr r = w - Expr(double(i));
        return ((c3 * r + c2) * r + c1) * r + k1;
      };
      for (size_t j = 0; j < n; ++j) {
        Expr value = segment(spans - 1, j);
        for (size_t i = spans - 1; i-- > 0;) value = select(lt(w, Expr(double(i + 1))), segment(i, j), value);
        write(s, j, Expr(1.0),
              select(lt(u, Expr(0.0)), knots[j], select(gt(u, Expr(1.0)), knots[(count - 1) * n + j], value)));
      }
      return Expr(1.0);
    }
    case Attr::Ignored: break;
  }
  return Expr(1.0);
}

}  // namespace frep::lang::detail
