// Live ViSP windows on the closed loop: camera image with the loop's state,
// the scene view, and vpPlot curves; clicks and keys pause and end the run.
#include "ofv/display/live_display.h"

#include "ofv/loop/scene_picture.h"
#include "ofv/servo/feature_sphere_view.h"
#include "ofv/servo/target_pose.h"

#include <visp3/core/vpConfig.h>
#include <visp3/core/vpDisplay.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpImageDraw.h>
#include <visp3/core/vpImagePoint.h>
#include <visp3/core/vpRect.h>
#include <visp3/core/vpTime.h>
#include <visp3/gui/vpPlot.h>
#if defined(VISP_HAVE_X11)
#include <visp3/gui/vpDisplayX.h>
#elif defined(VISP_HAVE_OPENCV)
#include <visp3/gui/vpDisplayOpenCV.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

namespace ofv {

namespace detail {
bool x11_connects(const char* name);  // x11_check.cpp (Xlib's macros stay there)
}  // namespace detail

DisplayControl::State DisplayControl::handle(Event event) {
  if (state_ == State::Quit) return state_;
  switch (event) {
    case Event::LeftClick:
    case Event::MiddleClick:
    case Event::PauseKey:
      if (pausable_) state_ = state_ == State::Running ? State::Paused : State::Running;
      break;
    case Event::RightClick:
    case Event::QuitKey:
      state_ = State::Quit;
      break;
  }
  return state_;
}

std::optional<DisplayControl::Event> DisplayControl::key_event(const std::string& key) {
  if (key == "q" || key == "Q" || key == "\x1b" || key == "Escape") return Event::QuitKey;
  if (key == " " || key == "p" || key == "P" || key == "space") return Event::PauseKey;
  return std::nullopt;
}

namespace {

#if defined(VISP_HAVE_X11)
using WindowDisplay = vpDisplayX;
#elif defined(VISP_HAVE_OPENCV)
using WindowDisplay = vpDisplayOpenCV;
#endif

// The scene view's camera path: the last positions kept (100 s at 30 Hz), and
// the span of the curves before they start again [s].
constexpr std::size_t kPathLength = 3000;
constexpr double kPlotWindow = 120.0;

// The drawing colours (R, G, B); the tests look for some of them.
const vpColor kSupervoxel(60, 160, 255);
const vpColor kOccluder(230, 60, 60);
const vpColor kTrack(255, 150, 40);
const vpColor kCurrent(0, 255, 0);    // s: the projection of C
const vpColor kDesired(255, 255, 0);  // s*: the image centre
const vpColor kText(255, 255, 255);

std::optional<vpImagePoint> project(const Eigen::Isometry3d& cMw, const CameraIntrinsics& k,
                                    const Eigen::Vector3d& w) {
  const Eigen::Vector3d c = cMw * w;
  if (!(c.z() > 1e-3)) return std::nullopt;
  const double u = k.fx * c.x() / c.z() + k.cx, v = k.fy * c.y() / c.z() + k.cy;
  if (!std::isfinite(u) || !std::isfinite(v) || std::abs(u) > 1e5 || std::abs(v) > 1e5)
    return std::nullopt;
  return vpImagePoint(v, u);
}

std::string format(const char* fmt, double a, double b, double c, double d) {
  char line[160];
  std::snprintf(line, sizeof line, fmt, a, b, c, d);
  return line;
}

}  // namespace

struct LiveDisplay::Impl {
  LiveDisplayOptions options;
  // handle() may come from another thread (a front end, a test) while show() waits.
  mutable std::mutex mutex;
  DisplayControl control;
  DisplayControl::State state() const {
    const std::lock_guard<std::mutex> lock(mutex);
    return control.state();
  }
  void handle(DisplayControl::Event e) {
    const std::lock_guard<std::mutex> lock(mutex);
    control.handle(e);
  }
  std::function<void()> pause_hook;
  vpImage<vpRGBa> camera;
  vpImage<vpRGBa> scene;
#if defined(VISP_HAVE_DISPLAY)
  std::unique_ptr<WindowDisplay> camera_window;
  std::unique_ptr<WindowDisplay> scene_window;
  std::unique_ptr<vpPlot> plot;
#endif
  unsigned velocity_graph = 0, error_graph = 1;
  std::vector<Eigen::Vector3d> path;  ///< the camera's last kPathLength positions
  std::optional<double> plot_start;   ///< time the curves start from [s]
  std::optional<Eigen::Vector3d> last_centroid;
  std::optional<Eigen::Vector2d> centroid_pixel;
  vpColVector feature_error;
  std::optional<std::chrono::steady_clock::time_point> last_shown;

