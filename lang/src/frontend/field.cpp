#include "frep/lang/field.h"

#include <stdexcept>
#include <string>

namespace frep::lang {

namespace {

// e(x, a) with a bound and x remapped as the spec says.
Expr bound(const Model& model, const Expr& e, const FieldSpec& spec, double iso) {
  if (spec.params.size() > size_t(model.aSize))
    throw std::invalid_argument("object '" + model.objectName + "' has a[" + std::to_string(model.aSize) + "], got " +
                                std::to_string(spec.params.size()) + " parameter values");
  std::vector<Expr> values(size_t(model.aSize), Expr(0.0));
  for (size_t i = 0; i < spec.params.size(); ++i) values[i] = spec.params[i];
  Expr f = bindParams(e, values);
  if (iso != 0.0) f = f - Expr(iso);
  if (spec.axis.empty()) return f;
  if (spec.axis.size() != size_t(model.xSize) || spec.constant.size() != spec.axis.size())
    throw std::invalid_argument("object '" + model.objectName + "' has x[" + std::to_string(model.xSize) +
                                "]: the coordinate mapping needs one entry per coordinate");
  std::vector<Expr> vars;
  for (size_t i = 0; i < spec.axis.size(); ++i)
    vars.push_back(spec.axis[i] >= 0 ? Expr::x(uint32_t(spec.axis[i])) : Expr(spec.constant[i]));
  return remap(f, vars);
}

}  // namespace

Expr fieldOf(const Model& model, const FieldSpec& spec) { return bound(model, model.field, spec, spec.iso); }

std::vector<Expr> colourOf(const Model& model, const FieldSpec& spec) {
  std::vector<Expr> rgb;
  if (!model.hasAttributes || model.attributes.size() < 3) return rgb;
  for (size_t c = 0; c < 3; ++c) rgb.push_back(bound(model, model.attributes[c], spec, 0.0));
  return rgb;
}

}  // namespace frep::lang
