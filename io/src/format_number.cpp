#include "frep/io/format_number.h"

#include <charconv>
#include <cmath>

namespace frep::io {

std::string formatNumber(double v) {
  if (v == 0.0) return "0";  // no "-0" in reports
  if (std::isnan(v)) return "nan";  // one spelling, whatever the sign bit
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

}  // namespace frep::io
