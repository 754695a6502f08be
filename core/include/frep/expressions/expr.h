// Models as DAGs: hash-consed expression nodes over coordinates x[0..n) and parameters a[0..m).
//
// Every Expr is an immutable node shared through a global intern table, so two structurally
// identical sub-expressions are the same node (hash-consing) and pointer equality is structural
// equality. Constructors fold constants and apply a few exact identities (x+0, x*1, --x).
//
// Domain conventions (documented in docs/core.md, identical in every evaluator):
//   sqrt(x<0) = 0, log/log10(x<=0) = log(DBL_MIN-ish floor) -> see kLogFloor, asin/acos clamp to [-1,1],
//   x/0 follows IEEE (±inf, NaN for 0/0), pow(x<0, non-integer) = NaN, fmod(x, 0) = NaN.
//   Comparisons and logic give 1.0 (true) or 0.0 (false); logic treats any non-zero as true.
//   select(c, a, b) = (c != 0) ? a : b.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace frep {

enum class Op : uint8_t {
  // leaves
  Const, Var, Param,
  // max/min over hidden variables (extremum.h). Its children are not in Node::args but in
  // Node::spec->inputs (any number); opArity() reports 0, so generic code that only looks at
  // args must special-case it (forEachNode, remap, bindParams, toString already do).
  Extremum,
  // unary
  Neg, Abs, Sqrt, Exp, Log, Log10, Sin, Cos, Tan, Asin, Acos, Atan, Sinh, Cosh, Tanh,
  Floor, Ceil, Trunc, Frac, PowI /* integer power, exponent in Node::value */, Not,
  Copy /* tapes only: out = a (a pruned min/max/select) */,
  // binary
  Add, Sub, Mul, Div, Pow, Atan2, Min, Max, Fmod, Lt, Le, Gt, Ge, Eq, Ne, And, Or,
  // R-functions with the survey's parameter a (in Node::value), -1 < a < 1 (Pasko-Survey):
  // RAnd = (f1 + f2 - sqrt(f1^2 + f2^2 - 2a f1 f2)) / (1 + a), ROr with +. One node instead of
  // the expanded formula because they are monotone in both arguments, which gives exact
  // interval bounds (the expanded formula's bounds blow up with every nesting level).
  RAnd, ROr,
  // ternary
  Select,
  // fn(a, b, c) of a FieldFunction object in Node::fn (field_function.h): data-driven fields
  // such as volume splines. Tapes keep the object in a table (Instr::imm is its index).
  Field,
  Count_
};

const char* opName(Op op);
int opArity(Op op);
// Floor, ceil, trunc, comparisons and logic: constant between jumps (derivative 0 where defined).
inline bool isPiecewiseConstant(Op op) {
  switch (op) {
    case Op::Floor: case Op::Ceil: case Op::Trunc: case Op::Not: case Op::Lt: case Op::Le:
    case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne: case Op::And: case Op::Or:
      return true;
    default:
      return false;
  }
}

// Floor applied to the argument of log/log10 (documented domain convention).
constexpr double kLogFloor = 1e-300;

struct Node;
struct ExtremumSpec;  // extremum.h
class FieldFunction;  // field_function.h
using NodePtr = std::shared_ptr<const Node>;

struct Node {
  Op op;
  uint32_t index = 0;      // Var / Param index
  double value = 0.0;      // Const value, PowI exponent
  NodePtr args[3];
  size_t hash = 0;
  uint32_t depth = 0;      // longest path to a leaf (used for stable ordering)
  std::shared_ptr<const ExtremumSpec> spec;  // Op::Extremum only (body, domain, inputs)
  std::shared_ptr<const FieldFunction> fn;   // Op::Field only
};

// Children of a node: args[0..arity) for ordinary ops, spec->inputs for Op::Extremum.
size_t numChildren(const Node& n);
const Node& child(const Node& n, size_t i);

class Expr {
 public:
  Expr();                       // the constant 0
  Expr(double c);               // NOLINT: implicit constants make formulas readable
  explicit Expr(NodePtr n) : n_(std::move(n)) {}

  static Expr x(uint32_t i);      // coordinate x[i], 0-based
  static Expr param(uint32_t i);  // parameter a[i], 0-based
  static Expr constant(double c);

  const Node& node() const { return *n_; }
  const NodePtr& ptr() const { return n_; }
  Op op() const { return n_->op; }
  bool isConst() const { return n_->op == Op::Const; }
  bool isConst(double v) const { return isConst() && n_->value == v; }
  double constValue() const { return n_->value; }
  Expr arg(int i) const { return Expr(n_->args[i]); }
  bool same(const Expr& o) const { return n_ == o.n_; }

  // Builds a node from an op and arguments (folding constants). Exposed for generic rewrites.
  static Expr make(Op op, const Expr& a);
  static Expr make(Op op, const Expr& a, const Expr& b);
  static Expr make(Op op, const Expr& a, const Expr& b, const Expr& c);
  static Expr powi(const Expr& a, int n);
  // A binary op carrying an immediate (RAnd / ROr and their parameter a).
  static Expr makeWithImm(Op op, const Expr& a, const Expr& b, double imm);
  // The extremum node of a validated spec (use frep::extremum() in extremum.h, which checks it).
  static Expr makeExtremum(std::shared_ptr<const ExtremumSpec> spec);

 private:
  NodePtr n_;
};

