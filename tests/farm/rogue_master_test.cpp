// A worker against a scripted rogue master (docs/farm.md, "Threat model"): a job's model may
// name any path, and the worker opens none of them unless the job ships the file or the path
// lies inside the worker's --data-dir; what it answers never quotes a file's bytes and never
// waits on a FIFO or reads a device.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <zmq.hpp>

#include "farm_test_util.h"
#include "frep/net/wire.h"

using namespace farmtest;

namespace {

using Clock = std::chrono::steady_clock;

// A master scripted by the test: a ROUTER that speaks the protocol by hand.
struct RogueMaster {
  zmq::context_t ctx{1};
  zmq::socket_t router{ctx, zmq::socket_type::router};
  std::string endpoint;
  std::string worker;  // the worker's routing id, from its hello
  RogueMaster() {
    router.set(zmq::sockopt::linger, 0);
    router.bind("tcp://127.0.0.1:*");
    endpoint = router.get(zmq::sockopt::last_endpoint);
  }
  // The next message that is not a heartbeat, within `ms` (body_case 0 if none came).
  Incoming next(int ms = 10000) {
    Incoming in;
    std::string err;
    auto deadline = Clock::now() + std::chrono::milliseconds(ms);
    while (Clock::now() < deadline) {
      zmq::pollitem_t item{static_cast<void*>(router), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(50));
      while (receive(router, true, in, &err))
        if (err.empty() && in.envelope.body_case() != Envelope::kHeartbeat) return in;
    }
    return Incoming{};
  }
  void acceptHello() {
    Incoming hello = next();
    ASSERT_EQ(hello.envelope.body_case(), Envelope::kHello);
    worker = hello.routingId;
  }
  // Welcomes the worker to `job` and leases it brick 0; returns the worker's answer and how
  // long it took.
  Incoming runBrick(const JobSpec& job, double* seconds) {
    Envelope w;
    w.set_job_id(jobIdOf(job));
    w.mutable_welcome()->set_heartbeat_ms(uint32_t(scaledMs(100)));
    *w.mutable_welcome()->mutable_job() = job;
    send(router, worker, w);
    Envelope t;
    t.set_job_id(jobIdOf(job));
    t.mutable_task()->set_brick_id(0);
    t.mutable_task()->set_attempt(1);
    for (int a = 0; a < 3; ++a) t.mutable_task()->add_lo(0), t.mutable_task()->add_hi(8);
    const auto t0 = Clock::now();
    send(router, worker, t);
    Incoming answer = next(20000);
    *seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return answer;
  }
  void bye() {
    Envelope b;
    b.mutable_bye()->set_reason("test over");
    send(router, worker, b);
  }
};

JobSpec jobReading(const std::string& call) {
  JobSpec j;
  j.set_operation("sample");
  j.set_model_source("my_model(x[3], a[1]) { my_model = " + call + "; }");
  j.set_model_name("rogue.hf");
  setGrid(j, GridSpec::fromBounds({-1, -1, -1}, {1, 1, 1}, 8));
  j.set_band(3);
  return j;
}

std::string splineOf(const std::string& path) { return "frVolumeSplineFile(x, \"" + path + "\", 0.01)"; }

struct TempDir {
  std::string path;
  TempDir() {
    char t[] = "/tmp/frep-rogue-XXXXXX";
    path = mkdtemp(t);
  }
  ~TempDir() { std::system(("rm -rf '" + path + "'").c_str()); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path + "/" + name, std::ios::binary) << text;
    return path + "/" + name;
  }
};

const char* kPoints = "0 0 0 1\n1 0 0 -1\n0 1 0 -1\n0 0 1 -1\n-1 -1 -1 -1\n";

}  // namespace

