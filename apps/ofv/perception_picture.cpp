// Fig. 6-like pictures drawn with ViSP's vpImageDraw into a vpImage<vpRGBa>.
#include "perception_picture.h"

#include <visp3/core/vpColor.h>
#include <visp3/core/vpFont.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpImageDraw.h>
#include <visp3/core/vpImagePoint.h>
#include <visp3/io/vpImageIo.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace ofv::cli {

namespace {

constexpr int kWidth = 800;
constexpr int kHeight = 600;

/// A pinhole observer looking at `target` from `eye`, `up` roughly up in the image.
class Observer {
 public:
  Observer(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up,
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
  /// Image point of world point p, or nothing behind the observer.
  [[nodiscard]] std::optional<vpImagePoint> operator()(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d c = cRw_ * (p - eye_);
    if (c.z() < 1e-3) {
      return std::nullopt;
    }
    return vpImagePoint(focal_ * c.y() / c.z() + kHeight / 2.0,
                        focal_ * c.x() / c.z() + kWidth / 2.0);
  }

 private:
  Eigen::Matrix3d cRw_;
  Eigen::Vector3d eye_;
  double focal_;
};

void line(vpImage<vpRGBa>& image, const Observer& obs, const Eigen::Vector3d& a,
          const Eigen::Vector3d& b, const vpColor& colour, unsigned thickness = 1) {
  const auto pa = obs(a);
  const auto pb = obs(b);
  if (pa && pb) {
    vpImageDraw::drawLine(image, *pa, *pb, colour, thickness);
  }
}

void dot(vpImage<vpRGBa>& image, const Observer& obs, const Eigen::Vector3d& p,
         const vpColor& colour, unsigned thickness = 1) {
  if (const auto ip = obs(p);
      ip && ip->get_i() >= 0 && ip->get_j() >= 0 && ip->get_i() < kHeight && ip->get_j() < kWidth) {
    vpImageDraw::drawPoint(image, *ip, colour, thickness);
  }
}

void square(vpImage<vpRGBa>& image, const Observer& obs, const Eigen::Vector3d& p,
            const vpColor& colour, double half = 3.0) {
  if (const auto ip = obs(p)) {
    vpImageDraw::drawRectangle(
        image, vpRect(ip->get_j() - half, ip->get_i() - half, 2 * half, 2 * half), colour);
  }
}

/// Text whose top-left corner is inside the picture (vpFont clips nothing).
void text(vpImage<vpRGBa>& image, const vpFont& font, const std::string& s, const vpImagePoint& at,
          const vpColor& colour) {
  if (at.get_i() >= 0 && at.get_j() >= 0 && at.get_i() < kHeight - 12 && at.get_j() < kWidth - 8) {
    font.drawText(image, s, at, colour);
  }
}

void marker(vpImage<vpRGBa>& image, const vpFont& font, const Observer& obs,
            const Eigen::Vector3d& p, const vpColor& colour, const std::string& label) {
  if (const auto ip = obs(p)) {
    vpImageDraw::drawCircle(image, *ip, 7, colour, 2);
    text(image, font, label, vpImagePoint(ip->get_i() - 22, ip->get_j() + 8), colour);
  }
}

}  // namespace

void save_perception_picture(const std::string& path, const RgbdFrame& frame,
                             const PerceptionResult& r, const std::optional<ViewEstimate>& e,
                             double r_sphere) {
  vpImage<vpRGBa> image(kHeight, kWidth, vpRGBa(24, 24, 32));
  const vpFont font(16, vpFont::GENERIC_MONOSPACE);
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
      (Eigen::AngleAxisd(55.0 * M_PI / 180.0, cam_up) * back + 0.5 * cam_up).normalized();
  const Observer obs(c + 2.4 * r_sphere * dir, c, cam_up, 0.9 * kHeight);

  // Background and other voxels, faint; the sphere as three great circles.
  for (std::size_t i = 0; i < r.voxels.size(); i += 2) {
    const SupervoxelClass cls = r.supervoxels[static_cast<std::size_t>(r.voxel_owner[i])].label;
    if (cls == SupervoxelClass::Background || cls == SupervoxelClass::Occluder) {
      dot(image, obs, r.voxels[i].cast<double>(), vpColor(90, 90, 100));
    }
  }
  if (tracked) {
    const Eigen::Matrix3d& a = r.axes;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = a.col(k);
      const Eigen::Vector3d v = a.col((k + 1) % 3);
      for (int s = 0; s < 72; ++s) {
        const double t0 = 2 * M_PI * s / 72, t1 = 2 * M_PI * (s + 1) / 72;
        line(image, obs, c + r_sphere * (std::cos(t0) * u + std::sin(t0) * v),
             c + r_sphere * (std::cos(t1) * u + std::sin(t1) * v), vpColor(70, 70, 110));
      }
    }
  }
  // Occluders: small red squares, under everything else.
  for (Eigen::Index b = 0; b < r.problem.occluders.cols(); ++b) {
    square(image, obs, r.problem.occluders.col(b), vpColor(200, 40, 40), 1.5);
  }
  // Interacting (yellow) and object (green) voxels.
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const SupervoxelClass cls = r.supervoxels[static_cast<std::size_t>(r.voxel_owner[i])].label;
    if (cls == SupervoxelClass::Object) {
      dot(image, obs, r.voxels[i].cast<double>(), vpColor(60, 220, 90), 3);
    } else if (cls == SupervoxelClass::Interacting) {
      dot(image, obs, r.voxels[i].cast<double>(), vpColor(230, 200, 40), 2);
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
               corner[static_cast<std::size_t>(k | bit)], vpColor(60, 220, 120));
        }
      }
    }
    // Supervoxel normals (red) and normals-to-sphere rays (blue).
    const ViewProblem& p = r.problem;
    for (Eigen::Index n = 0; n < p.positions.cols(); ++n) {
      const Eigen::Vector3d v = p.positions.col(n);
      const Eigen::Vector3d nn = p.normals.col(n).normalized();
      if ((v - c).norm() < r_sphere) {
        line(image, obs, c, sphere_exit(c, r_sphere, v, nn), vpColor(70, 110, 255));
      }
      line(image, obs, v, v + 0.03 * nn, vpColor(255, 90, 90));
    }
  }
  // Cameras.
  marker(image, font, obs, camera, vpColor::white, "t_real");
  line(image, obs, camera, camera + 0.08 * frame.wMc.linear().col(2), vpColor::white, 2);
  if (e) {
    line(image, obs, c, e->t0, vpColor::cyan, 2);
    line(image, obs, c, e->tf, vpColor(255, 60, 255), 2);
    marker(image, font, obs, e->t0, vpColor::cyan, "t0");
    marker(image, font, obs, e->tf, vpColor(255, 60, 255), "tf");
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
      if (!frame.rgb.empty()) {
        image[v + 8][u + 8] = vpRGBa(frame.rgb[3 * i], frame.rgb[3 * i + 1], frame.rgb[3 * i + 2]);
      } else {
        const auto g = static_cast<unsigned char>(std::min(255.0f, frame.depth[i] * 100.0f));
        image[v + 8][u + 8] = vpRGBa(g, g, g);
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
    const vpColor colour = sv.label == SupervoxelClass::Object        ? vpColor(60, 220, 90)
                           : sv.label == SupervoxelClass::Interacting ? vpColor(240, 210, 40)
                                                                      : vpColor(240, 40, 40);
    vpImageDraw::drawPoint(image, vpImagePoint(v, u), colour, 2);
  }
  vpImageDraw::drawRectangle(image, vpRect(7, 7, inset_w + 2, inset_h + 2), vpColor::white);

  // Legend and figures.
  char line1[256];
  char line2[256];
  std::snprintf(line1, sizeof line1, "t=%.3fs  %s  N=%zu  interacting=%zu  occluders=%zu",
                frame.timestamp, to_string(r.status), r.counts.object, r.counts.interacting,
                r.counts.occluders);
  text(image, font, line1, vpImagePoint(kHeight - 48, 10), vpColor::white);
  if (e) {
    std::snprintf(line2, sizeof line2, "%s, %d iterations, tf-t0 %.1f deg, front end %.1f ms",
                  to_string(e->status), e->iterations, e->tf_to_t0_deg, r.timings.total);
  } else {
    std::snprintf(line2, sizeof line2, "object lost: %s", r.message.c_str());
  }
  text(image, font, line2, vpImagePoint(kHeight - 26, 10), vpColor::white);
  text(image, font, "green object, yellow interacting, red occluders, blue S_n rays, red normals",
       vpImagePoint(kHeight - 70, 10), vpColor(160, 160, 170));

  try {
    vpImageIo::write(image, path);
  } catch (const std::exception& ex) {
    throw std::runtime_error(path + ": cannot write the picture: " + ex.what());
  }
}

}  // namespace ofv::cli
