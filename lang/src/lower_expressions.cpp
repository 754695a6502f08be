// Expressions: operators, names, array elements and constant indices.
#include "frep/lang/lower_object.h"

namespace frep::lang::detail {

size_t ObjectLowering::constIndex(const AstExpr& e, const Value& arr) {
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

Expr ObjectLowering::readElement(const AstExpr& e) {
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

}  // namespace frep::lang::detail
