// The documented outcome codes of frepfarm (the frep command's exit codes, docs/cli.md) and the
// error the libraries throw to end with one of them.
#pragma once

#include <stdexcept>
#include <string>

namespace frep::io {

enum ExitCode : int {
  kExitOk = 0,
  kExitModelError = 1,  // the model has errors (diagnostics were printed)
  kExitBadArgs = 2,     // a command-line argument is missing or malformed
  kExitIoError = 3,     // a file could not be read or written
  kExitInternal = 4,    // a bug or an unexpected failure inside frep
  kExitPoisoned = 5,    // some bricks failed 3 times (named on stderr); no output, journal kept
  kExitInterrupted = 6, // SIGTERM/SIGINT: journal flushed, continue with --resume
  kExitFarmError = 7,   // the farm could not run (bind failed, no worker alive, CURVE keys, journal)
  kExitUncertified = 8, // --strict: some extremum searches did not certify their tolerance; no output
  kExitOpenMesh = 9,    // the merged mesh is not closed (a bug, named edge by edge); no output
};

// What a user reads after "frep --help".
inline const char* exitCodeHelp() {
  return "Exit codes: 0 ok, 1 model error (diagnostics printed), 2 bad arguments, "
         "3 I/O error, 4 internal error, 5 bricks poisoned (named), 6 interrupted (use --resume), "
         "7 farm error.";
}

// Thrown by the readers, writers and commands; frep prints what() and exits with code.
struct Error : std::runtime_error {
  int code;
  Error(int c, const std::string& message) : std::runtime_error(message), code(c) {}
};

inline Error badArgs(const std::string& message) { return {kExitBadArgs, message}; }
inline Error ioError(const std::string& message) { return {kExitIoError, message}; }

}  // namespace frep::io
