// Calls: builtins, library functions (array arguments by reference), attribute functions and
// earlier objects.
#include "lowering/object_lowering.h"

#include <sstream>
#include <stdexcept>

namespace frep::lang::detail {

Value& ObjectLowering::arrayArgument(const AstExpr& arg, const std::string& callee, size_t index) {
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

int ObjectLowering::findObject(const std::string& name) const {
  for (size_t i = 0; i < sh_.program.objects.size(); ++i)
    if (sh_.program.objects[i].name == name) return static_cast<int>(i);
  return -1;
}

void ObjectLowering::objectArgument(const AstExpr& arg, const std::string& callee, size_t index,
                                    Arg& out) {
  const std::string which = "argument " + std::to_string(index + 1) + " of " + callee;
  if (arg.kind != AstExpr::Kind::Name)
    throw CompileError{arg.loc, which + " must be the name of an object defined earlier in the file"};
  int i = findObject(arg.name);
  if (i < 0) {
    auto it = env_.find(arg.name);
    if (it != env_.end() && (it->second.isArray || it->second.state != Def::Undefined))
      throw CompileError{arg.loc, which + " must be an object name, but '" + arg.spelling +
                                      "' is a variable"};
    throw CompileError{arg.loc, which + " must be an object name: no object '" + arg.spelling +
                                    "' is defined in this file"};
  }
  const ObjectDecl& o = sh_.program.objects[static_cast<size_t>(i)];
  if (&o == &obj_)
    throw CompileError{arg.loc, "object '" + obj_.spelling + "' cannot use itself in " + callee};
  if (static_cast<size_t>(i) >= sh_.done.size())
    throw CompileError{arg.loc, "object '" + o.spelling + "' is defined later (line " +
                                    std::to_string(o.loc.line) +
                                    "); " + callee + " can only use objects defined before it"};
  const LoweredObject& lowered = sh_.done[static_cast<size_t>(i)];
  out.isObject = true;
  out.name = o.spelling;
  out.objectDims = o.xSize;
  if (!o.headerOk || !lowered.ok) {  // its errors are already reported: the call gives 0
    out.objectDims = -1;
    return;
  }
  // Its a[] reads the caller's a values (zeros where the caller has fewer).
  std::vector<Expr> params;
  auto ait = env_.find("a");
  for (int j = 0; j < o.aSize; ++j) {
    if (ait != env_.end() && ait->second.isArray && static_cast<size_t>(j) < ait->second.elems.size() &&
        ait->second.elemState[static_cast<size_t>(j)] != Def::Undefined)
      params.push_back(ait->second.elems[static_cast<size_t>(j)]);
    else
      params.push_back(Expr(0.0));
  }
  out.value = bindParams(lowered.field, params);
}

Expr ObjectLowering::call(const AstExpr& e) {
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

std::vector<Expr> ObjectLowering::lowerArgsRightToLeft(const AstExpr& e) {
  std::vector<Expr> args(e.args.size());
  for (size_t i = e.args.size(); i-- > 0;) args[i] = lower(*e.args[i]);
  return args;
}

Expr ObjectLowering::callBuiltin(const AstExpr& e, const Builtin& b) {
  if (static_cast<int>(e.args.size()) != b.arity)
    throw CompileError{e.loc, "'" + std::string(b.name) + "' takes " +
                                  plural(static_cast<size_t>(b.arity), "argument") + ", not " +
                                  std::to_string(e.args.size())};
  return b.lower(lowerArgsRightToLeft(e));
}

std::string ObjectLowering::describeSignature(const std::string& sig) {
  std::string out;
  for (size_t i = 0; i < sig.size(); ++i) {
    if (i) out += ", ";
    out += sig[i] == 'A' ? "array" : sig[i] == 'O' ? "object" : sig[i] == 'F' ? "file name" : sig[i] == 'T' ? "string" : "scalar";
  }
  return out;
}

Expr ObjectLowering::callLibrary(const AstExpr& e, const LibraryFunction& f) {
  std::string sig = f.signature;
  if (sig == "*") {  // any arguments: bare array names pass as arrays, the rest as scalars
    sig.clear();
    for (const auto& a : e.args) {
      auto it = a->kind == AstExpr::Kind::Name ? env_.find(a->name) : env_.end();
      bool isVar = it != env_.end() && (it->second.isArray || it->second.state != Def::Undefined);
      if (a->kind == AstExpr::Kind::String) sig += sig.find('F') == std::string::npos ? 'F' : 'T';
      else if (it != env_.end() && it->second.isArray) sig += 'A';
      else if (a->kind == AstExpr::Kind::Name && !isVar && findObject(a->name) >= 0) sig += 'O';
      else sig += 'S';
    }
  }
  if (e.args.size() != sig.size())
    throw CompileError{e.loc, f.name + " takes " + plural(sig.size(), "argument") + " (" +
                                  describeSignature(sig) + "), not " +
                                  std::to_string(e.args.size())};
  std::vector<Arg> args(sig.size());
  // Scalars first (right to left, as hfp); arrays are bound afterwards by reference.
  for (size_t i = sig.size(); i-- > 0;) {
    if (sig[i] == 'A') continue;
    const AstExpr& a = *e.args[i];
    if (sig[i] == 'O') {
      objectArgument(a, f.name, i, args[i]);
      continue;
    }
    if (sig[i] == 'F') {
      if (a.kind != AstExpr::Kind::String)
        throw CompileError{a.loc, "argument " + std::to_string(i + 1) + " of " + f.name +
                                      " must be a file name in double quotes"};
      args[i].name = a.name;
      args[i].file = &readModelFile(a);
      continue;
    }
    if (sig[i] == 'T') {
      if (a.kind != AstExpr::Kind::String)
        throw CompileError{a.loc, "argument " + std::to_string(i + 1) + " of " + f.name +
                                      " must be a string in double quotes"};
      args[i].isText = true;
      args[i].name = a.name;
      continue;
    }
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
  for (const Arg& a : args)
    if (a.isObject && a.objectDims < 0) return Expr(0.0);  // an operand's errors are reported
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
  for (const std::string& w : takeFileWarnings()) sh_.diags.warning(e.loc, w);
  for (Value* arr : arrays) {
    if (arr->elems.size() != arr->elemState.size())
      throw CompileError{e.loc, "internal error: " + f.name + " changed the size of array '" +
                                    arr->spelling + "'"};
  }
  return result;
}

Expr ObjectLowering::callObject(const AstExpr& e, const ObjectDecl& callee, const LoweredObject& lowered) {
  if (e.args.size() != 2 && e.args.size() != 3)
    throw CompileError{e.loc, "object '" + callee.spelling + "' is called with its arrays: " +
                                  callee.spelling + "(x, a) or " + callee.spelling +
                                  "(x, a, s), not with " + plural(e.args.size(), "argument")};
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
                                             plural(arr.elems.size(), "element")};
    arrs.push_back(&arr);
  }
  if (!lowered.ok) return Expr(0.0);  // its errors are already reported
  // Substitute x and a at once: a's params first become fresh vars beyond the callee's x.
  std::vector<Expr> paramsAsVars, vars = arrs[0]->elems;
  for (int j = 0; j < callee.aSize; ++j) paramsAsVars.push_back(Expr::x(callee.xSize + j));
  vars.insert(vars.end(), arrs[1]->elems.begin(), arrs[1]->elems.end());
  return remap(bindParams(lowered.field, paramsAsVars), vars);
}

const std::string& ObjectLowering::readModelFile(const AstExpr& path) {
  const std::string& written = path.name;
  auto cached = sh_.fileCache.find(written);
  if (cached != sh_.fileCache.end()) return cached->second;
  std::string contents;
  auto given = sh_.options.files.find(written);
  if (given != sh_.options.files.end()) {
    contents = given->second;
  } else {
    try {
      contents = readModelFileFromDisk(written, sh_.modelFile, sh_.options);
    } catch (const std::runtime_error& e) {
      throw CompileError{path.loc, e.what()};
    }
  }
  sh_.files->emplace_back(written, contents);
  return sh_.fileCache.emplace(written, std::move(contents)).first->second;
}

}  // namespace frep::lang::detail
