// Geometry that is not a formula (triangle meshes, polygons, sampled volumes) as an operand of a
// model: FieldFunction implementations (frep/expressions/field_function.h, the one Op::Field
// node of issue 14) whose value is a signed distance, f = sign * dist (Choporov-Hybrid eq. 1-3,
// positive inside). They read their point from the node's three child expressions (a planar
// field ignores the third), so they compose with every operation and transformation.
//
// The interval bound of a distance field is its Lipschitz bound: dist is 1-Lipschitz in the
// Euclidean norm, so over a box with centre c and half-diagonal r, f lies in f(c) +- L r. It is
// sound and tight to within the box's half-diagonal, so sparse sampling, pruning and meshing cost
// in proportion to the surface, not the volume.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "frep/expressions/field_function.h"

namespace frep {

class DistanceField : public FieldFunction {
 public:
  // Returns f(p) and its gradient. Default: central differences of value().
  double gradient(const double p[3], double g[3]) const override;
  // f(centre) +- lipschitz() * half-diagonal over the dims() coordinates the field reads.
  Interval bound(const Interval box[3]) const override;
  // Same dynamic type, same content hash and sameGeometry().
  bool sameContent(const FieldFunction& other) const override;

  // Lipschitz constant of f in the Euclidean norm (1 for an exact distance).
  virtual double lipschitz() const { return 1.0; }
  // Coordinates the field reads (2: a planar field ignores p[2], so its bound ignores box[2]).
  virtual int dims() const { return 3; }
  // Where value() is the exact Euclidean signed distance to its solid S = {f >= 0}: outside
  // (f(p) = -dist(p, S)) and inside (f(p) = dist(p, complement of S)). Minkowski sums and
  // differences with a ball then reduce to offsets (minkowski_algebra/distance_offset.h).
  // Default: neither (a sampled or approximate field).
  virtual bool exactOutside() const { return false; }
  virtual bool exactInside() const { return false; }

 protected:
  // The gradient of an exact signed distance f at p from q, the nearest boundary point:
  // ±(p − q)/|f| over the dims() coordinates (the rest 0), 0 on the boundary. Returns f.
  double gradientFromNearest(double f, const double* p, const double* q, double g[3]) const;
  // Called only for another object of the same dynamic type and content hash.
  virtual bool sameGeometry(const DistanceField& other) const = 0;
};
using DistanceFieldPtr = std::shared_ptr<const DistanceField>;

// The node f(x, y, z) of a geometry field (planar fields: z = 0).
inline Expr fieldExpr(DistanceFieldPtr field, const Expr& x, const Expr& y, const Expr& z = Expr(0.0)) {
  return fieldCall(std::move(field), x, y, z);
}

}  // namespace frep
