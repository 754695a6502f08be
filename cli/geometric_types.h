// Geometric types of coordinates for models of more than three dimensions (Pasko-Survey,
// "geometric types"): in -x, besides X, Y, Z and constants, a coordinate may be
//   T  time: a sequence of frames (numbered pictures) over --t-range,
//   V  a column and W a row of a "geometric spreadsheet": a grid of small pictures, one per
//      value pair over --v-range and --w-range,
//   C  colour: the union of the sections at --c-levels values over --c-range, each point
//      coloured by the spectral colour of the section it belongs to,
//   G  group: the union of the sections at the listed --g-values, drawn in one picture.
// The typed coordinates become constants, one mapping per frame, cell and section.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace frep::cli {

struct GeometricRequest {
  int tFrames = 0;               // frames over the T coordinate (or x[4] without -x)
  std::string tRange = "0,1";
  std::string vRange = "0,1", wRange = "0,1";
  int vCells = 4, wCells = 4;     // columns and rows of the grid
  std::string cRange = "0,1";
  int cLevels = 8;                // sections of a C coordinate
  std::string gValues;            // sections of a G coordinate: v1,v2,...
};

struct GeometricTypes {
  enum Type { T, V, W, C, G, kTypes };
  std::vector<std::string> items;          // the -x items, typed ones as given
  std::array<int, kTypes> coordinate{-1, -1, -1, -1, -1};  // 0-based model coordinate of each type
  std::vector<double> t, v, w, sections;   // values: frames, columns, rows, sections (C or G)
  bool colourSections = false;             // C: sections coloured along the spectrum

  bool has(Type type) const { return coordinate[type] >= 0; }
  int sectionCoordinate() const { return has(C) ? coordinate[C] : coordinate[G]; }
  // The -x text with T, V, W and the section coordinate set to the given values (a type that
  // is absent ignores its value); "" when there was no -x.
  std::string mapping(double t, double v, double w, double section) const;
};

// Parses the geometric types of `mapping` (-x) against `request`. `defaultT`: without -x, a
// requested T sweep runs over x[4] (X,Y,Z,T). Throws CliError(kExitBadArgs) naming the option:
// a type used twice, C with G, ranges that are not first,last, counts out of 1..kMaxValues, a
// T/V/W/C/G option without its coordinate in -x.
constexpr int kMaxValues = 10000;
GeometricTypes parseGeometricTypes(const std::string& mapping, const GeometricRequest& request, bool defaultT);

// The frame's file name: NAME.png -> NAME_0007.png (single pictures keep the name).
std::string framePath(const std::string& out, int frame, int frames);

// Spectral colour of s in [0, 1]: red (0) through yellow, green, cyan, blue to violet (1).
std::array<double, 3> spectralColour(double s);

}  // namespace frep::cli