  void open_camera(unsigned width, unsigned height) {
#if defined(VISP_HAVE_DISPLAY)
    if (camera_window && camera.getWidth() == width && camera.getHeight() == height) return;
    if (camera_window) camera_window->close(camera);
    camera.resize(height, width, vpRGBa(0, 0, 0));
    camera_window = std::make_unique<WindowDisplay>();
    camera_window->init(camera, 0, 0, options.title + ": camera");
#else
    (void)width;
    (void)height;
#endif
  }

  // Non-blocking: every click and key waiting in every window.
  void poll() {
#if defined(VISP_HAVE_DISPLAY)
    auto events = [&](const auto& image) {
      vpImagePoint ip;
      vpMouseButton::vpMouseButtonType button;
      while (state() != DisplayControl::State::Quit &&
             vpDisplay::getClick(image, ip, button, false)) {
        handle(button == vpMouseButton::button3   ? DisplayControl::Event::RightClick
               : button == vpMouseButton::button2 ? DisplayControl::Event::MiddleClick
                                                  : DisplayControl::Event::LeftClick);
      }
      std::string key;
      while (state() != DisplayControl::State::Quit &&
             vpDisplay::getKeyboardEvent(image, key, false)) {
        if (const auto e = DisplayControl::key_event(key)) handle(*e);
      }
    };
    if (camera_window) events(camera);
    if (scene_window) events(scene);
    if (plot) events(plot->I);
#endif
  }

