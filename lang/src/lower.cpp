// Compiles HyperFun objects to core expressions by running their statements symbolically:
// variables hold Exprs, arrays hold one Expr per element, loops with a compile-time condition
// unroll, and an 'if' whose condition depends on x runs both branches and merges every variable
// with select(). See docs/language.md, "Semantics".
#include "frep/lang/lower.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <unordered_set>

#include "frep/lang/builtins.h"
#include "frep/lang/library.h"

namespace frep::lang {
namespace {

// Deleting an expression frees its nodes recursively, so an unrolled loop that builds a chain
// deeper than this could overflow the stack; refuse it with an error instead.
constexpr uint32_t kMaxExprDepth = 10000;

struct CompileError {
  Loc loc;
  std::string message;
};
struct StopObject {};  // a fatal error (already reported) ends the object's lowering

// Whether a variable (or array element) has a value at this point of the program.
enum class Def : uint8_t {
  Undefined,
  Defined,
  OneBranch,  // assigned in only one branch of an if whose condition depends on x
  Poisoned,   // its assignment failed with an error: reads are silent, the object is not ok
};

struct Value {
  bool isArray = false;
  std::string spelling;
  Expr scalar;
  Def state = Def::Undefined;
  std::vector<Expr> elems;
  std::vector<Def> elemState;
  Loc branchIf;  // the if that left it OneBranch
};
using Env = std::map<std::string, Value>;

// HyperFun's attribute functions: they fill s[] (colour) and never change geometry.
const std::unordered_set<std::string>& attributeFunctions() {
  static const std::unordered_set<std::string> names = {
      "hfa_setcolor", "hfa_wave", "hfa_checkerboard", "hfa_union", "hfa_crackles",
      "hfa_circles", "hfa_noiseg", "hfa_noisep", "hfa_turbulence", "hfa_setattributes",
      "hfa_lerp", "hfa_cerp", "hfa_clamp", "hfa_floor", "hfa_pulse", "hfa_lookuptable",
      "hfa_smoothlookuptable", "hfa_step", "hfa_smoothstep", "hfa_modulo", "hfa_spline",
      "hfa_rgbtohsv", "hfa_hsvtorgb"};
  return names;
}

std::string lowerCase(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string locText(Loc l) { return std::to_string(l.line) + ":" + std::to_string(l.column); }

std::string fmtNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

struct Shared {
  const Program& program;
  const CompileOptions& options;
  DiagnosticSink& diags;
  std::vector<LoweredObject>& done;  // objects lowered so far, in file order
  bool warnedAttributes = false;
};

class ObjectLowering {
 public:
  ObjectLowering(const ObjectDecl& obj, Shared& shared) : obj_(obj), sh_(shared) {}

  LoweredObject run() {
    LoweredObject out;
    out.info = ObjectInfo{obj_.name, obj_.xSize, obj_.aSize, obj_.sSize, obj_.loc.line};
    if (!obj_.headerOk) return out;
    setUpEnvironment();
    collectAssigned(obj_.body);
    // Statements that failed to parse leave their targets poisoned, not unknown (no cascade).
    for (const auto& name : obj_.brokenNames) {
      if (env_.count(name)) continue;
      Value v;
      v.spelling = name;
      v.state = Def::Poisoned;
      env_[name] = v;
    }
    try {
      execBlock(obj_.body);
      finish(out);
    } catch (const StopObject&) {
    } catch (const std::exception& e) {  // a bug or resource limit: report, never crash
      ++errors_;
      sh_.diags.error(obj_.loc, std::string("internal error while compiling this object: ") + e.what());
    }
    out.ok = out.ok && errors_ == 0;
    return out;
  }

 private:
  // ---- environment ------------------------------------------------------------------------
  static Value makeArray(const std::string& spelling, std::vector<Expr> elems, Def state) {
    Value v;
    v.isArray = true;
    v.spelling = spelling;
    v.elemState.assign(elems.size(), state);
    v.elems = std::move(elems);
    return v;
  }

  void setUpEnvironment() {
    std::vector<Expr> xs, as;
    for (int i = 0; i < obj_.xSize; ++i) xs.push_back(Expr::x(i));
    for (int i = 0; i < obj_.aSize; ++i) as.push_back(Expr::param(i));
    env_["x"] = makeArray("x", xs, Def::Defined);
    env_["a"] = makeArray("a", as, Def::Defined);
    // s[] holds attributes only; without s in the header it has one element (hfp's S_dim).
    env_["s"] = makeArray("s", std::vector<Expr>(std::max(1, obj_.sSize), Expr(0.0)), Def::Defined);
    for (const auto& d : obj_.arrays) {
      std::string why = reservedReason(d.name);
      if (env_.count(d.name)) {
        error(d.loc, "array '" + d.spelling + "' is already declared");
      } else if (!why.empty()) {
        error(d.loc, "cannot declare an array named '" + d.spelling + "': " + why);
      } else {
        env_[d.name] = makeArray(d.spelling, std::vector<Expr>(d.size), Def::Undefined);
      }
    }
  }

  void collectAssigned(const std::vector<Stmt>& stmts) {
    for (const auto& s : stmts) {
      if (s.kind == Stmt::Kind::Assign) assigned_.insert(s.name);
      collectAssigned(s.body);
      collectAssigned(s.elseBody);
    }
  }

  // Why a name cannot be a variable or array ("" when it can).
  std::string reservedReason(const std::string& name) const {
    if (findBuiltin(name)) return "it is a builtin function";
    if (const auto* f = findLibraryFunction(name)) return "it is the library function " + f->name;
    if (attributeFunctions().count(name)) return "it is an attribute function";
    for (const auto& o : sh_.done)
      if (o.info.name == name) return "it is the object defined at line " + std::to_string(o.info.line);
    return "";
  }

  // ---- diagnostics ------------------------------------------------------------------------
  void error(Loc loc, const std::string& message) {
    ++errors_;
    sh_.diags.error(loc, message);
    if (sh_.diags.full()) throw StopObject{};
  }

  std::vector<std::string> knownNames(bool functionsOnly) const {
    std::vector<std::string> names;
    if (!functionsOnly)
      for (const auto& [k, v] : env_)
        if (v.isArray || v.state != Def::Undefined) names.push_back(v.spelling);
    for (const auto& b : builtins()) names.push_back(b.name);
    for (const auto& f : libraryFunctions()) names.push_back(f.name);
    for (const auto& o : sh_.done) names.push_back(o.info.name);
    return names;
  }

  std::string suggestion(const std::string& spelling, bool functionsOnly) const {
    std::string best = closestName(spelling, knownNames(functionsOnly));
    return best.empty() ? "" : "; did you mean '" + best + "'?";
  }

  [[noreturn]] void unknownName(const AstExpr& e, bool asFunction) {
    if (!asFunction && assigned_.count(e.name))
      throw CompileError{e.loc, "'" + e.spelling + "' is used before it is assigned"};
    throw CompileError{e.loc, std::string(asFunction ? "unknown function '" : "unknown name '") +
                                  e.spelling + "'" + suggestion(e.spelling, asFunction)};
  }

  [[noreturn]] void oneBranchError(Loc loc, const std::string& what, Loc ifLoc) {
    throw CompileError{loc, what + " may be unassigned here: it is assigned in only one branch "
                                   "of the 'if' at " + locText(ifLoc) +
                                   ", whose condition depends on x (assign it before the 'if' "
                                   "or in both branches)"};
  }

  // ---- statements -------------------------------------------------------------------------
  void execBlock(const std::vector<Stmt>& stmts) {
    for (const auto& s : stmts) {
      try {
        exec(s);
      } catch (const CompileError& e) {
        error(e.loc, e.message);
        poisonTarget(s);
      }
    }
  }

  // After a failed assignment the target reads as 0 without further errors (no cascade).
  void poisonTarget(const Stmt& s) {
    auto it = env_.find(s.name);
    if (s.kind == Stmt::Kind::Assign) {
      if (it == env_.end()) {
        Value v;
        v.spelling = s.spelling;
        v.state = Def::Poisoned;
        env_[s.name] = v;
      } else if (!it->second.isArray) {
        it->second.state = Def::Poisoned;
      }
    } else if ((s.kind == Stmt::Kind::AssignElem || s.kind == Stmt::Kind::AssignArray) &&
               it != env_.end() && it->second.isArray) {
      for (auto& st : it->second.elemState)
        if (st != Def::Defined) st = Def::Poisoned;
    }
  }

  void exec(const Stmt& s) {
    switch (s.kind) {
      case Stmt::Kind::Assign: return execAssign(s);
      case Stmt::Kind::AssignElem: return execAssignElem(s);
      case Stmt::Kind::AssignArray: return execAssignArray(s);
      case Stmt::Kind::If: return execIf(s);
      case Stmt::Kind::While: return execWhile(s);
    }
  }

  Value& assignableArray(const Stmt& s) {
    if (s.name == "x" || s.name == "a")
      throw CompileError{s.loc, "cannot assign to '" + s.spelling +
                                    "': x and a are read-only (library transformations may "
                                    "still change them)"};
    auto it = env_.find(s.name);
    if (it == env_.end()) {
      throw CompileError{s.loc, "'" + s.spelling + "' is not a declared array (declare it with "
                                    "'array " + s.spelling + "[n];' at the top of the body)" +
                                    suggestion(s.spelling, false)};
    }
    if (!it->second.isArray)
      throw CompileError{s.loc, "'" + s.spelling + "' is a scalar variable, not an array"};
    return it->second;
  }

  void checkDepth(const Expr& v, Loc loc) {
    if (v.node().depth > kMaxExprDepth)
      throw CompileError{loc, "expression too deep (more than " + std::to_string(kMaxExprDepth) +
                                  " nested operations, e.g. a long unrolled loop)"};
  }

  void execAssign(const Stmt& s) {
    if (s.name == "x" || s.name == "a" || s.name == "s") {
      if (s.name == "s") {
        throw CompileError{s.loc, "'s' is an array; assign an element (s[i] = ...) or a "
                                  "literal (s = [...])"};
      }
      assignableArray(s);
    }
    auto it = env_.find(s.name);
    if (it != env_.end() && it->second.isArray)
      throw CompileError{s.loc, "'" + s.spelling + "' is an array; assign an element (" +
                                    s.spelling + "[i] = ...) or a literal (" + s.spelling +
                                    " = [...])"};
    if (it == env_.end()) {
      std::string why = reservedReason(s.name);
      if (!why.empty())
        throw CompileError{s.loc, "cannot assign to '" + s.spelling + "': " + why};
    }
    Expr v = lower(*s.value);
    checkDepth(v, s.loc);
    Value& var = env_[s.name];
    var.spelling = s.spelling;
    var.scalar = v;
    var.state = Def::Defined;
  }

  void execAssignElem(const Stmt& s) {
    Value& arr = assignableArray(s);
    Expr v = lower(*s.value);
    checkDepth(v, s.loc);
    size_t i = constIndex(*s.index, arr);
    arr.elems[i] = v;
    arr.elemState[i] = Def::Defined;
  }

  void execAssignArray(const Stmt& s) {
    Value& arr = assignableArray(s);
    if (s.elems.size() != arr.elems.size())
      throw CompileError{s.loc, "array '" + arr.spelling + "' has " +
                                    std::to_string(arr.elems.size()) + " elements but the literal has " +
                                    std::to_string(s.elems.size())};
    std::vector<Expr> vals;
    for (const auto& e : s.elems) vals.push_back(lower(*e));
    // Re-find: lowering may have run library calls, but never adds or removes arrays.
    Value& target = env_[s.name];
    target.elems = vals;
    target.elemState.assign(vals.size(), Def::Defined);
  }

  void execIf(const Stmt& s) {
    Expr c = truth(lower(*s.value));
    if (c.isConst()) {
      execBlock(c.constValue() != 0.0 ? s.body : s.elseBody);
      return;
    }
    // Depends on x (or a): run both branches and merge with select().
    Env before = env_;
    execBlock(s.body);
    Env thenEnv = std::move(env_);
    env_ = std::move(before);
    execBlock(s.elseBody);
    Env elseEnv = std::move(env_);
    env_.clear();
    std::set<std::string> keys;
    for (const auto& kv : thenEnv) keys.insert(kv.first);
    for (const auto& kv : elseEnv) keys.insert(kv.first);
    for (const auto& k : keys) {
      auto t = thenEnv.find(k), f = elseEnv.find(k);
      const Value* tv = t == thenEnv.end() ? nullptr : &t->second;
      const Value* fv = f == elseEnv.end() ? nullptr : &f->second;
      env_[k] = merge(c, tv, fv, s.loc);
    }
  }

  struct Slot {
    Def state;
    Expr value;
    Loc branchIf;
  };
  static Slot mergeSlot(const Expr& c, Slot t, Slot f, Loc ifLoc) {
    if (t.state == Def::Poisoned || f.state == Def::Poisoned) return {Def::Poisoned, Expr(), {}};
    if (t.state == Def::Undefined && f.state == Def::Undefined) return {Def::Undefined, Expr(), {}};
    if (t.state == Def::Undefined) return {Def::OneBranch, f.value, ifLoc};
    if (f.state == Def::Undefined) return {Def::OneBranch, t.value, ifLoc};
    Expr v = select(c, t.value, f.value);
    if (t.state == Def::Defined && f.state == Def::Defined) return {Def::Defined, v, {}};
    return {Def::OneBranch, v, t.state == Def::OneBranch ? t.branchIf : f.branchIf};
  }

  static Value merge(const Expr& c, const Value* t, const Value* f, Loc ifLoc) {
    Value out = t ? *t : *f;
    if (!out.isArray) {
      Slot ts = t ? Slot{t->state, t->scalar, t->branchIf} : Slot{Def::Undefined, Expr(), {}};
      Slot fs = f ? Slot{f->state, f->scalar, f->branchIf} : Slot{Def::Undefined, Expr(), {}};
      Slot m = mergeSlot(c, ts, fs, ifLoc);
      out.state = m.state;
      out.scalar = m.value;
      out.branchIf = m.branchIf;
      return out;
    }
    for (size_t i = 0; i < out.elems.size(); ++i) {
      Slot ts = t ? Slot{t->elemState[i], t->elems[i], t->branchIf} : Slot{Def::Undefined, Expr(), {}};
      Slot fs = f ? Slot{f->elemState[i], f->elems[i], f->branchIf} : Slot{Def::Undefined, Expr(), {}};
      Slot m = mergeSlot(c, ts, fs, ifLoc);
      out.elemState[i] = m.state;
      out.elems[i] = m.value;
      if (m.state == Def::OneBranch) out.branchIf = m.branchIf;
    }
    return out;
  }

  void execWhile(const Stmt& s) {
    while (true) {
      Expr c = truth(lower(*s.value));
      if (!c.isConst()) {
        bool onX = numVars(c) > 0;
        throw CompileError{s.loc, std::string("the condition of this 'while' depends on ") +
                                      (onX ? "x" : "the parameters a[]") +
                                      "; loops must have a trip count known at compile time "
                                      "(use 'if' for conditions on x)"};
      }
      if (c.constValue() == 0.0) return;
      if (++iterations_ > sh_.options.maxLoopIterations) {
        error(s.loc, "loop does not terminate within " +
                         std::to_string(sh_.options.maxLoopIterations) + " iterations");
        throw StopObject{};
      }
      size_t before = errors_;
      execBlock(s.body);
      if (errors_ != before) return;  // the same error would repeat every iteration
    }
  }

  // ---- expressions ------------------------------------------------------------------------
  // Folds an index to a constant, rounds it (ties up) and checks it against the array (0-based).
  size_t constIndex(const AstExpr& e, const Value& arr) {
    Expr i = lower(e);
    if (!i.isConst())
      throw CompileError{e.loc, std::string("array index must be known at compile time; this "
                                            "one depends on ") +
                                    (numVars(i) > 0 ? "x" : "the parameters a[]")};
    double r = hfRound(i.constValue());
    if (!(r >= 1 && r <= static_cast<double>(arr.elems.size())))
      throw CompileError{e.loc, "index " + fmtNumber(i.constValue()) + " is out of range for '" +
                                    arr.spelling + "' (elements 1 to " +
                                    std::to_string(arr.elems.size()) + ")"};
    return static_cast<size_t>(r) - 1;
  }

  Expr lower(const AstExpr& e) {
    switch (e.kind) {
      case AstExpr::Kind::Number: return Expr(e.number);
      case AstExpr::Kind::Name: return readScalar(e);
      case AstExpr::Kind::Index: return readElement(e);
      case AstExpr::Kind::Call: return call(e);
      case AstExpr::Kind::Unary: {
        Expr v = lower(*e.args[0]);
        return e.unop == UnOp::Plus ? v : -v;
      }
      case AstExpr::Kind::Binary: {
        // hfp evaluates operands right to left (visible through mutating library calls).
        Expr r = lower(*e.args[1]);
        Expr l = lower(*e.args[0]);
        switch (e.binop) {
          case BinOp::Add: return l + r;
          case BinOp::Sub: return l - r;
          case BinOp::Union: return hfUnion(l, r);
          case BinOp::Inter: return hfIntersection(l, r);
          case BinOp::Cart: return hfIntersection(l, r);
          case BinOp::Diff: return hfDifference(l, r);
          case BinOp::Mul: return l * r;
          case BinOp::Div: return l / r;
          case BinOp::Pow: return hfPower(l, r);
        }
        break;
      }
      case AstExpr::Kind::Compare: {
        Expr r = lower(*e.args[1]);
        Expr l = lower(*e.args[0]);
        switch (e.relop) {
          case RelOp::Eq: return hfCompareEq(l, r);
          case RelOp::Ne: return hfCompareNe(l, r);
          case RelOp::Lt: return lt(l, r);
          case RelOp::Gt: return gt(l, r);
          case RelOp::Le: return le(l, r);
          case RelOp::Ge: return ge(l, r);
        }
        break;
      }
      case AstExpr::Kind::And: {
        Expr r = truth(lower(*e.args[1]));
        return logicalAnd(truth(lower(*e.args[0])), r);
      }
      case AstExpr::Kind::Or: {
        Expr r = truth(lower(*e.args[1]));
        return logicalOr(truth(lower(*e.args[0])), r);
      }
      case AstExpr::Kind::Not: return logicalNot(truth(lower(*e.args[0])));
    }
    return Expr(0.0);
  }

  bool isCallable(const std::string& name) const {
    if (findBuiltin(name) || findLibraryFunction(name) || attributeFunctions().count(name))
      return true;
    for (const auto& o : sh_.program.objects)
      if (o.name == name && o.name != obj_.name) return true;
    return false;
  }

  Expr readScalar(const AstExpr& e) {
    auto it = env_.find(e.name);
    if (it != env_.end()) {
      const Value& v = it->second;
      if (v.isArray)
        throw CompileError{e.loc, "'" + e.spelling + "' is an array; use an element, e.g. " +
                                      e.spelling + "[1]"};
      switch (v.state) {
        case Def::Defined: return v.scalar;
        case Def::Poisoned: return Expr(0.0);
        case Def::OneBranch: oneBranchError(e.loc, "'" + e.spelling + "'", v.branchIf);
        case Def::Undefined: break;
      }
    }
    if (isCallable(e.name))
      throw CompileError{e.loc, "'" + e.spelling + "' is a function; call it as " + e.spelling +
                                    "(...)"};
    unknownName(e, false);
  }

  Value& arrayNamed(const AstExpr& e) {
    auto it = env_.find(e.name);
    if (it == env_.end()) {
      if (isCallable(e.name))
        throw CompileError{e.loc, "'" + e.spelling + "' is a function, not an array"};
      unknownName(e, false);
    }
    if (!it->second.isArray)
      throw CompileError{e.loc, "'" + e.spelling + "' is a scalar variable, not an array"};
    return it->second;
  }

  Expr readElement(const AstExpr& e) {
    Value& arr = arrayNamed(e);
    size_t i = constIndex(*e.args[0], arr);
    switch (arr.elemState[i]) {
      case Def::Defined: return arr.elems[i];
      case Def::Poisoned: return Expr(0.0);
      case Def::OneBranch:
        oneBranchError(e.loc, "'" + e.spelling + "[" + std::to_string(i + 1) + "]'", arr.branchIf);
      case Def::Undefined: break;
    }
    throw CompileError{e.loc, "element " + e.spelling + "[" + std::to_string(i + 1) +
                                  "] is read before it is assigned"};
  }

  // An array argument: a bare name of x, a, s or a declared array whose elements all have values.
  Value& arrayArgument(const AstExpr& arg, const std::string& callee, size_t index) {
    if (arg.kind != AstExpr::Kind::Name)
      throw CompileError{arg.loc, "argument " + std::to_string(index + 1) + " of " + callee +
                                      " must be an array name (x, a, s or a declared array)"};
    Value& arr = arrayNamed(arg);
    for (size_t i = 0; i < arr.elems.size(); ++i) {
      if (arr.elemState[i] == Def::Undefined)
        throw CompileError{arg.loc, "array '" + arr.spelling + "' is passed to " + callee +
                                        " before all its elements are assigned (" + arr.spelling +
                                        "[" + std::to_string(i + 1) + "] has no value)"};
      if (arr.elemState[i] == Def::OneBranch)
        oneBranchError(arg.loc, "'" + arr.spelling + "[" + std::to_string(i + 1) + "]'",
                       arr.branchIf);
    }
    return arr;
  }

  Expr call(const AstExpr& e) {
    if (const Builtin* b = findBuiltin(e.name)) return callBuiltin(e, *b);
    // Attribute functions first: even when the library registers them, they only warn.
    if (attributeFunctions().count(e.name)) return callAttribute(e);
    if (const LibraryFunction* f = findLibraryFunction(e.name)) return callLibrary(e, *f);
    for (size_t i = 0; i < sh_.program.objects.size(); ++i) {
      const ObjectDecl& o = sh_.program.objects[i];
      if (o.name != e.name) continue;
      if (&o == &obj_)
        throw CompileError{e.loc, "object '" + obj_.spelling + "' cannot call itself"};
      if (i >= sh_.done.size())
        throw CompileError{e.loc, "object '" + o.spelling + "' is defined later (line " +
                                      std::to_string(o.loc.line) +
                                      "); an object can only call objects defined before it"};
      return callObject(e, o, sh_.done[i]);
    }
    auto it = env_.find(e.name);
    if (it != env_.end() && (it->second.isArray || it->second.state != Def::Undefined))
      throw CompileError{e.loc, "'" + e.spelling + "' is a variable, not a function"};
    unknownName(e, true);
  }

  std::vector<Expr> lowerArgsRightToLeft(const AstExpr& e) {
    std::vector<Expr> args(e.args.size());
    for (size_t i = e.args.size(); i-- > 0;) args[i] = lower(*e.args[i]);
    return args;
  }

  Expr callBuiltin(const AstExpr& e, const Builtin& b) {
    if (static_cast<int>(e.args.size()) != b.arity)
      throw CompileError{e.loc, "'" + std::string(b.name) + "' takes " + std::to_string(b.arity) +
                                    (b.arity == 1 ? " argument" : " arguments") + ", not " +
                                    std::to_string(e.args.size())};
    return b.lower(lowerArgsRightToLeft(e));
  }

  static std::string describeSignature(const std::string& sig) {
    std::string out;
    for (size_t i = 0; i < sig.size(); ++i) {
      if (i) out += ", ";
      out += sig[i] == 'A' ? "array" : "scalar";
    }
    return out;
  }

  Expr callLibrary(const AstExpr& e, const LibraryFunction& f) {
    std::string sig = f.signature;
    if (sig == "*") {  // any arguments: bare array names pass as arrays, the rest as scalars
      sig.clear();
      for (const auto& a : e.args) {
        auto it = a->kind == AstExpr::Kind::Name ? env_.find(a->name) : env_.end();
        sig += it != env_.end() && it->second.isArray ? 'A' : 'S';
      }
    }
    if (e.args.size() != sig.size())
      throw CompileError{e.loc, f.name + " takes " + std::to_string(sig.size()) + " arguments (" +
                                    describeSignature(sig) + "), not " +
                                    std::to_string(e.args.size())};
    std::vector<Arg> args(sig.size());
    // Scalars first (right to left, as hfp); arrays are bound afterwards by reference.
    for (size_t i = sig.size(); i-- > 0;) {
      if (sig[i] == 'A') continue;
      const AstExpr& a = *e.args[i];
      if (a.kind == AstExpr::Kind::Name) {
        auto it = env_.find(a.name);
        if (it != env_.end() && it->second.isArray)
          throw CompileError{a.loc, "argument " + std::to_string(i + 1) + " of " + f.name +
                                        " must be a scalar, but '" + a.spelling + "' is an array"};
      }
      args[i].value = lower(a);
    }
    std::vector<Value*> arrays;
    for (size_t i = 0; i < sig.size(); ++i) {
      if (sig[i] != 'A') continue;
      Value& arr = arrayArgument(*e.args[i], f.name, i);
      args[i].isArray = true;
      args[i].array = &arr.elems;
      args[i].name = arr.spelling;
      arrays.push_back(&arr);
    }
    Expr result;
    try {
      result = f.lower(args);
    } catch (const LibraryError& le) {
      Loc at = le.argIndex >= 0 && le.argIndex < static_cast<int>(e.args.size())
                   ? e.args[le.argIndex]->loc : e.loc;
      std::string msg = le.what();
      // Library messages usually name their function already.
      if (lowerCase(msg.substr(0, f.name.size())) != lowerCase(f.name)) msg = f.name + ": " + msg;
      throw CompileError{at, msg};
    } catch (const std::exception& ex) {
      throw CompileError{e.loc, "internal error in " + f.name + ": " + ex.what()};
    }
    for (Value* arr : arrays) {
      if (arr->elems.size() != arr->elemState.size())
        throw CompileError{e.loc, "internal error: " + f.name + " changed the size of array '" +
                                      arr->spelling + "'"};
    }
    return result;
  }

  Expr callAttribute(const AstExpr& e) {
    if (!sh_.warnedAttributes) {
      sh_.warnedAttributes = true;
      sh_.diags.warning(e.loc, "attribute functions (" + e.spelling +
                                   ", hfA_*) are accepted but ignored: they only set s[] "
                                   "(colour) and do not change geometry; the call's value is 1");
    }
    // Check the arguments for errors; their values are not used.
    for (const auto& a : e.args) {
      if (a->kind == AstExpr::Kind::Name) {
        auto it = env_.find(a->name);
        if (it != env_.end() && it->second.isArray) continue;
      }
      lower(*a);
    }
    return Expr(1.0);
  }

  Expr callObject(const AstExpr& e, const ObjectDecl& callee, const LoweredObject& lowered) {
    if (e.args.size() != 2 && e.args.size() != 3)
      throw CompileError{e.loc, "object '" + callee.spelling + "' is called with its arrays: " +
                                    callee.spelling + "(x, a) or " + callee.spelling +
                                    "(x, a, s), not with " + std::to_string(e.args.size()) +
                                    " arguments"};
    if (!callee.headerOk) return Expr(0.0);  // its header error is already reported
    const int sizes[3] = {callee.xSize, callee.aSize, std::max(1, callee.sSize)};
    const char* roles[3] = {"x", "a", "s"};
    std::vector<Value*> arrs;
    for (size_t i = 0; i < e.args.size(); ++i) {
      Value& arr = arrayArgument(*e.args[i], "object '" + callee.spelling + "'", i);
      if (static_cast<int>(arr.elems.size()) != sizes[i])
        throw CompileError{e.args[i]->loc, "object '" + callee.spelling + "' expects " + roles[i] +
                                               "[" + std::to_string(sizes[i]) + "], but '" +
                                               arr.spelling + "' has " +
                                               std::to_string(arr.elems.size()) + " elements"};
      arrs.push_back(&arr);
    }
    if (!lowered.ok) return Expr(0.0);  // its errors are already reported
    // Substitute x and a at once: a's params first become fresh vars beyond the callee's x.
    std::vector<Expr> paramsAsVars, vars = arrs[0]->elems;
    for (int j = 0; j < callee.aSize; ++j) paramsAsVars.push_back(Expr::x(callee.xSize + j));
    vars.insert(vars.end(), arrs[1]->elems.begin(), arrs[1]->elems.end());
    return remap(bindParams(lowered.field, paramsAsVars), vars);
  }

  // ---- result -----------------------------------------------------------------------------
  void finish(LoweredObject& out) {
    auto it = env_.find(obj_.name);
    Loc at = obj_.endLoc.line ? obj_.endLoc : obj_.loc;
    if (it == env_.end() || it->second.isArray || it->second.state == Def::Undefined) {
      // After another error the assignment may sit in code that failed: say nothing more.
      if (obj_.syntaxErrors > 0 || errors_ > 0) return;
      error(at, "object '" + obj_.spelling + "' never assigns its value; end the body with '" +
                    obj_.spelling + " = expression;'");
      return;
    }
    const Value& v = it->second;
    if (v.state == Def::OneBranch) {
      try {
        oneBranchError(at, "the value of object '" + obj_.spelling + "'", v.branchIf);
      } catch (const CompileError& e) {
        error(e.loc, e.message);
      }
      return;
    }
    if (v.state == Def::Poisoned) return;
    out.field = v.scalar;
    out.ok = true;
  }

  const ObjectDecl& obj_;
  Shared& sh_;
  Env env_;
  std::set<std::string> assigned_;
  long iterations_ = 0;
  size_t errors_ = 0;
};

}  // namespace

std::vector<LoweredObject> lowerProgram(const Program& program, const CompileOptions& options,
                                        DiagnosticSink& diags) {
  std::vector<LoweredObject> done;
  Shared shared{program, options, diags, done};
  for (const auto& obj : program.objects) {
    LoweredObject lo;
    std::string clash;
    for (const auto& prev : done)
      if (prev.info.name == obj.name)
        clash = "object '" + obj.spelling + "' is already defined at line " +
                std::to_string(prev.info.line);
    if (clash.empty() && findBuiltin(obj.name))
      clash = "an object cannot be named '" + obj.spelling + "': it is a builtin function";
    if (clash.empty() && (findLibraryFunction(obj.name) || attributeFunctions().count(obj.name)))
      clash = "an object cannot be named '" + obj.spelling + "': it is a library function";
    if (clash.empty() && (obj.name == "x" || obj.name == "a" || obj.name == "s"))
      clash = "an object cannot be named '" + obj.spelling + "'";
    if (!clash.empty()) {
      diags.error(obj.loc, clash);
      lo.info = ObjectInfo{obj.name, obj.xSize, obj.aSize, obj.sSize, obj.loc.line};
    } else {
      lo = ObjectLowering(obj, shared).run();
    }
    done.push_back(lo);
  }
  return done;
}

}  // namespace frep::lang
