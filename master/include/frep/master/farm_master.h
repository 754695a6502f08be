// The master: plans a job as bricks, leases them to workers over a ZeroMQ ROUTER (or computes
// them in-process), survives workers that die or stall, journals what it merged, and returns
// the merged result. Writing the output files is the caller's business (cli/).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "farm.pb.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/render/raycast.h"
#include "frep/sampling/sample.h"

namespace frep::farm {

// "sample": the merged output handed to the caller slab by slab as it is merged instead of built
// whole in FarmOutcome::result.leaves (then empty for a complete job), so that a consumer that
// writes as it goes (io::LevelSetBuilder) never holds the leaves and its own output at once
// (docs/farm.md, "Throughput"). Streaming is on when `leaves` is set. The bricks are planned in
// x-slabs; as soon as every brick of the next slab is merged (not after the job's last brick),
// the master's merge thread calls, for that slab, `tiles` with its tiles sorted (if it has any),
// then `leaves` with its leaves sorted by origin (if it has any), in pieces: kSinkPieceLeaves
// leaves a call, the slab's last piece the rest. The slabs follow one another in the sort, so
// the calls in turn hand over result's tiles and leaves in result's order, and a slab's tiles
// never cover an earlier slab's leaves. The calls come from the merge thread, one at a time, all
// before runJob returns; an exception from either ends the job (runJob throws it). A job that
// does not complete (a brick poisoned, or interrupted) hands over only the slabs before the
// first one it did not complete: result.leaves holds the merged leaves of the others
// (result.tiles always holds every tile, sorted). A piece is one of a few buffers (one per merge
// thread), refilled: read it during the call and keep nothing that points into it.
// `restart` (optional): forget everything handed over so far; the slabs are handed over again
// from the first. runJob calls it, then merges the whole job once more from the journal, when a
// worker convicted of forging (FarmOptions::verifyFraction) had bricks in slabs already handed
// over: its bricks are recomputed and the output must not keep its values. Without `restart` (or
// without a journal) such a job throws std::runtime_error instead of returning a forged output.
struct SampleSink {
  std::function<void(const std::vector<Tile>& tiles)> tiles;  // optional
  std::function<void(const std::vector<LeafBlock>& leaves)> leaves;
  std::function<void()> restart;  // optional
};

// Whether brick `brick` of job `jobId` is in the verification sample of `fraction` drawn with
// `seed` (FarmOptions::verifyFraction, verifySeed): a pseudo-random choice, the same for the same
// job, seed and brick (a resumed job checks the same bricks). fraction >= 1: every brick; <= 0:
// none.
bool verifySelected(uint64_t jobId, uint64_t seed, uint64_t brick, double fraction);

// The leaves of a SampleSink::leaves call (but a slab's last): ~0.5 MB, decoded into a buffer
// that stays in the core's cache while the sink reads it (a whole slab's buffer, ~70 MB for a
// 1024^2 slab of surface bricks, went through memory twice: decoded into, then read).
constexpr size_t kSinkPieceLeaves = 256;

// The decode threads of FarmOptions::decodeThreads 0: every core but the two that the master's
// scheduling loop and ZeroMQ's I/O thread keep busy, at least one (then the loop's own).
int defaultDecodeThreads();

struct FarmOptions {
  int workers = -1;              // local worker processes: -1 one per core, 0 compute in-process
  std::string listen;            // cluster mode: bind here (tcp://*:5555) and spawn nothing
  int expectWorkers = 0;         // cluster mode: workers expected (progress, warnings)
  int brickVoxels = 64;          // brick edge, a multiple of 8
  int heartbeatMs = 500;         // both ways
  int liveness = 6;              // missed beats before a peer counts as dead
  int maxAttempts = 3;           // holder failures, or distinct workers dying with it alone, that poison a brick
  double leaseSeconds = 0;       // re-issue a brick running longer; 0: max(30 s, 10 x median)
  int noWorkerTimeoutSec = 120;  // give up when no worker is alive for this long
  std::string curveDir;          // require CURVE keys (frep keygen)
  bool insecure = false;         // allow --listen on a non-loopback address without curveDir
  std::string journalPath;       // empty: no journal
  // "sample" with a journal: bytes of received payloads kept in memory until their slab's merge
  // (beyond it the merge reads the journal's copy back; 0: always read back).
  size_t heldPayloadBytes = size_t(256) << 20;
  bool resume = false;
  bool progressJson = false;     // JSON progress events on stdout
  bool progressBar = false;      // progress bar on stderr
  std::string workerExecutable;  // local mode: path of frep-worker ("" = next to this program)
  int workerThreads = 1;         // local mode: threads per worker
  int threads = 0;               // in-process mode: threads per brick (0: all cores)
  int decodeThreads = 0;         // farm: threads verifying and decoding results (0: defaultDecodeThreads(); 1: the loop's own)
                                 // (streaming a sample: as many again merge its slabs, on their own thread)
  std::string logLevel = "warn"; // local mode: workers' --log-level
  // Verification (docs/farm.md, "Verification"): < 0 off. Otherwise the fraction (0..1) of the
  // bricks, chosen by verifySelected, whose result is merged only once two distinct workers
  // returned the same bytes; every result of a peer under suspicion (refuted failures) is
  // checked too, even with 0. A mismatch goes to a third worker; the workers outvoted are banned
  // and every brick they returned unchecked is recomputed. 1: no single worker changes a result.
  double verifyFraction = -1;
  // The sample's seed, mixed with the job id; 0: a random one, written to the journal so that a
  // resumed job checks the same bricks (a worker knows the job id, not the seed). Tests set it.
  uint64_t verifySeed = 0;
  SampleSink sampleSink;         // "sample": stream the merged output (see SampleSink)
  // Called once the master is bound, with the actual endpoint (tcp://127.0.0.1:* picks a free
  // port): tests and embedders start their workers from it.
  std::function<void(const std::string& endpoint)> onListening;
};

struct WorkerShare {
  uint64_t bricks = 0, pointEvals = 0;
  double computeSeconds = 0;
  // Where the worker's time went, by its own results (docs/farm.md, "Scaling"): every result it
  // sent (merged or not: results - bricks are the duplicates it computed), the CPU its compute
  // thread spent in computeBrick and on whole tasks (the difference: model look-up, encoding,
  // CRC), its process's CPU by its last result (the rest: start-up, compiling the job, the I/O
  // thread's receiving and sending), and the time its compute thread waited with no task.
  uint64_t results = 0;
  double computeCpuSeconds = 0, taskCpuSeconds = 0, processCpuSeconds = 0, idleSeconds = 0;
  double firstIdleSeconds = -1;  // of those, the wait for its first task (start-up); -1: no result yet
  // From its last result to the job's last one: done while others still computed (the tail).
  double tailIdleSeconds = 0;
};

struct PoisonedBrick {
  uint64_t brick;
  std::array<int32_t, 3> lo, hi;
  std::string error;
};

struct FarmReport {
  std::string operation = "sample";
  double wallSeconds = 0;
  // Peak resident memory of this (the master's) process so far, getrusage's ru_maxrss: taken
  // when the job ends; the cli refreshes it after writing the output ("peak_rss_bytes").
  uint64_t peakRssBytes = 0;
  uint64_t bricks = 0, bricksComputed = 0, bricksFromJournal = 0;
  uint64_t pointEvals = 0, intervalEvals = 0, denseEvals = 0, nanValues = 0;
  DomainCounts domainErrors;
  uint64_t leaves = 0, tiles = 0;        // "sample": merged output
  uint64_t vertices = 0, triangles = 0;  // "mesh": merged output (after simplification)
  uint64_t pixelsHit = 0;                // "render": pixels on the solid (centre or footprint)
  // "mesh": the simplification of the merged mesh (frep/meshing/mesh_simplify.h; run by the caller).
  double simplifyTolerance = 0;  // voxels; 0: not simplified
  bool sharpFeatures = false;
  SimplifyStats simplify;
  std::vector<std::string> cutFaces;  // the box's faces that cut the solid ("x-min", "z-max", ...)
  bool capped = false;   // ... and whether the mesh was capped there (solid ∩ box)
  double surfaceErrorBound = 0;  // "mesh": no point of the mesh is further from the surface (world units)
  uint64_t retries = 0, duplicates = 0, lateResults = 0, malformed = 0, oversized = 0;
  uint64_t deadWorkers = 0, handedBack = 0, stragglerReissues = 0, queuedReissues = 0, leaseReissues = 0, refused = 0;
  uint64_t curveRejected = 0;
  // Hostile or broken peers and faults (docs/farm.md, "Threat model" and "Faults"):
  uint64_t foreignResults = 0;  // results or failures for a brick the sender does not hold
  uint64_t bannedPeers = 0;     // peers dropped for garbage or failing peers (their bricks not charged)
  uint64_t refutedFailures = 0;     // failures of a brick that another worker then computed
  uint64_t failingPeersBanned = 0;  // peers banned for them (docs/farm.md, "Failing peers")
  // Verification (FarmOptions::verifyFraction; "verification" in the JSON):
  double verifyFraction = -1;     // as asked (< 0: off)
  uint64_t verifySeed = 0;        // the sample's seed (from the journal on a resume)
  uint64_t verifiedBricks = 0;    // merged once two distinct workers returned the same bytes
  uint64_t verifyMismatches = 0;  // results that differed from another worker's for the brick
  uint64_t liarsBanned = 0;       // workers outvoted on a brick: banned
  uint64_t bricksRedone = 0;      // merged bricks of theirs (or of suspects) recomputed
  uint64_t unverifiedBricks = 0;  // selected, merged unchecked: no second worker to check them
  std::string verifyUnavailable;  // why verification could not run ("" when it could)
  bool restreamed = false;        // "sample" streamed: merged once more from the journal (SampleSink::restart)
  uint64_t suspectBricks = 0;   // bricks whose worker died computing them (then retried alone)
  uint64_t reconnects = 0;      // workers back under a new connection, leases kept
  uint64_t masterStalls = 0;    // the master's own loop stopped longer than the liveness window
  uint64_t extremumSearches = 0, extremumUncertified = 0, extremumSignDecided = 0;
  double extremumWidestGap = 0;  // the widest gap an uncertified search left (infinite: unknown)
  std::vector<std::string> errorBounds;  // one line per extremum node of the model
  int workersSeen = 0;
  std::string inProcessRule;  // why the CLI ran the job in-process unasked (no --workers), or ""
  // The master's own CPU (its process, every thread; local workers are other processes): the
  // whole job, and after its last brick came in (the final merge; farm_master.cpp, runJob).
  double masterCpuSeconds = 0, masterCpuAfterLastBrick = 0;
  std::map<std::string, WorkerShare> perWorker;  // by worker id ("in-process" for --workers 0)
  std::vector<PoisonedBrick> poisoned;
  bool interrupted = false;  // SIGTERM/SIGINT: journal flushed, resume with --resume
  std::string toJson() const;
};

// The merged result of a job; which member is filled depends on the job's operation. Both are
// complete only if nothing was poisoned (and the job was not interrupted).
struct FarmOutcome {
  SampleResult result;  // "sample": merged, sorted as sample() sorts
  Mesh mesh;            // "mesh": the bricks' pieces stitched by mergePieces (as meshGrid does)
  DepthImage image;     // "render": the tiles' hits, as castRays gives them
  FarmReport report;
};

// Runs a job ("sample", "mesh" or "render"): one scheduling loop; only the final merge depends on the
// operation. Throws std::invalid_argument for a bad job or options (unknown operation, brick
// size, --listen on a non-loopback address without CURVE or insecure) and std::runtime_error
// for setup failures (bind, journal, keys, local workers that keep dying).
FarmOutcome runJob(const JobSpec& job, const FarmOptions& options);

// True if a tcp:// endpoint binds only the loopback interface (127.*, ::1, localhost).
bool isLoopbackEndpoint(const std::string& endpoint);

// Peak resident set of the calling process in bytes (getrusage RUSAGE_SELF; 0 if unavailable).
uint64_t peakRssBytes();

}  // namespace frep::farm
