// `frep sample` on the farm, end to end through the built binaries: identical bytes for any
// worker count and brick size, a master killed and resumed, SIGTERM, poisoned bricks, CURVE.
#include <signal.h>
#include <sys/stat.h>

#include <chrono>
#include <cstring>
#include <thread>

#include "farm_runner.h"

using namespace frep_cli_test;

namespace {

class FarmCli : public FarmTest {
 protected:
  void SetUp() override {
    FarmTest::SetUp();
    write("part.hf", kPartModel);
  }
  std::string sampleArgs(const std::string& out) const {
    return "sample part.hf -b 1 --res 95 --no-progress --heartbeat-ms 100 -O " + out;
  }
};

}  // namespace

TEST_F(FarmCli, SameBytesForAnyWorkerCountAndBrickSize) {
  ASSERT_EQ(run(sampleArgs("w0.vdb") + " --workers 0").code, 0);
  const std::string reference = readText(path("w0.vdb"));
  ASSERT_GT(reference.size(), 1000u);
  for (const char* variant : {"--workers 1", "--workers 2", "--workers 4", "--workers 2 --brick 32",
                              "--workers 0 --brick 16"}) {
    SCOPED_TRACE(variant);
    RunResult r = run(sampleArgs("w.vdb") + " " + variant);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(readText(path("w.vdb")) == reference) << "output bytes differ";
    std::string report = readText(path("w.vdb.report.json"));
    EXPECT_NE(report.find("\"poisoned\": []"), std::string::npos) << report;
  }
  EXPECT_FALSE(fileExists(path("w.vdb.journal")));  // removed once the output is complete
}

