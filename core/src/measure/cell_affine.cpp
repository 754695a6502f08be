// First-order enclosures of f over a box by forward differentiation in interval arithmetic,
// with switch symbols for kinks (cell_affine.h).
#include "measure/cell_affine.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "frep/expressions/field_function.h"
#include "frep/extremum/extremum.h"

namespace frep::measure_detail {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool isZeroI(const Interval& a) { return a.lo == 0.0 && a.hi == 0.0; }
bool finiteI(const Interval& a) { return std::isfinite(a.lo) && std::isfinite(a.hi); }
Interval negI(const Interval& a) { return {-a.hi, -a.lo}; }
Interval addI(const Interval& a, const Interval& b) {
  if (isZeroI(b)) return a;
  if (isZeroI(a)) return b;
  return applyOp(Op::Add, a, b);
}
Interval mulI(const Interval& a, const Interval& b) {
  if (isZeroI(a) || isZeroI(b)) return Interval(0.0);
  return applyOp(Op::Mul, a, b);
}
Interval divI(const Interval& a, const Interval& b) { return applyOp(Op::Div, a, b); }
Interval hullI(const Interval& a, const Interval& b) { return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; }
// t * a for some t in [0, 1].
Interval hull0(const Interval& a) { return {std::min(a.lo, 0.0), std::max(a.hi, 0.0)}; }
bool excludesZero(const Interval& a) { return a.lo > 0.0 || a.hi < 0.0; }
bool isPoint(const Interval& a) { return a.lo == a.hi && std::isfinite(a.lo); }
// [-1, 1] ∩ a, with the sign of `sign` (m_k / |m| has the sign of m_k).
Interval unitRatio(Interval a, const Interval& sign) {
  if (std::isnan(a.lo) || std::isnan(a.hi)) a = Interval(-1.0, 1.0);
  Interval r{std::max(a.lo, -1.0), std::min(a.hi, 1.0)};
  if (sign.lo >= 0.0) r.lo = std::max(r.lo, 0.0);
  if (sign.hi <= 0.0) r.hi = std::min(r.hi, 0.0);
  if (r.lo > r.hi) r = Interval(-1.0, 1.0);  // cannot happen for a sound ratio; stay safe
  return r;
}

Row failRow() {
  Row r;
  r.zero = false;
  for (auto& g : r.g) g = Interval::everything();
  return r;
}

Row negRow(const Row& a) {
  Row r = a;
  for (auto& g : r.g) g = negI(g);
  for (int j = 0; j < r.n; ++j)
    for (auto& s : r.s[j]) s = negI(s);
  return r;
}

Row scaleRow(const Row& a, const Interval& p) {
  if (a.zero || isZeroI(p)) return Row{};
  Row r;
  r.zero = false;
  r.n = a.n;
  for (int i = 0; i < 3; ++i) r.g[i] = mulI(a.g[i], p);
  for (int j = 0; j < a.n; ++j) {
    r.sym[j] = a.sym[j];
    for (int i = 0; i < 3; ++i) r.s[j][i] = mulI(a.s[j][i], p);
  }
  return r;
}

// Drops switch terms that are exactly 0 (they would take a slot for nothing).
void compact(Row& r) {
  int k = 0;
  for (int j = 0; j < r.n; ++j) {
    if (isZeroI(r.s[j][0]) && isZeroI(r.s[j][1]) && isZeroI(r.s[j][2])) continue;
    if (k != j) {
      r.sym[k] = r.sym[j];
      for (int i = 0; i < 3; ++i) r.s[k][i] = r.s[j][i];
    }
    ++k;
  }
  r.n = k;
}

// a + b (b negated when `minus`), merging switch terms by symbol; terms beyond kMaxSwitches
// fold into the constant part as t * s with t in [0, 1].
Row addRows(const Row& a, const Row& b, bool minus = false) {
  if (b.zero) return a;
  if (a.zero) return minus ? negRow(b) : b;
  Row r = a;
  compact(r);
  for (int i = 0; i < 3; ++i) r.g[i] = addI(r.g[i], minus ? negI(b.g[i]) : b.g[i]);
  for (int j = 0; j < b.n; ++j) {
    if (isZeroI(b.s[j][0]) && isZeroI(b.s[j][1]) && isZeroI(b.s[j][2])) continue;
    int k = 0;
    while (k < r.n && r.sym[k] != b.sym[j]) ++k;
    if (k == r.n && r.n < kMaxSwitches) {
      r.sym[r.n] = b.sym[j];
      for (auto& s : r.s[r.n]) s = Interval(0.0);
      ++r.n;
    }
    for (int i = 0; i < 3; ++i) {
      const Interval v = minus ? negI(b.s[j][i]) : b.s[j][i];
      if (k < r.n) r.s[k][i] = addI(r.s[k][i], v);
      else r.g[i] = addI(r.g[i], hull0(v));
    }
  }
  compact(r);
  return r;
}

void collapse(const Row& r, Interval out[3]) {
  for (int i = 0; i < 3; ++i) {
    Interval v = r.g[i];
    for (int j = 0; j < r.n; ++j) v = addI(v, hull0(r.s[j][i]));
    out[i] = v;
  }
}

uint64_t constId(double v) {
  uint64_t bits;
  if (v == 0.0) v = 0.0;  // -0 and +0 are one constant
  std::memcpy(&bits, &v, sizeof bits);
  return (uint64_t(1) << 63) ^ (bits >> 1) ^ (bits << 62);
}
constexpr uint64_t kVarId = 1, kInstrId = uint64_t(1) << 32;

}  // namespace

