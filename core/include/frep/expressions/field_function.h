// Fields that are data rather than formulas: a node f(u, v, w) whose function is a C++ object
// (a volume spline over 10^4 centres, a kernel integrated numerically over a skeleton), with the
// four evaluations every evaluator needs. One node instead of a formula of 10^5 nodes: the tape
// stays short, the centres stay out of the register file, and the object can bound itself far
// tighter than interval arithmetic over the expanded sum.
//
// Contract (checked by the tests of each implementation): value() is the reference; values()
// gives the same bits lane by lane; gradient() is d value / d (u, v, w) wherever value() is
// differentiable; bound() is sound (encloses value() over the box, [-inf, inf] where NaN may
// occur).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "frep/evaluators/interval.h"
#include "frep/expressions/expr.h"

namespace frep {

class FieldFunction {
 public:
  virtual ~FieldFunction() = default;
  // For toString and messages, e.g. "volume_spline(10000 centres)".
  virtual std::string describe() const = 0;
  // Content identity: two objects with the same content hash and sameContent() share one node.
  virtual uint64_t contentHash() const = 0;
  virtual bool sameContent(const FieldFunction& other) const = 0;

  virtual double value(const double p[3]) const = 0;
  // n points in structure-of-arrays form; the default calls value() per point.
  virtual void values(const double* u, const double* v, const double* w, double* out, size_t n) const;
  // Values of which only the class is kept: inside (>= 0), outside (< 0) or NaN as values()
  // gives, except that a value of 0 (a point on the surface, where either class is right) may
  // read as outside. For callers that read nothing else (the simplifier's inside/outside
  // pairs); a field whose value costs more than its class (a distance outside a sum)
  // overrides it. The default is values().
  virtual void signs(const double* u, const double* v, const double* w, double* out, size_t n) const {
    values(u, v, w, out, n);
  }
  // Returns the value and writes the three partial derivatives.
  virtual double gradient(const double p[3], double g[3]) const = 0;
  virtual Interval bound(const Interval box[3]) const = 0;
  // How far the boundary of this field's solid may lie from the one the model names (a sampled
  // operand's meshing bound, minkowski_algebra/sampled_operand.h); 0 for exact geometry. Added
  // to a mesh's surface_error_bound (rawMeshErrorBound).
  virtual double setErrorBound() const { return 0.0; }
};

using FieldFunctionPtr = std::shared_ptr<const FieldFunction>;

// The node fn(u, v, w); constant inputs fold to fn's value.
Expr fieldCall(FieldFunctionPtr fn, const Expr& u, const Expr& v, const Expr& w);

}  // namespace frep
