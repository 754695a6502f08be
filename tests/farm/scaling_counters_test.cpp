// The workers' account of their time (docs/farm.md, "Scaling"): what bench_farm_scaling.py reads
// to tell where a 2-worker run loses against one, whatever the machine's load. Checked here:
// the counters add up (a thread's CPU within its process's, the compute within the task, every
// merged brick counted once), and the report carries them.
#include <nlohmann/json.hpp>

#include "farm_test_util.h"

using namespace farmtest;

TEST(Scaling, TwoLocalWorkersAccountForTheirTimeAndTheMasterForItsCpu) {
  JobSpec j = partJob("sample", 96);
  FarmOutcome ref = runJob(j, fast(0));
  FarmOutcome o = runJob(j, fast(2, 16));
  ASSERT_EQ(o.result.leaves.size(), ref.result.leaves.size());
  for (size_t i = 0; i < ref.result.leaves.size(); ++i)
    ASSERT_EQ(o.result.leaves[i].values, ref.result.leaves[i].values);
  const FarmReport& r = o.report;
  ASSERT_FALSE(r.perWorker.empty());
  uint64_t bricks = 0;
  double lastTail = 1e300;
  for (const auto& [id, w] : r.perWorker) {
    SCOPED_TRACE(id);
    bricks += w.bricks;
    EXPECT_GE(w.results, w.bricks);  // the rest: duplicates it computed
    EXPECT_GT(w.computeCpuSeconds, 0.0);
    EXPECT_LE(w.computeCpuSeconds, w.taskCpuSeconds);  // the compute thread's CPU on its tasks
    EXPECT_LE(w.taskCpuSeconds, w.processCpuSeconds);  // within its process's, every thread
    EXPECT_GE(w.firstIdleSeconds, 0.0);
    EXPECT_GE(w.idleSeconds, w.firstIdleSeconds);
    EXPECT_GE(w.tailIdleSeconds, 0.0);
    lastTail = std::min(lastTail, w.tailIdleSeconds);
  }
  EXPECT_EQ(bricks, r.bricksComputed);
  EXPECT_EQ(bricks, r.bricks);
  EXPECT_EQ(lastTail, 0.0);  // the worker that sent the job's last result has no tail
  EXPECT_GT(r.masterCpuSeconds, 0.0);
  EXPECT_GE(r.masterCpuSeconds, r.masterCpuAfterLastBrick);
  EXPECT_GE(r.masterCpuAfterLastBrick, 0.0);
  const nlohmann::json js = nlohmann::json::parse(r.toJson());
  EXPECT_EQ(js["master_cpu_seconds"].get<double>(), r.masterCpuSeconds);
  for (const auto& [id, w] : r.perWorker) {
    const nlohmann::json& jw = js["per_worker"][id];
    EXPECT_EQ(jw["results"].get<uint64_t>(), w.results);
    EXPECT_EQ(jw["process_cpu_seconds"].get<double>(), w.processCpuSeconds);
    EXPECT_EQ(jw["tail_idle_seconds"].get<double>(), w.tailIdleSeconds);
  }
  // In-process: no worker sends results, so no time counters.
  for (const auto& [id, w] : ref.report.perWorker) EXPECT_EQ(w.results, 0u);
}