struct CellAffineEvaluator::Impl {
  struct SosTerm {
    Interval v;
    Row r;
    uint64_t id = 0;
  };
  std::vector<Interval> val;
  std::vector<Row> row;
  std::vector<uint64_t> id;
  std::vector<int32_t> sos;  // index into sosPool, -1: not a sum of squares
  std::vector<std::vector<SosTerm>> sosPool;
  size_t sosUsed = 0;
  std::vector<std::pair<uint64_t, uint64_t>> switches;
  ExtremumSlots extrema;
  uint64_t bodiesRoot = 0;
  std::vector<std::unique_ptr<CellAffineEvaluator>> bodies;
  IntervalEvaluator bodyIntervals;
  std::vector<Interval> xbuf;

  uint32_t switchOf(uint64_t x, uint64_t y) {
    for (size_t i = 0; i < switches.size(); ++i)
      if (switches[i].first == x && switches[i].second == y) return uint32_t(i);
    switches.emplace_back(x, y);
    return uint32_t(switches.size() - 1);
  }
  std::vector<char> product;  // per symbol: a product of two others (its key: their indices)
  uint32_t productOf(uint32_t a, uint32_t b) {
    const uint32_t p = switchOf(~uint64_t(std::min(a, b)), std::max(a, b));
    if (product.size() < switches.size()) product.resize(switches.size(), 0);
    product[p] = 1;
    return p;
  }
  // Base switches of a symbol (itself, or the factors of a product, recursively).
  void factors(uint32_t sym, std::vector<uint32_t>& out) const {
    if (sym >= product.size() || !product[sym]) {
      out.push_back(sym);
      return;
    }
    factors(uint32_t(~switches[sym].first), out);
    factors(uint32_t(switches[sym].second), out);
  }
  void expand(Row& r) const {
    std::vector<uint32_t> bases, f;
    r.nBase = 0;
    for (int j = 0; j < r.n; ++j) {
      f.clear();
      factors(r.sym[j], f);
      uint32_t m = 0;
      for (uint32_t b : f) {
        size_t k = std::find(bases.begin(), bases.end(), b) - bases.begin();
        if (k == bases.size()) bases.push_back(b);
        if (k < 32) m |= 1u << k;
      }
      r.mask[j] = m;
    }
    r.nBase = int(bases.size());
    if (r.nBase > 16) {  // too many to enumerate: every term its own switch (a superset)
      for (int j = 0; j < r.n; ++j) r.mask[j] = 1u << j;
      r.nBase = r.n;
    }
  }
  uint64_t freshCount = 0;
  uint32_t fresh() { return switchOf(0x5A5A5A5A5A5A5A5Aull, freshCount++); }
  // Every term with a varying row has a value of one sign, and every other term is 0.
  static bool othersZeroBut(const std::vector<SosTerm>& terms) {
    for (const auto& t : terms) {
      if (t.r.zero ? !isZeroI(t.v) : !(t.v.lo >= 0.0 || t.v.hi <= 0.0)) return false;
    }
    return true;
  }
  // The weights' box nearly holds w = 0 (sum of the smallest |w_k| below 1/2): the norm may be
  // small against the terms' spread, and the unit-vector form bounds the gradients better.
  static bool normNearZero(const std::vector<SosTerm>& terms, const Interval& norm) {
    if (norm.lo <= 0.0) return true;
    double sum = 0.0;
    for (const auto& t : terms) {
      if (t.r.zero) continue;
      const Interval w = unitRatio(divI(t.v, norm), t.v);
      sum += w.lo > 0.0 ? w.lo : (w.hi < 0.0 ? -w.hi : 0.0);
    }
    return sum < 0.5;
  }
  int32_t newSos() {
    if (sosUsed == sosPool.size()) sosPool.emplace_back();
    sosPool[sosUsed].clear();
    return int32_t(sosUsed++);
  }
  // base + t * D for the symbol t: t * t = t, and t * t' (another symbol) is a symbol of its own
  // (the product is 0 or 1 wherever t and t' are), so min(min(a, b), c) keeps its three normals
  // as the vertices R_c, R_a, R_b, R_c + R_b - R_a instead of a box around them.
  Row mix(const Row& base, const Row& D, uint32_t sym) {
    if (D.zero) return base;
    Row T;
    T.zero = false;
    T.n = 1;
    T.sym[0] = sym;
    for (int i = 0; i < 3; ++i) {
      T.s[0][i] = D.g[i];
      T.g[i] = Interval(0.0);
    }
    for (int j = 0; j < D.n; ++j) {
      if (D.sym[j] == sym) {
        for (int i = 0; i < 3; ++i) T.s[0][i] = addI(T.s[0][i], D.s[j][i]);
        continue;
      }
      const uint32_t p = productOf(sym, D.sym[j]);
      int k = 0;
      while (k < T.n && T.sym[k] != p) ++k;
      if (k == T.n && T.n < kMaxSwitches) {
        T.sym[T.n] = p;
        for (auto& v : T.s[T.n]) v = Interval(0.0);
        ++T.n;
      }
      for (int i = 0; i < 3; ++i) {
        if (k < T.n) T.s[k][i] = addI(T.s[k][i], D.s[j][i]);
        else T.g[i] = addI(T.g[i], hull0(D.s[j][i]));
      }
    }
    return addRows(base, T);
  }
  // |m| of a value m with row r and identity mid: the Abs rule.
  Row absRow(const Interval& m, const Row& r, uint64_t mid) {
    if (m.lo >= 0.0) return r;
    if (m.hi <= 0.0) return negRow(r);
    if (r.zero) return r;
    const uint64_t z = constId(0.0);
    if (mid == z) return Row{};
    Row two = scaleRow(r, Interval(2.0));
    if (mid < z) return mix(negRow(r), two, switchOf(mid, z));  // t = [m > 0]: -m + 2 t m
    return mix(r, negRow(two), switchOf(z, mid));                 // t = [0 > m]: m - 2 t m
  }
  Row extremumRow(const Tape& tape, const Instr& ins, const Interval& F);
  bool walk(const Tape& tape, const Interval* vars, const Row* seeds, bool rows, Interval* value, Interval out[3]);
};

