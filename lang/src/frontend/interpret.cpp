// Tree-walking evaluation of one object at one point (see interpret.h). Operators use the core's
// scalar semantics (applyOp), so the results agree with the compiled tape.
#include "frep/lang/frontend/interpret.h"

#include <cmath>
#include <unordered_map>

#include "frep/lang/library/builtins.h"
#include "frep/lang/frontend/diagnostics.h"
#include "frep/lang/frontend/lexer.h"
#include "frep/lang/library/library.h"
#include "frep/lang/frontend/parser.h"

namespace frep::lang {
namespace {

double truthOf(double v) { return std::fabs(v) >= kHfEps ? 1.0 : 0.0; }

// '^': near-integer exponents (within 1e-6 above) count as integers only when written as a
// literal, which is when the compiler can fold them; computed ones must be exact integers.
double power(double b, double e, bool literal) {
  double tolerance = literal ? kHfEps : 0.0;
  if (std::isfinite(e) && std::fabs(e) < 1e9 && e - std::floor(e) <= tolerance) {
    int n = static_cast<int>(hfRound(std::fabs(e)));
    return applyOp(Op::PowI, b, 0, 0, e < 0 ? -n : n);
  }
  return applyOp(Op::Pow, b, e);
}

double builtin(const std::string& name, const std::vector<double>& v) {
  static const std::unordered_map<std::string, Op> unary = {
      {"sqrt", Op::Sqrt}, {"exp", Op::Exp},   {"log", Op::Log},     {"logd", Op::Log10},
      {"sin", Op::Sin},   {"cos", Op::Cos},   {"tan", Op::Tan},     {"asin", Op::Asin},
      {"acos", Op::Acos}, {"atan", Op::Atan}, {"abs", Op::Abs},     {"sinh", Op::Sinh},
      {"cosh", Op::Cosh}, {"tanh", Op::Tanh}, {"ceil", Op::Ceil},   {"floor", Op::Floor},
      {"int", Op::Trunc}, {"frac", Op::Frac}};
  auto it = unary.find(name);
  if (it != unary.end()) return applyOp(it->second, v[0]);
  if (name == "atan2") return applyOp(Op::Atan2, v[0], v[1]);
  if (name == "max") return applyOp(Op::Max, v[0], v[1]);
  if (name == "min") return applyOp(Op::Min, v[0], v[1]);
  if (name == "mod") return applyOp(Op::Fmod, hfRound(v[0]), hfRound(v[1]));
  if (name == "sign") return v[0] > 0 ? 1.0 : v[0] < 0 ? -1.0 : 0.0;
  throw InterpretError("unknown builtin " + name);
}

double uni(double a, double b) { return a + b + applyOp(Op::Sqrt, a * a + b * b); }
double inter(double a, double b) { return a + b - applyOp(Op::Sqrt, a * a + b * b); }

struct Frame {
  std::unordered_map<std::string, double> scalars;
  std::unordered_map<std::string, std::vector<double>> arrays;
};

class Run {
 public:
  Run(const Program& p, const CompileOptions& o) : program_(p), options_(o) {}

  double object(const ObjectDecl& o, std::vector<double> x, std::vector<double> a,
                std::vector<double> s) {
    Frame f;
    x.resize(o.xSize, 0.0);
    a.resize(o.aSize, 0.0);
    s.resize(std::max(1, o.sSize), 0.0);
    f.arrays["x"] = std::move(x);
    f.arrays["a"] = std::move(a);
    f.arrays["s"] = std::move(s);
    for (const auto& d : o.arrays) f.arrays[d.name] = std::vector<double>(d.size, 0.0);
    long iterations = 0;
    Frame* saved = frame_;
    long* savedIt = iterations_;
    frame_ = &f;
    iterations_ = &iterations;
    block(o.body);
    frame_ = saved;
    iterations_ = savedIt;
    auto it = f.scalars.find(o.name);
    if (it == f.scalars.end()) throw InterpretError("object " + o.name + " has no value");
    return it->second;
  }

 private:
  void block(const std::vector<Stmt>& stmts) {
    for (const auto& s : stmts) stmt(s);
  }

