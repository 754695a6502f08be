// An output file that appears complete or not at all: it is written to a temporary file next to
// the target (same directory, so rename() is atomic) and renamed on commit(). Destroying it
// without commit() removes the temporary file, and so does SIGINT/SIGTERM/SIGHUP arriving outside
// the farm's job loop (the process then exits 6, docs/cli.md). The target must be new or a
// regular file: a symlink, FIFO, device, socket or directory is refused (exit 3), never replaced.
#pragma once

#include <string>

namespace frep::io {

class AtomicOutput {
 public:
  // Creates the temporary file now, so an unwritable path fails before any work is done.
  // Throws Error(kExitIoError) naming `field` and the path (also for a non-regular target).
  AtomicOutput(const std::string& field, const std::string& path);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  const std::string& tempPath() const { return temp_; }
  const std::string& path() const { return path_; }
  void commit();  // fsync temp, rename temp -> path; throws Error(kExitIoError)

 private:
  std::string field_, path_, temp_;
  bool committed_ = false;
  int slot_ = -1;  // in the signal handler's table
};

}  // namespace frep::io
