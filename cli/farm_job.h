// What `frep sample` and `frep mesh` share to run a job on the farm: the JobSpec built from a
// loaded model and grid, the farm options from the command line (validated, exit 2 on bad
// values), running the job with failures mapped to exit codes, and the report beside the output.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "frep/io/atomic_output.h"
#include "commands.h"
#include "frep/master/farm_master.h"
#include "frep/sampling/sample.h"
#include "model_loader.h"

namespace frep::cli {

// The job for `operation` ("sample" or "mesh") over `grid`; the caller adds the operation's own
// options (band, mesh spec).
farm::JobSpec makeJob(const LoadedModel& m, const std::string& modelPath, const GridSpec& grid,
                      const std::string& operation);

// Limits of the integer options (docs/cli.md lists every one).
constexpr int kMaxBrick = 1024;             // --brick: voxels per brick edge
constexpr int kMaxProcesses = 4096;         // --workers, --expect-workers, --threads
constexpr uint64_t kMaxBricks = uint64_t(1) << 21;  // bricks the master plans (128^3)
constexpr uint64_t kPlannedBytesPerBrick = 256;     // the master's state per planned brick, about

// Refuses (exit 2, with the brick count and an estimate of the planning memory) a grid that
// makes more than kMaxBricks bricks of `brick`^3 voxels: checked before planning anything.
void checkJobSize(const GridSpec& grid, int brick);

// Validates the farm options (throws CliError(kExitBadArgs) naming the option). The journal is
// OUT.journal; `threads` is the in-process run's thread count (--workers 0).
farm::FarmOptions farmOptions(const FarmRequest& f, const std::string& out, const std::string& logLevel, int threads);

// The default when --workers is not given: a job of at most kInProcessMaxPoints grid points (one
// default brick, 64^3) is computed in-process on all cores, as the farm's start costs more than
// such a job (each worker's exec, library loading and model compile, the job's exchange; measured
// in docs/cli.md). Not with --listen, --expect-workers, --verify or --replicate (they need
// workers). Returns the reason, for the log and the report, or "" (the farm runs).
constexpr uint64_t kInProcessMaxPoints = uint64_t(64) * 64 * 64;
std::string smallJobInProcess(const FarmRequest& f, const std::array<int32_t, 3>& dims);

// The brick edge when --brick is not given: 64, halved (down to 16) until the grid has at
// least two bricks per worker (workers < 0: one per core; in cluster mode --expect-workers, else
// 64). Any brick gives the same output bytes; this only keeps every worker busy.
int chooseBrick(const std::array<int32_t, 3>& dims, int workers, const std::string& listen, int expectWorkers);

// Runs the job: std::invalid_argument -> exit 2, std::runtime_error -> exit 7 (farm error).
farm::FarmOutcome runFarmJob(const farm::JobSpec& job, const farm::FarmOptions& options);

// Writes report.toJson(), with peak_rss_bytes refreshed (after the output was written), to the
// report's temporary file and commits it.
void writeReport(io::AtomicOutput& reportOut, const farm::FarmReport& report);
// The outputs and the report appear together or not at all (a full disk at the report left the
// output in place with exit 3): the report's bytes are written and synced first, then
// commitOutputs() renames the outputs (returning their paths), then the report is renamed; if
// that fails, the outputs are removed again.
void writeReportWith(io::AtomicOutput& reportOut, const farm::FarmReport& report,
                     const std::function<std::vector<std::string>()>& commitOutputs);

// An interrupted or poisoned job: writes the report and throws CliError with exit 6 (resume) or
// 5 (the poisoned bricks named). Returns when the job is complete.
// The faces of the grid's box that the solid reaches (facesReached), named "x-min, z-max".
struct BoxCut {
  unsigned faces = 0;
  std::vector<std::string> names() const;  // "x-min", "z-max", ...
  std::string text() const;                // "x-min, z-max"
};
// Finds them and warns naming them (what the output does there: `what`).
BoxCut findBoxCut(const LoadedModel& m, const GridSpec& grid, int threads, const std::string& what);
// Sets the job's cut box (JobSpec cut_lo/cut_hi): its field becomes min(f, the box's faces).
void setCutBox(farm::JobSpec& job, const std::array<double, 3>& lo, const std::array<double, 3>& hi);

void requireComplete(io::AtomicOutput& reportOut, const farm::FarmReport& report, bool strict = false);

// The same without a report or journal (frep render): throws CliError with exit 6 or 5.
void requireComplete(const farm::FarmReport& report);

// "bricks N (C computed, J from the journal), workers W, retries R, T s" for the summary.
std::string bricksSummary(const farm::FarmReport& report);
// "; verified V (mismatches M, workers banned for them L, bricks recomputed R)" with --verify, else "".
std::string verificationSummary(const farm::FarmReport& report);

}  // namespace frep::cli
