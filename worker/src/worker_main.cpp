// frep-worker: joins a frepfarm master and computes bricks until the job ends.
#include <CLI/CLI.hpp>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <sys/stat.h>

#include <cstdlib>

#include "frep/farm/allocator_tuning.h"
#include "frep/worker/brick.h"
#include "frep/io/geometry_files.h"
#include "frep/worker/worker.h"

int main(int argc, char** argv) {
  frep::farm::applyAllocatorPolicy();
  frep::io::installGeometryLoader();  // frMesh / frVolume read files through frep_io
  CLI::App app{"frep-worker: computes bricks for a frepfarm master.\n"
               "Exit codes: 0 done or stopped by SIGTERM, 2 bad arguments, 75 no master reachable,\n"
               "78 refused by the master (e.g. protocol version)."};
  frep::farm::WorkerOptions opt;
  std::string level = "info";
  if (const char* env = std::getenv("FREP_MASTER")) opt.endpoint = env;
  app.add_option("--connect", opt.endpoint, "master endpoint, e.g. tcp://host:5555 (default: $FREP_MASTER)");
  app.add_option("--threads", opt.threads, "threads per brick (default: all cores)");
  app.add_option("--curve", opt.curveDir, "directory with CURVE keys from `frep keygen`");
  std::string dataDir;
  app.add_option("--data-dir", dataDir,
                 "directory whose regular files a job's model may read when the job does not ship them "
                 "(default: none; a worker opens no other path a job names)");
  app.add_option("--master-timeout", opt.masterTimeoutSec, "seconds without a master before giving up")
      ->capture_default_str();
  app.set_version_flag("--version", "frep-worker " FREP_VERSION);
  CLI::Option* levelOption =
      app.add_option("--log-level", level, "trace, debug, info, warn, error, off (default info, or $SPDLOG_LEVEL)")
          ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int rc = app.exit(e);
    return rc == 0 ? 0 : frep::farm::kWorkerBadArgs;
  }
  if (opt.endpoint.empty()) {
    spdlog::error("--connect: no master endpoint given (or set FREP_MASTER)");
    return frep::farm::kWorkerBadArgs;
  }
  if (!dataDir.empty()) {
    struct stat st {};
    if (::stat(dataDir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
      spdlog::error("--data-dir: '{}' is not a directory", dataDir);
      return frep::farm::kWorkerBadArgs;
    }
    frep::farm::setWorkerDataDir(dataDir);
  }
  spdlog::set_level(spdlog::level::from_str(level));
  // $SPDLOG_LEVEL (e.g. debug, or warn,frep=debug) unless --log-level is given: the option wins.
  if (levelOption->count() == 0) spdlog::cfg::load_env_levels();
  try {
    return frep::farm::runWorker(opt);
  } catch (const std::exception& e) {
    spdlog::error("worker: {}", e.what());
    return frep::farm::kWorkerBadArgs;
  }
}
