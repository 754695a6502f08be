// Fractal Perlin gradient noise with proved range and slope (solid_noise.h).
#include "frep/primitives/solid_noise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frep {
namespace {

// The twelve cube-edge directions and four of them again (a table of 16 indexed by 4 hash
// bits): every gradient has two components of +-1, which the range and slope bounds rely on.
constexpr double kGrad[16][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                 {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1},
                                 {1, 1, 0},  {-1, 1, 0},  {0, -1, 1}, {0, -1, -1}};

uint64_t splitmix(uint64_t& s) {
  uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
double fadeSlope(double t) { return 30 * t * t * (t * (t - 2) + 1); }

}  // namespace

std::shared_ptr<const SolidNoise> SolidNoise::make(double frequency, uint32_t seed, int octaves) {
  if (!(frequency > 0) || !std::isfinite(frequency))
    throw std::invalid_argument("the noise frequency must be a finite number > 0 (got " + std::to_string(frequency) +
                                ")");
  if (octaves < 1 || octaves > 16)
    throw std::invalid_argument("the number of octaves must be 1 to 16 (got " + std::to_string(octaves) + ")");
  std::shared_ptr<SolidNoise> n(new SolidNoise());
  n->frequency_ = frequency;
  n->seed_ = seed;
  n->octaves_ = octaves;
  uint64_t s = 0x5eedULL * (uint64_t(seed) + 1);
  std::array<uint8_t, 256> p;
  for (int i = 0; i < 256; ++i) p[size_t(i)] = uint8_t(i);
  for (int i = 255; i > 0; --i) std::swap(p[size_t(i)], p[size_t(splitmix(s) % uint64_t(i + 1))]);
  for (int i = 0; i < 512; ++i) n->perm_[size_t(i)] = p[size_t(i & 255)];
  for (auto& o : n->shift_)
    for (double& c : o) c = double(splitmix(s) >> 11) * 0x1p-53 * 256.0;
  // Octave k has weight 2^-k and frequency 2^k f: the slopes add up to octaves * f * 8.5.
  double weights = 0.0;
  for (int k = 0; k < octaves; ++k) weights += std::ldexp(1.0, -k);
  n->scale_ = 1.0 / (kPerlinBound * weights);
  n->lipschitz_ = n->scale_ * octaves * frequency * kPerlinSlope;
  n->hash_ = std::hash<double>()(frequency) * 1000003u ^ (uint64_t(seed) << 8) ^ uint64_t(octaves);
  return n;
}

std::string SolidNoise::describe() const {
  return "solid_noise(frequency " + std::to_string(frequency_) + ", seed " + std::to_string(seed_) + ", " +
         std::to_string(octaves_) + " octaves)";
}

bool SolidNoise::sameContent(const FieldFunction& other) const {
  const auto* o = dynamic_cast<const SolidNoise*>(&other);
  return o && o->frequency_ == frequency_ && o->seed_ == seed_ && o->octaves_ == octaves_;
}

// n(p) = sum over the cell's corners c of W_c(t) g_c . (t - c), t the position in the cell and
// W_c the product of the fades (s(t_i) towards corner 1, 1 - s(t_i) towards corner 0).
double SolidNoise::perlin(const double p[3], double* grad) const {
  int cell[3];
  double t[3], s[3], ds[3];
  for (int i = 0; i < 3; ++i) {
    const double fl = std::floor(p[i]);
    t[i] = p[i] - fl;
    cell[i] = int(int64_t(fl) & 255);
    s[i] = fade(t[i]);
    ds[i] = fadeSlope(t[i]);
  }
  double v = 0.0, g[3] = {0, 0, 0};
  for (int c = 0; c < 8; ++c) {
    const int b[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
    const int h = perm_[size_t(perm_[size_t(perm_[size_t(cell[0] + b[0])] + cell[1] + b[1])] + cell[2] + b[2])] & 15;
    double w[3], dw[3], d[3];
    for (int i = 0; i < 3; ++i) {
      w[i] = b[i] ? s[i] : 1 - s[i];
      dw[i] = b[i] ? ds[i] : -ds[i];
      d[i] = t[i] - b[i];
    }
    const double dot = kGrad[h][0] * d[0] + kGrad[h][1] * d[1] + kGrad[h][2] * d[2];
    const double W = w[0] * w[1] * w[2];
    v += W * dot;
    if (grad) {
      g[0] += dw[0] * w[1] * w[2] * dot + W * kGrad[h][0];
      g[1] += w[0] * dw[1] * w[2] * dot + W * kGrad[h][1];
      g[2] += w[0] * w[1] * dw[2] * dot + W * kGrad[h][2];
    }
  }
  if (grad)
    for (int i = 0; i < 3; ++i) grad[i] = g[i];
  return v;
}

double SolidNoise::eval(const double p[3], double* grad) const {
  double v = 0.0, g[3] = {0, 0, 0};
  double f = frequency_, w = 1.0;
  for (int k = 0; k < octaves_; ++k, f *= 2, w *= 0.5) {
    const double q[3] = {p[0] * f + shift_[size_t(k)][0], p[1] * f + shift_[size_t(k)][1],
                         p[2] * f + shift_[size_t(k)][2]};
    double gk[3];
    v += w * perlin(q, grad ? gk : nullptr);
    if (grad)
      for (int i = 0; i < 3; ++i) g[i] += w * f * gk[i];
  }
  if (grad)
    for (int i = 0; i < 3; ++i) grad[i] = g[i] * scale_;
  return v * scale_;
}

double SolidNoise::value(const double p[3]) const { return eval(p, nullptr); }

double SolidNoise::gradient(const double p[3], double g[3]) const { return eval(p, g); }

Interval SolidNoise::bound(const Interval box[3]) const {
  double c[3], reach = 1e-12;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(box[i].lo) || !std::isfinite(box[i].hi)) return Interval(-1.0, 1.0);
    c[i] = box[i].mid();
    // The rounded centre is within 2 ulps of the true one: reach it from the box's far side.
    reach += lipschitz_ * (std::max(c[i] - box[i].lo, box[i].hi - c[i]) * (1 + 1e-12) + 4e-16 * std::fabs(c[i]));
  }
  // 1e-12 covers the rounding of the centre value (|value| <= 1, a few dozen operations).
  const double v = value(c);
  return Interval(std::max(-1.0, v - reach - 1e-12), std::min(1.0, v + reach + 1e-12));
}

}  // namespace frep