  void draw_camera(const DisplayInput& in, const Eigen::Vector3d* centroid,
                   const std::optional<Eigen::Vector3d>& target) {
#if defined(VISP_HAVE_DISPLAY)
    const CameraIntrinsics k = in.frame ? in.frame->intrinsics : in.intrinsics;
    open_camera(static_cast<unsigned>(k.width), static_cast<unsigned>(k.height));
    if (in.frame && in.frame->rgb.size() == static_cast<std::size_t>(k.width) *
                                                static_cast<std::size_t>(k.height) * 3) {
      const std::uint8_t* p = in.frame->rgb.data();
      vpRGBa* q = camera.bitmap;
      for (std::size_t i = 0, n = camera.getSize(); i < n; ++i, p += 3)
        q[i] = vpRGBa(p[0], p[1], p[2]);
    } else {
      camera = vpRGBa(70, 70, 70);
    }
    const Eigen::Isometry3d cMw = in.wMc.inverse();
    // The problem's points, thousands of occluder cells with ground truth,
    // go into the image itself (vpImageDraw): one X call per point
    // (vpDisplay) cost 70 ms a frame.
    const auto inside = [&](const vpImagePoint& a, double margin) {
      return a.get_u() >= margin && a.get_v() >= margin && a.get_u() < k.width - 1 - margin &&
             a.get_v() < k.height - 1 - margin;
    };
    if (in.observation && in.observation->problem) {
      const ViewProblem& problem = *in.observation->problem;
      const Eigen::Matrix3Xd occluders = in.observation->all_occluders();
      for (Eigen::Index i = 0; i < occluders.cols(); ++i) {
        const auto a = project(cMw, k, occluders.col(i));
        if (a && inside(*a, 2))
          vpImageDraw::drawRectangle(camera, vpRect(a->get_u() - 1, a->get_v() - 1, 3, 3),
                                     kOccluder, true);
      }
      for (Eigen::Index i = 0; i < problem.positions.cols(); ++i) {
        const auto a = project(cMw, k, problem.positions.col(i));
        if (a && inside(*a, 4)) vpImageDraw::drawCircle(camera, *a, 2, kSupervoxel, 2);
      }
    }
    vpDisplay::display(camera);
    if (in.step) {
      for (const OccluderTrack& t : in.step->tracks) {
        if (!t.confirmed || t.points.cols() == 0) continue;
        const auto a = project(cMw, k, t.position),
                   b = project(cMw, k, t.position + 0.5 * t.velocity);
        if (a && b) vpDisplay::displayArrow(camera, *a, *b, kTrack, 6, 3, 2);
        if (a)
          vpDisplay::displayText(camera, *a + vpImagePoint(14, 6), "#" + std::to_string(t.id),
                                 kTrack);
      }
    }
    // The sphere feature: s* puts C at the image centre (x = y = 0) on the
    // sphere, on the target's ray; s is where C is now.
    const vpImagePoint centre(k.cy, k.cx);
    vpDisplay::displayCircle(camera, centre, 9, kDesired, false, 2);
    vpDisplay::displayCross(camera, centre, 10, kDesired, 1);
    centroid_pixel.reset();
    feature_error = vpColVector();
    if (centroid) {
      if (const auto c = project(cMw, k, *centroid)) {
        centroid_pixel = Eigen::Vector2d(c->get_u(), c->get_v());
        vpDisplay::displayLine(camera, centre, *c, vpColor::cyan, 1);
        vpDisplay::displayCross(camera, *c, 16, kCurrent, 3);
      }
      if (target && (*target - *centroid).norm() > 1e-9) {
        try {
          servo::FeatureSphereView s;
          s.build(servo::to_visp(in.wMc).inverse(),
                  vpColVector{centroid->x(), centroid->y(), centroid->z()},
                  vpColVector{target->x(), target->y(), target->z()}, options.r_sphere);
          feature_error = s.get_s();  // s* = 0
        } catch (const std::exception&) {
          // C behind the camera: the feature is undefined this frame.
        }
      }
    }
    std::string head = format("t=%.2f s", in.time, 0, 0, 0);
    if (in.visible_fraction) head += format("  visible %.3f", *in.visible_fraction, 0, 0, 0);
    if (in.status) {
      head += std::string("  ") + to_string(*in.status);
    } else if (in.step) {
      head += std::string("  ") + to_string(in.step->status);
    }
    if (in.step && in.step->safety != servo::SafetyAction::None)
      head += std::string("  safety: ") + to_string(in.step->safety);
    vpDisplay::displayText(camera, 14, 6, head, kText);
    if (feature_error.size() == 6) {
      const double f =
          std::sqrt(feature_error[3] * feature_error[3] + feature_error[4] * feature_error[4] +
                    feature_error[5] * feature_error[5]);
      vpDisplay::displayText(camera, 30, 6,
                             format("s: x %+.3f  y %+.3f  rho-R %+.3f  |f| %.3f", feature_error[0],
                                    feature_error[1], feature_error[2], f),
                             kCurrent);
      vpDisplay::displayText(camera, 46, 6, "s*: 0 (C centred, on the sphere, on the target ray)",
                             kDesired);
    }
    vpDisplay::displayText(camera, static_cast<int>(camera.getHeight()) - 8, 6,
                           state() == DisplayControl::State::Paused
                               ? "PAUSED - left click: resume, right click: end"
                           : options.pause ? "left click: pause, right click or q: end"
                                           : "right click or q: end (no pause here)",
                           kText);
    vpDisplay::flush(camera);
#else
    (void)in;
    (void)centroid;
    (void)target;
#endif
  }

  void draw_scene(const DisplayInput& in, const Eigen::Vector3d* centroid,
                  const std::optional<Eigen::Vector3d>& target) {
#if defined(VISP_HAVE_DISPLAY)
    if (!scene_window) return;
    SceneState state;
    state.time = in.time;
    state.wMc = in.wMc;
    if (centroid) state.centroid = *centroid;
    state.visible_fraction = in.visible_fraction;
    if (in.status) {
      state.status = in.status;
    } else if (in.step) {
      state.status = in.step->status;
    }
    state.observation = in.observation;
    state.step = in.step;
    state.target = target;
    const RgbPicture picture = scene_picture(state, path, options.r_sphere);
    const std::uint8_t* p = picture.rgb.data();
    vpRGBa* q = scene.bitmap;
    for (std::size_t i = 0, n = scene.getSize(); i < n; ++i, p += 3)
      q[i] = vpRGBa(p[0], p[1], p[2]);
    vpDisplay::display(scene);
    vpDisplay::flush(scene);
#else
    (void)in;
    (void)centroid;
    (void)target;
#endif
  }

