#include "frep/master/local_workers.h"

#include <signal.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace frep::farm {

std::string siblingExecutable(const std::string& name) {
  std::error_code ec;
  auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return name;
  return (self.parent_path() / name).string();
}

LocalWorkers::LocalWorkers(std::string executable, std::vector<std::string> args) : args_(std::move(args)) {
  if (!executable.empty()) exe_ = executable;
  else if (const char* env = std::getenv("FREP_WORKER")) exe_ = env;
  else exe_ = siblingExecutable("frep-worker");
  if (::access(exe_.c_str(), X_OK) != 0)
    throw std::runtime_error("worker program not found or not executable: " + exe_ +
                             " (set FREP_WORKER or use --workers 0)");
}

LocalWorkers::~LocalWorkers() { terminateAll(); }

void LocalWorkers::spawn(int count) {
  for (int i = 0; i < count; ++i) {
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(exe_.c_str()));
    for (auto& a : args_) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = 0;
    int rc = posix_spawn(&pid, exe_.c_str(), nullptr, nullptr, argv.data(), environ);
    if (rc != 0) throw std::runtime_error("cannot start " + exe_ + ": " + std::strerror(rc));
    pids_.push_back(pid);
    spdlog::debug("started local worker pid {}", pid);
  }
}

int LocalWorkers::reap() {
  int exited = 0;
  for (auto it = pids_.begin(); it != pids_.end();) {
    int status = 0;
    if (::waitpid(*it, &status, WNOHANG) == *it) {
      lastExit_ = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                      : "exited with " + std::to_string(WEXITSTATUS(status));
      if (WIFSIGNALED(status) && !(terminating_ && WTERMSIG(status) == SIGTERM))
        spdlog::warn("local worker pid {} killed by signal {}", *it, WTERMSIG(status));
      else if (WIFSIGNALED(status))
        spdlog::debug("local worker pid {} ended by the SIGTERM it was sent", *it);
      else
        spdlog::debug("local worker pid {} exited with {}", *it, WEXITSTATUS(status));
      it = pids_.erase(it);
      ++exited;
    } else {
      ++it;
    }
  }
  return exited;
}

void LocalWorkers::terminateAll() {
  // Workers sent their bye (the job's end) exit within milliseconds: a short grace first, as a
  // SIGTERM makes each wait 100 ms for its frames to leave (worker.cpp), which the master, and
  // a small job's end to end time, waited out too (0.1 s of tetra (+) ball's 0.7 s at 48^3).
  auto now = std::chrono::steady_clock::now();
  for (const auto grace = now + std::chrono::milliseconds(30); !pids_.empty() && now < grace;
       now = std::chrono::steady_clock::now()) {
    reap();
    if (!pids_.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  terminating_ = true;
  for (pid_t p : pids_) ::kill(p, SIGTERM);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (!pids_.empty() && std::chrono::steady_clock::now() < deadline) {
    reap();
    if (!pids_.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (pid_t p : pids_) {
    ::kill(p, SIGKILL);
    ::waitpid(p, nullptr, 0);
  }
  pids_.clear();
}

}  // namespace frep::farm
