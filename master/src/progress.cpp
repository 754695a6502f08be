#include "frep/master/progress.h"

#include <cstdio>
#include <memory>
#include <mutex>

#include "frep/master/status_line.h"

namespace frep::farm {

double etaSeconds(uint64_t done, uint64_t total, double elapsed) {
  if (done >= total) return 0;
  if (done == 0) return -1;
  return elapsed * double(total - done) / double(done);
}

std::string progressLine(uint64_t done, uint64_t total, double evalsPerSec, double eta, int workers) {
  const int width = 30;
  const int fill = total ? int(width * done / total) : width;
  std::string bar(size_t(width), '.');
  for (int i = 0; i < fill; ++i) bar[size_t(i)] = '#';
  char etaText[32];
  if (eta < 0) std::snprintf(etaText, sizeof etaText, "ETA --");
  else std::snprintf(etaText, sizeof etaText, "ETA %.0f s", eta);
  char line[160];
  std::snprintf(line, sizeof line, "[%s] %llu/%llu bricks  %.2f M evals/s  %s  workers %d", bar.c_str(),
                (unsigned long long)done, (unsigned long long)total, evalsPerSec / 1e6, etaText, workers);
  return line;
}

std::string simplifyLine(int stage, uint64_t done, uint64_t total) {
  const int width = 30;
  const int fill = total ? int(width * done / total) : width;
  std::string bar(size_t(width), '.');
  for (int i = 0; i < fill; ++i) bar[size_t(i)] = '#';
  char line[160];
  std::snprintf(line, sizeof line, "[%s] simplifying: pass %d of 5, %llu/%llu %s", bar.c_str(), stage + 1,
                (unsigned long long)done, (unsigned long long)total, stage < 4 ? "blocks" : "candidates");
  return line;
}

std::function<void(int, uint64_t, uint64_t)> simplifyProgress(bool bar, bool json) {
  if (!bar && !json) return {};
  struct State {
    std::mutex mutex;
    std::chrono::steady_clock::time_point last{};
  };
  auto state = std::make_shared<State>();
  return [=](int stage, uint64_t done, uint64_t total) {
    std::lock_guard<std::mutex> lock(state->mutex);
    const auto now = std::chrono::steady_clock::now();
    const bool end = done == total;  // a pass's first and last calls are always shown
    if (!end && done != 0 && now - state->last < std::chrono::milliseconds(200)) return;
    state->last = now;
    if (json) {
      std::printf("{\"event\":\"progress\",\"phase\":\"simplify\",\"pass\":%d,\"done\":%llu,\"total\":%llu}\n",
                  stage + 1, (unsigned long long)done, (unsigned long long)total);
      std::fflush(stdout);
    }
    if (bar) {
      StatusLine::instance().show(simplifyLine(stage, done, total));
      if (stage == 4 && end) StatusLine::instance().finish();
    }
  };
}

Progress::Progress(bool bar, bool json, uint64_t total)
    : bar_(bar), json_(json), total_(total), start_(std::chrono::steady_clock::now()), last_() {}

void Progress::update(uint64_t done, uint64_t evals, int workers, bool force) {
  if (!bar_ && !json_) return;
  auto now = std::chrono::steady_clock::now();
  if (!force && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  double secs = std::chrono::duration<double>(now - start_).count();
  double rate = secs > 0 ? double(evals) / secs : 0;
  double eta = etaSeconds(done, total_, secs);
  if (json_) {
    char etaText[32];
    if (eta < 0) std::snprintf(etaText, sizeof etaText, "null");
    else std::snprintf(etaText, sizeof etaText, "%.1f", eta);
    std::printf("{\"event\":\"progress\",\"bricks_done\":%llu,\"bricks_total\":%llu,\"evals_per_s\":%.0f,"
                "\"eta_s\":%s,\"workers_alive\":%d,\"elapsed_s\":%.2f}\n",
                (unsigned long long)done, (unsigned long long)total_, rate, etaText, workers, secs);
    std::fflush(stdout);
  }
  if (bar_) StatusLine::instance().show(progressLine(done, total_, rate, eta, workers));
}

void Progress::finish(uint64_t done, uint64_t evals, int workers) {
  update(done, evals, workers, true);
  if (bar_) StatusLine::instance().finish();
}

}  // namespace frep::farm
