// Fig. 6-like pictures drawn with OpenCV into an 8-bit BGR image.
#include "ofv/perception/picture.h"
#include "ofv/constants.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace ofv::perception {

namespace {

constexpr int kWidth = 800;
constexpr int kHeight = 600;

/// An OpenCV colour (B, G, R) from R, G, B.
cv::Scalar rgb(int r, int g, int b) {
  return {static_cast<double>(b), static_cast<double>(g), static_cast<double>(r)};
}

const cv::Scalar kWhite = rgb(255, 255, 255);
const cv::Scalar kCyan = rgb(0, 255, 255);
const cv::Scalar kMagenta = rgb(255, 60, 255);

/// A pinhole observer looking at `target` from `eye`, `up` roughly up in the image.
class Viewpoint {
 public:
  Viewpoint(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up,
           double focal)
      : focal_(focal) {
    const Eigen::Vector3d z = (target - eye).normalized();
    Eigen::Vector3d x = z.cross(up);
    if (x.norm() < 1e-9) {
      x = z.unitOrthogonal();
    }
    x.normalize();
    const Eigen::Vector3d y = z.cross(x);
    cRw_.row(0) = x.transpose();
    cRw_.row(1) = y.transpose();
    cRw_.row(2) = z.transpose();
    eye_ = eye;
  }
  /// Pixel (u right, v down) of world point p, or nothing behind the observer.
  [[nodiscard]] std::optional<cv::Point2d> operator()(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d c = cRw_ * (p - eye_);
    if (c.z() < 1e-3) {
      return std::nullopt;
    }
    return cv::Point2d(focal_ * c.x() / c.z() + kWidth / 2.0,
                       focal_ * c.y() / c.z() + kHeight / 2.0);
  }

 private:
  Eigen::Matrix3d cRw_;
  Eigen::Vector3d eye_;
  double focal_;
};

cv::Point pixel(const cv::Point2d& p) {
  return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))};
}

/// A filled `size` x `size` square with its top-left corner at p.
void point(cv::Mat& image, const cv::Point2d& p, const cv::Scalar& colour, int size) {
  cv::rectangle(image, cv::Rect(pixel(p), cv::Size(size, size)), colour, cv::FILLED);
}

void line(cv::Mat& image, const Viewpoint& obs, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
          const cv::Scalar& colour, int thickness = 1) {
  const auto pa = obs(a);
  const auto pb = obs(b);
  if (pa && pb) {
    cv::line(image, pixel(*pa), pixel(*pb), colour, thickness);
  }
}

void dot(cv::Mat& image, const Viewpoint& obs, const Eigen::Vector3d& p, const cv::Scalar& colour,
         int size) {
  if (const auto ip = obs(p); ip && ip->x >= 0 && ip->y >= 0 && ip->x < kWidth && ip->y < kHeight) {
    point(image, *ip, colour, size);
  }
}

void square(cv::Mat& image, const Viewpoint& obs, const Eigen::Vector3d& p, const cv::Scalar& colour,
            double half) {
  if (const auto ip = obs(p)) {
    const auto side = static_cast<int>(2 * half);
    cv::rectangle(image, cv::Rect(pixel(*ip - cv::Point2d(half, half)), cv::Size(side, side)),
                  colour);
  }
}

/// Text whose top-left corner is `at`, drawn only when that corner is inside the picture.
void text(cv::Mat& image, const std::string& s, const cv::Point2d& at, const cv::Scalar& colour) {
  if (at.x >= 0 && at.y >= 0 && at.y < kHeight - 12 && at.x < kWidth - 8) {
    constexpr double kScale = 0.45;
    int baseline = 0;
    const cv::Size size = cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, kScale, 1, &baseline);
    cv::putText(image, s, pixel(at) + cv::Point(0, size.height), cv::FONT_HERSHEY_SIMPLEX, kScale,
                colour, 1, cv::LINE_AA);
  }
}

