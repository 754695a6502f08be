#include "frep/io/heatmap.h"

#include <algorithm>
#include <cmath>

namespace frep::io {
namespace {

using Rgb = std::array<double, 3>;

// Three stops per ramp: pale near the surface, saturated in the middle, dark deep inside/outside.
const Rgb kWarm[3] = {{255, 236, 170}, {240, 120, 30}, {140, 10, 10}};
const Rgb kCool[3] = {{205, 235, 255}, {60, 140, 220}, {15, 30, 120}};

Rgb lerp(const Rgb& a, const Rgb& b, double t) {
  return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
}

}  // namespace

double robustScale(std::vector<double> magnitudes) {
  if (magnitudes.empty()) return 1.0;
  size_t k = static_cast<size_t>(0.95 * double(magnitudes.size() - 1));
  std::nth_element(magnitudes.begin(), magnitudes.begin() + long(k), magnitudes.end());
  double s = magnitudes[k];
  return s > 0.0 ? s : 1.0;
}

std::array<uint8_t, 3> rampColour(bool inside, double t) {
  const Rgb* ramp = inside ? kWarm : kCool;
  t = std::clamp(t, 0.0, 1.0);
  Rgb c = t < 0.5 ? lerp(ramp[0], ramp[1], t * 2.0) : lerp(ramp[1], ramp[2], t * 2.0 - 1.0);
  return {uint8_t(std::lround(c[0])), uint8_t(std::lround(c[1])), uint8_t(std::lround(c[2]))};
}

RgbImage renderHeatmap(const std::vector<double>& values, int width, int height) {
  std::vector<double> inside, outside;
  for (double v : values) {
    if (v > 0.0) inside.push_back(v);
    else if (v < 0.0) outside.push_back(-v);
  }
  const double scaleIn = robustScale(std::move(inside)), scaleOut = robustScale(std::move(outside));

  RgbImage image(width, height);
  auto at = [&](int c, int r) { return values[size_t(r) * size_t(width) + size_t(c)]; };
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      double v = at(c, r);
      uint8_t* p = image.pixel(c, r);
      if (std::isnan(v)) { p[0] = p[1] = p[2] = 128; continue; }
      auto colour = rampColour(v >= 0.0, v >= 0.0 ? v / scaleIn : -v / scaleOut);
      std::copy(colour.begin(), colour.end(), p);
    }

  auto blacken = [&](int c, int r) { uint8_t* p = image.pixel(c, r); p[0] = p[1] = p[2] = 0; };
  // Contour: each sign change between right/down neighbours marks the pixel nearer to zero.
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      double v = at(c, r);
      if (v == 0.0) { blacken(c, r); continue; }
      const int nbr[2][2] = {{c + 1, r}, {c, r + 1}};
      for (const auto& n : nbr) {
        if (n[0] >= width || n[1] >= height) continue;
        double w = at(n[0], n[1]);
        if (std::isnan(v) || std::isnan(w) || (v > 0.0) == (w > 0.0) || w == 0.0) continue;
        if (std::abs(v) <= std::abs(w)) blacken(c, r);
        else blacken(n[0], n[1]);
      }
    }
  return image;
}

RgbImage renderMask(const std::vector<double>& values, int width, int height) {
  RgbImage img(width, height);
  for (size_t p = 0; p < values.size(); ++p) {
    const double v = values[p];
    const uint8_t g = std::isnan(v) ? 128 : v >= 0.0 ? 255 : 0;
    img.rgb[3 * p] = img.rgb[3 * p + 1] = img.rgb[3 * p + 2] = g;
  }
  return img;
}

}  // namespace frep::io