  void draw_plot(const DisplayInput& in, const vpColVector& velocity) {
#if defined(VISP_HAVE_DISPLAY)
    if (!plot) return;
    // A run of hours: the curves start again every kPlotWindow seconds
    // (vpPlot keeps every point and redraws them all when it rescales).
    if (!plot_start || in.time < *plot_start || in.time - *plot_start > kPlotWindow) {
      if (plot_start) {
        for (unsigned g = 0; g <= error_graph; ++g) plot->resetPointList(g);
      }
      plot_start = in.time;
    }
    if (options.ground_truth && in.visible_fraction)
      plot->plot(0, 0, in.time, *in.visible_fraction);
    if (velocity.size() == 6) plot->plot(velocity_graph, in.time, velocity);
    if (feature_error.size() == 6) plot->plot(error_graph, in.time, feature_error);
#else
    (void)in;
    (void)velocity;
#endif
  }
};

LiveDisplay::LiveDisplay(const LiveDisplayOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  m.control = DisplayControl(options.pause);
  if (!(options.r_sphere > 0.0) || !std::isfinite(options.r_sphere)) {
    throw std::invalid_argument("display: r_sphere must be a positive length, not " +
                                std::to_string(options.r_sphere));
  }
#if !defined(VISP_HAVE_DISPLAY)
  throw DisplayUnavailable("--display: this ViSP was built without a display (X11 or OpenCV)");
#else
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    throw DisplayUnavailable(
        "--display: no display (DISPLAY is not set); run without --display, or under xvfb-run");
  }
#if defined(VISP_HAVE_X11)
  // The connection first, by itself: vpDisplayX leaks its colour table when
  // it cannot connect (ViSP 3.5), which the sanitizer build reports.
  if (!detail::x11_connects(display)) {
    throw DisplayUnavailable(std::string("--display: cannot connect to the X display ") + display);
  }
#endif
  try {
    // The camera window opens at the first frame, at the frame's size (a
    // window made again is a new window); the others open here, and so
    // check the connection. With neither, the camera window opens here.
    if (!options.scene && !options.plot) m.open_camera(640, 480);
    if (options.scene) {
      m.scene.resize(480, 640, vpRGBa(30, 30, 30));
      m.scene_window = std::make_unique<WindowDisplay>();
      m.scene_window->init(m.scene, 660, 0, options.title + ": scene");
      vpDisplay::display(m.scene);
      vpDisplay::flush(m.scene);
    }
    if (options.plot) {
      const unsigned graphs = options.ground_truth ? 3 : 2;
      m.plot = std::make_unique<vpPlot>(graphs, 180 * graphs + 60, 640, 0, 520,
                                        options.title + ": curves");
      unsigned g = 0;
      if (options.ground_truth) {
        m.plot->initGraph(g, 1);
        m.plot->setTitle(g, "true visible fraction");
        m.plot->setLegend(g, 0, "visible");
        m.plot->setColor(g, 0, vpColor::blue);
        m.plot->initRange(g, 0.0, 1.0, 0.0, 1.05);
        ++g;
      }
      m.velocity_graph = g++;
      m.error_graph = g;
      m.plot->initGraph(m.velocity_graph, 6);
      m.plot->setTitle(m.velocity_graph, "camera velocity [m/s, rad/s]");
      m.plot->initRange(m.velocity_graph, 0.0, 1.0, -0.6, 0.6);  // widened as the curves need
      m.plot->initGraph(m.error_graph, 6);
      m.plot->setTitle(m.error_graph, "feature error s - s*");
      m.plot->initRange(m.error_graph, 0.0, 1.0, -0.2, 0.2);
      const char* v_names[6] = {"vx", "vy", "vz", "wx", "wy", "wz"};
      const char* e_names[6] = {"x", "y", "rho-R", "fx", "fy", "fz"};
      const vpColor colours[6] = {vpColor::red,    vpColor::green,  vpColor::blue,
                                  vpColor::orange, vpColor::purple, vpColor::cyan};
      for (unsigned i = 0; i < 6; ++i) {
        m.plot->setLegend(m.velocity_graph, i, v_names[i]);
        m.plot->setColor(m.velocity_graph, i, colours[i]);
        m.plot->setLegend(m.error_graph, i, e_names[i]);
        m.plot->setColor(m.error_graph, i, colours[i]);
      }
    }
  } catch (const vpException& e) {
    throw DisplayUnavailable(std::string("--display: cannot open a window on display ") + display +
                             ": " + e.getStringMessage());
  }
#endif
}

