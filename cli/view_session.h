// frep view's model session: watches the .hf file's mtime and, on every save, runs `frep mesh`
// on it as a child process (view_child.h) with the view's options, interrupting the run of the
// previous save. Holds what the page shows: the last mesh (.glb bytes), the report text that
// frep mesh printed, or the error it printed (file:line:column and the caret), and slices.
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"

namespace frep::cli {

class ViewSession {
 public:
  ViewSession(const ViewRequest& request, std::string frepExe);
  ~ViewSession();
  void start();  // the watcher thread: the first job starts at once
  void stop();   // interrupts the job in progress and joins the threads

  // {generation, status: computing|ready|error, message, report, log, command, exit_code,
  //  mesh_generation, interrupted, seconds, bounds[6], model, report_json}
  nlohmann::json state() const;
  // The .glb of the last successful job (empty before one), and its generation.
  std::shared_ptr<const std::string> mesh(uint64_t* generation) const;

  struct Slice {
    bool ok = false;
    std::string png, error;  // the PNG, or what frep slice printed on failure
  };
  // frep slice of the current file: plane normal to `axis` (x, y, z) at `at`, `res` pixels along
  // the longer side of the box's face.
  Slice slice(char axis, double at, int res) const;

 private:
  void watchLoop();
  void runJob(uint64_t generation, std::shared_ptr<std::atomic<bool>> cancel);
  std::vector<std::string> modelArgs() const;  // the model and -o -a -x -i -b options

  const ViewRequest request_;
  const std::string exe_;
  std::array<double, 6> bounds_{};
  std::atomic<bool> stopping_{false};
  std::thread watcher_, job_;
  std::shared_ptr<std::atomic<bool>> jobCancel_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  uint64_t generation_ = 0, meshGeneration_ = 0, interrupted_ = 0;
  std::string status_ = "computing", message_, report_, log_, command_;
  int exitCode_ = -1;
  double seconds_ = 0;
  nlohmann::json reportJson_;
  std::shared_ptr<const std::string> mesh_ = std::make_shared<const std::string>();
};

}  // namespace frep::cli
