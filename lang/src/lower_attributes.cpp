// HyperFun's attribute functions (hfA_*): they write the attribute array s[] (colour: s[1..3] as
// red, green, blue in [0, 1]) and return a value, and never change the geometry unless the
// model uses that value. Compiled like every other statement: a write that depends on f
// (hfA_SetColor colours where f >= 0) is a select() on the old value, so s[] ends the body as
// one expression per element over x and a (docs/language.md, "Attributes"). Semantics re-derived
// from HyperFun's attribute library documentation (hfA_* in hfp); arguments are in call order.
#include <cmath>

#include "frep/lang/lower_object.h"

namespace frep::lang::detail {

namespace {

// The attribute functions compiled here; the others (procedural textures) are accepted with a
// warning and return 1.
enum class Attr { SetColor, SetAttributes, Union, Lerp, Cerp, Clamp, Pulse, Step, SmoothStep, Modulo, Floor, Ignored };

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
    case Attr::Ignored: break;
  }
  return "";
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
    case Attr::Ignored: break;
  }
  return Expr(1.0);
}

}  // namespace frep::lang::detail
