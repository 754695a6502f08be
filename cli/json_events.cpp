#include "json_events.h"

#include <cstdio>

#include <nlohmann/json.hpp>

namespace frep::cli {
namespace {

bool enabled = false;

void emit(const nlohmann::json& event) {
  // One line each, flushed: a batch system reads them as they come. dump() escapes the text
  // (paths, messages); invalid UTF-8 in them is replaced rather than thrown.
  std::printf("%s\n", event.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  std::fflush(stdout);
}

}  // namespace

void enableJsonEvents() { enabled = true; }
bool jsonEventsEnabled() { return enabled; }

void jsonPhase(const std::string& name) {
  if (enabled) emit({{"event", "phase"}, {"phase", name}});
}

void jsonError(int exitCode, const std::string& message) {
  if (enabled) emit({{"event", "error"}, {"exit_code", exitCode}, {"message", message}});
}

void jsonDone(const std::string& output, bool withReport) {
  if (!enabled) return;
  nlohmann::json e = {{"event", "done"}, {"output", output}};
  if (withReport) e["report"] = output + ".report.json";
  emit(e);
}

}  // namespace frep::cli
