// frep view's child processes (cli/view_child.h): output and exit status captured, a cancel
// answered by SIGTERM, and SIGKILL for a child that ignores it, with what it started.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <thread>

#include "view_child.h"

namespace frep::cli {
namespace {

TEST(ViewChild, CapturesBothStreamsAndTheExitCode) {
  ChildResult r = runChild({"/bin/sh", "-c", "echo out; echo err >&2; exit 3"}, nullptr);
  EXPECT_EQ(r.out, "out\n");
  EXPECT_EQ(r.err, "err\n");
  EXPECT_EQ(r.exitCode, 3);
  EXPECT_FALSE(r.cancelled);
}

TEST(ViewChild, AProgramThatCannotRunSaysWhy) {
  ChildResult r = runChild({"/nonexistent/frep", "mesh"}, nullptr);
  EXPECT_EQ(r.exitCode, 127);
  EXPECT_NE(r.err.find("cannot run /nonexistent/frep: No such file or directory"), std::string::npos) << r.err;
}

TEST(ViewChild, CancelSendsSigterm) {
  std::atomic<bool> cancel{false};
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    cancel = true;
  });
  // exec: the shell becomes sleep, which SIGTERM ends (status 128 + 15).
  ChildResult r = runChild({"/bin/sh", "-c", "exec sleep 60"}, &cancel);
  canceller.join();
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.exitCode, 128 + 15);
}

TEST(ViewChild, AChildIgnoringSigtermIsKilledWithWhatItStarted) {
  const std::string ready = ::testing::TempDir() + "view_child_ready";
  std::remove(ready.c_str());
  std::atomic<bool> cancel{false};
  std::thread canceller([&] {
    while (!std::ifstream(ready)) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    cancel = true;  // the trap is set
  });
  // The shell ignores SIGTERM and so does its sleep, which holds the output pipes: both go by
  // the group's SIGKILL, else this would wait for the minute.
  ChildResult r = runChild({"/bin/sh", "-c", "trap '' TERM; touch '" + ready + "'; sleep 60; echo late"}, &cancel);
  canceller.join();
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.exitCode, 128 + 9);
  EXPECT_EQ(r.out, "");
  std::remove(ready.c_str());
}

}  // namespace
}  // namespace frep::cli
