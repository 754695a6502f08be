// The fixture of the hardening tests (hardening_test.cpp) and of the process fuzz loops
// (process_fuzz/): frep run as a process in a scratch directory, with a shell prefix.
#pragma once

#include <string>

#include "frep_runner.h"

namespace frep_cli_test {

class Hardening : public FrepTest {
 protected:
  // As run(), with `prefix` run by bash first (ulimit, trap) and frep exec'd in its place.
  RunResult runWith(const std::string& prefix, const std::string& args) const {
    return capture("bash -c \"" + prefix + "; exec '" FREP_BINARY "' " + args + "\"");
  }
  bool noTemporaries() const { return listing().find(".tmp") == std::string::npos; }
  std::string sampleArgs(const std::string& out) const {
    return "sample sphere.hf -b 1.5 --res 16 --workers 0 --no-progress -O " + out;
  }
};

}  // namespace frep_cli_test
