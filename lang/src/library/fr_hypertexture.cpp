// Hypertexture over a solid's boundary layer (Pasko-Survey, 3D texture by solid noise; the
// layer is Perlin and Hoffert's soft region): frHypertexture(x, F, A, freq, T, seed [, octaves])
// is F + A w(F / T) N(x), N the solid noise of frep/primitives/solid_noise.h (|N| <= 1) and
// w(s) = max(1 - s^2, 0)^2. So F is unchanged, bit for bit, where |F| >= T; the change is at
// most |A| anywhere; and the new surface lies where |F| < min(T, |A|). The bound of the sum
// is interval arithmetic over F's bound, w's and N's (N's from its range and slope).
#include <cmath>
#include <string>

#include "frep/primitives/solid_noise.h"
#include "library/hf_util.h"

namespace frep::lang {
namespace {

using hf::arrayAtLeast;
using hf::constArg;
using hf::scalarArg;

uint32_t seedArg(const char* fn, std::vector<Arg>& a, int i) {
  const double seed = constArg(fn, a, i, "the seed");
  if (!(seed >= 0 && seed < 4294967296.0) || seed != std::floor(seed))
    throw LibraryError(
        std::string(fn) + ": the seed must be an integer 0 to 2^32 - 1 (got " + std::to_string(seed) + ")", i);
  return uint32_t(seed);
}

int octavesArg(const char* fn, std::vector<Arg>& a, int i) {
  const double oct = constArg(fn, a, i, "the number of octaves");
  if (oct != std::floor(oct) || oct < 1 || oct > 16)
    throw LibraryError(
        std::string(fn) + ": the number of octaves must be an integer 1 to 16 (got " + std::to_string(oct) + ")", i);
  return int(oct);
}

std::shared_ptr<const SolidNoise> makeNoise(const char* fn, double freq, uint32_t seed, int oct, int freqArg) {
  try {
    return SolidNoise::make(freq, seed, oct);
  } catch (const std::invalid_argument& e) {
    throw LibraryError(std::string(fn) + ": " + e.what(), freqArg);
  }
}

Expr frHypertexture(std::vector<Arg>& a) {
  const char* fn = "frHypertexture";
  if (a.size() != 6 && a.size() != 7)
    throw LibraryError(std::string(fn) + " takes (x, F, amplitude, frequency, thickness, seed [, octaves]) (got " +
                       std::to_string(a.size()) + " arguments)");
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  const Expr& F = scalarArg(fn, a, 1);
  const Expr& A = scalarArg(fn, a, 2);
  const double freq = constArg(fn, a, 3, "the frequency");
  const double T = constArg(fn, a, 4, "the layer thickness");
  const uint32_t seed = seedArg(fn, a, 5);
  const int oct = a.size() == 7 ? octavesArg(fn, a, 6) : 4;
  if (!(T > 0) || !std::isfinite(T))
    throw LibraryError(
        std::string(fn) + ": the layer thickness must be a finite number > 0 (got " + std::to_string(T) + ")", 4);
  std::shared_ptr<const SolidNoise> noise = makeNoise(fn, freq, seed, oct, 3);
  const Expr s = F * (1.0 / T);
  const Expr u = max(1.0 - s * s, 0.0);
  return F + A * (u * u) * fieldCall(noise, x[0], x[1], x[2]);
}

// frNoise(x, freq, seed [, octaves]): the solid noise itself, a primitive with values in [-1, 1].
Expr frNoise(std::vector<Arg>& a) {
  const char* fn = "frNoise";
  if (a.size() != 3 && a.size() != 4)
    throw LibraryError(std::string(fn) + " takes (x, frequency, seed [, octaves]) (got " + std::to_string(a.size()) +
                       " arguments)");
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  const double freq = constArg(fn, a, 1, "the frequency");
  const uint32_t seed = seedArg(fn, a, 2);
  const int oct = a.size() == 4 ? octavesArg(fn, a, 3) : 4;
  return fieldCall(makeNoise(fn, freq, seed, oct, 1), x[0], x[1], x[2]);
}

const bool registered = registerAll({
    {"frNoise", "*", "solid noise in [-1, 1]: fractal Perlin gradient noise (Pasko-Survey, solid noise)", frNoise},
    {"frHypertexture", "*",
     "F + A w(F/T) noise(x): solid noise in the layer |F| < T only, change at most |A| (Pasko-Survey, 3D texture)",
     frHypertexture},
});

}  // namespace
}  // namespace frep::lang
