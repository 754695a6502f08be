#include "frep/master/status_line.h"

namespace frep::farm {

StatusLine& StatusLine::instance() {
  static StatusLine line;
  return line;
}

void StatusLine::show(const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Padded to the previous text's length: a shorter line leaves none of the longer one behind.
  std::string padded = text;
  if (shown_ && text_.size() > padded.size()) padded.append(text_.size() - padded.size(), ' ');
  text_ = text;
  shown_ = true;
  std::fputs(("\r" + padded).c_str(), out_);
  std::fflush(out_);
}

void StatusLine::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shown_) std::fputs("\n", out_);
  std::fflush(out_);
  shown_ = false;
  text_.clear();
}

void StatusLine::setStream(std::FILE* out) {
  std::lock_guard<std::mutex> lock(mutex_);
  out_ = out;
}

}  // namespace frep::farm
