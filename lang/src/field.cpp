#include "frep/lang/field.h"

#include <stdexcept>
#include <string>

namespace frep::lang {

Expr fieldOf(const Model& model, const FieldSpec& spec) {
  if (spec.params.size() > size_t(model.aSize))
    throw std::invalid_argument("object '" + model.objectName + "' has a[" + std::to_string(model.aSize) + "], got " +
                                std::to_string(spec.params.size()) + " parameter values");
  std::vector<Expr> values(size_t(model.aSize), Expr(0.0));
  for (size_t i = 0; i < spec.params.size(); ++i) values[i] = spec.params[i];
  Expr f = bindParams(model.field, values);
  if (spec.iso != 0.0) f = f - Expr(spec.iso);
  if (spec.axis.empty()) return f;
  if (spec.axis.size() != size_t(model.xSize) || spec.constant.size() != spec.axis.size())
    throw std::invalid_argument("object '" + model.objectName + "' has x[" + std::to_string(model.xSize) +
                                "]: the coordinate mapping needs one entry per coordinate");
  std::vector<Expr> vars;
  for (size_t i = 0; i < spec.axis.size(); ++i)
    vars.push_back(spec.axis[i] >= 0 ? Expr::x(uint32_t(spec.axis[i])) : Expr(spec.constant[i]));
  return remap(f, vars);
}

}  // namespace frep::lang
