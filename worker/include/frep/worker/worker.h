// The worker process: a ZeroMQ DEALER that says hello, takes bricks, computes them on a
// compute thread while its I/O thread keeps heartbeating, and reconnects with back-off when
// the master goes away.
#pragma once

#include <string>

namespace frep::farm {

struct WorkerOptions {
  std::string endpoint;       // tcp://host:port of the master
  int threads = 0;            // threads per brick (0: all cores)
  std::string curveDir;       // directory with CURVE keys (frep keygen), empty: plain TCP
  int masterTimeoutSec = 300; // give up when no master answered for this long
};

// Documented exit codes of frep-worker.
enum WorkerExit : int {
  kWorkerOk = 0,          // job done (Bye), or SIGTERM handled
  kWorkerBadArgs = 2,     // bad command line
  kWorkerNoMaster = 75,   // no master for masterTimeoutSec (EX_TEMPFAIL)
  kWorkerRejected = 78,   // refused by the master (protocol version, ...) (EX_CONFIG)
};

int runWorker(const WorkerOptions& options);

}  // namespace frep::farm
