// Objects whose dimension changes along a parameter (Pasko-Survey: the Cartesian product raises
// the dimension, f3(x, y, z) = f1(x, y) & f2(z) with the segment f2 = (z - z1) & (z2 - z)):
//   frProduct(x, A, axis, z1, z2)
// is A over the coordinates of x other than x[axis] (the first A-many of them, in order) times
// the segment z1 <= x[axis] <= z2, with & = min. z1 and z2 may depend on other coordinates
// (a time x[4]): where z1 < z2 the product has A's dimension plus one, where z1 = z2 it is A
// itself, one dimension lower (F = min(A, -|x[axis] - z1|) >= 0 only on that hyperplane: the
// survey's objects need not be regularised), and where z1 > z2 it is empty.
#include <cmath>
#include <string>

#include "library/hf_util.h"

namespace frep::lang {
namespace {

using hf::constArg;
using hf::scalarArg;

Expr frProduct(std::vector<Arg>& a) {
  const char* fn = "frProduct";
  if (a.size() != 5)
    throw LibraryError(std::string(fn) + " takes (x, A, axis, z1, z2) (got " + std::to_string(a.size()) +
                       " arguments)");
  if (!a[0].isArray || !a[0].array)
    throw LibraryError(std::string(fn) + ": argument 1 must be the coordinate array (x)", 0);
  if (!a[1].isObject)
    throw LibraryError(std::string(fn) + ": argument 2 (A) must be the name of an object defined earlier in the file",
                       1);
  const std::vector<Expr>& x = *a[0].array;
  const double axis = constArg(fn, a, 2, "the axis");
  if (axis != std::floor(axis) || axis < 1 || axis > double(x.size()))
    throw LibraryError(std::string(fn) + ": the axis must be an integer 1 to " + std::to_string(x.size()) +
                           " (the size of " + hf::argName(a, 0, "x") + "; got " + std::to_string(axis) + ")",
                       2);
  const size_t k = size_t(axis) - 1;
  std::vector<Expr> rest;
  for (size_t i = 0; i < x.size(); ++i)
    if (i != k) rest.push_back(x[i]);
  if (size_t(a[1].objectDims) > rest.size())
    throw LibraryError(std::string(fn) + ": " + a[1].name + " has " + std::to_string(a[1].objectDims) +
                           " coordinates, but " + hf::argName(a, 0, "x") + " without the axis leaves " +
                           std::to_string(rest.size()),
                       1);
  rest.resize(size_t(a[1].objectDims));
  const Expr& z1 = scalarArg(fn, a, 3);
  const Expr& z2 = scalarArg(fn, a, 4);
  return min(remap(a[1].value, rest), min(x[k] - z1, z2 - x[k]));
}

const bool registered = registerAll({
    {"frProduct", "*",
     "A x [z1, z2] along x[axis] (Pasko-Survey, Cartesian product); z1 = z2 leaves A, one dimension lower", frProduct},
});

}  // namespace
}  // namespace frep::lang
