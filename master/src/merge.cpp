// The merge of the bricks' outputs: a sample's slabs (streamed or not), a mesh, an image.

#include <spdlog/spdlog.h>
#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "frep/farm/crc32.h"
#include "frep/meshing/mesh_merge.h"
#include "frep/master/leaf_order.h"
#include "frep/farm/allocator_tuning.h"
#include "master.h"

namespace frep::farm::detail {

// A kept payload's bytes: as received, in the arena, or read back from the journal into
// `buffer` and checked against the CRC-32 it was verified with (the file is the master's own,
// but what it merges must be exactly what it verified).
std::string_view Master::keptPayload(const KeptBrick& k, size_t brick, ReadBack& buffer) {
  if (k.received.held()) return k.received.bytes();
  if (!k.inJournal) return {k.payload.data(), k.payload.size()};
  char* bytes = buffer.room(k.size);
  journal_->read(k.journalAt, bytes, k.size);
  if (crc32Of(bytes, k.size) != k.crc)
    throw JournalIoError("journal " + journal_->path() + ": the record of brick " + std::to_string(brick) +
                         " changed after it was written (its CRC-32 no longer matches)");
  return {bytes, k.size};
}

// The leaf records of the slab of bricks [first, last), sorted by origin, and its tiles
// (appended to `tiles`). Payloads read back from the journal are kept in readBack (a buffer per
// brick of the slab, reused by the next slab) while the records point into them. Runs on `threads`.
void Master::slabRecords(size_t first, size_t last, tbb::task_arena& threads, std::vector<LeafRecord>& sorted,
                 std::vector<ReadBack>& readBack, std::vector<Tile>& tiles) {
  std::vector<std::array<int32_t, 3>> origins;  // the slab's, brick by brick
  std::vector<size_t> start(1, 0), rank;         // rank[start[brick] + leaf]: the leaf's place in the slab
  for (size_t i = first; i < last; ++i) {
    origins.insert(origins.end(), kept_[i].origins.begin(), kept_[i].origins.end());
    start.push_back(origins.size());
    tiles.insert(tiles.end(), kept_[i].tiles.begin(), kept_[i].tiles.end());
  }
  sorted.resize(origins.size());
  readBack.resize(last - first);
  threads.execute([&] {
    rankByOrigin(origins, bricks_[first].lo, bricks_[last - 1].hi, rank);
    tbb::parallel_for(first, last, [&](size_t i) {
      const KeptBrick& k = kept_[i];
      if (k.origins.empty()) return;
      const std::string_view bytes = keptPayload(k, i, readBack[i - first]);
      const size_t* to = rank.data() + start[i - first];
      for (size_t l = 0; l < k.leafAt.size(); ++l) {
        const size_t end = l + 1 < k.leafAt.size() ? k.leafAt[l + 1] : bytes.size();
        sorted[to[l]] = LeafRecord{bytes.data() + k.leafAt[l], uint32_t(end - k.leafAt[l])};
      }
    });
  });
}

// After a slab's records were decoded: its payloads go (the arena unmaps emptied chunks); the
// read-back buffers stay for the next slab.
void Master::releaseSlab(size_t first, size_t last) {
  for (size_t i = first; i < last; ++i) kept_[i] = KeptBrick{};
}

// Streaming (FarmOptions::sampleSink): the loop hands the merge thread every slab whose bricks
// are all merged, in slab order, as soon as they are (commit), so that the merge overlaps the
// receiving of the next slabs instead of following the last brick.
void Master::queueCompleteSlabs() {
  size_t queued = slabsQueued_;
  while (queued < slabLeft_.size() && slabLeft_[queued] == 0) ++queued;
  if (queued == slabsQueued_) return;
  slabsQueued_ = queued;
  {
    std::lock_guard<std::mutex> lock(mergeMutex_);
    slabsReady_ = queued;
  }
  mergeWake_.notify_one();
}

// The merge thread: each slab handed over, in order, given to the sink: its tiles sorted, then
// its leaves in pieces of kSinkPieceLeaves, decoded on its own threads (a piece each) into
// buffers that are refilled; on every core once the loop is done (told to stop: the slabs
// left are all there is to do). Stops when told to, once the slabs handed over are done.
void Master::mergeSlabs() {
  const SampleSink& sink = opt_.sampleSink;
  std::vector<std::vector<LeafBlock>> pieces(
      size_t(std::max({1, mergers_.max_concurrency(), allCores_.max_concurrency()})));
  for (auto& p : pieces) p.reserve(kSinkPieceLeaves);
  std::vector<LeafRecord> sorted;
  std::vector<ReadBack> readBack;
  std::vector<Tile> tiles;
  try {
    for (size_t next = 0;; ++next) {
      bool alone = false;
      {
        std::unique_lock<std::mutex> lock(mergeMutex_);
        mergeWake_.wait(lock, [&] { return slabsReady_ > next || mergeStop_; });
        if (slabsReady_ <= next) return;  // stopped, nothing more handed over
        alone = mergeStop_;
      }
      tbb::task_arena& threads = alone ? allCores_ : mergers_;
      const size_t inParallel = size_t(std::max(1, threads.max_concurrency()));
      const size_t first = next * perSlab_, last = std::min(bricks_.size(), first + perSlab_);
      tiles.clear();
      slabRecords(first, last, threads, sorted, readBack, tiles);
      std::vector<LeafBlock> noLeaves;
      sortByOrigin(noLeaves, tiles);
      if (!tiles.empty() && sink.tiles) sink.tiles(tiles);
      const size_t n = sorted.size();
      for (size_t round = 0; round < n; round += inParallel * kSinkPieceLeaves) {
        const size_t count = std::min(inParallel, (n - round + kSinkPieceLeaves - 1) / kSinkPieceLeaves);
        auto decodePiece = [&](size_t p) {
          const size_t from = round + p * kSinkPieceLeaves, to = std::min(n, from + kSinkPieceLeaves);
          pieces[p].resize(to - from);  // not zeroed (LeafBlock): decoded into
          decodeLeafRecords(sorted.data() + from, to - from, pieces[p].data());
        };
        if (count == 1) decodePiece(0);
        else threads.execute([&] { tbb::parallel_for(size_t(0), count, decodePiece); });
        for (size_t p = 0; p < count; ++p) sink.leaves(pieces[p]);
      }
      releaseSlab(first, last);
      streamedTiles_.insert(streamedTiles_.end(), tiles.begin(), tiles.end());
      std::lock_guard<std::mutex> lock(mergeMutex_);
      slabsStreamed_ = next + 1;
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mergeMutex_);
    mergeError_ = std::current_exception();
    mergeFailed_ = true;
  }
}

// Waits for the merge thread to finish the slabs handed over, and ends it.
void Master::stopMerger() {
  if (!merger_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mergeMutex_);
    mergeStop_ = true;
  }
  mergeWake_.notify_one();
  merger_.join();
}

