// The files of a simulated episode: trajectory, metrics, pictures, video, recording.
#include "ofv/loop/episode_files.h"

#include "gnuplot.h"
#include "ofv/constants.h"

#include "ofv/loop/metrics_json.h"
#include "ofv/sources/tum_sequence.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace ofv {

namespace {

namespace fs = std::filesystem;

// Pinhole projection of a world point for drawing; nullopt behind the camera.
std::optional<cv::Point> project(const Eigen::Isometry3d& wMc, const CameraIntrinsics& k,
                                 const Eigen::Vector3d& p) {
  const Eigen::Vector3d c = wMc.inverse() * p;
  if (c.z() <= 1e-3) return std::nullopt;
  return cv::Point(static_cast<int>(std::lround(k.fx * c.x() / c.z() + k.cx)),
                   static_cast<int>(std::lround(k.fy * c.y() / c.z() + k.cy)));
}

// The camera's image with the true centroid (+) and the chosen target drawn on it.
cv::Mat camera_picture(const StepRecord& rec, const StepDetail& d) {
  const CameraIntrinsics& k = d.frame->intrinsics;
  cv::Mat rgb(k.height, k.width, CV_8UC3, const_cast<std::uint8_t*>(d.frame->rgb.data()));
  cv::Mat img;
  cv::cvtColor(rgb, img, cv::COLOR_RGB2BGR);
  if (auto c = project(rec.wMc, k, rec.true_centroid)) {
    cv::drawMarker(img, *c, {255, 255, 255}, cv::MARKER_CROSS, 14, 2);
  }
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "t=" << rec.time << "s  visible " << rec.visible_fraction
       << "  " << to_string(rec.status);
  cv::putText(img, text.str(), {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {255, 255, 255}, 1, cv::LINE_AA);
  return img;
}

// A Fig. 6-style view of the scene from a virtual observer beside the camera:
// object supervoxels and normals (blue), occluders (red), the sphere, C, the
// real camera and its path (white), t0 (yellow), tf (green) and, where
// target hysteresis kept another, the target the controller follows (magenta);
// each confirmed occluder track as an orange arrow from its position to
// where it will be in 0.5 s, with its id.
cv::Mat scene_picture(const StepRecord& rec, const StepDetail& d,
                      const std::vector<Eigen::Vector3d>& path, double r_sphere) {
  const std::optional<ViewEstimate>& estimate = d.step->estimate;
  const Eigen::Vector3d c = estimate ? estimate->centroid : rec.true_centroid;
  const Eigen::Vector3d eye = c + Eigen::Vector3d(0.9, -0.7, -0.6);
  const Eigen::Vector3d z = (c - eye).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d(0, 1, 0).cross(z).normalized();
  Eigen::Isometry3d wMo = Eigen::Isometry3d::Identity();
  wMo.linear() << x, z.cross(x), z;
  wMo.translation() = eye;
  const CameraIntrinsics k{640, 480, 520.0, 520.0, 320.0, 240.0};
  cv::Mat img(k.height, k.width, CV_8UC3, cv::Scalar(30, 30, 30));
  auto p = [&](const Eigen::Vector3d& w) { return project(wMo, k, w); };
  // The sphere's outline: great circles in three planes.
  for (int axis = 0; axis < 3; ++axis) {
    std::optional<cv::Point> prev;
    for (int s = 0; s <= 72; ++s) {
      const double a = 2.0 * kPi * s / 72;
      Eigen::Vector3d q = Eigen::Vector3d::Zero();
      q((axis + 1) % 3) = std::cos(a);
      q((axis + 2) % 3) = std::sin(a);
      const auto pt = p(c + r_sphere * q);
      if (pt && prev) cv::line(img, *prev, *pt, {90, 90, 90}, 1, cv::LINE_AA);
      prev = pt;
    }
  }
  if (d.problem) {
    for (Eigen::Index i = 0; i < d.problem->positions.cols(); ++i) {
      const auto a = p(d.problem->positions.col(i));
      const auto b = p(d.problem->positions.col(i) + 0.03 * d.problem->normals.col(i).normalized());
      if (a) cv::circle(img, *a, 2, {255, 160, 60}, cv::FILLED);
      if (a && b) cv::line(img, *a, *b, {200, 120, 60}, 1, cv::LINE_AA);
    }
    for (Eigen::Index i = 0; i < d.problem->occluders.cols(); ++i) {
      if (const auto a = p(d.problem->occluders.col(i))) cv::rectangle(img, *a - cv::Point(2, 2), *a + cv::Point(2, 2), {60, 60, 230}, cv::FILLED);
    }
  }
  for (const OccluderTrack& t : d.step->tracks) {
    if (!t.confirmed || t.points.cols() == 0) continue;
    const auto a = p(t.position), b = p(t.position + 0.5 * t.velocity);
    if (a && b) cv::arrowedLine(img, *a, *b, {40, 150, 255}, 2, cv::LINE_AA, 0, 0.2);
    if (a) cv::putText(img, "#" + std::to_string(t.id), *a + cv::Point(6, 12), cv::FONT_HERSHEY_SIMPLEX, 0.4, {40, 150, 255}, 1, cv::LINE_AA);
  }
  for (std::size_t i = 1; i < path.size(); ++i) {
    const auto a = p(path[i - 1]), b = p(path[i]);
    if (a && b) cv::line(img, *a, *b, {220, 220, 220}, 1, cv::LINE_AA);
  }
  auto mark = [&](const Eigen::Vector3d& w, const cv::Scalar& colour, const char* label) {
    if (const auto a = p(w)) {
      cv::circle(img, *a, 6, colour, 2, cv::LINE_AA);
      cv::putText(img, label, *a + cv::Point(8, -6), cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
    }
  };
  mark(c, {255, 255, 255}, "C");
  mark(rec.wMc.translation(), {255, 255, 255}, "t_real");
  if (estimate) {
    mark(estimate->t0, {0, 220, 255}, "t0");
    mark(estimate->tf, {80, 220, 80}, "tf");
    if (d.step->target && (*d.step->target - estimate->tf).norm() > 1e-3) mark(*d.step->target, {220, 80, 220}, "target");
  }
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "t=" << rec.time << " s   visible " << rec.visible_fraction
       << "   status " << to_string(rec.status);
  cv::putText(img, text.str(), {10, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.55, {255, 255, 255}, 1, cv::LINE_AA);
  return img;
}

// Visibility and distance error over time, drawn by gnuplot, run in `dir`
// without a shell: the script names its files relative to `dir`, so the
// folder's name (the user's --out) appears nowhere.
bool plot_visibility(const fs::path& dir) {
  std::ofstream gp(dir / "visibility.gp");
  gp << "set terminal pngcairo size 900,420 font 'Sans,10'\nset output 'visibility.png'\n"
        "set datafile separator ','\nset grid\nset xlabel 'time [s]'\nset ylabel 'visible fraction'\n"
        "set y2label 'distance to the sphere [cm]'\nset ytics nomirror\nset y2tics\nset yrange [0:1.05]\n"
        "set key bottom right\nplot 'trajectory.csv' using \"time\":\"visible_fraction\" with lines lw 2 "
        "title 'true visible fraction', '' using \"time\":(100*column(\"sphere_distance_error\")) axes x1y2 "
        "with lines title 'distance error [cm]'\n";
  gp.close();
  return gp && detail::run_gnuplot(dir, "visibility.gp", {});
}

}  // namespace

struct EpisodeWriter::Impl {
  fs::path dir;
  const EpisodeSetup& setup;
  EpisodeFiles files;
  long total = 0;
  double r_sphere = 0.0;
  long index = 0;
  long picture_at = -1;
  int last_occluders = 0;
  double last_visible = 1.0;
  std::vector<Eigen::Vector3d> path;
  std::vector<std::string> written;
  cv::VideoWriter video;
  std::unique_ptr<TumSequenceWriter> recording;

  Impl(const std::string& d, const EpisodeSetup& s, const EpisodeFiles& f) : dir(d), setup(s), files(f) {}
};

EpisodeWriter::EpisodeWriter(const std::string& dir, const EpisodeSetup& setup, const EpisodeFiles& files)
    : impl_(std::make_unique<Impl>(dir, setup, files)) {
  std::error_code ec;
  fs::create_directories(impl_->dir, ec);
  if (!fs::is_directory(impl_->dir)) throw std::runtime_error(dir + ": cannot create the output folder");
  impl_->r_sphere = setup.loop.estimator.resolve().r_sphere;
  impl_->total = static_cast<long>(std::floor(setup.duration * setup.scenario.rate + 1e-9)) + 1;
  if (files.video) {
    const fs::path file = impl_->dir / "episode.avi";
    impl_->video.open(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), setup.scenario.rate, {1280, 480});
    if (!impl_->video.isOpened()) throw std::runtime_error("cannot write the video " + file.string());
    impl_->written.push_back("episode.avi");
  }
  if (!files.record_dir.empty()) impl_->recording = std::make_unique<TumSequenceWriter>(files.record_dir);
}

EpisodeWriter::~EpisodeWriter() = default;

void EpisodeWriter::observe(const StepRecord& rec, const StepDetail& d) {
  Impl& m = *impl_;
  m.path.push_back(rec.wMc.translation());
  if (m.recording) m.recording->write(*d.frame);
  // Key moments: an occluder enters the sphere, the visibility falls below 0.9.
  const bool onset = rec.occluders_in_sphere > m.last_occluders || (rec.visible_fraction < 0.9 && m.last_visible >= 0.9);
  m.last_occluders = rec.occluders_in_sphere;
  m.last_visible = rec.visible_fraction;
  if (onset) m.picture_at = m.index + static_cast<long>(m.setup.scenario.rate);  // 1 s later
  const bool picture = m.files.pictures && (m.index == 0 || onset || m.index == m.picture_at || m.index == m.total - 1);
  if (picture || m.files.video) {
    const cv::Mat camera = camera_picture(rec, d);
    const cv::Mat scene = scene_picture(rec, d, m.path, m.r_sphere);
    if (picture) {
      char name[64];
      std::snprintf(name, sizeof name, "t%05.2f", rec.time);
      for (const auto& [kind, image] : {std::pair<const char*, const cv::Mat*>{"camera_", &camera}, {"scene_", &scene}}) {
        const std::string file = std::string(kind) + name + ".png";
        if (!cv::imwrite((m.dir / file).string(), *image)) throw std::runtime_error((m.dir / file).string() + ": cannot write");
        m.written.push_back(file);
      }
    }
    if (m.files.video) {
      cv::Mat frame(480, 1280, CV_8UC3);
      scene.copyTo(frame(cv::Rect(0, 0, 640, 480)));
      cv::resize(camera, frame(cv::Rect(640, 0, 640, 480)), {640, 480});
      m.video.write(frame);
    }
  }
  ++m.index;
}

std::vector<std::string> EpisodeWriter::finish(const EpisodeOutcome& outcome) {
  Impl& m = *impl_;
  {
    std::ofstream csv(m.dir / "trajectory.csv");
    csv << trajectory_csv_header() << '\n';
    for (const auto& s : outcome.steps) csv << trajectory_csv_row(s) << '\n';
    if (!csv) throw std::runtime_error((m.dir / "trajectory.csv").string() + ": cannot write");
  }
  nlohmann::json j = metrics_to_json(outcome.metrics);
  j["scenario"] = m.setup.scenario.name;
  j["method"] = to_string(m.setup.loop.method);
  j["robot"] = to_string(m.setup.robot);
  j["perception"] = to_string(m.setup.perception);
  std::ofstream(m.dir / "metrics.json") << j.dump(2) << '\n';
  std::vector<std::string> out{"trajectory.csv", "metrics.json"};
  if (m.files.pictures && plot_visibility(m.dir)) out.push_back("visibility.png");
  if (m.video.isOpened()) m.video.release();
  out.insert(out.end(), m.written.begin(), m.written.end());
  return out;
}

}  // namespace ofv
