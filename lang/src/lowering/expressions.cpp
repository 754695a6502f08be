// Expressions: operators, names, array elements and constant indices.
#include "lowering/object_lowering.h"

namespace frep::lang::detail {

size_t ObjectLowering::constIndex(const AstExpr& e, const Value& arr) {
  return constIndex(e, lower(e), arr);
}

size_t ObjectLowering::constIndex(const AstExpr& e, const Expr& i, const Value& arr) {
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

Expr ObjectLowering::lower(const AstExpr& e) {
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
    case AstExpr::Kind::String:
      throw CompileError{e.loc, "a string is only allowed as a file name argument (frVolumeSplineFile, frMesh, frVolume) or a grid name (frVolume)"};
  }
  return Expr(0.0);
}

bool ObjectLowering::isCallable(const std::string& name) const {
  if (findBuiltin(name) || findLibraryFunction(name) || attributeFunctions().count(name))
    return true;
  for (const auto& o : sh_.program.objects)
    if (o.name == name && o.name != obj_.name) return true;
  return false;
}

Expr ObjectLowering::readScalar(const AstExpr& e) {
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

Value& ObjectLowering::arrayNamed(const AstExpr& e) {
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

// An index that depends on x (or a[]), e.g. h[floor(u) + 1]: hfp rounds it per point (ties
// up) and reads that element. Compiled as a select chain on the rounded index, whose interval
// bound is the hull of the elements the index interval can reach (select's own bound). Out of
// range, hfp stops with an error and keeps a stale value; frepfarm clamps to the first or last
// element (docs/language.md).
Expr ObjectLowering::readVaryingElement(const AstExpr& e, Value& arr, const Expr& index) {
  const size_t n = arr.elems.size();
  for (size_t k = 0; k < n; ++k)
    if (arr.elemState[k] != Def::Defined && arr.elemState[k] != Def::Poisoned)
      throw CompileError{e.loc, "element " + e.spelling + "[" + std::to_string(k + 1) +
                                    "] is not assigned, and this index depends on x, so it may "
                                    "read any element: assign them all first"};
  auto elem = [&](size_t k) { return arr.elemState[k] == Def::Defined ? arr.elems[k] : Expr(0.0); };
  // Rounding ties up, round(i) <= k exactly when i < k + 0.5: compare the index itself (one
  // comparison per element, no rounding node to widen the interval).
  Expr v = elem(n - 1);
  for (size_t k = n - 1; k-- > 0;) v = select(lt(index, double(k) + 1.5), elem(k), v);
  return v;
}

Expr ObjectLowering::readElement(const AstExpr& e) {
  arrayNamed(e);  // the name's errors first
  Expr index = lower(*e.args[0]);
  Value& arr = arrayNamed(e);  // re-found: lowering may run library calls
  if (!index.isConst()) return readVaryingElement(e, arr, index);
  size_t i = constIndex(*e.args[0], index, arr);
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

}  // namespace frep::lang::detail
