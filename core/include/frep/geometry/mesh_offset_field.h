// A closed mesh's signed distance offset by a constant, f(p) = mesh(p) + level, as one field:
// the exact Minkowski sum with a ball of radius r (level r) or difference (level -r) that
// minkowski_algebra/distance_offset.h builds for a mesh operand (Pasko-Minkowski: the sum with
// a ball is the offset of an exact distance). Its values are the mesh field's plus the level,
// the same bits as the two nodes it stands for; signs() asks only whether some triangle lies
// within r (MeshField::offsetClass), which the simplifier's inside/outside pairs near the
// offset surface settle with one or a few triangles where a value needs the nearest.
#pragma once

#include <memory>
#include <string>

#include "frep/geometry/distance_fields.h"

namespace frep {

class MeshOffsetField : public FieldFunction {
 public:
  // mesh: closed (the offset is exact only then); level: finite and nonzero.
  MeshOffsetField(std::shared_ptr<const MeshField> mesh, double level);
  std::string describe() const override;
  uint64_t contentHash() const override;
  bool sameContent(const FieldFunction& other) const override;
  double value(const double p[3]) const override { return mesh_->value(p) + level_; }
  void signs(const double* u, const double* v, const double* w, double* out, size_t n) const override;
  double gradient(const double p[3], double g[3]) const override { return mesh_->gradient(p, g) + level_; }
  Interval bound(const Interval box[3]) const override;
  double setErrorBound() const override { return mesh_->setErrorBound(); }

 private:
  std::shared_ptr<const MeshField> mesh_;
  double level_;
};

}  // namespace frep