void marker(cv::Mat& image, const Viewpoint& obs, const Eigen::Vector3d& p, const cv::Scalar& colour,
            const std::string& label) {
  if (const auto ip = obs(p)) {
    cv::circle(image, pixel(*ip), 7, colour, 2);
    text(image, label, *ip + cv::Point2d(8, -22), colour);
  }
}

}  // namespace

void save_perception_picture(const std::string& path, const RgbdFrame& frame,
                             const PerceptionResult& r, const std::optional<ViewEstimate>& e,
                             double r_sphere) {
  cv::Mat image(kHeight, kWidth, CV_8UC3, rgb(24, 24, 32));
  const bool tracked = r.status != TrackingStatus::Lost;
  const Eigen::Vector3d c = tracked ? r.centroid : frame.wMc * Eigen::Vector3d(0, 0, 0.5);
  const Eigen::Vector3d camera = frame.wMc.translation();

  // The observer: beside and behind the real camera, 2.4 R_sphere from C,
  // 55 degrees round the camera's vertical axis and a little above it.
  const Eigen::Vector3d cam_up = -frame.wMc.linear().col(1);  // ViSP: Y down
  Eigen::Vector3d back = camera - c;
  if (back.norm() < 1e-6) {
    back = -frame.wMc.linear().col(2);
  }
  back.normalize();
  const Eigen::Vector3d dir =
      (Eigen::AngleAxisd(55.0 * kPi / 180.0, cam_up) * back + 0.5 * cam_up).normalized();
  const Viewpoint obs(c + 2.4 * r_sphere * dir, c, cam_up, 0.9 * kHeight);

  // The sphere as three great circles.
  if (tracked) {
    const Eigen::Matrix3d& a = r.axes;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = a.col(k);
      const Eigen::Vector3d v = a.col((k + 1) % 3);
      for (int s = 0; s < 72; ++s) {
        const double t0 = 2 * kPi * s / 72, t1 = 2 * kPi * (s + 1) / 72;
        line(image, obs, c + r_sphere * (std::cos(t0) * u + std::sin(t0) * v),
             c + r_sphere * (std::cos(t1) * u + std::sin(t1) * v), rgb(70, 70, 110));
      }
    }
  }
  // Occluders: small red squares, under everything else.
  for (Eigen::Index b = 0; b < r.problem.occluders.cols(); ++b) {
    square(image, obs, r.problem.occluders.col(b), rgb(200, 40, 40), 1.5);
  }
  // Interacting (yellow) and object (green) voxels.
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const SupervoxelClass cls = r.supervoxels[static_cast<std::size_t>(r.voxel_owner[i])].label;
    if (cls == SupervoxelClass::Object) {
      dot(image, obs, r.voxels[i].cast<double>(), rgb(60, 220, 90), 2);
    } else if (cls == SupervoxelClass::Interacting) {
      dot(image, obs, r.voxels[i].cast<double>(), rgb(230, 200, 40), 1);
    }
  }
  if (tracked) {
    // Augmented OBB.
    std::array<Eigen::Vector3d, 8> corner;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d s((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1);
      corner[static_cast<std::size_t>(k)] =
          r.obb.centre + r.obb.axes * s.cwiseProduct(r.obb.half_extents);
    }
    for (int k = 0; k < 8; ++k) {
      for (int bit : {1, 2, 4}) {
        if ((k & bit) == 0) {
          line(image, obs, corner[static_cast<std::size_t>(k)],
               corner[static_cast<std::size_t>(k | bit)], rgb(60, 220, 120));
        }
      }
    }
    // Supervoxel normals (red) and normals-to-sphere rays (blue).
    const ViewProblem& p = r.problem;
    for (Eigen::Index n = 0; n < p.positions.cols(); ++n) {
      const Eigen::Vector3d v = p.positions.col(n);
      const Eigen::Vector3d nn = p.normals.col(n).normalized();
      if ((v - c).norm() < r_sphere) {
        line(image, obs, c, sphere_exit(c, r_sphere, v, nn), rgb(70, 110, 255));
      }
      line(image, obs, v, v + 0.03 * nn, rgb(255, 90, 90));
    }
  }
  // Cameras.
  marker(image, obs, camera, kWhite, "t_real");
  line(image, obs, camera, camera + 0.08 * frame.wMc.linear().col(2), kWhite, 2);
  if (e) {
    line(image, obs, c, e->t0, kCyan, 2);
    line(image, obs, c, e->tf, kMagenta, 2);
    marker(image, obs, e->t0, kCyan, "t0");
    marker(image, obs, e->tf, kMagenta, "tf");
  }

  // Inset: the camera image, object supervoxel centroids in green, occluders in red.
  const CameraIntrinsics& k = frame.intrinsics;
  const int inset_w = 240;
  const int inset_h = inset_w * k.height / std::max(1, k.width);
  const double s = static_cast<double>(k.width) / inset_w;
  for (int v = 0; v < inset_h; ++v) {
    for (int u = 0; u < inset_w; ++u) {
      const int su = std::min(k.width - 1, static_cast<int>(u * s));
      const int sv = std::min(k.height - 1, static_cast<int>(v * s));
      const std::size_t i = frame.index(su, sv);
      cv::Vec3b& out = image.at<cv::Vec3b>(v + 8, u + 8);
      if (!frame.rgb.empty()) {
        out = cv::Vec3b(frame.rgb[3 * i + 2], frame.rgb[3 * i + 1], frame.rgb[3 * i]);
      } else {
        const auto g = static_cast<unsigned char>(std::min(255.0f, frame.depth[i] * 100.0f));
        out = cv::Vec3b(g, g, g);
      }
    }
  }
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  for (const SupervoxelInfo& sv : r.supervoxels) {
    if (sv.label != SupervoxelClass::Object && sv.label != SupervoxelClass::Occluder &&
        sv.label != SupervoxelClass::Interacting) {
      continue;
    }
    const Eigen::Vector3d pc = cMw * sv.centroid;
    if (pc.z() <= 0) {
      continue;
    }
    const double u = (k.fx * pc.x() / pc.z() + k.cx) / s + 8;
    const double v = (k.fy * pc.y() / pc.z() + k.cy) / s + 8;
    if (u < 8 || v < 8 || u >= inset_w + 8 || v >= inset_h + 8) {
      continue;
    }
    const cv::Scalar colour = sv.label == SupervoxelClass::Object        ? rgb(60, 220, 90)
                              : sv.label == SupervoxelClass::Interacting ? rgb(240, 210, 40)
                                                                         : rgb(240, 40, 40);
    point(image, cv::Point2d(u, v), colour, 1);
  }
  cv::rectangle(image, cv::Rect(7, 7, inset_w + 2, inset_h + 2), kWhite);

  // Legend and figures.
  char line1[256];
  char line2[256];
  std::snprintf(line1, sizeof line1, "t=%.3fs  %s  N=%zu  interacting=%zu  occluders=%zu",
                frame.timestamp, to_string(r.status), r.counts.object, r.counts.interacting,
                r.counts.occluders);
  text(image, line1, cv::Point2d(10, kHeight - 48), kWhite);
  if (e) {
    std::snprintf(line2, sizeof line2, "%s, %d iterations, tf-t0 %.1f deg, front end %.1f ms",
                  to_string(e->status), e->iterations, e->tf_to_t0_deg, r.timings.total);
  } else {
    std::snprintf(line2, sizeof line2, "object lost: %s", r.message.c_str());
  }
  text(image, line2, cv::Point2d(10, kHeight - 26), kWhite);
  text(image, "green object, yellow interacting, red occluders, blue S_n rays, red normals",
       cv::Point2d(10, kHeight - 70), rgb(160, 160, 170));

  bool written = false;
  try {
    written = cv::imwrite(path, image);
  } catch (const cv::Exception& ex) {
    throw std::runtime_error(path + ": cannot write the picture: " + ex.what());
  }
  if (!written) {
    throw std::runtime_error(path + ": cannot write the picture");
  }
}

}  // namespace ofv::perception
