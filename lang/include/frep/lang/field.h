// From a compiled object to the field that gets evaluated: parameters bound, the isovalue
// subtracted, model coordinates mapped to view axes or held constant. The frep command and the
// farm's workers both build their fields here, so a worker evaluates exactly what frep asked.
#pragma once

#include <vector>

#include "frep/expressions/expr.h"
#include "frep/lang/hyperfun.h"

namespace frep::lang {

struct FieldSpec {
  std::vector<double> params;  // a[1..]; missing ones are 0 (hfp's default)
  double iso = 0.0;            // the solid is f >= iso
  // One entry per model coordinate: the view axis it becomes (0, 1, 2), or -1 to hold it at
  // constant[i]. Empty: coordinates stay as they are.
  std::vector<int> axis;
  std::vector<double> constant;
};

// f(x, a) - iso with a bound and x remapped. Throws std::invalid_argument when the spec does
// not fit the model (too many params, mapping of the wrong length).
Expr fieldOf(const Model& model, const FieldSpec& spec);

// The colour of the model, s[1..3] (red, green, blue; docs/language.md, "Attributes"), with the
// same parameters and coordinate mapping as fieldOf (the isovalue does not apply). Empty when
// the model does not write s or its s has fewer than 3 elements.
std::vector<Expr> colourOf(const Model& model, const FieldSpec& spec);

}  // namespace frep::lang
