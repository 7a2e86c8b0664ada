// The files of a simulated episode: trajectory, metrics, pictures, video, recording.
#include "ofv/loop/episode_files.h"

#include "gnuplot.h"
#include "projection.h"

#include "ofv/loop/metrics_json.h"
#include "ofv/loop/scene_picture.h"
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

using detail::project;

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
  // The policy's decision on a line of its own: a 320-pixel image has no room beside the rest.
  const std::string decision = std::string(to_string(rec.mode)) + " (" + to_string(rec.proposer) + ")";
  cv::putText(img, decision, {6, 32}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {255, 255, 255}, 1, cv::LINE_AA);
  return img;
}

// The scene view (ofv/loop/scene_picture.h) of a simulated step, BGR for OpenCV.
cv::Mat scene_picture(const StepRecord& rec, const StepDetail& d, const std::vector<Eigen::Vector3d>& path,
                      double r_sphere) {
  SceneState state;
  state.time = rec.time;
  state.wMc = rec.wMc;
  state.centroid = rec.true_centroid;
  state.visible_fraction = rec.visible_fraction;
  state.status = rec.status;
  state.observation = d.observation;
  state.step = d.step;
  const RgbPicture picture = ofv::scene_picture(state, path, r_sphere);
  cv::Mat rgb(picture.height, picture.width, CV_8UC3, const_cast<std::uint8_t*>(picture.rgb.data()));
  cv::Mat img;
  cv::cvtColor(rgb, img, cv::COLOR_RGB2BGR);
  return img;
}

// Visibility and distance error over time, drawn by gnuplot, run in `dir`
// without a shell: the script names its files relative to `dir`, so the
// folder's name (the user's --out) appears nowhere. Two bands along the
// bottom show when an occluder is in the sphere and when the sensor sees one.
bool plot_visibility(const fs::path& dir) {
  std::ofstream gp(dir / "visibility.gp");
  gp << "set terminal pngcairo size 900,460 font 'Sans,10'\nset output 'visibility.png'\n"
        "set datafile separator ','\nset grid\nset xlabel 'time [s]'\nset ylabel 'visible fraction'\n"
        "set y2label 'distance to the sphere [cm]'\nset ytics nomirror\nset y2tics\nset yrange [0:1.05]\n"
        "set key below\nset style fill transparent solid 0.5 noborder\n"
        "plot 'trajectory.csv' using \"time\":(0):(column(\"occluders_in_sphere\") > 0 ? 0.04 : 0) "
        "with filledcurves lc rgb '#999999' title 'occluder in the sphere', "
        "'' using \"time\":(0.04):(column(\"occluders_in_view\") > 0 ? 0.08 : 0.04) "
        "with filledcurves lc rgb '#e66101' title 'occluder in view', "
        "'' using \"time\":\"visible_fraction\" with lines lw 2 lc rgb '#5e3c99' title 'true visible fraction', "
        "'' using \"time\":(100*column(\"sphere_distance_error\")) axes x1y2 with lines lc rgb '#1b9e77' "
        "title 'distance error [cm]'\n";
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
  j["perception"]["mode"] = to_string(m.setup.perception);  // beside the scores, if any
  std::ofstream(m.dir / "metrics.json") << j.dump(2) << '\n';
  std::vector<std::string> out{"trajectory.csv", "metrics.json"};
  if (m.files.pictures && plot_visibility(m.dir)) out.push_back("visibility.png");
  if (m.video.isOpened()) m.video.release();
  out.insert(out.end(), m.written.begin(), m.written.end());
  return out;
}

}  // namespace ofv
