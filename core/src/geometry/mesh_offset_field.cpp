// A closed mesh's distance offset as one field (mesh_offset_field.h).
#include "frep/geometry/mesh_offset_field.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <typeinfo>

#include "frep/evaluators/interval.h"

namespace frep {

MeshOffsetField::MeshOffsetField(std::shared_ptr<const MeshField> mesh, double level)
    : mesh_(std::move(mesh)), level_(level) {
  if (!mesh_ || !mesh_->check().closed()) throw std::invalid_argument("a mesh offset needs a closed mesh");
  if (!(level_ != 0) || !std::isfinite(level_))
    throw std::invalid_argument("a mesh offset needs a finite nonzero level");
}

std::string MeshOffsetField::describe() const {
  char buf[48];
  std::snprintf(buf, sizeof buf, " %c %.17g", level_ > 0 ? '+' : '-', std::abs(level_));
  return mesh_->describe() + buf;
}

uint64_t MeshOffsetField::contentHash() const {
  uint64_t bits;
  std::memcpy(&bits, &level_, sizeof bits);
  return (mesh_->contentHash() ^ bits) * 0x100000001b3ULL;
}

bool MeshOffsetField::sameContent(const FieldFunction& other) const {
  if (typeid(other) != typeid(*this)) return false;
  const auto& o = static_cast<const MeshOffsetField&>(other);
  return o.level_ == level_ && mesh_->sameContent(*o.mesh_);
}

void MeshOffsetField::signs(const double* u, const double* v, const double* w, double* out, size_t n) const {
  for (size_t i = 0; i < n; ++i) {
    const double p[3] = {u[i], v[i], w[i]};
    out[i] = mesh_->offsetClass(p, level_);
  }
}

// As the two nodes' interval evaluation: the mesh's bound, then the addition of the level.
Interval MeshOffsetField::bound(const Interval box[3]) const {
  return applyOp(Op::Add, mesh_->bound(box), Interval(level_));
}

}  // namespace frep
