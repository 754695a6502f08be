// Convolution surfaces with the kernels of Vyatkin-Perturbation eq. 1-6 (Gaussian, inverse,
// inverse square, metaballs, soft objects, W-shaped quartic) over the skeletons of eq. 7
// (points, segments, arcs, triangles, planes): one family frConv<Kernel><Skeleton>, arguments as
// the Cauchy-kernel functions have them (hfConvPoint, hfConvLine, hfConvArc, hfConvTriangle,
// frConvPlane): the coordinates, the skeleton arrays, one width factor S per element, and the
// threshold T; the field is sum_i int h(S_i |x - s|) ds - T (frep/primitives/convolution.h has
// the integration method and the bounds). The skeleton and the widths must be known at compile
// time (the field is one node over a C++ object); x and T may be any expressions.
#include <cmath>
#include <string>

#include "frep/primitives/convolution.h"
#include "library/hf_util.h"

namespace frep::lang {
namespace {

using hf::argName;
using hf::arrayArg;
using hf::arrayAtLeast;
using hf::arrayExactly;
using hf::scalarArg;

constexpr double kPi = 3.14159265358979323846;

struct Ctx {
  const char* fn;
  std::vector<Arg>& a;
  double num(int i, size_t k) const {
    const Expr& e = (*a[i].array)[k];
    if (!e.isConst())
      throw LibraryError(std::string(fn) + ": element " + std::to_string(k + 1) + " of " + argName(a, i, "the array") +
                             " must be known at compile time (the skeleton is fixed when the model compiles)",
                         i);
    return e.constValue();
  }
};

std::vector<ConvElement> pointElements(Ctx& c) {
  auto& S = arrayArg(c.fn, c.a, 2);
  arrayExactly(c.fn, c.a, 1, 3 * S.size(), " (3 per element of " + argName(c.a, 2, "S") + ")");
  std::vector<ConvElement> out(S.size());
  for (size_t i = 0; i < S.size(); ++i) {
    out[i].geometry = {c.num(1, 3 * i), c.num(1, 3 * i + 1), c.num(1, 3 * i + 2)};
    out[i].S = c.num(2, i);
  }
  return out;
}

// (x, b, e, S, T) and (x, p, n, S, T): two 3-vectors per element.
std::vector<ConvElement> pairElements(Ctx& c) {
  auto& S = arrayArg(c.fn, c.a, 3);
  std::string why = " (3 per element of " + argName(c.a, 3, "S") + ")";
  arrayExactly(c.fn, c.a, 1, 3 * S.size(), why);
  arrayExactly(c.fn, c.a, 2, 3 * S.size(), why);
  std::vector<ConvElement> out(S.size());
  for (size_t i = 0; i < S.size(); ++i) {
    for (int arr = 1; arr <= 2; ++arr)
      for (size_t k = 0; k < 3; ++k) out[i].geometry.push_back(c.num(arr, 3 * i + k));
    out[i].S = c.num(3, i);
  }
  return out;
}

std::vector<ConvElement> triangleElements(Ctx& c) {
  auto& S = arrayArg(c.fn, c.a, 2);
  arrayExactly(c.fn, c.a, 1, 9 * S.size(), " (9 per element of " + argName(c.a, 2, "S") + ")");
  std::vector<ConvElement> out(S.size());
  for (size_t i = 0; i < S.size(); ++i) {
    for (size_t k = 0; k < 9; ++k) out[i].geometry.push_back(c.num(1, 9 * i + k));
    out[i].S = c.num(2, i);
  }
  return out;
}

// (x, c, r, theta, axis, angle, S, T) as hfConvArc (degrees; the arc from the local x axis
// towards the local y axis in the local xy-plane, turned by `angle` about `axis` through c),
// without hfp's quirks: exact pi, no 1e-6 added to the axis and angle.
std::vector<ConvElement> arcElements(Ctx& c) {
  auto& S = arrayArg(c.fn, c.a, 6);
  size_t n = S.size();
  std::string per = " (one per element of " + argName(c.a, 6, "S") + ")";
  std::string per3 = " (3 per element of " + argName(c.a, 6, "S") + ")";
  arrayExactly(c.fn, c.a, 1, 3 * n, per3);
  arrayExactly(c.fn, c.a, 2, n, per);
  arrayExactly(c.fn, c.a, 3, n, per);
  arrayExactly(c.fn, c.a, 4, 3 * n, per3);
  arrayExactly(c.fn, c.a, 5, n, per);
  std::vector<ConvElement> out(n);
  const double deg = kPi / 180.0;
  for (size_t i = 0; i < n; ++i) {
    double ax[3] = {c.num(4, 3 * i), c.num(4, 3 * i + 1), c.num(4, 3 * i + 2)};
    double angle = c.num(5, i) * deg;
    double len = std::sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    if (!(len > 0.0)) {
      if (angle != 0.0)
        throw LibraryError(std::string(c.fn) + ": rotation axis " + std::to_string(i + 1) + " of " +
                               argName(c.a, 4, "axis") + " is zero",
                           4);
      ax[0] = 0, ax[1] = 0, ax[2] = 1, len = 1;
    }
    for (double& v : ax) v /= len;
    // Rodrigues: R w = w cos + (ax x w) sin + ax (ax . w)(1 - cos).
    double cb = std::cos(angle), sb = std::sin(angle);
    auto rot = [&](const double w[3], double* o) {
      double cr[3] = {ax[1] * w[2] - ax[2] * w[1], ax[2] * w[0] - ax[0] * w[2], ax[0] * w[1] - ax[1] * w[0]};
      double d = ax[0] * w[0] + ax[1] * w[1] + ax[2] * w[2];
      for (int k = 0; k < 3; ++k) o[k] = w[k] * cb + cr[k] * sb + ax[k] * d * (1.0 - cb);
    };
    const double e1[3] = {1, 0, 0}, e2[3] = {0, 1, 0};
    double u[3], v[3];
    rot(e1, u);
    rot(e2, v);
    double theta = c.num(3, i);
    if (!(theta > 0.0 && theta <= 360.0))
      throw LibraryError(std::string(c.fn) + ": opening " + std::to_string(i + 1) + " of " + argName(c.a, 3, "theta") +
                             " must be in (0, 360] degrees",
                         3);
    out[i].geometry = {c.num(1, 3 * i), c.num(1, 3 * i + 1), c.num(1, 3 * i + 2), u[0], u[1], u[2], v[0], v[1], v[2],
                       c.num(2, i), theta * deg};
    out[i].S = c.num(6, i);
  }
  return out;
}

Expr lowerConv(ConvKernel kernel, ConvSkeleton skeleton, const std::string& name, std::vector<Arg>& a) {
  const char* fn = name.c_str();
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  Ctx c{fn, a};
  std::vector<ConvElement> els;
  int tArg = 0;
  switch (skeleton) {
    case ConvSkeleton::Point: els = pointElements(c), tArg = 3; break;
    case ConvSkeleton::Segment:
    case ConvSkeleton::Plane: els = pairElements(c), tArg = 4; break;
    case ConvSkeleton::Triangle: els = triangleElements(c), tArg = 3; break;
    case ConvSkeleton::Arc: els = arcElements(c), tArg = 7; break;
  }
  const Expr& T = scalarArg(fn, a, tArg);
  std::shared_ptr<const Convolution> conv;
  try {
    conv = Convolution::make(kernel, skeleton, std::move(els));
  } catch (const std::invalid_argument& e) {
    throw LibraryError(name + ": " + e.what());
  }
  return fieldCall(conv, x[0], x[1], x[2]) - T;
}

const char* kernelFormula(ConvKernel k) {
  switch (k) {
    case ConvKernel::Gauss: return "exp(-q^2) (eq. 1)";
    case ConvKernel::Inverse: return "1/q (eq. 2)";
    case ConvKernel::InverseSquare: return "1/q^2 (eq. 3)";
    case ConvKernel::Metaball: return "1-3q^2 | 3/2(1-q)^2 | 0 (eq. 4)";
    case ConvKernel::Soft: return "(1-q^2)^2(9-4q^2)/9 for q<1 (eq. 5, Wyvill)";
    case ConvKernel::Quartic: return "(1-q^2)^2 for q<1 (eq. 6)";
  }
  return "";
}

bool registerFamily() {
  const ConvKernel kernels[] = {ConvKernel::Gauss,    ConvKernel::Inverse, ConvKernel::InverseSquare,
                                ConvKernel::Metaball, ConvKernel::Soft,    ConvKernel::Quartic};
  const ConvSkeleton skeletons[] = {ConvSkeleton::Point, ConvSkeleton::Segment, ConvSkeleton::Arc,
                                    ConvSkeleton::Triangle, ConvSkeleton::Plane};
  std::vector<LibraryFunction> fns;
  for (ConvKernel k : kernels)
    for (ConvSkeleton s : skeletons) {
      // The integral of 1/r or 1/r^2 over a plane diverges (the paper's note under eq. 3).
      if (s == ConvSkeleton::Plane && (k == ConvKernel::Inverse || k == ConvKernel::InverseSquare)) continue;
      std::string name = std::string("frConv") + convKernelName(k) + convSkeletonName(s);
      const char* sig = s == ConvSkeleton::Point || s == ConvSkeleton::Triangle ? "AAAS"
                        : s == ConvSkeleton::Arc                                 ? "AAAAAAAS"
                                                                                 : "AAAAS";
      std::string summary = std::string("sum of h(S_i r) over ") + convSkeletonName(s) + "s - T, h(q) = " +
                            kernelFormula(k);
      fns.push_back({name, sig, summary, [k, s, name](std::vector<Arg>& a) { return lowerConv(k, s, name, a); }});
    }
  return registerAll(std::move(fns));
}

const bool registered = registerFamily();

}  // namespace
}  // namespace frep::lang
