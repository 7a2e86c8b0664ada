// ofv::ProgressBar: counting from several threads, silence off a terminal.
#include "ofv/loop/progress.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include <unistd.h>

namespace ofv {
namespace {

TEST(ProgressBar, CountsTicksFromSeveralThreads) {
  constexpr int kThreads = 4;
  constexpr int kTicks = 500;
  ProgressBar bar(kThreads * kTicks, "episodes", false);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      for (int k = 0; k < kTicks; ++k) bar.tick();
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_DOUBLE_EQ(bar.done(), kThreads * kTicks);
}

TEST(ProgressBar, SetReplacesTheAmountDone) {
  ProgressBar bar(4.0, "s", false);
  bar.tick(0.5);
  bar.set(2.25);
  EXPECT_DOUBLE_EQ(bar.done(), 2.25);
}

TEST(ProgressBar, DrawsNothingWhenStderrIsNotATerminal) {
  if (isatty(2) != 0) GTEST_SKIP() << "stderr is a terminal";
  testing::internal::CaptureStderr();
  {
    ProgressBar bar(3.0, "episodes");
    for (int k = 0; k < 3; ++k) bar.tick();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace ofv
