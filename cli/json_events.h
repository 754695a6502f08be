// --json: machine-readable events on stdout, one JSON object a line (docs/cli.md): the phases
// of a command, its errors and its end. The farm adds "listening" and "progress" events.
#pragma once

#include <string>

namespace frep::cli {

void enableJsonEvents();  // main, when the verb's --json is given
bool jsonEventsEnabled();

// {"event":"phase","phase":NAME}: "compute" (the farm job), "simplify" (mesh), "write".
void jsonPhase(const std::string& name);
// {"event":"error","exit_code":CODE,"message":TEXT}: just before frep exits with CODE.
void jsonError(int exitCode, const std::string& message);
// {"event":"done","output":OUT[,"report":OUT.report.json]}
void jsonDone(const std::string& output, bool withReport);

}  // namespace frep::cli