CellAffineEvaluator::CellAffineEvaluator() : impl_(std::make_unique<Impl>()) {}
CellAffineEvaluator::~CellAffineEvaluator() = default;

Interval CellAffineEvaluator::valueAt(const Tape& tape, const double* x) {
  Interval box[3];
  const uint32_t n = std::min<uint32_t>(tape.numVars(), 3);
  for (uint32_t i = 0; i < n; ++i) box[i] = Interval(x[i]);
  Interval v;
  impl_->walk(tape, box, nullptr, false, &v, nullptr);
  return v;
}

bool CellAffineEvaluator::gradient(const Tape& tape, const Interval* box, Interval grad[3], Interval* value, Row* row) {
  Row seeds[3];
  for (int i = 0; i < 3; ++i) {
    seeds[i].zero = false;
    seeds[i].g[i] = Interval(1.0);
  }
  Interval v;
  const bool ok = impl_->walk(tape, box, seeds, true, &v, grad);
  if (value) *value = v;
  if (row) {
    *row = impl_->row[tape.resultReg()];
    impl_->expand(*row);
  }
  return ok;
}

bool CellAffineEvaluator::walk(const Tape& tape, const Interval* vars, const Row* seeds, bool rows, Interval* value,
                               Interval out[3]) {
  return impl_->walk(tape, vars, seeds, rows, value, out);
}

