// The live display: its state machine, its refusal without a display, and,
// under Xvfb, its windows (grabbed back with vpDisplay::getImage), the pause
// and the quit, with the display driven from a real simulated episode.
#include "ofv/display/live_display.h"

#include "ofv/loop/episode.h"

#include <gtest/gtest.h>
#include <visp3/core/vpImageTools.h>
#include <visp3/io/vpImageIo.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

namespace ofv {
namespace {

using State = DisplayControl::State;
using Event = DisplayControl::Event;

TEST(DisplayControl, LeftClickPausesAndResumes) {
  DisplayControl c;
  EXPECT_EQ(c.state(), State::Running);
  EXPECT_EQ(c.handle(Event::LeftClick), State::Paused);
  EXPECT_EQ(c.handle(Event::LeftClick), State::Running);
  EXPECT_EQ(c.handle(Event::MiddleClick), State::Paused);
  EXPECT_EQ(c.handle(Event::PauseKey), State::Running);
}

TEST(DisplayControl, RightClickOrQuitKeyEndsFromEitherStateForGood) {
  for (const Event quit : {Event::RightClick, Event::QuitKey}) {
    DisplayControl running, paused;
    EXPECT_EQ(running.handle(quit), State::Quit);
    paused.handle(Event::LeftClick);
    EXPECT_EQ(paused.handle(quit), State::Quit);
    for (const Event e : {Event::LeftClick, Event::MiddleClick, Event::PauseKey})
      EXPECT_EQ(paused.handle(e), State::Quit);
  }
}

TEST(DisplayControl, WithoutPauseOnlyQuitChangesTheState) {
  DisplayControl c(/*pausable=*/false);
  for (const Event e : {Event::LeftClick, Event::MiddleClick, Event::PauseKey})
    EXPECT_EQ(c.handle(e), State::Running);
  EXPECT_EQ(c.handle(Event::QuitKey), State::Quit);
}

TEST(DisplayControl, KeysMapToEvents) {
  EXPECT_EQ(DisplayControl::key_event("q"), Event::QuitKey);
  EXPECT_EQ(DisplayControl::key_event("\x1b"), Event::QuitKey);
  EXPECT_EQ(DisplayControl::key_event(" "), Event::PauseKey);
  EXPECT_EQ(DisplayControl::key_event("p"), Event::PauseKey);
  EXPECT_FALSE(DisplayControl::key_event("x").has_value());
}

// Restores DISPLAY when the test ends.
class DisplayEnv {
 public:
  DisplayEnv() {
    if (const char* d = std::getenv("DISPLAY")) saved_ = d;
  }
  ~DisplayEnv() {
    if (saved_.empty()) {
      unsetenv("DISPLAY");
    } else {
      setenv("DISPLAY", saved_.c_str(), 1);
    }
  }
  DisplayEnv(const DisplayEnv&) = delete;
  DisplayEnv& operator=(const DisplayEnv&) = delete;