// A failure of the merge thread (its sink threw, the journal could not be read) ends the job.
void Master::rethrowMergeError() {
  if (!mergeFailed_) return;
  std::lock_guard<std::mutex> lock(mergeMutex_);
  std::rethrow_exception(mergeError_);
}

// The merged sample in `result`. Streaming, the merge thread has handed every slab of a
// complete job to the sink; of an incomplete one (a brick poisoned, or stopped) the slabs it
// handed over (those before the first one not complete) and result.leaves holds the merged
// leaves of the others. result.tiles holds every tile, sorted. Without a sink, the slabs are
// decoded here into result.leaves, sized once.
void Master::mergeLeaves(SampleResult& result) {
  stopMerger();
  rethrowMergeError();
  result.tiles = std::move(streamedTiles_);
  size_t leaves = 0;
  const size_t firstKept = slabsStreamed_ * perSlab_;
  for (size_t i = firstKept; i < kept_.size(); ++i) leaves += kept_[i].origins.size();
  result.leaves.reserve(leaves);  // filled slab by slab: pages are touched as payloads are freed
  // Fresh memory (a mapping of its own above the allocator's threshold): in 2 MiB pages its first
  // touch took 99-120 against 188-261 us a brick's 272 kB in 4 KiB pages (docs/farm.md, "Throughput").
  adviseHugePages(result.leaves.data(), leaves * sizeof(LeafBlock));
  std::vector<Tile> tiles;
  std::vector<LeafRecord> sorted;
  std::vector<ReadBack> readBack;
  for (size_t first = firstKept; first < kept_.size(); first += perSlab_) {
    const size_t last = std::min(kept_.size(), first + perSlab_), at = result.leaves.size();
    slabRecords(first, last, decoders_, sorted, readBack, tiles);
    result.leaves.resize(at + sorted.size());  // not zeroed (LeafBlock): decoded into below, in ranges of a sink's piece
    decoders_.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, sorted.size(), kSinkPieceLeaves), [&](const tbb::blocked_range<size_t>& r) {
        decodeLeafRecords(sorted.data() + r.begin(), r.size(), result.leaves.data() + at + r.begin());
      });
    });
    releaseSlab(first, last);
  }
  std::vector<LeafBlock> noLeaves;
  sortByOrigin(noLeaves, tiles);
  result.tiles.insert(result.tiles.end(), tiles.begin(), tiles.end());  // after the streamed slabs' tiles
  kept_.clear();
}

