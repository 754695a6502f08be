#include "frep/io/input_file.h"

#include <stdexcept>

#include "frep/io/error.h"
#include "frep/lang/hyperfun.h"

namespace frep::io {

std::string readInputFile(const std::string& path, uint64_t maxBytes) {
  try {
    return lang::readRegularFile(path, maxBytes);
  } catch (const std::runtime_error& e) {
    throw ioError(e.what());
  }
}

}  // namespace frep::io