  std::vector<double>& array(const std::string& name) {
    auto it = frame_->arrays.find(name);
    if (it == frame_->arrays.end()) throw InterpretError("no array " + name);
    return it->second;
  }

  size_t index(const AstExpr& e, const std::vector<double>& arr) {
    double r = hfRound(eval(e));
    if (!(r >= 1 && r <= static_cast<double>(arr.size()))) throw InterpretError("index out of range");
    return static_cast<size_t>(r) - 1;
  }

  // A read clamps as the compiled select chain does for an index that depends on x (a constant
  // index out of range is a compile error, so it never gets here): below 1 the first element,
  // above n or NaN the last (docs/language.md).
  size_t readIndex(const AstExpr& e, const std::vector<double>& arr) {
    double v = eval(e);
    if (std::isnan(v) || v >= static_cast<double>(arr.size()) + 0.5) return arr.size() - 1;
    double r = hfRound(v);
    return r < 1 ? 0 : static_cast<size_t>(r) - 1;
  }

  void stmt(const Stmt& s) {
    switch (s.kind) {
      case Stmt::Kind::Assign: frame_->scalars[s.name] = eval(*s.value); return;
      case Stmt::Kind::AssignElem: {
        double v = eval(*s.value);
        auto& arr = array(s.name);
        arr[index(*s.index, arr)] = v;
        return;
      }
      case Stmt::Kind::AssignArray: {
        std::vector<double> vals;
        for (const auto& e : s.elems) vals.push_back(eval(*e));
        array(s.name) = vals;
        return;
      }
      case Stmt::Kind::If:
        block(truthOf(eval(*s.value)) != 0.0 ? s.body : s.elseBody);
        return;
      case Stmt::Kind::While:
        while (truthOf(eval(*s.value)) != 0.0) {
          if (++*iterations_ > options_.maxLoopIterations) throw InterpretError("endless loop");
          block(s.body);
        }
        return;
    }
  }

  double eval(const AstExpr& e) {
    switch (e.kind) {
      case AstExpr::Kind::Number: return e.number;
      case AstExpr::Kind::Name: {
        auto it = frame_->scalars.find(e.name);
        if (it == frame_->scalars.end()) throw InterpretError("no value for " + e.name);
        return it->second;
      }
      case AstExpr::Kind::Index: {
        auto& arr = array(e.name);
        return arr[readIndex(*e.args[0], arr)];
      }
      case AstExpr::Kind::Call: return call(e);
      case AstExpr::Kind::Unary: {
        double v = eval(*e.args[0]);
        return e.unop == UnOp::Plus ? v : -v;
      }
      case AstExpr::Kind::Binary: {
        double r = eval(*e.args[1]);  // right to left, as hfp and the compiler
        double l = eval(*e.args[0]);
        switch (e.binop) {
          case BinOp::Add: return l + r;
          case BinOp::Sub: return l - r;
          case BinOp::Mul: return l * r;
          case BinOp::Div: return l / r;
          case BinOp::Pow: return power(l, r, isLiteral(*e.args[1]));
          case BinOp::Union: return uni(l, r);
          case BinOp::Inter: case BinOp::Cart: return inter(l, r);
          case BinOp::Diff: return inter(l, -r);
        }
        break;
      }
      case AstExpr::Kind::Compare: {
        double r = eval(*e.args[1]);
        double l = eval(*e.args[0]);
        switch (e.relop) {
          case RelOp::Eq: return std::fabs(l - r) < kHfEps ? 1.0 : 0.0;
          case RelOp::Ne: return std::fabs(l - r) >= kHfEps ? 1.0 : 0.0;
          case RelOp::Lt: return l < r ? 1.0 : 0.0;
          case RelOp::Gt: return l > r ? 1.0 : 0.0;
          case RelOp::Le: return l <= r ? 1.0 : 0.0;
          case RelOp::Ge: return l >= r ? 1.0 : 0.0;
        }
        break;
      }
      case AstExpr::Kind::And: {
        double r = truthOf(eval(*e.args[1]));
        return (truthOf(eval(*e.args[0])) != 0.0 && r != 0.0) ? 1.0 : 0.0;
      }
      case AstExpr::Kind::Or: {
        double r = truthOf(eval(*e.args[1]));
        return (truthOf(eval(*e.args[0])) != 0.0 || r != 0.0) ? 1.0 : 0.0;
      }
      case AstExpr::Kind::Not: return truthOf(eval(*e.args[0])) != 0.0 ? 0.0 : 1.0;
      case AstExpr::Kind::String: throw InterpretError("a string has no value");
    }
    return 0.0;
  }

