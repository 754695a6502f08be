#include "progress.h"

#include <cstdio>

namespace frep::farm {

Progress::Progress(bool bar, bool json, uint64_t total)
    : bar_(bar), json_(json), total_(total), start_(std::chrono::steady_clock::now()), last_() {}

void Progress::update(uint64_t done, uint64_t evals, int workers, bool force) {
  if (!bar_ && !json_) return;
  auto now = std::chrono::steady_clock::now();
  if (!force && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  double secs = std::chrono::duration<double>(now - start_).count();
  double rate = secs > 0 ? double(evals) / secs : 0;
  double eta = done > 0 && done < total_ ? secs * double(total_ - done) / double(done) : 0;
  if (json_) {
    std::printf("{\"event\":\"progress\",\"bricks_done\":%llu,\"bricks_total\":%llu,\"evals_per_s\":%.0f,"
                "\"eta_s\":%.1f,\"workers_alive\":%d,\"elapsed_s\":%.2f}\n",
                (unsigned long long)done, (unsigned long long)total_, rate, eta, workers, secs);
    std::fflush(stdout);
  }
  if (bar_) {
    const int width = 30;
    int fill = total_ ? int(width * done / total_) : width;
    char barText[width + 1];
    for (int i = 0; i < width; ++i) barText[i] = i < fill ? '#' : '.';
    barText[width] = 0;
    std::fprintf(stderr, "\r[%s] %llu/%llu bricks  %.2f M evals/s  ETA %.0f s  workers %d   ", barText,
                 (unsigned long long)done, (unsigned long long)total_, rate / 1e6, eta, workers);
    std::fflush(stderr);
  }
}

void Progress::finish(uint64_t done, uint64_t evals, int workers) {
  update(done, evals, workers, true);
  if (bar_) std::fprintf(stderr, "\n");
}

}  // namespace frep::farm