// Danskin: for X, Y in the box and u_Y a maximiser at Y, f(Y) - f(X) <= g(Y, u_Y) - g(X, u_Y),
// and >= g(Y, u_X) - g(X, u_X): both in G . (Y - X) when G holds d g / d X over the box times
// every u that can be a maximiser there. Those u are searched by interval bisection of the
// hidden domain: a u box whose body values all stay below the extremum's lower bound over the
// X box (above its upper bound, for a min) holds none.
Row CellAffineEvaluator::Impl::extremumRow(const Tape& tape, const Instr& ins, const Interval& F) {
  const ExtremumEntry& e = tape.extrema()[ins.a];
  const ExtremumSpec& spec = *e.spec;
  const uint32_t n = uint32_t(e.inputRegs.size()), m = spec.hidden;
  bool anyRow = false;
  for (uint32_t k = 0; k < n; ++k) anyRow = anyRow || !row[e.inputRegs[k]].zero;
  if (!anyRow) return Row{};
  if (bodiesRoot != tape.root()->id()) {
    bodies.clear();
    bodiesRoot = tape.root()->id();
  }
  if (bodies.size() < tape.extrema().size()) bodies.resize(tape.extrema().size());
  if (!bodies[ins.a]) bodies[ins.a] = std::make_unique<CellAffineEvaluator>();

  std::vector<Interval> vars(n + m);
  std::vector<Row> seeds(n + m);
  for (uint32_t k = 0; k < n; ++k) {
    vars[k] = val[e.inputRegs[k]];
    const Row& r = row[e.inputRegs[k]];
    if (!r.zero) {  // outer switch symbols mean nothing in the body: fold them
      seeds[k].zero = false;
      collapse(r, seeds[k].g);
    }
  }
  std::vector<std::vector<Interval>> boxes(1, std::vector<Interval>(m));
  for (uint32_t j = 0; j < m; ++j)
    boxes[0][j] = spec.domain == DomainKind::Box ? Interval(spec.lo[j], spec.hi[j])
                                                 : Interval(-spec.radius, spec.radius);
  const bool isMax = spec.kind == ExtremumKind::Max;
  const bool canPrune = isMax ? std::isfinite(F.lo) : std::isfinite(F.hi);
  int evals = 0;
  constexpr int kBudget = 64;
  while (canPrune && evals < kBudget) {
    std::vector<std::vector<Interval>> next;
    for (const auto& b : boxes) {
      uint32_t axis = 0;
      for (uint32_t j = 1; j < m; ++j)
        if (b[j].width() > b[axis].width()) axis = j;
      const double mid = b[axis].mid();
      for (int side = 0; side < 2; ++side) {
        std::vector<Interval> c = b;
        (side ? c[axis].lo : c[axis].hi) = mid;
        for (uint32_t j = 0; j < m; ++j) vars[n + j] = c[j];
        const Interval g = bodyIntervals.eval(*e.body, vars.data());
        ++evals;
        if (isMax ? g.hi < F.lo : g.lo > F.hi) continue;  // no maximiser (minimiser) here
        next.push_back(std::move(c));
      }
    }
    boxes = std::move(next);
    if (boxes.empty() || boxes.size() > 16) break;
  }
  if (boxes.empty()) return failRow();  // cannot happen for a sound F; stay safe
  if (boxes.size() > 8) {  // one box around the survivors
    std::vector<Interval> h = boxes[0];
    for (const auto& b : boxes)
      for (uint32_t j = 0; j < m; ++j) h[j] = hullI(h[j], b[j]);
    boxes.assign(1, h);
  }
  Row r;
  r.zero = false;
  bool first = true;
  for (const auto& b : boxes) {
    for (uint32_t j = 0; j < m; ++j) vars[n + j] = b[j];
    Interval v, g[3];
    if (!bodies[ins.a]->walk(*e.body, vars.data(), seeds.data(), true, &v, g)) return failRow();
    for (int i = 0; i < 3; ++i) r.g[i] = first ? g[i] : hullI(r.g[i], g[i]);
    first = false;
  }
  return r;
}

