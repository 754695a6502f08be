// A slice of f as a picture: inside (f > 0) on a warm ramp, outside (f < 0) on a cool ramp,
// darker with |f|, and the zero contour in black -- the style of Choporov-Hybrid's figures.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frep/io/png_writer.h"

namespace frep::io {

// |f| that maps to the darkest colour: the 95th percentile of the given magnitudes, so a few
// huge values (f grows like |x|^k far away) do not wash the picture out. 1 if all are zero.
double robustScale(std::vector<double> magnitudes);

// Colour at t in [0, 1] (0: at the surface, pale; 1: deep, dark) on the inside or outside ramp.
std::array<uint8_t, 3> rampColour(bool inside, double t);

// values: width * height samples, row-major from the top row. NaN samples are grey. A pixel is
// on the contour (black) where f == 0, or where a 4-neighbour has the other sign and this pixel
// has the smaller |f| of the two (so the line is one pixel wide and hugs the true zero).
RgbImage renderHeatmap(const std::vector<double>& values, int width, int height);

// Inside (f >= 0) white, outside black, NaN grey: the picture of the solid alone (frep slice
// --mask), for which pixels in tiles whose sign an interval decided need no evaluation.
RgbImage renderMask(const std::vector<double>& values, int width, int height);

}  // namespace frep::io
