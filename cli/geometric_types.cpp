#include "geometric_types.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "arg_parse.h"
#include "exit_codes.h"

namespace frep::cli {
namespace {

constexpr const char* kLetters = "TVWCG";
constexpr const char* kOption[] = {"--t-frames/--t-range", "--v-range/--v-cells", "--w-range/--w-cells",
                                   "--c-range/--c-levels", "--g-values"};

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> items;
  size_t start = 0;
  for (size_t comma; (comma = text.find(',', start)) != std::string::npos; start = comma + 1)
    items.push_back(text.substr(start, comma - start));
  items.push_back(text.substr(start));
  return items;
}

// n values from first to last (n == 1: first).
std::vector<double> sweep(const char* option, const std::string& range, int n) {
  if (n < 1 || n > kMaxValues)
    throw badArgs(std::string(option) + ": expected a count from 1 to " + std::to_string(kMaxValues) + ", got " +
                  std::to_string(n));
  const std::vector<double> r = parseNumbers(option, range, "2");
  if (r.size() != 2) throw badArgs(std::string(option) + ": expected first,last, got '" + range + "'");
  std::vector<double> values;
  for (int k = 0; k < n; ++k) values.push_back(n == 1 ? r[0] : r[0] + (r[1] - r[0]) * k / (n - 1));
  return values;
}

}  // namespace

GeometricTypes parseGeometricTypes(const std::string& mapping, const GeometricRequest& q, bool defaultT) {
  GeometricTypes g;
  if (!mapping.empty()) g.items = split(mapping);
  else if (defaultT && q.tFrames > 0) g.items = {"X", "Y", "Z", "T"};
  for (size_t i = 0; i < g.items.size(); ++i) {
    const std::string& item = g.items[i];
    if (item.size() != 1) continue;
    const char* p = std::strchr(kLetters, std::toupper(static_cast<unsigned char>(item[0])));
    if (!p || !*p) continue;
    const int type = int(p - kLetters);
    if (g.coordinate[size_t(type)] >= 0)
      throw badArgs("-x/--map: geometric type " + std::string(1, kLetters[type]) + " is given twice in '" + mapping + "'");
    g.coordinate[size_t(type)] = int(i);
  }
  if (g.has(GeometricTypes::C) && g.has(GeometricTypes::G))
    throw badArgs("-x/--map: C and G both make a union of sections; give one of them");
  if (g.has(GeometricTypes::T)) {
    if (q.tFrames < 1) throw badArgs("--t-frames: the T coordinate needs the number of frames (1 or more)");
    g.t = sweep("--t-frames/--t-range", q.tRange, q.tFrames);
  } else if (q.tFrames > 0) {
    throw badArgs("--t-frames: give T in -x for the swept coordinate (e.g. -x X,Y,Z,T)");
  }
  if (g.has(GeometricTypes::V)) g.v = sweep("--v-range/--v-cells", q.vRange, q.vCells);
  if (g.has(GeometricTypes::W)) g.w = sweep("--w-range/--w-cells", q.wRange, q.wCells);
  if (g.has(GeometricTypes::C)) {
    g.sections = sweep("--c-range/--c-levels", q.cRange, q.cLevels);
    g.colourSections = true;
  }
  if (g.has(GeometricTypes::G)) {
    if (q.gValues.empty()) throw badArgs("--g-values: the G coordinate needs its values, e.g. --g-values 0,0.5,1");
    g.sections = parseNumbers("--g-values", q.gValues, "1 or more");
    if (g.sections.size() > size_t(kMaxValues)) throw badArgs("--g-values: at most " + std::to_string(kMaxValues) + " values");
  } else if (!q.gValues.empty()) {
    throw badArgs("--g-values: give G in -x for the grouped coordinate");
  }
  return g;
}

std::string GeometricTypes::mapping(double tv, double vv, double wv, double section) const {
  std::string text;
  for (size_t i = 0; i < items.size(); ++i) {
    std::string item = items[i];
    const int c = int(i);
    if (c == coordinate[T]) item = formatNumber(tv);
    else if (c == coordinate[V]) item = formatNumber(vv);
    else if (c == coordinate[W]) item = formatNumber(wv);
    else if (c == coordinate[C] || c == coordinate[G]) item = formatNumber(section);
    text += (i ? "," : "") + item;
  }
  return text;
}

std::string framePath(const std::string& out, int frame, int frames) {
  if (frames <= 1) return out;
  const size_t dot = out.find_last_of('.'), slash = out.find_last_of('/');
  const bool hasExt = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  char num[16];
  std::snprintf(num, sizeof num, "_%04d", frame);
  return hasExt ? out.substr(0, dot) + num + out.substr(dot) : out + num;
}

std::array<double, 3> spectralColour(double s) {
  // Hue from 0 (red) to 270 degrees (violet), full saturation, value 0.9.
  const double h = std::clamp(s, 0.0, 1.0) * 270.0 / 60.0;
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  std::array<double, 3> rgb{};
  switch (std::min(int(h), 5)) {
    case 0: rgb = {1, x, 0}; break;
    case 1: rgb = {x, 1, 0}; break;
    case 2: rgb = {0, 1, x}; break;
    case 3: rgb = {0, x, 1}; break;
    default: rgb = {x, 0, 1}; break;
  }
  for (double& c : rgb) c *= 0.9;
  return rgb;
}

}  // namespace frep::cli