bool CellAffineEvaluator::Impl::walk(const Tape& tape, const Interval* vars, const Row* seeds, bool rows,
                                     Interval* value, Interval out[3]) {
  const size_t nr = tape.numRegs();
  val.resize(nr);
  id.resize(nr);
  if (rows) {
    row.resize(nr);
    sos.assign(nr, -1);
  }
  sosUsed = 0;
  freshCount = 0;
  switches.clear();
  product.clear();
  const auto& u = tape.uniforms();
  for (size_t i = 0; i < u.size(); ++i) {
    val[i] = std::isnan(u[i]) ? Interval::everything() : Interval(u[i]);
    id[i] = constId(u[i]);
    if (rows) row[i] = Row{};
  }
  for (uint32_t i = 0; i < tape.numVars(); ++i) {
    const uint32_t r = tape.varReg(i);
    val[r] = vars[i];
    id[r] = kVarId + i;
    if (rows) row[r] = seeds ? seeds[i] : Row{};
  }

  const auto& code = tape.code();
  for (size_t k = 0; k < code.size(); ++k) {
    const Instr& ins = code[k];
    const Interval A = val[ins.a], B = val[ins.b], C = val[ins.c];
    Interval V;
    Row R;
    uint64_t ID = kInstrId + k;
    int32_t S = -1;
    auto pass = [&](uint32_t reg) {
      V = val[reg];
      ID = id[reg];
      if (rows) {
        R = row[reg];
        S = sos[reg];
      }
    };
    const Op op = ins.op;
    if (op == Op::Extremum) {
      const ExtremumEntry& e = tape.extrema()[ins.a];
      xbuf.resize(e.inputRegs.size());
      for (size_t i = 0; i < e.inputRegs.size(); ++i) xbuf[i] = val[e.inputRegs[i]];
      V = extrema.get(tape, ins.a).bound(xbuf.data(), false, false);
      if (rows) R = extremumRow(tape, ins, V);
    } else if (op == Op::Field) {
      const Interval in[3] = {A, B, C};
      V = tape.field(ins).bound(in);
      if (rows && !(row[ins.a].zero && row[ins.b].zero && row[ins.c].zero)) R = failRow();
    } else if (op == Op::Copy) {
      pass(ins.a);
    } else if (op == Op::Min || op == Op::Max) {
      const bool isMin = op == Op::Min;
      if (isMin ? A.hi <= B.lo : B.hi <= A.lo) pass(ins.a);
      else if (isMin ? B.hi < A.lo : B.lo > A.hi) pass(ins.b);
      else if (id[ins.a] == id[ins.b]) pass(ins.a);
      else {
        V = applyOp(op, A, B);
        if (rows) {
          const bool aFirst = id[ins.a] < id[ins.b];
          const uint32_t x = aFirst ? ins.a : ins.b, y = aFirst ? ins.b : ins.a;
          const uint32_t t = switchOf(id[x], id[y]);  // t = [x > y]
          if (isMin) R = mix(row[x], addRows(row[y], row[x], true), t);  // x + t (y - x)
          else R = mix(row[y], addRows(row[x], row[y], true), t);        // y + t (x - y)
        }
      }
    } else if (op == Op::Select) {
      if (excludesZero(A) || std::isnan(A.lo)) pass(ins.b);
      else if (isZeroI(A)) pass(ins.c);
      else {
        V = applyOp(op, A, B, C);
        if (rows && !(row[ins.b].zero && row[ins.c].zero && isPoint(B) && B.lo == C.lo && isPoint(C)))
          R = failRow();  // a jump where the condition changes
      }
    } else if (op == Op::Abs && A.lo >= 0.0) {
      pass(ins.a);
    } else {
      // x * x as x^2, as the interval evaluator does (tighter than x * y).
      V = op == Op::Mul && ins.a == ins.b ? applyOp(Op::PowI, A, {}, {}, 2.0) : applyOp(op, A, B, C, ins.imm);
      if (rows) {
        const Row& Ra = row[ins.a];
        const Row& Rb = row[ins.b];
        const bool unary = opArity(op) == 1;
        const bool constIn = Ra.zero && (unary || Rb.zero) && (opArity(op) < 3 || row[ins.c].zero);
        auto chain = [&](const Interval& p, const Interval& q) {
          R = addRows(scaleRow(Ra, p), unary ? Row{} : scaleRow(Rb, q));
        };
        // Sums of squares are tracked whatever the rows (a constant square may join a varying one).
        if ((op == Op::Mul && ins.a == ins.b) || (op == Op::PowI && ins.imm == 2.0)) {
          S = newSos();
          sosPool[size_t(S)].push_back({A, Ra, id[ins.a]});
        } else if (op == Op::Add && sos[ins.a] >= 0 && sos[ins.b] >= 0 &&
                   sosPool[size_t(sos[ins.a])].size() + sosPool[size_t(sos[ins.b])].size() <= 4) {
          std::vector<SosTerm> joined(sosPool[size_t(sos[ins.a])]);
          const auto& tb = sosPool[size_t(sos[ins.b])];
          joined.insert(joined.end(), tb.begin(), tb.end());
          S = newSos();
          sosPool[size_t(S)] = std::move(joined);
        }
        if (constIn) {
          R = Row{};
        } else if (isPiecewiseConstant(op)) {
          if (!isPoint(V)) R = failRow();
        } else {
          switch (op) {
            case Op::Neg: R = negRow(Ra); break;
            case Op::Abs: R = absRow(A, Ra, id[ins.a]); break;
            case Op::Sqrt:
              if (sos[ins.a] >= 0) {
                // The Euclidean norm |m| of the squared terms m_k: sum_k (m_k / |m|) grad m_k.
                const auto& terms = sosPool[size_t(sos[ins.a])];
                int active = 0, which = -1;
                bool othersZero = true;
                for (size_t t = 0; t < terms.size(); ++t)
                  if (!terms[t].r.zero) {
                    ++active;
                    which = int(t);
                  }
                for (size_t t = 0; t < terms.size(); ++t)
                  if (int(t) != which && !isZeroI(terms[t].v)) othersZero = false;
                if (active == 1 && othersZero) {
                  R = absRow(terms[size_t(which)].v, terms[size_t(which)].r, terms[size_t(which)].id);
                } else if (othersZeroBut(terms) && normNearZero(terms, V)) {
                  // Where |m| may vanish every weight spans [0, 1] and their box holds w = 0;
                  // but w = m / |m| (a limit of them, at m = 0) is a unit vector with the signs of
                  // the m_k, so sum_k |w_k| >= 1: w lies in e_1 + sum_k>=2 t_k (e_k - e_1) + t_c e_1
                  // (signs folded in, fresh symbols in [0, 1]), none of whose vertices is 0.
                  R = Row{};
                  const Row* firstRow = nullptr;
                  Row first;
                  for (const auto& t : terms) {
                    if (t.r.zero) continue;
                    const Row sr = t.v.lo >= 0.0 ? t.r : negRow(t.r);
                    if (!firstRow) {
                      first = sr;
                      firstRow = &first;
                      R = sr;
                    } else {
                      R = mix(R, addRows(sr, first, true), fresh());
                    }
                  }
                  R = mix(R, first, fresh());
                } else {
                  R = Row{};
                  for (const auto& t : terms)
                    if (!t.r.zero) R = addRows(R, scaleRow(t.r, unitRatio(divI(t.v, V), t.v)));
                }
              } else if (A.lo > 0.0) {
                chain(divI(Interval(0.5), V), {});
              } else if (A.hi <= 0.0) {
                R = Row{};  // sqrt(max(a, 0)) = 0 on the whole box
              } else {
                R = failRow();
              }
              break;
            case Op::Exp: chain(V, {}); break;
            case Op::Log: case Op::Log10:
              if (A.lo > kLogFloor) chain(divI(Interval(1.0), op == Op::Log ? A : mulI(A, Interval(std::log(10.0)) )), {});
              else if (A.hi <= kLogFloor) R = Row{};
              else R = failRow();
              break;
            case Op::Sin: chain(applyOp(Op::Cos, A), {}); break;
            case Op::Cos: chain(negI(applyOp(Op::Sin, A)), {}); break;
            case Op::Tan: chain(addI(Interval(1.0), applyOp(Op::PowI, V, {}, {}, 2.0)), {}); break;
            case Op::Asin: case Op::Acos:
              if (A.lo > -1.0 && A.hi < 1.0) {
                Interval p = divI(Interval(1.0), applyOp(Op::Sqrt, applyOp(Op::Sub, Interval(1.0),
                                                                           applyOp(Op::PowI, A, {}, {}, 2.0))));
                chain(op == Op::Asin ? p : negI(p), {});
              } else if (A.lo >= 1.0 || A.hi <= -1.0) {
                R = Row{};  // clamped: constant
              } else {
                R = failRow();
              }
              break;
            case Op::Atan: chain(divI(Interval(1.0), addI(Interval(1.0), applyOp(Op::PowI, A, {}, {}, 2.0))), {}); break;
            case Op::Sinh: chain(applyOp(Op::Cosh, A), {}); break;
            case Op::Cosh: chain(applyOp(Op::Sinh, A), {}); break;
            case Op::Tanh: chain(applyOp(Op::Sub, Interval(1.0), applyOp(Op::PowI, V, {}, {}, 2.0)), {}); break;
            case Op::Frac:
              if (std::floor(A.lo) == std::floor(A.hi)) R = Ra;
              else R = failRow();
              break;
            case Op::PowI: {
              const double n = ins.imm;
              if (n == 0.0) R = Row{};
              else chain(mulI(Interval(n), applyOp(Op::PowI, A, {}, {}, n - 1.0)), {});
              break;
            }
            case Op::Add: case Op::Sub:
              R = addRows(Ra, Rb, op == Op::Sub);
              break;
            case Op::Mul:
              if (ins.a == ins.b) {
                R = scaleRow(Ra, mulI(Interval(2.0), A));
              } else {
                chain(B, A);
              }
              break;
            case Op::Div:
              if (excludesZero(B)) chain(divI(Interval(1.0), B), negI(divI(V, B)));
              else R = failRow();
              break;
            case Op::Pow:
              if (A.lo > 0.0) chain(divI(mulI(B, V), A), mulI(V, applyOp(Op::Log, A)));
              else R = failRow();
              break;
            case Op::Atan2: {
              const Interval r2 = addI(applyOp(Op::PowI, A, {}, {}, 2.0), applyOp(Op::PowI, B, {}, {}, 2.0));
              if (r2.lo > 0.0 && !(A.lo <= 0.0 && A.hi >= 0.0 && B.lo < 0.0)) chain(divI(B, r2), negI(divI(A, r2)));
              else R = failRow();  // the jump along the negative b axis
              break;
            }
            case Op::Fmod: {
              const Interval q = divI(A, B);
              if (excludesZero(B) && finiteI(q) && std::trunc(q.lo) == std::trunc(q.hi))
                R = addRows(Ra, scaleRow(Rb, Interval(std::trunc(q.lo))), true);
              else R = failRow();
              break;
            }
            case Op::RAnd: case Op::ROr: {
              // d/df1 = (1 -+ (f1 - a f2) / root) / (1 + a), |(f1 - a f2) / root| <= 1 for |a| < 1.
              const double a = ins.imm, sg = op == Op::ROr ? 1.0 : -1.0;
              const Interval s = applyOp(Op::Sub, addI(applyOp(Op::PowI, A, {}, {}, 2.0), applyOp(Op::PowI, B, {}, {}, 2.0)),
                                         mulI(Interval(2.0 * a), mulI(A, B)));
              const Interval root = applyOp(Op::Sqrt, s);
              Interval r1(-1.0, 1.0), r2(-1.0, 1.0);
              if (s.lo > 0.0) {
                r1 = unitRatio(divI(applyOp(Op::Sub, A, mulI(Interval(a), B)), root), Interval(-1.0, 1.0));
                r2 = unitRatio(divI(applyOp(Op::Sub, B, mulI(Interval(a), A)), root), Interval(-1.0, 1.0));
              }
              const Interval k = divI(Interval(1.0), Interval(1.0 + a));
              const Interval c1 = mulI(addI(Interval(1.0), mulI(Interval(sg), r1)), k);
              const Interval c2 = mulI(addI(Interval(1.0), mulI(Interval(sg), r2)), k);
              const double m0 = (2.0 - std::sqrt(2.0 * (1.0 - a))) / (1.0 + a);
              if (a >= 0.0 && c1.lo + c2.lo < 0.5 * m0) {
                // Where the root may vanish (near an edge of the solid) the weights c_k = (1 -+ r_k) / (1 + a)
                // lie in [0, cmax]^2 with c_1 + c_2 >= m > 0 (|r_1 + r_2| <= sqrt(2 (1 - a))): in
                // (m, 0) + t1 (-m, m) + t2 (cmax, 0) + t3 (0, cmax), fresh t's in [0, 1], no vertex 0.
                const double cmax = 2.0 / (1.0 + a) * (1.0 + 1e-15);
                const double m = m0 * (1.0 - 1e-12);
                R = scaleRow(Ra, Interval(m));
                R = mix(R, addRows(scaleRow(Rb, Interval(m)), scaleRow(Ra, Interval(m)), true), fresh());
                R = mix(R, scaleRow(Ra, Interval(cmax)), fresh());
                R = mix(R, scaleRow(Rb, Interval(cmax)), fresh());
                break;
              }
              chain(c1, c2);
              break;
            }
            default:
              R = failRow();
              break;
          }
        }
      }
    }
    val[ins.out] = V;
    id[ins.out] = ID;
    if (rows) {
      row[ins.out] = R;
      sos[ins.out] = S;
    }
  }
  const uint32_t res = tape.resultReg();
  *value = val[res];
  if (!rows) return finiteI(val[res]);
  collapse(row[res], out);
  for (int i = 0; i < 3; ++i)
    if (!finiteI(out[i])) return false;
  return true;
}

}  // namespace frep::measure_detail