// Arithmetic
Expr operator+(const Expr& a, const Expr& b);
Expr operator-(const Expr& a, const Expr& b);
Expr operator*(const Expr& a, const Expr& b);
Expr operator/(const Expr& a, const Expr& b);
Expr operator-(const Expr& a);
Expr pow(const Expr& a, const Expr& b);  // integer constant exponent -> PowI
Expr square(const Expr& a);
Expr sqrt(const Expr& a);
Expr exp(const Expr& a);
Expr log(const Expr& a);
Expr log10(const Expr& a);
Expr sin(const Expr& a);
Expr cos(const Expr& a);
Expr tan(const Expr& a);
Expr asin(const Expr& a);
Expr acos(const Expr& a);
Expr atan(const Expr& a);
Expr atan2(const Expr& y, const Expr& x);
Expr sinh(const Expr& a);
Expr cosh(const Expr& a);
Expr tanh(const Expr& a);
Expr abs(const Expr& a);
Expr min(const Expr& a, const Expr& b);
Expr max(const Expr& a, const Expr& b);
Expr floor(const Expr& a);
Expr ceil(const Expr& a);
Expr trunc(const Expr& a);
Expr frac(const Expr& a);  // a - trunc(a)
Expr fmod(const Expr& a, const Expr& b);
Expr sign(const Expr& a);  // -1, 0, 1 (built from select)
// Comparisons and logic (1.0 / 0.0)
Expr lt(const Expr& a, const Expr& b);
Expr le(const Expr& a, const Expr& b);
Expr gt(const Expr& a, const Expr& b);
Expr ge(const Expr& a, const Expr& b);
Expr eq(const Expr& a, const Expr& b);
Expr ne(const Expr& a, const Expr& b);
Expr logicalAnd(const Expr& a, const Expr& b);
Expr logicalOr(const Expr& a, const Expr& b);
Expr logicalNot(const Expr& a);
Expr select(const Expr& cond, const Expr& ifTrue, const Expr& ifFalse);
// R-conjunction / R-disjunction with a constant parameter a in (-1, 1) (ops.h has the checked,
// general versions; a = 1 is min/max there).
Expr rAnd(const Expr& f1, const Expr& f2, double a);
Expr rOr(const Expr& f1, const Expr& f2, double a);

// Scalar semantics of one op (the reference every evaluator must agree with).
double applyOp(Op op, double a, double b = 0.0, double c = 0.0, double imm = 0.0);
// Domain errors: evaluations that fall back on one of the documented values above. Point and
// batch evaluators count them on request (PointEvaluator/BatchEvaluator::countDomainErrors).
enum class DomainError : uint8_t {
  SqrtOfNegative, LogOfNonPositive, AsinAcosOutOfRange, DivisionByZero, PowOfNegativeBase, FmodByZero, Count_
};
constexpr size_t kDomainErrorKinds = static_cast<size_t>(DomainError::Count_);
const char* domainErrorName(DomainError kind);  // e.g. "sqrt of a negative"
struct DomainCounts {
  uint64_t n[kDomainErrorKinds] = {};
  uint64_t total() const;
  void add(const DomainCounts& o);
  std::string describe() const;  // "sqrt of a negative 3, division by zero 1" or ""
};
// Whether op(a, b) is a domain error, and which.
inline bool isDomainError(Op op, double a, double b, DomainError& kind) {
  switch (op) {
    case Op::Sqrt: kind = DomainError::SqrtOfNegative; return a < 0.0;
    case Op::Log: case Op::Log10: kind = DomainError::LogOfNonPositive; return !(a > kLogFloor);
    case Op::Asin: case Op::Acos: kind = DomainError::AsinAcosOutOfRange; return a < -1.0 || a > 1.0;
    case Op::Div: kind = DomainError::DivisionByZero; return b == 0.0;
    case Op::Pow: kind = DomainError::PowOfNegativeBase; return a < 0.0 && b != std::trunc(b);
    case Op::Fmod: kind = DomainError::FmodByZero; return b == 0.0;
    default: return false;
  }
}

// The R-function value (RAnd: disjunction = false), shared by every scalar evaluator.
double rFunctionValue(bool disjunction, double f1, double f2, double a);
// Its partial derivatives; at f1 = f2 = 0 (not differentiable) both are 1 / (2 (1 + a)).
void rFunctionPartials(bool disjunction, double f1, double f2, double a, double& d1, double& d2);

// Structural queries and rewrites (memoised over the DAG, so cost is linear in node count).
uint32_t numVars(const Expr& e);    // 1 + highest Var index (0 if none)
uint32_t numParams(const Expr& e);  // 1 + highest Param index
size_t nodeCount(const Expr& e);    // distinct nodes
// Replaces Var(i) by vars[i] (vars shorter than needed: remaining vars keep their index).
Expr remap(const Expr& e, const std::vector<Expr>& vars);
// Replaces Param(i) by params[i].
Expr bindParams(const Expr& e, const std::vector<Expr>& params);
// Symbolic partial derivative d e / d x[var] (piecewise ops differentiate their active branch).
// An extremum node whose inputs depend on x[var] has no closed-form derivative (Danskin's
// theorem needs the maximiser): derivative() throws std::logic_error for it; use the
// GradientEvaluator, which applies Danskin numerically.
Expr derivative(const Expr& e, uint32_t var);
// Stable 64-bit structural hash (independent of addresses; for caches and metadata).
uint64_t structuralHash(const Expr& e);
// Human-readable prefix form, for diagnostics and tests.
std::string toString(const Expr& e);
// Visits every distinct node once, children before parents.
void forEachNode(const Expr& e, const std::function<void(const Node&)>& fn);

}  // namespace frep
