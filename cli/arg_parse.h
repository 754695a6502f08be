// Parsing of the frep command's list-valued arguments (hfp's forms), with messages that name the
// offending option and quote what the user typed. Everything throws CliError(kExitBadArgs).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "frep/io/format_number.h"

namespace frep::cli {

struct Box {
  std::array<double, 3> lo{-10, -10, -10}, hi{10, 10, 10};  // hfp's default: ±10
};

// "1,2.5,-3" -> {1, 2.5, -3}; every item must be a finite number. `expected` describes the
// accepted counts for the message, e.g. "1, 2, 3 or 6".
std::vector<double> parseNumbers(const std::string& field, const std::string& text,
                                 const std::string& expected);

// hfp's -b: B -> [-|B|,|B|]^3; min,max on every axis; bx,by,bz -> ±each;
// xmin,ymin,zmin,xmax,ymax,zmax. Every max must exceed its min.
Box parseBounds(const std::string& field, const std::string& text);

// hfp's -g: N or Nx,Ny,Nz grid cells per axis, each in [1, kMaxCells].
constexpr int kMaxCells = 65535;
std::array<int, 3> parseCells(const std::string& field, const std::string& text);

// x, y or z (either case) -> 0, 1, 2.
int parseAxis(const std::string& field, const std::string& text);

// hfp's -x: one entry per model coordinate x[1..n]; X, Y or Z maps it to that axis (each
// letter at most once), a number holds it constant. Example: "X,Y,Z,0.5".
struct AxisMapping {
  std::vector<int> axis;         // per model coordinate: 0..2, or -1 for a constant
  std::vector<double> constant;  // its value when axis == -1
  int viewDims = 0;              // 1 + the highest axis used (0 if none)
};
AxisMapping parseMapping(const std::string& field, const std::string& text);

using io::formatNumber;  // shortest text that reads back as the same double

}  // namespace frep::cli