FarmOutcome Master::finish() {
  FarmOutcome o;
  // Bricks of a convicted worker were in slabs already streamed: the journal holds the job as
  // it must be; runJob merges it once more from there (a job that did not complete writes
  // nothing anyway, and its journal is right for --resume).
  report_.restreamed = streamTainted_ && leases_.done() == bricks_.size() && !report_.interrupted;
  report_.operation = op_ == Operation::Mesh ? "mesh" : op_ == Operation::Render ? "render" : "sample";
  if (op_ == Operation::Render && leases_.done() == bricks_.size()) {
    // The merge step of a render job: each tile's hits to their pixels (split-invariant, as
    // castRegion's regions give the whole image's hits).
    DepthImage& img = o.image;
    img.width = grid_.dims[0], img.height = grid_.dims[1];
    img.pixelStep = 2.0 * job_.render().half_width() / img.width;
    img.hits.assign(size_t(img.width) * size_t(img.height), RayHit{});
    for (const BrickOutput& out : outputs_) {
      const int w = out.tileHi[0] - out.tileLo[0];
      for (size_t i = 0; i < out.hits.size(); ++i) {
        const RayHit& h = out.hits[i];
        img.hits[size_t(out.tileLo[1] + int(i) / w) * size_t(img.width) + size_t(out.tileLo[0] + int(i) % w)] = h;
        report_.pixelsHit += h.kind != RayHit::kNone;
      }
    }
    outputs_.clear();
  }
  if (op_ == Operation::Mesh && leases_.done() == bricks_.size()) {
    // The merge step of a mesh job: the pieces stitched by global edge key (split-invariant).
    // mergePiecesReleasing frees each piece as soon as it is stitched: the master holds about
    // one copy of the output mesh instead of three (the same mesh as mergePieces).
    std::vector<MeshPiece> pieces;
    pieces.reserve(outputs_.size());
    for (auto& out : outputs_) pieces.push_back(std::move(out.piece));
    outputs_.clear();
    o.mesh = mergePiecesReleasing(pieces, !allocatorPolicyApplied());
    report_.vertices = o.mesh.positions.size();
    report_.triangles = o.mesh.triangles.size();
  }
  o.result.grid = grid_;
  o.result.bandVoxels = job_.band();
  mergeLeaves(o.result);
  o.result.stats.pointEvals = report_.pointEvals;
  o.result.stats.intervalEvals = report_.intervalEvals;
  o.result.stats.nanValues = report_.nanValues;
  o.result.stats.domainErrors = report_.domainErrors;
  o.result.stats.denseEvals = uint64_t(grid_.dims[0]) * grid_.dims[1] * grid_.dims[2];
  report_.denseEvals = o.result.stats.denseEvals;
  const LeaseStats& leases = leases_.stats();
  report_.retries = leases.retries;
  report_.deadWorkers = leases.deadWorkers;
  report_.stragglerReissues = leases.stragglerReissues;
  report_.queuedReissues = leases.queuedReissues;
  report_.leaseReissues = leases.leaseReissues;
  report_.suspectBricks = leases.suspectBricks;
  report_.masterStalls = leases.masterStalls;
  report_.refutedFailures = leases.refutedFailures;
  report_.wallSeconds = std::chrono::duration<double>(Clock::now() - start_).count();
  report_.peakRssBytes = peakRssBytes();
  o.report = report_;
  return o;
}

}  // namespace frep::farm::detail
