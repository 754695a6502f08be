// Private to lang/src/lowering/: the per-object lowering, split over lower.cpp (set-up, result),
// statements.cpp, expressions.cpp, calls.cpp and attributes.cpp.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <unordered_set>
#include <vector>

#include "frep/lang/library/builtins.h"
#include "frep/lang/library/library.h"
#include "frep/lang/lowering/lower.h"

namespace frep::lang::detail {

// Deleting an expression frees its nodes recursively, so an unrolled loop that builds a chain
// deeper than this could overflow the stack; refuse it with an error instead.
inline constexpr uint32_t kMaxExprDepth = 10000;

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

// HyperFun's attribute functions (hfA_*): they fill s[] (colour) and never change geometry.
const std::unordered_set<std::string>& attributeFunctions();
std::string lowerCase(std::string s);
std::string plural(size_t n, const std::string& word);  // "1 element", "3 elements"
std::string locText(Loc l);                              // "line:column"
std::string fmtNumber(double v);

struct Shared {
  const Program& program;
  const CompileOptions& options;
  DiagnosticSink& diags;
  std::vector<LoweredObject>& done;  // objects lowered so far, in file order
  bool warnedAttributes = false;
  bool fixParams = false;  // the object being lowered is the selected one (options.params)
  std::string modelFile;   // the model's file name: file arguments are relative to its directory
  std::vector<std::pair<std::string, std::string>>* files = nullptr;  // files read so far
  std::map<std::string, std::string> fileCache;  // the same, by path (stable references)
};

class ObjectLowering {
 public:
  ObjectLowering(const ObjectDecl& obj, Shared& shared) : obj_(obj), sh_(shared) {}

  LoweredObject run();

 private:
  // ---- environment ------------------------------------------------------------------------
  static Value makeArray(const std::string& spelling, std::vector<Expr> elems, Def state);
  void setUpEnvironment();
  void collectAssigned(const std::vector<Stmt>& stmts);
  // Why a name cannot be a variable or array ("" when it can).
  std::string reservedReason(const std::string& name) const;

  // ---- diagnostics ------------------------------------------------------------------------
  void error(Loc loc, const std::string& message);
  // The contents of a file argument (a String node): CompileOptions::files, else the disk as
  // CompileOptions::fileAccess allows (readModelFileFromDisk).
  const std::string& readModelFile(const AstExpr& path);
  std::vector<std::string> knownNames(bool functionsOnly) const;
  std::string suggestion(const std::string& spelling, bool functionsOnly) const;
  // Throws the error for an unknown (or not yet assigned) name, with a suggestion.
  [[noreturn]] void unknownName(const AstExpr& e, bool asFunction);
  // Throws the error for reading something assigned in only one branch of an if on x.
  [[noreturn]] void oneBranchError(Loc loc, const std::string& what, Loc ifLoc);

  // ---- statements -------------------------------------------------------------------------
  void execBlock(const std::vector<Stmt>& stmts);
  // After a failed assignment the target reads as 0 without further errors (no cascade).
  void poisonTarget(const Stmt& s);
  void exec(const Stmt& s);
  Value& assignableArray(const Stmt& s);
  void checkDepth(const Expr& v, Loc loc);
  void execAssign(const Stmt& s);
  void execAssignElem(const Stmt& s);
  void execAssignArray(const Stmt& s);
  void execIf(const Stmt& s);
  struct Slot {
    Def state;
    Expr value;
    Loc branchIf;
  };
  static Slot mergeSlot(const Expr& c, Slot t, Slot f, Loc ifLoc);
  static Value merge(const Expr& c, const Value* t, const Value* f, Loc ifLoc);
  void execWhile(const Stmt& s);

  // ---- expressions ------------------------------------------------------------------------
  // Folds an index to a constant, rounds it (ties up) and checks it against the array (0-based).
  size_t constIndex(const AstExpr& e, const Value& arr);
  size_t constIndex(const AstExpr& e, const Expr& index, const Value& arr);  // index lowered
  Expr readVaryingElement(const AstExpr& e, Value& arr, const Expr& index);
  Expr lower(const AstExpr& e);
  bool isCallable(const std::string& name) const;
  Expr readScalar(const AstExpr& e);
  Value& arrayNamed(const AstExpr& e);
  Expr readElement(const AstExpr& e);
  // An array argument: a bare name of x, a, s or a declared array whose elements all have values.
  Value& arrayArgument(const AstExpr& arg, const std::string& callee, size_t index);
  // An object argument of a library call (signature 'O'): an earlier object's name; fills
  // out.value with its field over its own x (a[] bound to the caller's a, zeros beyond).
  void objectArgument(const AstExpr& arg, const std::string& callee, size_t index, Arg& out);
  int findObject(const std::string& name) const;  // index in the program, -1 when none
  Expr call(const AstExpr& e);
  std::vector<Expr> lowerArgsRightToLeft(const AstExpr& e);
  Expr callBuiltin(const AstExpr& e, const Builtin& b);
  static std::string describeSignature(const std::string& sig);
  Expr callLibrary(const AstExpr& e, const LibraryFunction& f);
  // hfA_*: writes s[] (or another array) and returns the function's value (attributes.cpp).
  Expr callAttribute(const AstExpr& e);
  Value& attributeArray(const AstExpr& e, size_t index, size_t minSize);
  Expr callObject(const AstExpr& e, const ObjectDecl& callee, const LoweredObject& lowered);

  // ---- result -----------------------------------------------------------------------------
  void finish(LoweredObject& out);
  const ObjectDecl& obj_;
  Shared& sh_;
  Env env_;
  std::set<std::string> assigned_;
  long iterations_ = 0;
  size_t errors_ = 0;
  bool attributesWritten_ = false;  // s[] was assigned or written by an hfA_* call
};
}  // namespace frep::lang::detail
