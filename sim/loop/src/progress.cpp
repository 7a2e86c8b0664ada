// A progress bar on stderr, shared by the long-running commands.
#include "ofv/loop/progress.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>

#include <unistd.h>

namespace ofv {

ProgressBar::ProgressBar(double total, std::string unit, bool enabled)
    : total_(total), unit_(std::move(unit)), drawn_(enabled && isatty(2) != 0) {}

ProgressBar::~ProgressBar() {
  if (line_open_) std::fprintf(stderr, "\n");
}

void ProgressBar::tick(double amount) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += amount;
  draw();
}

void ProgressBar::set(double done) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = done;
  draw();
}

double ProgressBar::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_;
}

void ProgressBar::draw() {
  if (!drawn_ || finished_) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = done_ > 0.0 ? elapsed / done_ * (total_ - done_) : 0.0;
  constexpr int kWidth = 30;
  // Multiplied first: exact for whole counts (3 of 10 fills 9 cells, not 8).
  const int filled = total_ > 0.0 ? std::min(kWidth, static_cast<int>(kWidth * done_ / total_)) : kWidth;
  std::fprintf(stderr, "\r[%s%s] %g/%g %s, %.0f s elapsed, ETA %.0f s ",
               std::string(static_cast<std::size_t>(filled), '#').c_str(),
               std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(), done_, total_,
               unit_.c_str(), elapsed, eta);
  finished_ = done_ >= total_;
  line_open_ = !finished_;
  if (finished_) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

}  // namespace ofv
