// The Fig. 6-style scene view of one frame (ofv simulate's scene pictures, the live display).
#include "ofv/loop/scene_picture.h"

#include "ofv/constants.h"
#include "projection.h"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace ofv {

using detail::project;

// Drawn in BGR order with OpenCV (the colours below are B, G, R), returned as RGB.
RgbPicture scene_picture(const SceneState& s, const std::vector<Eigen::Vector3d>& path,
                         double r_sphere) {
  const std::optional<ViewEstimate>* estimate_ptr = s.step ? &s.step->estimate : nullptr;
  const bool has_estimate = estimate_ptr && estimate_ptr->has_value();
  const Eigen::Vector3d c = has_estimate ? (*estimate_ptr)->centroid : s.centroid;
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
    for (int i = 0; i <= 72; ++i) {
      const double a = 2.0 * kPi * i / 72;
      Eigen::Vector3d q = Eigen::Vector3d::Zero();
      q((axis + 1) % 3) = std::cos(a);
      q((axis + 2) % 3) = std::sin(a);
      const auto pt = p(c + r_sphere * q);
      if (pt && prev) cv::line(img, *prev, *pt, {90, 90, 90}, 1, cv::LINE_AA);
      prev = pt;
    }
  }
  if (s.observation && s.observation->problem) {
    const ViewProblem& problem = *s.observation->problem;
    for (Eigen::Index i = 0; i < problem.positions.cols(); ++i) {
      const auto a = p(problem.positions.col(i));
      const auto b = p(problem.positions.col(i) + 0.03 * problem.normals.col(i).normalized());
      if (a) cv::circle(img, *a, 2, {255, 160, 60}, cv::FILLED);
      if (a && b) cv::line(img, *a, *b, {200, 120, 60}, 1, cv::LINE_AA);
    }
    // Seen occluders filled; those presumed beyond the image border hollow.
    const Eigen::Matrix3Xd occluders = s.observation->all_occluders();
    for (Eigen::Index i = 0; i < occluders.cols(); ++i) {
      if (const auto a = p(occluders.col(i))) {
        cv::rectangle(img, *a - cv::Point(2, 2), *a + cv::Point(2, 2), {60, 60, 230},
                      i < problem.occluders.cols() ? cv::FILLED : 1);
      }
    }
  }
  if (s.step) {
    for (const OccluderTrack& t : s.step->tracks) {
      if (!t.confirmed || t.points.cols() == 0) continue;
      const auto a = p(t.position), b = p(t.position + 0.5 * t.velocity);
      if (a && b) cv::arrowedLine(img, *a, *b, {40, 150, 255}, 2, cv::LINE_AA, 0, 0.2);
      if (a) {
        cv::putText(img, "#" + std::to_string(t.id), *a + cv::Point(6, 12),
                    cv::FONT_HERSHEY_SIMPLEX, 0.4, {40, 150, 255}, 1, cv::LINE_AA);
      }
    }
  }
  for (std::size_t i = 1; i < path.size(); ++i) {
    const auto a = p(path[i - 1]), b = p(path[i]);
    if (a && b) cv::line(img, *a, *b, {220, 220, 220}, 1, cv::LINE_AA);
  }
  auto mark = [&](const Eigen::Vector3d& w, const cv::Scalar& colour, const char* label) {
    if (const auto a = p(w)) {
      cv::circle(img, *a, 6, colour, 2, cv::LINE_AA);
      cv::putText(img, label, *a + cv::Point(8, -6), cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1,
                  cv::LINE_AA);
    }
  };
  mark(c, {255, 255, 255}, "C");
  mark(s.wMc.translation(), {255, 255, 255}, "t_real");
  if (has_estimate) {
    const ViewEstimate& estimate = **estimate_ptr;
    mark(estimate.t0, {0, 220, 255}, "t0");
    mark(estimate.tf, {80, 220, 80}, "tf");
    if (s.step->target && (*s.step->target - estimate.tf).norm() > 1e-3)
      mark(*s.step->target, {220, 80, 220}, "target");
  } else if (s.target) {
    mark(*s.target, {220, 80, 220}, "target");
  }
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "t=" << s.time << " s   ";
  if (s.visible_fraction) text << "visible " << *s.visible_fraction << "   ";
  if (s.status) text << "status " << to_string(*s.status);
  if (s.step) text << "   " << to_string(s.step->mode) << " (" << to_string(s.step->proposer) << ")";
  cv::putText(img, text.str(), {10, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.55, {255, 255, 255}, 1,
              cv::LINE_AA);

  RgbPicture out;
  out.width = k.width;
  out.height = k.height;
  out.rgb.resize(static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height) * 3);
  cv::Mat rgb(k.height, k.width, CV_8UC3, out.rgb.data());
  cv::cvtColor(img, rgb, cv::COLOR_BGR2RGB);
  return out;
}

}  // namespace ofv