 private:
  std::string saved_;
};

TEST(LiveDisplay, WithoutDisplayThrowsOneLine) {
  const DisplayEnv env;
  unsetenv("DISPLAY");
  try {
    LiveDisplay display({});
    FAIL() << "opened a display without DISPLAY";
  } catch (const DisplayUnavailable& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("DISPLAY is not set"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(LiveDisplay, UnreachableDisplayThrowsOneLine) {
  const DisplayEnv env;
  setenv("DISPLAY", ":4093", 1);  // no server there
  try {
    LiveDisplay display({});
    FAIL() << "opened display :4093";
  } catch (const DisplayUnavailable& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(":4093"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// The X tests need a display; under ctest they run through xvfb-run with
// OFV_REQUIRE_DISPLAY set, so that they cannot pass by skipping.
bool have_display() {
  const char* d = std::getenv("DISPLAY");
  return d != nullptr && *d != '\0';
}
#define REQUIRE_DISPLAY()                                                            \
  do {                                                                               \
    if (!have_display()) {                                                           \
      if (std::getenv("OFV_REQUIRE_DISPLAY")) FAIL() << "no DISPLAY under xvfb-run"; \
      GTEST_SKIP() << "no DISPLAY (the ctest display.* tests run under xvfb-run)";   \
    }                                                                                \
  } while (0)

// Pixels of exactly `colour` within `radius` of (u, v).
int count_near(const vpImage<vpRGBa>& I, double u, double v, int radius, const vpRGBa& colour) {
  int n = 0;
  for (int r = static_cast<int>(v) - radius; r <= static_cast<int>(v) + radius; ++r) {
    for (int c = static_cast<int>(u) - radius; c <= static_cast<int>(u) + radius; ++c) {
      if (r < 0 || c < 0 || r >= static_cast<int>(I.getHeight()) ||
          c >= static_cast<int>(I.getWidth()))
        continue;
      const vpRGBa& p = I[r][c];
      n += p.R == colour.R && p.G == colour.G && p.B == colour.B ? 1 : 0;
    }
  }
  return n;
}

int count(const vpImage<vpRGBa>& I, const vpRGBa& colour) {
  return count_near(I, I.getWidth() / 2.0, I.getHeight() / 2.0,
                    static_cast<int>(std::max(I.getWidth(), I.getHeight())), colour);
}

EpisodeSetup short_episode(double duration) {
  return resolve_episode(sim::load_scenario("dvd-one-hand"),
                         {{"duration", std::to_string(duration)}, {"perception", "ground-truth"}});
}

TEST(LiveDisplay, WindowsShowTheDrawingsAtTheProjectedCentroid) {
  REQUIRE_DISPLAY();
  const EpisodeSetup setup =
      short_episode(1.2);  // the hand is in the sphere by then: tracks, occluders
  LiveDisplayOptions options;
  options.title = "ofv-test";
  options.r_sphere = setup.loop.estimator.resolve().r_sphere;
  options.ground_truth = true;
  LiveDisplay display(options);
  StepRecord last;
  int occluded_frames = 0;
  const EpisodeOutcome outcome =
      run_episode(setup, [&](const StepRecord& rec, const StepDetail& d) {
        ASSERT_TRUE(display.observe(rec, d));
        last = rec;
        occluded_frames += d.observation->problem && d.observation->problem->occluders.cols() > 0 ? 1 : 0;
      });
  ASSERT_GT(occluded_frames, 0);

  // Where the true centroid projects (independently of the display).
  const CameraIntrinsics k = sim::load_scenario("dvd-one-hand").sensor.intrinsics;
  const Eigen::Vector3d c = last.wMc.inverse() * last.true_centroid;
  const double u = k.fx * c.x() / c.z() + k.cx, v = k.fy * c.y() / c.z() + k.cy;
  ASSERT_TRUE(display.last_centroid_pixel().has_value());

  vpImage<vpRGBa> camera, scene, plot;
  display.grab_camera(camera);
  display.grab_scene(scene);
  display.grab_plot(plot);
  ASSERT_EQ(camera.getWidth(), static_cast<unsigned>(k.width));
  ASSERT_EQ(camera.getHeight(), static_cast<unsigned>(k.height));
  ASSERT_EQ(scene.getWidth(), 640u);
  if (const char* dir = std::getenv("OFV_DISPLAY_SNAPSHOT_DIR")) {
    vpImageIo::write(camera, std::string(dir) + "/display_camera.png");
    vpImageIo::write(scene, std::string(dir) + "/display_scene.png");
    vpImageIo::write(plot, std::string(dir) + "/display_plot.png");
  }
  // The feature's current value, a green cross, at the projected centroid
  // (the estimator's centroid is within a few pixels of the true one).
  EXPECT_GE(count_near(camera, u, v, 10, vpRGBa(0, 255, 0)), 12) << "u " << u << " v " << v;
  // The desired value, a yellow circle and cross, at the image centre.
  EXPECT_GE(count_near(camera, k.cx, k.cy, 12, vpRGBa(255, 255, 0)), 20);
  // Supervoxels (blue discs) and the hand's occluder cells (red squares).
  EXPECT_GE(count(camera, vpRGBa(60, 160, 255)), 20);
  EXPECT_GE(count(camera, vpRGBa(230, 60, 60)), 9);
  // The rendered frame is underneath: many colours, not a blank window.
  int differing = 0;
  for (unsigned i = 1; i < camera.getSize(); ++i)
    differing += camera.bitmap[i] == camera.bitmap[0] ? 0 : 1;
  EXPECT_GT(differing, static_cast<int>(camera.getSize() / 2));
  // The scene view: drawn on its dark background, with the supervoxels.
  EXPECT_LT(count(scene, vpRGBa(30, 30, 30)), static_cast<int>(scene.getSize()) - 2000);
  EXPECT_GT(count(scene, vpRGBa(60, 160, 255)), 0);
  // The curves: three graphs drawn over the window.
  ASSERT_GT(plot.getSize(), 0u);
  int drawn = 0;
  for (unsigned i = 1; i < plot.getSize(); ++i) drawn += plot.bitmap[i] == plot.bitmap[0] ? 0 : 1;
  EXPECT_GT(drawn, 5000);
  // The feature error is the sphere feature's value (s* = 0).
  ASSERT_EQ(display.last_feature_error().size(), 6u);
  EXPECT_LT(std::abs(display.last_feature_error()[2]), 0.05);  // on the sphere within 5 cm
  EXPECT_EQ(outcome.steps.size(), static_cast<std::size_t>(outcome.metrics.steps));
}

TEST(LiveDisplay, PauseCallsTheHookAndWaitsUntilResumed) {
  REQUIRE_DISPLAY();
  const EpisodeSetup setup = short_episode(0.2);
  LiveDisplayOptions options;
  options.plot = false;
  LiveDisplay display(options);
  std::atomic<int> hooked{0};
  // The hook runs while the display waits: resume from another thread a little later.
  std::thread resumer;
  display.set_pause_hook([&] {
    ++hooked;
    resumer = std::thread([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      display.handle(Event::LeftClick);
    });
  });
  int frames = 0;
  std::chrono::duration<double> longest{0};
  (void)run_episode(setup, [&](const StepRecord& rec, const StepDetail& d) {
    if (frames == 2) display.handle(Event::LeftClick);  // pause before the third frame
    const auto start = std::chrono::steady_clock::now();
    EXPECT_TRUE(display.observe(rec, d));
    longest =
        std::max(longest, std::chrono::duration<double>(std::chrono::steady_clock::now() - start));
    ++frames;
  });
  if (resumer.joinable()) resumer.join();
  EXPECT_EQ(hooked.load(), 1);
  EXPECT_GE(longest.count(), 0.18);
  EXPECT_EQ(display.state(), State::Running);
}

TEST(LiveDisplay, QuitEndsTheEpisodeFromTheObserver) {
  REQUIRE_DISPLAY();
  const EpisodeSetup setup = short_episode(1.0);
  LiveDisplayOptions options;
  options.scene = false;
  LiveDisplay display(options);
  struct Quit {};
  int frames = 0;
  bool quit = false;
  try {
    (void)run_episode(setup, [&](const StepRecord& rec, const StepDetail& d) {
      if (++frames == 5) display.handle(Event::RightClick);
      if (!display.observe(rec, d)) throw Quit{};
    });
  } catch (const Quit&) {
    quit = true;
  }
  EXPECT_TRUE(quit);
  EXPECT_EQ(frames, 5);
  EXPECT_TRUE(display.quit_requested());
  EXPECT_FALSE(display.show({}));  // stays ended
}

TEST(LiveDisplay, ALoopOfOnesOwnAndHoursOfCurves) {
  REQUIRE_DISPLAY();
  LiveDisplayOptions options;
  options.scene = false;
  LiveDisplay display(options);
  // No sensor, no ViewLoop: a centroid 0.5 m ahead, a target on the sphere,
  // a twist; the curves start again past their window (every 2 minutes).
  for (int k = 0; k <= 40; ++k) {
    DisplayInput in;
    in.time = 10.0 * k;
    in.centroid = Eigen::Vector3d(0, 0, 0.5);
    in.target = Eigen::Vector3d(0.25, 0, 0.5 - 0.433);
    in.velocity = vpColVector{0.01 * k, 0, 0, 0, 0, 0};
    ASSERT_TRUE(display.show(in));
  }
  vpImage<vpRGBa> camera;
  display.grab_camera(camera);
  ASSERT_EQ(camera.getWidth(), 640u);  // the default intrinsics
  EXPECT_GE(count_near(camera, 320, 240, 10, vpRGBa(0, 255, 0)), 12);  // C at the centre
  ASSERT_EQ(display.last_feature_error().size(), 6u);
  EXPECT_NEAR(display.last_feature_error()[2], 0.0, 1e-9);  // the camera at 0.5 m: on the sphere
}

}  // namespace
}  // namespace ofv
