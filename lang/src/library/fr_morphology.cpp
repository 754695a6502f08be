// Morphological opening and closing (Roerdink-Minkowski §I and §IV: the opening
// A ∘ B = (A ⊖ B) ⊕ B rounds off A's convex corners and removes what B cannot fit in; the
// closing A • B = (A ⊕ B) ⊖ B fills A's concave corners and gaps narrower than B):
//   frOpen(x, A, B [, options])    (A ⊖ B) ⊕ B
//   frClose(x, A, B [, options])   (A ⊕ B) ⊖ B
// Both chain frMinkowskiDiff and frMinkowski (fr_extremum.cpp), so each step takes the exact
// algebra where its operands allow (basic-set members, exact distances with a ball, polytopes)
// and the certified search elsewhere; the options go to both steps (the box is B's).
#include <string>

#include "frep/lang/library/library.h"
#include "frep/minkowski_algebra/registry.h"

namespace frep::lang {
namespace {

Expr morphology(const char* fn, std::vector<Arg>& a, bool open) {
  if (a.size() != 3 && !(a.size() == 4 && a[3].isArray))
    throw LibraryError(std::string(fn) + " takes (x, A, B [, options]) (got " + std::to_string(a.size()) +
                       " arguments)");
  if (!a[0].isArray || !a[0].array)
    throw LibraryError(std::string(fn) + ": argument 1 must be the coordinate array (x)", 0);
  for (int i = 1; i <= 2; ++i)
    if (!a[size_t(i)].isObject)
      throw LibraryError(std::string(fn) + ": argument " + std::to_string(i + 1) + " (" + (i == 1 ? "A" : "B") +
                             ") must be the name of an object defined earlier in the file",
                         i);
  // A convex A is its own closing by any B (a half-space holding A and not a point p holds
  // A ⊕ B shifted by B's support, which p + B leaves): a basic-set sum (Roerdink's
  // zonotope-like members, all convex) closes to itself with no search.
  if (!open && a.size() == 3 && a[1].objectDims == 3 && a[2].objectDims == 3 && a[0].array->size() >= 3) {
    std::optional<minkowski::ExactTerm> t = minkowski::lookupExact(a[1].value);
    if (t && t->kind == minkowski::ExactTerm::Kind::Sum) {
      const std::vector<Expr>& xs = *a[0].array;
      return remap(a[1].value, {xs[0], xs[1], xs[2]});
    }
  }
  const LibraryFunction* sum = findLibraryFunction("frMinkowski");
  const LibraryFunction* diff = findLibraryFunction("frMinkowskiDiff");
  if (!sum || !diff) throw LibraryError(std::string(fn) + ": internal: the Minkowski functions are not registered");
  const LibraryFunction& first = open ? *diff : *sum;
  const LibraryFunction& second = open ? *sum : *diff;
  auto call = [&](const LibraryFunction& f, std::vector<Arg>& args) {
    try {
      return f.lower(args);
    } catch (const LibraryError& e) {
      throw LibraryError(std::string(fn) + " (its " + f.name + " step): " + e.what(), e.argIndex);
    }
  };
  // The first step over the object's own coordinates: its result is then registered as exact
  // when it has a closed form, and the second step can take the exact path too.
  const int n = a[1].objectDims;
  std::vector<Expr> own;
  for (int i = 0; i < n; ++i) own.push_back(Expr::x(uint32_t(i)));
  std::vector<Arg> inner = a;
  inner[0].array = &own;
  Arg mid;
  mid.isObject = true;
  mid.objectDims = n;
  mid.value = call(first, inner);
  mid.name = a[1].name + (open ? " eroded by " : " dilated by ") + a[2].name;
  std::vector<Arg> outer = a;
  outer[1] = mid;
  return call(second, outer);
}

Expr frOpen(std::vector<Arg>& a) { return morphology("frOpen", a, true); }
Expr frClose(std::vector<Arg>& a) { return morphology("frClose", a, false); }

const bool registered = registerAll({
    {"frOpen", "*", "opening (A - B) + B: A with convex corners rounded by B", frOpen},
    {"frClose", "*", "closing (A + B) - B: A with concave corners and narrow gaps filled by B", frClose},
});

}  // namespace
}  // namespace frep::lang
