#include "arg_parse.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "exit_codes.h"

namespace frep::cli {
namespace {

std::vector<std::string> splitCommas(const std::string& text) {
  std::vector<std::string> items;
  size_t start = 0;
  while (true) {
    size_t comma = text.find(',', start);
    items.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return items;
    start = comma + 1;
  }
}

bool toDouble(const std::string& s, double& out) {
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return false;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(out);
}

std::string expectedMessage(const std::string& field, const std::string& text, const std::string& expected,
                            const std::string& what) {
  return field + ": expected " + expected + " comma-separated " + what + ", got '" + text + "'";
}

}  // namespace

std::vector<double> parseNumbers(const std::string& field, const std::string& text, const std::string& expected) {
  std::vector<double> values;
  for (const std::string& item : splitCommas(text)) {
    double v;
    if (!toDouble(item, v))
      throw badArgs(expectedMessage(field, text, expected, "numbers") + " ('" + item + "' is not a number)");
    values.push_back(v);
  }
  return values;
}

Box parseBounds(const std::string& field, const std::string& text) {
  const std::string expected = "1, 2, 3 or 6";
  std::vector<double> v = parseNumbers(field, text, expected);
  Box box;
  switch (v.size()) {
    case 1: for (int a = 0; a < 3; ++a) box.lo[a] = -std::abs(v[0]), box.hi[a] = std::abs(v[0]); break;
    case 2: for (int a = 0; a < 3; ++a) box.lo[a] = v[0], box.hi[a] = v[1]; break;
    case 3: for (int a = 0; a < 3; ++a) box.lo[a] = -std::abs(v[a]), box.hi[a] = std::abs(v[a]); break;
    case 6: for (int a = 0; a < 3; ++a) box.lo[a] = v[a], box.hi[a] = v[a + 3]; break;
    default: throw badArgs(expectedMessage(field, text, expected, "numbers"));
  }
  static const char* names = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (!(box.hi[a] > box.lo[a]))
      throw badArgs(field + ": the " + names[a] + " range is empty (max must exceed min), got '" + text + "'");
    // Every size derived from the box (its width, the voxel) must be a finite number: a width of
    // 2e308 is inf, and `-b 1e308` wrote a grid of one voxel of size inf.
    if (!std::isfinite(box.hi[a] - box.lo[a]))
      throw badArgs(field + ": the " + names[a] + " range is wider than the largest finite number (its width " +
                    "overflows to inf), got '" + text + "'");
  }
  return box;
}

std::array<int, 3> parseCells(const std::string& field, const std::string& text) {
  const std::string expected = "1 or 3";
  std::vector<std::string> items = splitCommas(text);
  if (items.size() != 1 && items.size() != 3)
    throw badArgs(expectedMessage(field, text, expected, "integers"));
  std::array<int, 3> cells{};
  for (size_t i = 0; i < items.size(); ++i) {
    const std::string& s = items[i];
    char* end = nullptr;
    long n = s.empty() ? 0 : std::strtol(s.c_str(), &end, 10);
    if (s.empty() || end != s.c_str() + s.size() || n < 1 || n > kMaxCells)
      throw badArgs(expectedMessage(field, text, expected, "integers") + " ('" + s +
                    "' is not an integer from 1 to " + std::to_string(kMaxCells) + ")");
    cells[i] = static_cast<int>(n);
  }
  if (items.size() == 1) cells[1] = cells[2] = cells[0];
  return cells;
}

int parseAxis(const std::string& field, const std::string& text) {
  if (text.size() == 1) {
    char c = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
    if (c >= 'x' && c <= 'z') return c - 'x';
  }
  throw badArgs(field + ": expected x, y or z, got '" + text + "'");
}

AxisMapping parseMapping(const std::string& field, const std::string& text) {
  AxisMapping m;
  bool used[3] = {false, false, false};
  for (const std::string& item : splitCommas(text)) {
    int axis = -1;
    double value = 0.0;
    if (item.size() == 1 && std::isalpha(static_cast<unsigned char>(item[0]))) {
      axis = parseAxis(field, item);
      if (used[axis])
        throw badArgs(field + ": axis " + item + " is mapped twice in '" + text + "'");
      used[axis] = true;
      m.viewDims = std::max(m.viewDims, axis + 1);
    } else if (!toDouble(item, value)) {
      throw badArgs(field + ": expected comma-separated X, Y, Z or numbers, got '" + text + "' ('" + item +
                    "' is neither)");
    }
    m.axis.push_back(axis);
    m.constant.push_back(value);
  }
  return m;
}


}  // namespace frep::cli
