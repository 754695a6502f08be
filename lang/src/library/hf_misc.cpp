// The rest of HyperFun's hf* library: Gardner noise, a truncated-Fourier sawtooth, the Bezier
// volume, and the hfA_* attribute functions (colour only: accepted, no effect on geometry).
#include <string>

#include "library/hf_util.h"

namespace frep::lang::hf {
namespace {

// Gardner's sum-of-sines noise in absolute coordinates:
//   S_x = amp sin(f x) + (amp/1.17) sin(f x / 1.35 + phase sin(f z)), S_y and S_z cyclically
//   (S_y uses sin(f x), S_z uses sin(f y)); the result is S_x S_y S_z.
Expr noiseG(std::vector<Arg>& a) {
  const char* fn = "hfNoiseG";
  auto& x = arrayAtLeast(fn, a, 0, 3, "x");
  Expr amp = scalarArg(fn, a, 1), freq = scalarArg(fn, a, 2), phase = scalarArg(fn, a, 3);
  Expr s[3], out = 1.0;
  for (int i = 0; i < 3; ++i) s[i] = sin(freq * x[i]);
  for (int i = 0; i < 3; ++i) {
    const Expr& prev = s[(i + 2) % 3];
    out = out * (amp * s[i] + (amp / 1.17) * sin(freq * x[i] / 1.35 + phase * prev));
  }
  return out;
}

// (2 / (a pi)) (0.5 - sum_{k=1}^{n-1} sin(2 pi k f t) / k); 0 when n <= 1. n is a constant.
Expr sawtooth(std::vector<Arg>& a) {
  const char* fn = "hfSawtooth";
  Expr t = scalarArg(fn, a, 0);
  double n = constArg(fn, a, 1, "the number of terms n");
  Expr amp = scalarArg(fn, a, 2), f = scalarArg(fn, a, 3);
  if (n > 100000) throw LibraryError(std::string(fn) + ": n must be at most 100000", 1);
  if (n <= 1) return 0.0;
  Expr sum = 0.0;
  for (int k = 1; k < n; ++k) sum = sum + sin(2.0 * kPi * k * f * t) / static_cast<double>(k);
  return 2.0 / (amp * kPi) * (0.5 - sum);
}

double binomial(int n, int k) {
  double c = 1.0;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return c;
}

// Bernstein polynomials B(i, deg, u) for i = 0..deg.
std::vector<Expr> bernstein(int deg, const Expr& u) {
  std::vector<Expr> out;
  for (int i = 0; i <= deg; ++i)
    out.push_back(binomial(deg, i) * Expr::powi(u, i) * Expr::powi(1.0 - u, deg - i));
  return out;
}

// Trivariate Bezier function with l x m x n scalar control values, bbox =
// (xmin, ymin, zmin, xmax, ymax, zmax), intersected (a = 0) with the box. As in hfp, the second
// index j pairs with the z parameter and the third index k with the y parameter.
Expr bezierVolume(std::vector<Arg>& a) {
  const char* fn = "hfBezierVolume";
  auto& x = arrayAtLeast(fn, a, 0, 3, "x");
  int l = static_cast<int>(constArg(fn, a, 1, "l")), m = static_cast<int>(constArg(fn, a, 2, "m")),
      n = static_cast<int>(constArg(fn, a, 3, "n"));
  if (l < 1 || m < 1 || n < 1 || l > 64 || m > 64 || n > 64)
    throw LibraryError(std::string(fn) + ": l, m, n must be between 1 and 64", 1);
  auto& box = arrayExactly(fn, a, 4, 6, " (xmin, ymin, zmin, xmax, ymax, zmax)");
  auto& w = arrayExactly(fn, a, 5, static_cast<size_t>(l) * m * n, " (l*m*n control values)");
  Expr u[3], slab[3];
  for (int i = 0; i < 3; ++i) {
    u[i] = (x[i] - box[i]) / (box[i + 3] - box[i]);
    slab[i] = (box[i + 3] - x[i]) * (x[i] - box[i]);
  }
  auto bu = bernstein(l - 1, u[0]), bz = bernstein(m - 1, u[2]), by = bernstein(n - 1, u[1]);
  Expr sum = 0.0;
  for (int i = 0; i < l; ++i)
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < n; ++k) sum = sum + bu[i] * bz[j] * by[k] * w[(i * m + j) * n + k];
  return rInter0(rInter0(rInter0(slab[0], slab[1]), slab[2]), sum);
}

Expr attribute(std::vector<Arg>&) { return 1.0; }

std::vector<LibraryFunction> all() {
  std::vector<LibraryFunction> fns = {
      {"hfNoiseG", "ASSS", "Gardner sum-of-sines noise S_x S_y S_z", noiseG},
      {"hfSawtooth", "SSSS", "(2/(a pi)) (0.5 - sum_{k<n} sin(2 pi k f t)/k)", sawtooth},
      {"hfBezierVolume", "ASSSAA", "Bezier volume function & the bounding box", bezierVolume},
  };
  // Attribute functions fill HyperFun's s[] attribute array (colour). The lowering compiles them
  // itself (lang/src/lowering/attributes.cpp); the entries make their names known (checks, help).
  // Signature "*": any number of arguments of either kind.
  for (const char* name :
       {"hfA_SetColor", "hfA_Wave", "hfA_CheckerBoard", "hfA_Union", "hfA_Crackles", "hfA_Circles",
        "hfA_NoiseG", "hfA_NoiseP", "hfA_Turbulence", "hfA_SetAttributes", "hfA_Lerp", "hfA_Cerp",
        "hfA_Clamp", "hfA_Floor", "hfA_Pulse", "hfA_LookUpTable", "hfA_SmoothLookUpTable",
        "hfA_Step", "hfA_SmoothStep", "hfA_Modulo", "hfA_Spline", "hfA_RGBToHSV",
        "hfA_HSVToRGB"})
    fns.push_back({name, "*", "attribute function: writes s[] (s[1..3] = colour), see docs/language.md",
                   attribute});
  return fns;
}

const bool registered = registerAll(all());

}  // namespace
}  // namespace frep::lang::hf
