// Spawns and reaps local frep-worker processes for the embedded default (no --listen).
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace frep::farm {

class LocalWorkers {
 public:
  // executable "" means frep-worker next to the running program (or $FREP_WORKER).
  LocalWorkers(std::string executable, std::vector<std::string> args);
  ~LocalWorkers();  // terminates what still runs
  void spawn(int count);
  // Reaps exited workers; returns how many exited since the last call. A worker killed by a
  // signal is a warning, except by the SIGTERM terminateAll sent (e.g. one still starting when
  // a small job ended: it has nothing to hand back).
  int reap();
  int running() const { return int(pids_.size()); }
  // How the last reaped worker ended ("killed by signal 6", "exited with 2"), for messages.
  const std::string& lastExit() const { return lastExit_; }
  void terminateAll();
  const std::string& executable() const { return exe_; }

 private:
  std::string exe_;
  std::vector<std::string> args_;
  std::vector<pid_t> pids_;
  std::string lastExit_ = "still running";
  bool terminating_ = false;  // terminateAll sent SIGTERM
};

// Path of a program installed next to the running one (build/bin/frep -> build/bin/NAME).
std::string siblingExecutable(const std::string& name);

}  // namespace frep::farm
