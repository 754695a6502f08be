// Hash-consed expression DAG: intern table, constant folding, structural rewrites.
#include "frep/expressions/expr.h"
#include "frep/expressions/pow_int.h"
#include "frep/expressions/sin_cos.h"

#include "frep/extremum/extremum.h"
#include "frep/expressions/field_function.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace frep {

namespace {

struct OpInfo {
  const char* name;
  int arity;
};

const OpInfo kOps[] = {
    {"const", 0}, {"x", 0},      {"a", 0},     {"extremum", 0}, {"neg", 1},   {"abs", 1},    {"sqrt", 1},
    {"exp", 1},   {"log", 1},    {"log10", 1}, {"sin", 1},   {"cos", 1},    {"tan", 1},
    {"asin", 1},  {"acos", 1},   {"atan", 1},  {"sinh", 1},  {"cosh", 1},   {"tanh", 1},
    {"floor", 1}, {"ceil", 1},   {"trunc", 1}, {"frac", 1},  {"powi", 1},   {"not", 1},
    {"copy", 1},  {"add", 2},    {"sub", 2},   {"mul", 2},   {"div", 2},    {"pow", 2},
    {"atan2", 2}, {"min", 2},    {"max", 2},   {"fmod", 2},  {"lt", 2},     {"le", 2},
    {"gt", 2},    {"ge", 2},     {"eq", 2},    {"ne", 2},    {"and", 2},    {"or", 2},
    {"rand", 2},  {"ror", 2},    {"select", 3}, {"field", 3}};
static_assert(sizeof(kOps) / sizeof(kOps[0]) == static_cast<size_t>(Op::Count_), "op table");

uint64_t mix(uint64_t h, uint64_t v) {
  h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  return h;
}

uint64_t bitsOf(double v) {
  uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// Content hash of an extremum spec (address-independent: body and inputs by structural hash).
uint64_t specHash(const ExtremumSpec& s) {
  uint64_t h = mix(static_cast<uint64_t>(s.kind), static_cast<uint64_t>(s.domain));
  h = mix(h, static_cast<uint64_t>(s.method));
  h = mix(h, s.hidden);
  h = mix(h, s.body.node().hash);
  for (double v : s.lo) h = mix(h, bitsOf(v));
  for (double v : s.hi) h = mix(h, bitsOf(v));
  h = mix(h, bitsOf(s.radius));
  h = mix(h, bitsOf(s.eps));
  h = mix(h, bitsOf(s.tolerance));
  h = mix(h, s.maxBoxes);
  h = mix(h, s.intervalBudget);
  for (const Expr& e : s.inputs) h = mix(h, e.node().hash);
  return h;
}

bool sameSpec(const ExtremumSpec& a, const ExtremumSpec& b) {
  if (&a == &b) return true;
  if (a.kind != b.kind || a.domain != b.domain || a.method != b.method || a.hidden != b.hidden ||
      !a.body.same(b.body) || a.inputs.size() != b.inputs.size() || a.lo.size() != b.lo.size() ||
      a.hi.size() != b.hi.size() || bitsOf(a.radius) != bitsOf(b.radius) ||
      bitsOf(a.eps) != bitsOf(b.eps) || bitsOf(a.tolerance) != bitsOf(b.tolerance) ||
      a.maxBoxes != b.maxBoxes || a.intervalBudget != b.intervalBudget)
    return false;
  for (size_t i = 0; i < a.lo.size(); ++i)
    if (bitsOf(a.lo[i]) != bitsOf(b.lo[i])) return false;
  for (size_t i = 0; i < a.hi.size(); ++i)
    if (bitsOf(a.hi[i]) != bitsOf(b.hi[i])) return false;
  for (size_t i = 0; i < a.inputs.size(); ++i)
    if (!a.inputs[i].same(b.inputs[i])) return false;
  return true;
}

// Extremum nodes are keyed by the spec's content (body, domain, method, inputs), so two builds
// of the same extremum share one node.
struct Key {
  Op op;
  uint32_t index;
  uint64_t valueBits;
  const Node* args[3];
  const ExtremumSpec* spec;
  const FieldFunction* fn;
  bool operator==(const Key& o) const {
    if (op != o.op) return false;
    if (op == Op::Extremum) return sameSpec(*spec, *o.spec);
    if (op == Op::Field && fn != o.fn && !fn->sameContent(*o.fn)) return false;
    return index == o.index && valueBits == o.valueBits && args[0] == o.args[0] &&
           args[1] == o.args[1] && args[2] == o.args[2];
  }
};
struct KeyHash {
  size_t operator()(const Key& k) const {
    uint64_t h = mix(static_cast<uint64_t>(k.op), k.index);
    h = mix(h, k.valueBits);
    if (k.spec) return mix(h, specHash(*k.spec));
    if (k.fn) h = mix(h, k.fn->contentHash());
    for (auto* a : k.args) h = mix(h, reinterpret_cast<uintptr_t>(a));
    return h;
  }
};

// The intern table holds weak references; a node unregisters itself when it dies.
struct InternTable {
  std::mutex mutex;
  std::unordered_map<Key, std::weak_ptr<const Node>, KeyHash> map;
};
InternTable& table() {
  static auto* t = new InternTable();  // never destroyed: nodes may die during static teardown
  return *t;
}

Key keyOf(const Node& n) {
  uint64_t vb = 0;
  std::memcpy(&vb, &n.value, sizeof vb);
  return Key{n.op, n.index, vb, {n.args[0].get(), n.args[1].get(), n.args[2].get()}, n.spec.get(),
             n.fn.get()};
}

// Deleting a node releases its children, which may delete them in turn: on a chain of 10^5
// nodes (an unrolled loop) plain recursion overflows the stack. Children are parked on a
// per-thread list instead and released one at a time by the outermost deletion.
void releaseIteratively(const Node* n) {
  thread_local std::vector<NodePtr> parked;
  thread_local bool draining = false;
  Node* mut = const_cast<Node*>(n);
  for (auto& a : mut->args)
    if (a) parked.push_back(std::move(a));
  delete n;  // an extremum's spec may still release its inputs here, one level deep
  if (draining) return;
  draining = true;
  while (!parked.empty()) {
    NodePtr last = std::move(parked.back());
    parked.pop_back();
    last.reset();  // may park more children
  }
  draining = false;
}

NodePtr intern(Node&& proto) {
  Key key = keyOf(proto);
  auto& t = table();
  std::lock_guard<std::mutex> lock(t.mutex);
  auto it = t.map.find(key);
  if (it != t.map.end()) {
    if (auto alive = it->second.lock()) return alive;
    // Replace the dead entry's key too: an extremum key points at its node's spec, which dies
    // with the node.
    t.map.erase(it);
  }
  uint64_t h = mix(static_cast<uint64_t>(proto.op), proto.index);
  h = mix(h, key.valueBits);
  uint32_t depth = 0;
  for (auto& a : proto.args)
    if (a) {
      h = mix(h, a->hash);
      depth = std::max(depth, a->depth + 1);
    }
  if (proto.spec) {
    h = mix(h, specHash(*proto.spec));
    depth = std::max(depth, proto.spec->body.node().depth + 1);
    for (const Expr& in : proto.spec->inputs) depth = std::max(depth, in.node().depth + 1);
  }
  if (proto.fn) h = mix(h, proto.fn->contentHash());
  proto.hash = h;
  proto.depth = depth;
  auto* raw = new Node(std::move(proto));
  NodePtr p(raw, [](const Node* n) {
    {
      auto& tt = table();
      std::lock_guard<std::mutex> l(tt.mutex);
      auto found = tt.map.find(keyOf(*n));
      if (found != tt.map.end() && found->second.expired()) tt.map.erase(found);
    }
    releaseIteratively(n);
  });
  t.map[key] = p;
  return p;
}

NodePtr leaf(Op op, uint32_t index, double value) {
  Node n;
  n.op = op;
  n.index = index;
  n.value = value;
  return intern(std::move(n));
}

bool isInt(double v) { return std::isfinite(v) && v == std::trunc(v) && std::fabs(v) < 1 << 30; }


}  // namespace

double rFunctionValue(bool disjunction, double f1, double f2, double a) {
  // Same association as the expanded formula, so a = 0 gives HyperFun's bits exactly.
  double s = a == 0.0 ? f1 * f1 + f2 * f2 : f1 * f1 + f2 * f2 - 2.0 * a * f1 * f2;
  double root = s > 0.0 ? std::sqrt(s) : 0.0;  // rounding can make s slightly negative
  double r = disjunction ? f1 + f2 + root : f1 + f2 - root;
  return a == 0.0 ? r : r / (1.0 + a);
}

void rFunctionPartials(bool disjunction, double f1, double f2, double a, double& d1, double& d2) {
  double s = a == 0.0 ? f1 * f1 + f2 * f2 : f1 * f1 + f2 * f2 - 2.0 * a * f1 * f2;
  const double sg = disjunction ? 1.0 : -1.0;
  if (!(s > 0.0)) {
    d1 = d2 = 0.5 / (1.0 + a);
    return;
  }
  const double root = std::sqrt(s);
  d1 = (1.0 + sg * (f1 - a * f2) / root) / (1.0 + a);
  d2 = (1.0 + sg * (f2 - a * f1) / root) / (1.0 + a);
}

const char* domainErrorName(DomainError kind) {
  static const char* names[] = {"sqrt of a negative", "log of a non-positive", "asin/acos outside [-1, 1]",
                                "division by zero", "power of a negative base", "mod by zero"};
  return names[static_cast<size_t>(kind)];
}
uint64_t DomainCounts::total() const {
  uint64_t t = 0;
  for (uint64_t v : n) t += v;
  return t;
}
void DomainCounts::add(const DomainCounts& o) {
  for (size_t i = 0; i < kDomainErrorKinds; ++i) n[i] += o.n[i];
}
std::string DomainCounts::describe() const {
  std::string s;
  for (size_t i = 0; i < kDomainErrorKinds; ++i)
    if (n[i]) s += (s.empty() ? "" : ", ") + std::string(domainErrorName(DomainError(i))) + " " + std::to_string(n[i]);
  return s;
}

const char* opName(Op op) { return kOps[static_cast<int>(op)].name; }

size_t numChildren(const Node& n) {
  if (n.op == Op::Extremum) return n.spec->inputs.size();
  return static_cast<size_t>(opArity(n.op));
}
const Node& child(const Node& n, size_t i) {
  if (n.op == Op::Extremum) return n.spec->inputs[i].node();
  return *n.args[i];
}

Expr Expr::makeExtremum(std::shared_ptr<const ExtremumSpec> spec) {
  Node n;
  n.op = Op::Extremum;
  n.spec = std::move(spec);
  return Expr(intern(std::move(n)));
}
int opArity(Op op) { return kOps[static_cast<int>(op)].arity; }

double applyOp(Op op, double a, double b, double c, double imm) {
  switch (op) {
    case Op::Const: case Op::Var: case Op::Param: return a;
    case Op::Extremum: break;  // not a scalar op: evaluated by a search (extremum.h)
    case Op::Field: break;     // evaluated by its FieldFunction object
    case Op::Neg: return -a;
    case Op::Abs: return std::fabs(a);
    case Op::Sqrt: return a > 0.0 ? std::sqrt(a) : 0.0;
    case Op::Exp: return std::exp(a);
    case Op::Log: return std::log(a > kLogFloor ? a : kLogFloor);
    case Op::Log10: return std::log10(a > kLogFloor ? a : kLogFloor);
    case Op::Sin: return ownSin(a);  // sin_cos.h: the bits every evaluator gives
    case Op::Cos: return ownCos(a);
    case Op::Tan: return std::tan(a);
    case Op::Asin: return std::asin(a < -1.0 ? -1.0 : (a > 1.0 ? 1.0 : a));
    case Op::Acos: return std::acos(a < -1.0 ? -1.0 : (a > 1.0 ? 1.0 : a));
    case Op::Atan: return std::atan(a);
    case Op::Sinh: return std::sinh(a);
    case Op::Cosh: return std::cosh(a);
    case Op::Tanh: return std::tanh(a);
    case Op::Floor: return std::floor(a);
    case Op::Ceil: return std::ceil(a);
    case Op::Trunc: return std::trunc(a);
    case Op::Frac: return a - std::trunc(a);
    case Op::PowI: return powInt(a, static_cast<int>(imm));
    case Op::Not: return a == 0.0 ? 1.0 : 0.0;
    case Op::Copy: return a;
    case Op::Add: return a + b;
    case Op::Sub: return a - b;
    case Op::Mul: return a * b;
    case Op::Div: return a / b;
    case Op::Pow: return std::pow(a, b);
    case Op::Atan2: return std::atan2(a, b);
    case Op::Min: return b < a ? b : a;
    case Op::Max: return b > a ? b : a;
    case Op::Fmod: return std::fmod(a, b);
    case Op::Lt: return a < b ? 1.0 : 0.0;
    case Op::Le: return a <= b ? 1.0 : 0.0;
    case Op::Gt: return a > b ? 1.0 : 0.0;
    case Op::Ge: return a >= b ? 1.0 : 0.0;
    case Op::Eq: return a == b ? 1.0 : 0.0;
    case Op::Ne: return a != b ? 1.0 : 0.0;
    case Op::And: return (a != 0.0 && b != 0.0) ? 1.0 : 0.0;
    case Op::Or: return (a != 0.0 || b != 0.0) ? 1.0 : 0.0;
    case Op::RAnd: case Op::ROr: return rFunctionValue(op == Op::ROr, a, b, imm);
    case Op::Select: return a != 0.0 ? b : c;
    case Op::Count_: break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

Expr::Expr() : n_(leaf(Op::Const, 0, 0.0)) {}
Expr::Expr(double c) : n_(leaf(Op::Const, 0, c)) {}
Expr Expr::x(uint32_t i) { return Expr(leaf(Op::Var, i, 0.0)); }
Expr Expr::param(uint32_t i) { return Expr(leaf(Op::Param, i, 0.0)); }
Expr Expr::constant(double c) { return Expr(c); }

namespace {
bool commutative(Op op) {
  switch (op) {
    case Op::Add: case Op::Mul: case Op::Min: case Op::Max: case Op::Eq: case Op::Ne:
    case Op::And: case Op::Or: case Op::RAnd: case Op::ROr:
      return true;
    default:
      return false;
  }
}

Expr build(Op op, Expr a, Expr b, Expr c, double imm) {
  if (op == Op::Field) throw std::invalid_argument("Expr::make: a field node needs its object (use fieldCall)");
  int arity = opArity(op);
  // Constant folding.
  bool allConst = a.isConst() && (arity < 2 || b.isConst()) && (arity < 3 || c.isConst());
  if (allConst)
    return Expr(applyOp(op, a.constValue(), arity > 1 ? b.constValue() : 0.0,
                        arity > 2 ? c.constValue() : 0.0, imm));
  // Exact identities only (they must hold for every input, inf and NaN aside).
  switch (op) {
    case Op::Copy: return a;
    case Op::Neg:
      if (a.op() == Op::Neg) return a.arg(0);
      break;
    case Op::Add:
      if (a.isConst(0.0)) return b;
      if (b.isConst(0.0)) return a;
      break;
    case Op::Sub:
      if (b.isConst(0.0)) return a;
      if (a.isConst(0.0)) return build(Op::Neg, b, Expr(), Expr(), 0);
      break;
    case Op::Mul:
      if (a.isConst(1.0)) return b;
      if (b.isConst(1.0)) return a;
      if (a.isConst(-1.0)) return build(Op::Neg, b, Expr(), Expr(), 0);
      if (b.isConst(-1.0)) return build(Op::Neg, a, Expr(), Expr(), 0);
      break;
    case Op::Div:
      if (b.isConst(1.0)) return a;
      break;
    case Op::PowI:
      if (imm == 1.0) return a;
      if (imm == 0.0) return Expr(1.0);
      break;
    case Op::Min: case Op::Max:
      if (a.same(b)) return a;
      break;
    case Op::Select:
      if (a.isConst()) return a.constValue() != 0.0 ? b : c;
      if (b.same(c)) return b;
      break;
    default:
      break;
  }
  // Canonical operand order for commutative ops, so a+b and b+a share one node.
  if (commutative(op) && b.node().hash < a.node().hash) std::swap(a, b);
  Node n;
  n.op = op;
  n.value = imm;
  n.args[0] = a.ptr();
  if (arity > 1) n.args[1] = b.ptr();
  if (arity > 2) n.args[2] = c.ptr();
  return Expr(intern(std::move(n)));
}
}  // namespace

Expr Expr::make(Op op, const Expr& a) { return build(op, a, Expr(), Expr(), 0.0); }
Expr Expr::make(Op op, const Expr& a, const Expr& b) { return build(op, a, b, Expr(), 0.0); }
Expr Expr::make(Op op, const Expr& a, const Expr& b, const Expr& c) { return build(op, a, b, c, 0.0); }
Expr Expr::powi(const Expr& a, int n) { return build(Op::PowI, a, Expr(), Expr(), n); }
Expr Expr::makeWithImm(Op op, const Expr& a, const Expr& b, double imm) { return build(op, a, b, Expr(), imm); }
Expr rAnd(const Expr& f1, const Expr& f2, double a) { return Expr::makeWithImm(Op::RAnd, f1, f2, a); }
Expr rOr(const Expr& f1, const Expr& f2, double a) { return Expr::makeWithImm(Op::ROr, f1, f2, a); }

Expr operator+(const Expr& a, const Expr& b) { return Expr::make(Op::Add, a, b); }
Expr operator-(const Expr& a, const Expr& b) { return Expr::make(Op::Sub, a, b); }
Expr operator*(const Expr& a, const Expr& b) { return Expr::make(Op::Mul, a, b); }
Expr operator/(const Expr& a, const Expr& b) { return Expr::make(Op::Div, a, b); }
Expr operator-(const Expr& a) { return Expr::make(Op::Neg, a); }
Expr pow(const Expr& a, const Expr& b) {
  if (b.isConst() && isInt(b.constValue())) return Expr::powi(a, static_cast<int>(b.constValue()));
  return Expr::make(Op::Pow, a, b);
}
Expr square(const Expr& a) { return Expr::powi(a, 2); }
Expr sqrt(const Expr& a) { return Expr::make(Op::Sqrt, a); }
Expr exp(const Expr& a) { return Expr::make(Op::Exp, a); }
Expr log(const Expr& a) { return Expr::make(Op::Log, a); }
Expr log10(const Expr& a) { return Expr::make(Op::Log10, a); }
Expr sin(const Expr& a) { return Expr::make(Op::Sin, a); }
Expr cos(const Expr& a) { return Expr::make(Op::Cos, a); }
Expr tan(const Expr& a) { return Expr::make(Op::Tan, a); }
Expr asin(const Expr& a) { return Expr::make(Op::Asin, a); }
Expr acos(const Expr& a) { return Expr::make(Op::Acos, a); }
Expr atan(const Expr& a) { return Expr::make(Op::Atan, a); }
Expr atan2(const Expr& y, const Expr& x) { return Expr::make(Op::Atan2, y, x); }
Expr sinh(const Expr& a) { return Expr::make(Op::Sinh, a); }
Expr cosh(const Expr& a) { return Expr::make(Op::Cosh, a); }
Expr tanh(const Expr& a) { return Expr::make(Op::Tanh, a); }
Expr abs(const Expr& a) { return Expr::make(Op::Abs, a); }
Expr min(const Expr& a, const Expr& b) { return Expr::make(Op::Min, a, b); }
Expr max(const Expr& a, const Expr& b) { return Expr::make(Op::Max, a, b); }
Expr floor(const Expr& a) { return Expr::make(Op::Floor, a); }
Expr ceil(const Expr& a) { return Expr::make(Op::Ceil, a); }
Expr trunc(const Expr& a) { return Expr::make(Op::Trunc, a); }
Expr frac(const Expr& a) { return Expr::make(Op::Frac, a); }
Expr fmod(const Expr& a, const Expr& b) { return Expr::make(Op::Fmod, a, b); }
Expr sign(const Expr& a) { return select(gt(a, 0.0), 1.0, select(lt(a, 0.0), -1.0, 0.0)); }
Expr lt(const Expr& a, const Expr& b) { return Expr::make(Op::Lt, a, b); }
Expr le(const Expr& a, const Expr& b) { return Expr::make(Op::Le, a, b); }
Expr gt(const Expr& a, const Expr& b) { return Expr::make(Op::Gt, a, b); }
Expr ge(const Expr& a, const Expr& b) { return Expr::make(Op::Ge, a, b); }
Expr eq(const Expr& a, const Expr& b) { return Expr::make(Op::Eq, a, b); }
Expr ne(const Expr& a, const Expr& b) { return Expr::make(Op::Ne, a, b); }
Expr logicalAnd(const Expr& a, const Expr& b) { return Expr::make(Op::And, a, b); }
Expr logicalOr(const Expr& a, const Expr& b) { return Expr::make(Op::Or, a, b); }
Expr logicalNot(const Expr& a) { return Expr::make(Op::Not, a); }
Expr select(const Expr& c, const Expr& t, const Expr& f) { return Expr::make(Op::Select, c, t, f); }

// ---- traversal and rewrites -------------------------------------------------------------

void forEachNode(const Expr& e, const std::function<void(const Node&)>& fn) {
  // Iterative post-order (models can be deep after loop unrolling).
  std::unordered_map<const Node*, bool> seen;
  std::vector<std::pair<const Node*, int>> stack{{&e.node(), 0}};
  while (!stack.empty()) {
    auto& [n, k] = stack.back();
    if (k == 0 && seen.count(n)) {
      stack.pop_back();
      continue;
    }
    const int arity = static_cast<int>(numChildren(*n));
    if (k < arity) {
      const Node* ch = &child(*n, static_cast<size_t>(k));
      ++k;
      if (!seen.count(ch)) stack.push_back({ch, 0});
      continue;
    }
    seen[n] = true;
    fn(*n);
    stack.pop_back();
  }
}

uint32_t numVars(const Expr& e) {
  uint32_t n = 0;
  forEachNode(e, [&](const Node& nd) {
    if (nd.op == Op::Var) n = std::max(n, nd.index + 1);
  });
  return n;
}
uint32_t numParams(const Expr& e) {
  uint32_t n = 0;
  forEachNode(e, [&](const Node& nd) {
    if (nd.op == Op::Param) n = std::max(n, nd.index + 1);
  });
  return n;
}
size_t nodeCount(const Expr& e) {
  size_t n = 0;
  forEachNode(e, [&](const Node&) { ++n; });
  return n;
}

namespace {
// Bottom-up rebuild with a leaf substitution; memoised so shared nodes are rebuilt once.
Expr rebuild(const Expr& e, const std::function<bool(const Node&, Expr&)>& leafMap) {
  std::unordered_map<const Node*, Expr> done;
  forEachNode(e, [&](const Node& n) {
    Expr out;
    if (!leafMap(n, out)) {
      int arity = opArity(n.op);
      if (n.op == Op::Extremum) {
        // Only the inputs live in the outer variable space; the body is left alone.
        bool changed = false;
        std::vector<Expr> ins;
        ins.reserve(n.spec->inputs.size());
        for (const Expr& in : n.spec->inputs) {
          ins.push_back(done.at(&in.node()));
          changed = changed || !ins.back().same(in);
        }
        if (!changed) {
          out = Expr(intern(Node(n)));
        } else {
          auto spec = std::make_shared<ExtremumSpec>(*n.spec);
          spec->inputs = std::move(ins);
          out = Expr::makeExtremum(std::move(spec));
        }
      } else if (n.op == Op::Field) {
        out = fieldCall(n.fn, done.at(n.args[0].get()), done.at(n.args[1].get()), done.at(n.args[2].get()));
      } else if (arity == 0) {
        out = Expr(n.op == Op::Const ? leaf(Op::Const, 0, n.value) : leaf(n.op, n.index, n.value));
      } else {
        Expr a = done.at(n.args[0].get());
        Expr b = arity > 1 ? done.at(n.args[1].get()) : Expr();
        Expr c = arity > 2 ? done.at(n.args[2].get()) : Expr();
        out = build(n.op, a, b, c, n.value);
      }
    }
    done.emplace(&n, out);
  });
  return done.at(&e.node());
}
}  // namespace

Expr remap(const Expr& e, const std::vector<Expr>& vars) {
  return rebuild(e, [&](const Node& n, Expr& out) {
    if (n.op == Op::Var && n.index < vars.size()) {
      out = vars[n.index];
      return true;
    }
    return false;
  });
}

Expr bindParams(const Expr& e, const std::vector<Expr>& params) {
  return rebuild(e, [&](const Node& n, Expr& out) {
    if (n.op == Op::Param && n.index < params.size()) {
      out = params[n.index];
      return true;
    }
    return false;
  });
}

Expr derivative(const Expr& e, uint32_t var) {
  // Forward rules per node, memoised: d[n] = d n / d x[var]. Each rule is a sum of
  // partial * input-derivative terms; a term whose input derivative is the constant 0 is
  // dropped (not multiplied out), so constant sub-expressions cost nothing and an infinite
  // partial (sqrt at 0, pow at 0, ...) times a constant input gives 0, not NaN. The
  // GradientEvaluator follows the same conventions.
  std::unordered_map<const Node*, Expr> d;
  auto term = [](const Expr& partial, const Expr& dx) { return dx.isConst(0.0) ? Expr(0.0) : partial * dx; };
  forEachNode(e, [&](const Node& n) {
    if (n.op == Op::Extremum) {
      // Danskin: d/dX max_u g = dg/dX at the maximiser, which is not an expression. Exact only
      // when no input depends on x[var].
      for (const Expr& in : n.spec->inputs)
        if (!d.at(&in.node()).isConst(0.0))
          throw std::logic_error(
              "derivative: an extremum node has no closed-form derivative (use GradientEvaluator)");
      d.emplace(&n, Expr(0.0));
      return;
    }
    if (n.op == Op::Field) {
      // The object's partials are not expressions (GradientEvaluator uses fn->gradient).
      for (int i = 0; i < 3; ++i)
        if (!d.at(n.args[i].get()).isConst(0.0))
          throw std::logic_error("derivative: " + n.fn->describe() +
                                 " has no closed-form derivative (use GradientEvaluator)");
      d.emplace(&n, Expr(0.0));
      return;
    }
    auto D = [&](int i) { return d.at(n.args[i].get()); };
    Expr a = opArity(n.op) > 0 ? Expr(n.args[0]) : Expr();
    Expr b = opArity(n.op) > 1 ? Expr(n.args[1]) : Expr();
    auto unary = [&](const Expr& pa) { return term(pa, D(0)); };
    auto binary = [&](const Expr& pa, const Expr& pb) { return term(pa, D(0)) + term(pb, D(1)); };
    Expr r;
    switch (n.op) {
      case Op::Const: case Op::Param: case Op::Extremum: case Op::Field: r = 0.0; break;
      case Op::Var: r = n.index == var ? 1.0 : 0.0; break;
      case Op::Neg: r = -D(0); break;
      case Op::Abs: r = unary(sign(a)); break;
      case Op::Sqrt: r = unary(select(gt(a, 0.0), 1.0 / (2.0 * sqrt(a)), 0.0)); break;
      case Op::Exp: r = unary(exp(a)); break;
      case Op::Log: r = unary(select(gt(a, kLogFloor), 1.0 / a, 0.0)); break;
      case Op::Log10: r = unary(select(gt(a, kLogFloor), 1.0 / (a * std::log(10.0)), 0.0)); break;
      case Op::Sin: r = unary(cos(a)); break;
      case Op::Cos: r = unary(-sin(a)); break;
      case Op::Tan: r = unary(1.0 + square(tan(a))); break;
      case Op::Asin: r = unary(select(lt(abs(a), 1.0), 1.0 / sqrt(1.0 - square(a)), 0.0)); break;
      case Op::Acos: r = unary(select(lt(abs(a), 1.0), -1.0 / sqrt(1.0 - square(a)), 0.0)); break;
      case Op::Atan: r = unary(1.0 / (1.0 + square(a))); break;
      case Op::Sinh: r = unary(cosh(a)); break;
      case Op::Cosh: r = unary(sinh(a)); break;
      case Op::Tanh: r = unary(1.0 - square(tanh(a))); break;
      case Op::Floor: case Op::Ceil: case Op::Trunc: case Op::Not:
      case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne:
      case Op::And: case Op::Or:
        r = 0.0;
        break;
      case Op::Frac: case Op::Copy: r = D(0); break;
      case Op::PowI: r = unary(n.value * Expr::powi(a, static_cast<int>(n.value) - 1)); break;
      case Op::Add: r = D(0) + D(1); break;
      case Op::Sub: r = D(0) - D(1); break;
      case Op::Mul: r = binary(b, a); break;
      case Op::Div: r = binary(1.0 / b, -a / square(b)); break;
      // d/da a^b = b a^(b-1): finite at a = 0 for b >= 1 and right for a < 0 with integer b
      // (the former p * b / a form gave NaN at a = 0). d/db = a^b log a, log with its floor.
      case Op::Pow: r = binary(b * pow(a, b - 1.0), pow(a, b) * log(a)); break;
      case Op::Atan2: r = binary(b / (square(a) + square(b)), -a / (square(a) + square(b))); break;
      case Op::Min: r = select(lt(b, a), D(1), D(0)); break;
      case Op::Max: r = select(gt(b, a), D(1), D(0)); break;
      case Op::Fmod: r = binary(1.0, -trunc(a / b)); break;
      case Op::Select: r = select(a, D(1), D(2)); break;
      case Op::RAnd: case Op::ROr: {
        const double al = n.value, sg = n.op == Op::ROr ? 1.0 : -1.0;
        Expr s = al == 0.0 ? square(a) + square(b) : square(a) + square(b) - 2.0 * al * a * b;
        Expr root = sqrt(s);
        Expr half = 0.5 / (1.0 + al);
        r = binary(select(gt(s, 0.0), (1.0 + sg * (a - al * b) / root) / (1.0 + al), half),
                   select(gt(s, 0.0), (1.0 + sg * (b - al * a) / root) / (1.0 + al), half));
        break;
      }
      case Op::Count_: break;
    }
    d.emplace(&n, r);
  });
  return d.at(&e.node());
}

uint64_t structuralHash(const Expr& e) { return e.node().hash; }

void FieldFunction::values(const double* u, const double* v, const double* w, double* out, size_t n) const {
  for (size_t i = 0; i < n; ++i) {
    const double p[3] = {u[i], v[i], w[i]};
    out[i] = value(p);
  }
}

Expr fieldCall(FieldFunctionPtr fn, const Expr& u, const Expr& v, const Expr& w) {
  if (u.isConst() && v.isConst() && w.isConst()) {
    const double p[3] = {u.constValue(), v.constValue(), w.constValue()};
    return Expr(fn->value(p));
  }
  Node n;
  n.op = Op::Field;
  n.args[0] = u.ptr(), n.args[1] = v.ptr(), n.args[2] = w.ptr();
  n.fn = std::move(fn);
  return Expr(intern(std::move(n)));
}

std::string toString(const Expr& e) {
  std::ostringstream os;
  std::unordered_map<const Node*, std::string> s;
  forEachNode(e, [&](const Node& n) {
    std::ostringstream o;
    o.precision(17);
    switch (n.op) {
      case Op::Const: o << n.value; break;
      case Op::Var: o << "x" << n.index; break;
      case Op::Param: o << "a" << n.index; break;
      case Op::Extremum: {
        const ExtremumSpec& sp = *n.spec;
        o << "(" << (sp.kind == ExtremumKind::Max ? "max" : "min") << " u"
          << (sp.domain == DomainKind::Box ? " box" : sp.domain == DomainKind::Sphere ? " sphere" : " ball");
        if (sp.domain == DomainKind::Box) {
          for (size_t i = 0; i < sp.lo.size(); ++i) o << " [" << sp.lo[i] << " " << sp.hi[i] << "]";
        } else {
          o << " m=" << sp.hidden << " r=" << sp.radius;
        }
        o << " " << (sp.method == ExtremumMethod::Grid ? "grid" : "bnb") << " {" << toString(sp.body) << "}";
        for (const Expr& in : sp.inputs) o << " " << s.at(&in.node());
        o << ")";
        break;
      }
      case Op::Field:
        o << "(field " << n.fn->describe() << " " << s.at(n.args[0].get()) << " " << s.at(n.args[1].get()) << " "
          << s.at(n.args[2].get()) << ")";
        break;
      default: {
        o << "(" << opName(n.op);
        if (n.op == Op::PowI) o << " " << n.value;
        for (int i = 0; i < opArity(n.op); ++i) o << " " << s.at(n.args[i].get());
        o << ")";
      }
    }
    s.emplace(&n, o.str());
  });
  return s.at(&e.node());
}

}  // namespace frep
