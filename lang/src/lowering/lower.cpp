// Compiles HyperFun objects to core expressions by running their statements symbolically:
// variables hold Exprs, arrays hold one Expr per element, loops with a compile-time condition
// unroll, and an 'if' whose condition depends on x runs both branches and merges every variable
// with select(). See docs/language.md, "Compilation". This file: set-up, result, lowerProgram.
#include <cctype>
#include <cstdio>

#include "lowering/object_lowering.h"

namespace frep::lang::detail {

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

// "1 element", "3 elements".
std::string plural(size_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

std::string locText(Loc l) { return std::to_string(l.line) + ":" + std::to_string(l.column); }

std::string fmtNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

void ObjectLowering::unknownName(const AstExpr& e, bool asFunction) {
  if (!asFunction && assigned_.count(e.name))
    throw CompileError{e.loc, "'" + e.spelling + "' is used before it is assigned"};
  if (asFunction && e.name == "hfr")
    throw CompileError{e.loc, "'" + e.spelling + "' is not supported: in the R package hyperfun "
                              "it calls back an R function at every point, which exists only "
                              "inside R; write the function in HyperFun instead"};
  throw CompileError{e.loc, std::string(asFunction ? "unknown function '" : "unknown name '") +
                                e.spelling + "'" + suggestion(e.spelling, asFunction)};
}

void ObjectLowering::oneBranchError(Loc loc, const std::string& what, Loc ifLoc) {
  throw CompileError{loc, what + " may be unassigned here: it is assigned in only one branch "
                                 "of the 'if' at " + locText(ifLoc) +
                                 ", whose condition depends on x (assign it before the 'if' "
                                 "or in both branches)"};
}

LoweredObject ObjectLowering::run() {
  LoweredObject out;
  out.info = ObjectInfo{obj_.name, obj_.xSize, obj_.aSize, obj_.sSize, obj_.loc.line};
  if (!obj_.headerOk) return out;
  // Everything below may stop at the error limit, the array declarations included.
  try {
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

Value ObjectLowering::makeArray(const std::string& spelling, std::vector<Expr> elems, Def state) {
  Value v;
  v.isArray = true;
  v.spelling = spelling;
  v.elemState.assign(elems.size(), state);
  v.elems = std::move(elems);
  return v;
}

void ObjectLowering::setUpEnvironment() {
  std::vector<Expr> xs, as;
  for (int i = 0; i < obj_.xSize; ++i) xs.push_back(Expr::x(i));
  // Fixed parameter values belong to the selected object; callees get their a[] from the call.
  static const std::vector<double> none;
  const auto& fixed = sh_.fixParams ? sh_.options.params : none;
  for (int i = 0; i < obj_.aSize; ++i)
    as.push_back(static_cast<size_t>(i) < fixed.size() ? Expr(fixed[i]) : Expr::param(i));
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

void ObjectLowering::collectAssigned(const std::vector<Stmt>& stmts) {
  for (const auto& s : stmts) {
    if (s.kind == Stmt::Kind::Assign) assigned_.insert(s.name);
    collectAssigned(s.body);
    collectAssigned(s.elseBody);
  }
}

std::string ObjectLowering::reservedReason(const std::string& name) const {
  if (findBuiltin(name)) return "it is a builtin function";
  if (const auto* f = findLibraryFunction(name)) return "it is the library function " + f->name;
  if (attributeFunctions().count(name)) return "it is an attribute function";
  for (const auto& o : sh_.done)
    if (o.info.name == name) return "it is the object defined at line " + std::to_string(o.info.line);
  return "";
}

void ObjectLowering::error(Loc loc, const std::string& message) {
  ++errors_;
  sh_.diags.error(loc, message);
  if (sh_.diags.full()) throw StopObject{};
}

std::vector<std::string> ObjectLowering::knownNames(bool functionsOnly) const {
  std::vector<std::string> names;
  if (!functionsOnly)
    for (const auto& [k, v] : env_)
      if (v.isArray || v.state != Def::Undefined) names.push_back(v.spelling);
  for (const auto& b : builtins()) names.push_back(b.name);
  for (const auto& f : libraryFunctions()) names.push_back(f.name);
  for (const auto& o : sh_.done) names.push_back(o.info.name);
  return names;
}

std::string ObjectLowering::suggestion(const std::string& spelling, bool functionsOnly) const {
  std::string best = closestName(spelling, knownNames(functionsOnly));
  return best.empty() ? "" : "; did you mean '" + best + "'?";
}

void ObjectLowering::finish(LoweredObject& out) {
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
  out.attributes = env_.at("s").elems;
  out.attributesWritten = attributesWritten_;
  out.ok = true;
}

}  // namespace frep::lang::detail

namespace frep::lang {

using detail::attributeFunctions;
using detail::ObjectLowering;
using detail::Shared;

int selectedObject(const Program& program, const CompileOptions& options) {
  auto find = [&](const std::string& name) {
    for (size_t i = 0; i < program.objects.size(); ++i)
      if (program.objects[i].name == name) return static_cast<int>(i);
    return -1;
  };
  if (program.objects.empty()) return -1;
  int i = options.object.empty() ? -1 : find(detail::lowerCase(options.object));
  if (i < 0) i = find("my_model");
  return i < 0 ? 0 : i;
}

std::vector<LoweredObject> lowerProgram(const Program& program, const CompileOptions& options,
                                        DiagnosticSink& diags) {
  std::vector<std::pair<std::string, std::string>> files;
  return lowerProgram(program, options, diags, "", files);
}

std::vector<LoweredObject> lowerProgram(const Program& program, const CompileOptions& options,
                                        DiagnosticSink& diags, const std::string& modelFile,
                                        std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<LoweredObject> done;
  Shared shared{program, options, diags, done};
  shared.modelFile = modelFile;
  shared.files = &files;
  const ObjectDecl* selected = nullptr;
  if (int sel = selectedObject(program, options); sel >= 0) selected = &program.objects[sel];
  for (const auto& obj : program.objects) {
    shared.fixParams = &obj == selected;
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

