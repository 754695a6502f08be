// The progress bar's text, its ETA, and log lines printed around it (status_line.h).
#include "frep/master/progress.h"
#include "frep/master/status_line.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <mutex>
#include <string>

using namespace frep::farm;

TEST(Progress, NoEtaBeforeTheFirstBrick) {
  EXPECT_LT(etaSeconds(0, 8, 3.0), 0);
  EXPECT_DOUBLE_EQ(etaSeconds(2, 8, 3.0), 9.0);  // 3 s for 2 bricks: 9 s for the other 6
  EXPECT_DOUBLE_EQ(etaSeconds(8, 8, 3.0), 0.0);
  const std::string start = progressLine(0, 8, 0, etaSeconds(0, 8, 0.0), 2);
  EXPECT_NE(start.find("ETA --"), std::string::npos) << start;
  EXPECT_EQ(start.find("ETA 0 s"), std::string::npos) << start;
  EXPECT_EQ(progressLine(2, 8, 1.5e6, 9.0, 2),
            "[#######.......................] 2/8 bricks  1.50 M evals/s  ETA 9 s  workers 2");
  EXPECT_EQ(simplifyLine(4, 50, 100), "[###############...............] simplifying: pass 5 of 5, 50/100 candidates");
  EXPECT_EQ(simplifyLine(0, 1, 4), "[#######.......................] simplifying: pass 1 of 5, 1/4 blocks");
}

namespace {

// Writes the formatted line to a FILE (the terminal of the test).
class FileSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit FileSink(std::FILE* f) : f_(f) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    spdlog::memory_buf_t buf;
    formatter_->format(msg, buf);
    std::fwrite(buf.data(), 1, buf.size(), f_);
  }
  void flush_() override { std::fflush(f_); }

 private:
  std::FILE* f_;
};

std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[256];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  return s;
}

}  // namespace

TEST(StatusLine, LogLinesAreWrittenAboveTheBarNotThroughIt) {
  std::FILE* term = std::tmpfile();
  ASSERT_NE(term, nullptr);
  StatusLine& line = StatusLine::instance();
  line.setStream(term);
  auto logger = std::make_shared<spdlog::logger>("status_line_test", std::make_shared<LineSafeSink>(std::make_shared<FileSink>(term)));
  logger->set_pattern("frep: %l: %v");
  logger->info("before the bar");
  line.show("[##..] 1/2 bricks");
  logger->warn("worker 3 dropped");
  line.show("[####] 2/2");  // shorter: padded over the longer text
  line.finish();
  logger->info("after the bar");
  line.setStream(stderr);
  EXPECT_EQ(contents(term),
            "frep: info: before the bar\n"
            "\r[##..] 1/2 bricks"
            "\r\033[K" "frep: warning: worker 3 dropped\n" "\r[##..] 1/2 bricks"
            "\r[####] 2/2       "
            "\n"
            "frep: info: after the bar\n");
  std::fclose(term);
}
