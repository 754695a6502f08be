// The one line of stderr that a progress bar redraws in place, and a spdlog sink that keeps log
// lines from breaking it: the bar is erased, the log line written, the bar drawn again below.
#pragma once

#include <cstdio>
#include <memory>
#include <mutex>
#include <string>

#include <spdlog/sinks/sink.h>

namespace frep::farm {

class StatusLine {
 public:
  static StatusLine& instance();
  void show(const std::string& text);  // replaces the line's text (drawn with "\r")
  void finish();                       // ends the line (newline); later output starts below it
  void setStream(std::FILE* out);      // stderr unless changed (tests)

  // For the sink: erase the line, run `write`, draw the line again.
  template <class Write>
  void around(Write&& write) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shown_) std::fputs("\r\033[K", out_);
    std::fflush(out_);
    write();
    if (shown_) std::fputs(("\r" + text_).c_str(), out_);
    std::fflush(out_);
  }

 private:
  std::mutex mutex_;
  std::FILE* out_ = stderr;
  std::string text_;
  bool shown_ = false;
};

// Forwards every log line to `inner` (which writes to the same terminal) around the status line.
class LineSafeSink : public spdlog::sinks::sink {
 public:
  explicit LineSafeSink(std::shared_ptr<spdlog::sinks::sink> inner) : inner_(std::move(inner)) {}
  void log(const spdlog::details::log_msg& msg) override {
    StatusLine::instance().around([&] {
      inner_->log(msg);
      inner_->flush();
    });
  }
  void flush() override { inner_->flush(); }
  void set_pattern(const std::string& pattern) override { inner_->set_pattern(pattern); }
  void set_formatter(std::unique_ptr<spdlog::formatter> f) override { inner_->set_formatter(std::move(f)); }

 private:
  std::shared_ptr<spdlog::sinks::sink> inner_;
};

}  // namespace frep::farm
