/**
 * \file progress.h
 * \brief A one-line progress bar with elapsed time and ETA on stderr.
 */
#pragma once

#include <chrono>
#include <mutex>
#include <string>

namespace ofv {

/**
 * \brief Progress of a long computation, drawn on stderr only when stderr is
 *        a terminal (logs and pipes stay clean):
 *
 *        `[#########.....................] 3/10 episodes, 12 s elapsed, ETA 28 s`
 *
 * Thread-safe: workers may call tick() concurrently. The line ends when the
 * total is reached, or when the bar is destroyed (an error message then
 * starts on its own line).
 */
class ProgressBar {
 public:
  /**
   * \param total   amount of work, in `unit`s
   * \param unit    word after the counts, e.g. `"episodes"` or `"s"`
   * \param enabled false draws nothing (e.g. `--quiet`)
   */
  ProgressBar(double total, std::string unit, bool enabled = true);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// \brief Adds `amount` units done and redraws.
  void tick(double amount = 1.0);
  /// \brief Sets the units done (e.g. the simulated time [s]) and redraws.
  void set(double done);
  /// \brief Units done so far.
  [[nodiscard]] double done() const;

 private:
  void draw();  // with mutex_ held

  double total_;
  std::string unit_;
  bool drawn_;  ///< enabled and stderr is a terminal
  bool line_open_ = false;  ///< drawn, without its final newline yet
  bool finished_ = false;   ///< the total was reached and the line ended
  double done_ = 0.0;
  mutable std::mutex mutex_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace ofv