TEST_F(FarmCli, MasterKilledHalfwayResumesFromItsJournal) {
  RunResult full = run(sampleArgs("ref.vdb") + " --workers 0");
  ASSERT_EQ(full.code, 0);
  long totalEvals = jsonNumber(readText(path("ref.vdb.report.json")), "point");
  // Slow workers, so that the kill lands mid-job.
  pid_t master = start(sampleArgs("out.vdb") + " --workers 2 --brick 32", "FREP_TEST_SLOW_MS=150");
  for (int i = 0; i < 200 && journalRecords("out.vdb.journal") < 6; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  kill(master, SIGKILL);
  waitFor(master);
  size_t journaled = journalRecords("out.vdb.journal");
  ASSERT_GE(journaled, 6u);
  ASSERT_LT(journaled, 27u);
  EXPECT_FALSE(fileExists(path("out.vdb")));
  EXPECT_NE(listing().find(".out.vdb.tmp"), std::string::npos) << listing();  // SIGKILL: no clean-up ran
  RunResult resumed = run(sampleArgs("out.vdb") + " --workers 2 --brick 32 --resume");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  // The dead master's temporaries go with the successful resume (issue 31).
  EXPECT_EQ(listing().find(".tmp"), std::string::npos) << listing();
  std::string report = readText(path("out.vdb.report.json"));
  EXPECT_EQ(jsonNumber(report, "from_journal"), long(journaled)) << report;
  EXPECT_EQ(jsonNumber(report, "computed"), 27 - long(journaled));
  EXPECT_LT(jsonNumber(report, "point"), totalEvals);  // journaled bricks were not recomputed
  RunResult again = run(sampleArgs("ref32.vdb") + " --workers 0 --brick 32");
  ASSERT_EQ(again.code, 0);
  EXPECT_TRUE(readText(path("out.vdb")) == readText(path("ref32.vdb")));
}

TEST_F(FarmCli, SigtermStopsTheMasterWhichResumesLater) {
  pid_t master = start(sampleArgs("out.vdb") + " --workers 2 --brick 32", "FREP_TEST_SLOW_MS=150");
  for (int i = 0; i < 200 && journalRecords("out.vdb.journal") < 3; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  kill(master, SIGTERM);
  EXPECT_EQ(waitFor(master), 6);
  EXPECT_NE(readText(path(".bg.err")).find("--resume"), std::string::npos);
  EXPECT_FALSE(fileExists(path("out.vdb")));
  RunResult resumed = run(sampleArgs("out.vdb") + " --workers 2 --brick 32 --resume");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_GT(jsonNumber(readText(path("out.vdb.report.json")), "from_journal"), 0);
}

TEST_F(FarmCli, PoisonedBrickExitsFiveAndIsNamed) {
  std::string cmd = "FREP_TEST_CRASH_BRICK=2 '" FREP_BINARY "' " + sampleArgs("out.vdb") + " --workers 2 --brick 32";
  RunResult r;
  {
    std::string full = "cd '" + dir_ + "' && " + cmd + " >" + path(".out") + " 2>" + path(".err");
    int status = std::system(full.c_str());
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = readText(path(".err"));
  }
  EXPECT_EQ(r.code, 5);
  EXPECT_NE(r.err.find("brick 2 voxels [0,0,64)-(32,32,96)"), std::string::npos) << r.err;  // 96 points: -48..47 (leafAlignedGrid)
  EXPECT_FALSE(fileExists(path("out.vdb")));
  EXPECT_TRUE(fileExists(path("out.vdb.journal")));
}

TEST_F(FarmCli, CurveKeysProtectTheLocalFarm) {
  ASSERT_EQ(run("keygen keys").code, 0);
  for (const char* f : {"master.pub", "master.key", "worker.pub", "worker.key", "authorized"})
    EXPECT_TRUE(fileExists(path(std::string("keys/") + f))) << f;
  ASSERT_EQ(run(sampleArgs("plain.vdb") + " --workers 0").code, 0);
  RunResult r = run(sampleArgs("curve.vdb") + " --workers 2 --curve keys");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(readText(path("curve.vdb")) == readText(path("plain.vdb")));
  EXPECT_EQ(run(sampleArgs("x.vdb") + " --workers 2 --curve missing").code, 7);
}

// frep keygen replaced a directory's keys without a word, locking out every worker that held the
// old ones (issue 31): now it refuses (exit 2, nothing changed) unless --force. Secret keys are
// created 0600 (never readable by others, even for a moment), public ones 0644.
TEST_F(FarmCli, KeygenKeepsExistingKeysUnlessForced) {
  ASSERT_EQ(run("keygen keys").code, 0);
  const std::string before = readText(path("keys/master.key"));
  struct stat st {};
  ASSERT_EQ(::stat(path("keys/master.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ASSERT_EQ(::stat(path("keys/worker.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ASSERT_EQ(::stat(path("keys/master.pub").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);
  RunResult r = run("keygen keys");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("already has CURVE keys (master.pub, master.key, worker.pub, worker.key, authorized)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(readText(path("keys/master.key")), before);
  ASSERT_EQ(run("keygen keys --force").code, 0);
  EXPECT_NE(readText(path("keys/master.key")), before);
}

TEST_F(FarmCli, BadFarmArgumentsAreNamed) {
  RunResult r = run(sampleArgs("x.vdb") + " --brick 12");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--brick"), std::string::npos);
  r = run(sampleArgs("x.vdb") + " --listen localhost:5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--listen"), std::string::npos);
  // An open farm on the network needs --curve or an explicit --insecure (loopback is fine).
  r = run(sampleArgs("x.vdb") + " --listen 'tcp://*:5'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--insecure"), std::string::npos) << r.err;
  EXPECT_FALSE(fileExists(path("x.vdb")));
}

// --verify (docs/farm.md, "Verification"): the checked run's bytes are the unchecked run's and
// the report counts what was checked; bad values are exit 2 naming the option; one worker
// cannot check and says so.
TEST_F(FarmCli, VerifyChecksBricksAndRefusesBadFractions) {
  ASSERT_EQ(run(sampleArgs("plain.vdb") + " --workers 2").code, 0);
  const std::string reference = readText(path("plain.vdb"));
  RunResult r = run(sampleArgs("checked.vdb") + " --workers 2 --replicate 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(readText(path("checked.vdb")) == reference) << "output bytes differ";
  std::string report = readText(path("checked.vdb.report.json"));
  EXPECT_EQ(jsonNumber(report, "verified_bricks"), jsonNumber(report, "total")) << report;
  EXPECT_EQ(jsonNumber(report, "verify_mismatches"), 0) << report;
  EXPECT_EQ(jsonNumber(report, "liars_banned"), 0) << report;
  EXPECT_NE(r.out.find("; verified "), std::string::npos) << r.out;
  r = run(sampleArgs("quarter.vdb") + " --workers 2 --verify 0.25");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(readText(path("quarter.vdb")) == reference) << "output bytes differ";
  EXPECT_GE(jsonNumber(readText(path("quarter.vdb.report.json")), "verified_bricks"), 0);
  r = run(sampleArgs("lone.vdb") + " --workers 1 --verify 1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("--verify cannot run: one local worker"), std::string::npos) << r.err;
  EXPECT_NE(readText(path("lone.vdb.report.json")).find("\"unavailable\": \"one local worker"), std::string::npos);
  for (const char* bad : {"--verify 1.5", "--verify -0.1", "--verify nan", "--verify x", "--replicate 3",
                          "--replicate 0", "--replicate 2 --verify 0.5"}) {
    SCOPED_TRACE(bad);
    r = run(sampleArgs("x.vdb") + " " + bad);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(std::string(bad).find("--replicate") == 0 ? "--replicate" : "--verify"), std::string::npos)
        << r.err;
  }
  EXPECT_FALSE(fileExists(path("x.vdb")));
}

TEST_F(FarmCli, JsonProgressEventsForBatchSystems) {
  RunResult r = run(sampleArgs("j.vdb") + " --workers 2 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("{\"event\":\"listening\""), std::string::npos);
  EXPECT_NE(r.out.find("{\"event\":\"progress\""), std::string::npos);
  EXPECT_NE(r.out.find("{\"event\":\"done\""), std::string::npos);
}