  static bool isLiteral(const AstExpr& e) {
    if (e.kind == AstExpr::Kind::Unary) return isLiteral(*e.args[0]);
    return e.kind == AstExpr::Kind::Number;
  }

  bool isArrayName(const AstExpr& a) const {
    return a.kind == AstExpr::Kind::Name && frame_->arrays.count(a.name);
  }

  double call(const AstExpr& e) {
    if (findBuiltin(e.name)) {
      std::vector<double> v(e.args.size());
      for (size_t i = e.args.size(); i-- > 0;) v[i] = eval(*e.args[i]);
      return builtin(e.name, v);
    }
    if (e.name.rfind("hfa_", 0) == 0) {
      for (const auto& a : e.args)
        if (!isArrayName(*a)) eval(*a);
      return 1.0;
    }
    if (const LibraryFunction* f = findLibraryFunction(e.name)) return library(e, *f);
    for (const auto& o : program_.objects) {
      if (o.name != e.name) continue;
      std::vector<double> arrs[3];
      for (size_t i = 0; i < e.args.size() && i < 3; ++i) arrs[i] = array(e.args[i]->name);
      return object(o, arrs[0], arrs[1], arrs[2]);
    }
    throw InterpretError("unknown function " + e.name);
  }

  // Library functions only exist as lowerings: call one with constant arguments and read the
  // folded constants back (arrays are mutated in place, as in hfp).
  double library(const AstExpr& e, const LibraryFunction& f) {
    std::vector<Arg> args(e.args.size());
    std::vector<std::vector<Expr>> arrays(e.args.size());
    for (size_t i = e.args.size(); i-- > 0;)
      if (!isArrayName(*e.args[i])) args[i].value = Expr(eval(*e.args[i]));
    for (size_t i = 0; i < e.args.size(); ++i) {
      if (!isArrayName(*e.args[i])) continue;
      for (double v : array(e.args[i]->name)) arrays[i].push_back(Expr(v));
      args[i].isArray = true;
      args[i].array = &arrays[i];
      args[i].name = e.args[i]->spelling;
    }
    Expr r = f.lower(args);
    for (size_t i = 0; i < e.args.size(); ++i) {
      if (!args[i].isArray) continue;
      auto& arr = array(e.args[i]->name);
      for (size_t k = 0; k < arr.size(); ++k) {
        if (!arrays[i][k].isConst()) throw InterpretError(f.name + " left a non-constant element");
        arr[k] = arrays[i][k].constValue();
      }
    }
    if (!r.isConst()) throw InterpretError(f.name + " did not fold to a constant");
    return r.constValue();
  }

  const Program& program_;
  const CompileOptions& options_;
  Frame* frame_ = nullptr;
  long* iterations_ = nullptr;
};

}  // namespace

Interpreter::Interpreter(const std::string& source, const CompileOptions& options)
    : options_(options) {
  CompileResult r = compile(source, "<interpreter>", options);
  if (!r.ok) {
    std::string msg = "the model does not compile";
    if (!r.diagnostics.empty()) msg += ": " + r.diagnostics.front().format();
    throw InterpretError(msg);
  }
  selected_ = r.model.objectName;
  DiagnosticSink sink("<interpreter>", source);
  program_ = parse(lex(source, sink), sink);
}

double Interpreter::eval(const std::vector<double>& x, const std::vector<double>& a) const {
  // Fixed parameters (CompileOptions::params) apply to the selected object only.
  std::vector<double> params = a;
  if (params.size() < options_.params.size()) params.resize(options_.params.size(), 0.0);
  for (size_t i = 0; i < options_.params.size(); ++i) params[i] = options_.params[i];
  for (const auto& o : program_.objects)
    if (o.name == selected_) return Run(program_, options_).object(o, x, params, {});
  throw InterpretError("no object " + selected_);
}

}  // namespace frep::lang
