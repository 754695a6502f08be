// frep view runs its work as child processes of the same binary (`frep mesh`, `frep slice`), so
// the page shows exactly what the command line computes and prints, and a new save stops the
// work in progress by frep's own interrupt contract: SIGTERM, which a farm job answers by
// stopping its local workers and exiting 6 (docs/farm.md).
#pragma once

#include <atomic>
#include <string>
#include <vector>

namespace frep::cli {

struct ChildResult {
  int exitCode = -1;       // the child's exit status; 128 + N when killed by signal N
  bool cancelled = false;  // `cancel` was set: the child was sent SIGTERM (SIGKILL after 2 s)
  double stopSeconds = 0;  // cancelled: from SIGTERM to the child's end
  std::string out, err;    // everything it wrote to stdout and stderr
};

// Runs argv[0] with arguments argv[1..] (no shell) in a process group of its own, signals
// unblocked and stdin closed, and waits for it, polling `cancel` (may be null) every 50 ms.
// Throws std::runtime_error when it cannot be started. frep mesh stops within about 0.1 s of
// SIGTERM; one that does not gets SIGKILL (to its whole group) 2 s later, which is safe since
// its output is a private temporary file that is thrown away.
ChildResult runChild(const std::vector<std::string>& argv, const std::atomic<bool>* cancel);

// The path of the running executable (/proc/self/exe), for running frep's own verbs.
std::string selfExecutable();

}  // namespace frep::cli
