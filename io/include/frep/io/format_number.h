// Shortest text that reads back as the same double: what reports, metadata and the frep
// command's parsers print and accept.
#pragma once

#include <string>

namespace frep::io {

std::string formatNumber(double v);

}  // namespace frep::io