LiveDisplay::~LiveDisplay() = default;

bool LiveDisplay::show(const DisplayInput& in) {
  Impl& m = *impl_;
  if (m.state() == DisplayControl::State::Quit) return false;
  m.path.emplace_back(in.wMc.translation());
  if (m.path.size() > 2 * kPathLength) m.path.erase(m.path.begin(), m.path.end() - kPathLength);
  const Eigen::Vector3d* centroid = nullptr;
  if (in.step && in.step->estimate) {
    m.last_centroid = in.step->estimate->centroid;
  } else if (in.centroid) {
    m.last_centroid = *in.centroid;
  }
  if (m.last_centroid) centroid = &*m.last_centroid;
  std::optional<Eigen::Vector3d> target = in.step ? in.step->target : in.target;
  if (!target && in.step && in.step->estimate) target = in.step->estimate->tf;
  vpColVector velocity = in.velocity ? *in.velocity : in.step ? in.step->velocity : vpColVector();

  m.draw_camera(in, centroid, target);
  m.draw_scene(in, centroid, target);
  m.draw_plot(in, velocity);

  if (m.options.pace_rate > 0.0) {
    const auto period = std::chrono::duration<double>(1.0 / m.options.pace_rate);
    if (m.last_shown)
      std::this_thread::sleep_until(
          *m.last_shown + std::chrono::duration_cast<std::chrono::steady_clock::duration>(period));
  }
  m.poll();
  if (m.state() == DisplayControl::State::Paused) {
    if (m.pause_hook) m.pause_hook();
    m.draw_camera(in, centroid, target);  // with the pause line
    while (m.state() == DisplayControl::State::Paused) {
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
      m.poll();
    }
  }
  m.last_shown = std::chrono::steady_clock::now();
  return m.state() != DisplayControl::State::Quit;
}

bool LiveDisplay::observe(const StepRecord& record, const StepDetail& detail) {
  DisplayInput in;
  in.time = record.time;
  in.wMc = record.wMc;
  in.frame = detail.frame;
  in.observation = detail.observation;
  in.step = detail.step;
  in.centroid = record.true_centroid;
  in.visible_fraction = record.visible_fraction;
  in.status = record.status;
  return show(in);
}

bool LiveDisplay::observe(const servo::RobotLoopFrame& f) {
  DisplayInput in;
  if (f.frame && f.bad_frame.empty()) {  // a skipped frame's images may not match its intrinsics
    in.time = f.frame->timestamp;
    in.wMc = f.frame->wMc;
    in.frame = f.frame;
  }
  in.observation = f.observation;
  if (f.observation && f.observation->problem && f.observation->problem->positions.cols() > 0) {
    in.centroid = f.observation->problem->positions.rowwise().mean();
  }
  in.step = f.step;
  return show(in);
}

void LiveDisplay::set_pause_hook(std::function<void()> hook) {
  impl_->pause_hook = std::move(hook);
}
DisplayControl::State LiveDisplay::handle(DisplayControl::Event event) {
  impl_->handle(event);
  return impl_->state();
}
DisplayControl::State LiveDisplay::state() const { return impl_->state(); }

void LiveDisplay::grab_camera(vpImage<vpRGBa>& image) const {
#if defined(VISP_HAVE_DISPLAY)
  vpDisplay::getImage(impl_->camera, image);
#else
  image = vpImage<vpRGBa>();
#endif
}

void LiveDisplay::grab_scene(vpImage<vpRGBa>& image) const {
#if defined(VISP_HAVE_DISPLAY)
  if (impl_->scene_window) {
    vpDisplay::getImage(impl_->scene, image);
    return;
  }
#endif
  image = vpImage<vpRGBa>();
}

void LiveDisplay::grab_plot(vpImage<vpRGBa>& image) const {
#if defined(VISP_HAVE_DISPLAY)
  if (impl_->plot) {
    vpDisplay::getImage(impl_->plot->I, image);
    return;
  }
#endif
  image = vpImage<vpRGBa>();
}

std::optional<Eigen::Vector2d> LiveDisplay::last_centroid_pixel() const {
  return impl_->centroid_pixel;
}
vpColVector LiveDisplay::last_feature_error() const { return impl_->feature_error; }

}  // namespace ofv
