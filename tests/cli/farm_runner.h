// Helpers for the farm's end-to-end tests (frep sample and frep mesh on the farm): a frep run
// in the background, journal records, numbers in the report JSON.
#pragma once

#include <signal.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "frep_runner.h"

namespace frep_cli_test {

// A block with a spherical bite: faces, edges, corners and a curved pocket in most bricks.
inline const char* kPartModel =
    "-- a block with a spherical bite\n"
    "my_model(x[3], a[1]) {\n"
    "  array c[3], v[3];\n"
    "  c = [0.3, 0.2, 0.4];\n"
    "  v = [-0.7, -0.6, -0.5];\n"
    "  b = hfBlock(x, v, 1.4, 1.2, 1.0);\n"
    "  ball = hfSphere(x, c, 0.45);\n"
    "  my_model = b \\ ball;\n"
    "}\n";

class FarmTest : public FrepTest {
 protected:
  // Starts frep in the background; returns its pid.
  pid_t start(const std::string& args, const std::string& env = "") const {
    std::string cmd = "cd '" + dir_ + "' && " + env + " exec '" FREP_BINARY "' " + args + " >" + path(".bg.out") +
                      " 2>" + path(".bg.err");
    pid_t pid = fork();
    if (pid == 0) {
      execl("/bin/sh", "sh", "-c", cmd.c_str(), (char*)nullptr);
      _exit(127);
    }
    return pid;
  }
  static int waitFor(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  // Number of bricks recorded in a journal (12-byte header, records of 20 bytes + payload).
  size_t journalRecords(const std::string& name) const {
    std::string j = readText(path(name));
    size_t pos = 12, n = 0;
    while (pos + 20 <= j.size()) {
      uint64_t size;
      std::memcpy(&size, j.data() + pos + 12, 8);
      if (pos + 20 + size > j.size()) break;
      pos += 20 + size;
      ++n;
    }
    return n;
  }
  static long jsonNumber(const std::string& json, const std::string& key) {
    size_t at = json.find("\"" + key + "\"");
    if (at == std::string::npos) return -1;
    return std::strtol(json.c_str() + json.find(':', at) + 1, nullptr, 10);
  }
};

}  // namespace frep_cli_test
