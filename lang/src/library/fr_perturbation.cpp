// Freeforms by analytical perturbation functions (Vyatkin-Perturbation eq. 10): a base field F
// plus perturbations R_i = Q_i^3 where the perturbing quadric Q_i >= 0, else 0. The cube makes
// each R_i C^2 across the quadric's zero set, so the freeform stays smooth. Written as
// max(Q, 0)^3: the interval bound is the cube of a non-negative interval (sound and tight).
#include <string>

#include "library/hf_util.h"

namespace frep::lang {
namespace {

using hf::arrayAtLeast;
using hf::arrayArg;
using hf::arrayExactly;
using hf::argName;
using hf::scalarArg;

Expr cubedPart(const Expr& q) {
  Expr m = max(q, 0.0);
  return m * m * m;
}

// frPerturb(F, Q): F + R(Q), one term of eq. 10 for any quadric (or other) expression Q.
Expr frPerturb(std::vector<Arg>& a) {
  const char* fn = "frPerturb";
  return scalarArg(fn, a, 0) + cubedPart(scalarArg(fn, a, 1));
}

// frPerturbQuadric(x, F, c, r, A): F + sum_i A_i Q_i^3 over Q_i >= 0, with the ellipsoidal
// quadric Q_i = 1 - sum_k ((x_k - c_ik) / r_ik)^2 centred at c_i[3] with semi-axes r_i[3]: the
// bump's support is the ellipsoid, A_i its height at the centre (negative: a dent).
Expr frPerturbQuadric(std::vector<Arg>& a) {
  const char* fn = "frPerturbQuadric";
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  Expr F = scalarArg(fn, a, 1);
  std::vector<Expr>& A = arrayArg(fn, a, 4);
  std::string per3 = " (3 per element of " + argName(a, 4, "A") + ")";
  std::vector<Expr>& c = arrayExactly(fn, a, 2, 3 * A.size(), per3);
  std::vector<Expr>& r = arrayExactly(fn, a, 3, 3 * A.size(), per3);
  Expr sum = F;
  for (size_t i = 0; i < A.size(); ++i) {
    Expr q = 1.0;
    for (size_t k = 0; k < 3; ++k) {
      const Expr& rk = r[3 * i + k];
      if (rk.isConst() && rk.constValue() == 0.0)
        throw LibraryError(std::string(fn) + ": semi-axis " + std::to_string(3 * i + k + 1) + " of " +
                               argName(a, 3, "r") + " is zero",
                           3);
      Expr u = (x[k] - c[3 * i + k]) / rk;
      q = q - u * u;
    }
    sum = sum + A[i] * cubedPart(q);
  }
  return sum;
}

const bool registered = registerAll({
    {"frPerturb", "SS", "F + (Q >= 0 ? Q^3 : 0) (Vyatkin-Perturbation eq. 10)", frPerturb},
    {"frPerturbQuadric", "ASAAA",
     "F + sum A_i max(Q_i, 0)^3, Q_i = 1 - |(x - c_i) / r_i|^2 (eq. 10 with ellipsoidal quadrics)",
     frPerturbQuadric},
});

}  // namespace
}  // namespace frep::lang