// The rows of issue 31: /etc/passwd (whose first token came back in the error), /dev/zero (read
// to 1 GB), a FIFO (parked the worker), a path that climbs out of the model's directory, a
// symbolic link and a file of the worker's own: each brick fails at once with a message that
// names the path and says why, and carries none of the file's bytes.
TEST(RogueMaster, AWorkerOpensNoPathTheJobDoesNotShip) {
  TempDir d;
  const std::string fifo = d.path + "/fifo.xyz";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string secret = d.write("secret.xyz", "TOPSECRET 1 2 3\n");
  ASSERT_EQ(symlink("/etc/passwd", (d.path + "/link.xyz").c_str()), 0);
  RogueMaster m;
  WorkerProcess worker(m.endpoint);
  m.acceptHello();
  for (const std::string& path : {std::string("/etc/passwd"), std::string("/dev/zero"), fifo,
                                  std::string("../../../../../../etc/passwd"), d.path + "/link.xyz", secret}) {
    double seconds = 0;
    Incoming a = m.runBrick(jobReading(splineOf(path)), &seconds);
    ASSERT_EQ(a.envelope.body_case(), Envelope::kFailed) << path << ": no failure within 20 s";
    const std::string& err = a.envelope.failed().error();
    EXPECT_FALSE(a.envelope.failed().handed_back());
    EXPECT_NE(err.find("'" + path + "'"), std::string::npos) << err;
    EXPECT_NE(err.find("is not among the files the job ships"), std::string::npos) << err;
    EXPECT_NE(err.find("--data-dir"), std::string::npos) << err;
    EXPECT_EQ(err.find("root:"), std::string::npos) << err;
    EXPECT_EQ(err.find("TOPSECRET"), std::string::npos) << err;
    EXPECT_LT(seconds, 5.0) << path;
    std::printf("[ rogue    ] %s refused in %.2f ms\n", path.c_str(), seconds * 1e3);
  }
  // A job that ships its file is computed, as before.
  JobSpec shipped = jobReading(splineOf("points.xyz"));
  ModelFile* f = shipped.add_model_files();
  f->set_path("points.xyz");
  f->set_contents(kPoints);
  f->set_hash(modelFileHash(kPoints));
  double seconds = 0;
  EXPECT_EQ(m.runBrick(shipped, &seconds).envelope.body_case(), Envelope::kResult);
  m.bye();
  EXPECT_EQ(worker.wait(20), 0);
}

// frep-worker --data-dir DIR: regular files inside DIR are read (relative to DIR), nothing
// else: not a link leading out, not a FIFO or device inside, not a path that climbs out; a
// file that is no point cloud is named by line and byte, its text not quoted.
TEST(RogueMaster, DataDirAllowsRegularFilesInsideItOnly) {
  TempDir d;
  d.write("points.xyz", kPoints);
  d.write("secret.xyz", "TOPSECRET 1 2 3\n");
  ASSERT_EQ(mkfifo((d.path + "/fifo.xyz").c_str(), 0600), 0);
  ASSERT_EQ(symlink("/etc/passwd", (d.path + "/link.xyz").c_str()), 0);
  ASSERT_EQ(symlink("/dev/zero", (d.path + "/zero.xyz").c_str()), 0);
  ASSERT_EQ(mkdir((d.path + "/sub").c_str(), 0700), 0);
  d.write("sub/inner.xyz", kPoints);
  RogueMaster m;
  WorkerProcess worker(m.endpoint, {}, {"--data-dir", d.path});
  m.acceptHello();
  double seconds = 0;
  EXPECT_EQ(m.runBrick(jobReading(splineOf("points.xyz")), &seconds).envelope.body_case(), Envelope::kResult);
  EXPECT_EQ(m.runBrick(jobReading(splineOf("sub/../sub/inner.xyz")), &seconds).envelope.body_case(),
            Envelope::kResult);
  EXPECT_EQ(m.runBrick(jobReading(splineOf(d.path + "/points.xyz")), &seconds).envelope.body_case(),
            Envelope::kResult);
  struct Case {
    std::string path, says;
  };
  for (const Case& c : {Case{"/etc/passwd", "outside the worker's data directory"},
                        Case{"../../../../../../etc/passwd", "outside the worker's data directory"},
                        Case{"link.xyz", "outside the worker's data directory"},
                        Case{"zero.xyz", "outside the worker's data directory"},
                        Case{"fifo.xyz", "is not a regular file"},
                        Case{"sub", "is a directory"},
                        Case{"none.xyz", "nor in the worker's data directory"},
                        Case{"secret.xyz", "frVolumeSplineFile: secret.xyz:1: not a finite number at byte 1"}}) {
    Incoming a = m.runBrick(jobReading(splineOf(c.path)), &seconds);
    ASSERT_EQ(a.envelope.body_case(), Envelope::kFailed) << c.path;
    const std::string& err = a.envelope.failed().error();
    EXPECT_NE(err.find(c.says), std::string::npos) << c.path << ": " << err;
    EXPECT_EQ(err.find("root:"), std::string::npos) << err;
    EXPECT_EQ(err.find("TOPSECRET"), std::string::npos) << err;
    EXPECT_LT(seconds, 5.0) << c.path;
  }
  m.bye();
  EXPECT_EQ(worker.wait(20), 0);
}

// frep-worker --data-dir refuses what is not a directory (exit 2).
TEST(RogueMaster, DataDirMustBeADirectory) {
  WorkerProcess w("tcp://127.0.0.1:9", {}, {"--data-dir", "/etc/passwd"});
  EXPECT_EQ(w.wait(20), 2);
}
