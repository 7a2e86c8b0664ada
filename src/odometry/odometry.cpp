// RGB-D odometry on OpenCV's rgbd module (ofv/odometry/odometry.h).
#include "ofv/odometry/odometry.h"

#include <Eigen/Eigenvalues>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ofv::odometry {

namespace {

constexpr double kDegree = M_PI / 180.0;
// Pixel step of the inlier count: 1/16 of the pixels give the fraction
// within a percent at a tenth of the cost of the odometry itself.
constexpr int kInlierStride = 4;
// The still scene's patches: kPatch x kPatch pixels as matched, at least
// kPatchUsed of them used and away from the object, flat (the least spread
// of their points at most kFlat of the next); fewer than kMinPatches: no constraint.
constexpr int kPatch = 8;
constexpr int kPatchUsed = 48;
constexpr double kFlat = 0.05;
constexpr int kMinPatches = 8;
// Ok steps whose residuals set what a step's may be (max_residual_ratio).
constexpr std::size_t kResiduals = 9;
// Rounds of restarts at most (OdometrySettings::restart_distance).
constexpr double kRestartRounds = 10.0;

cv::Ptr<cv::rgbd::Odometry> make_odometry(const OdometrySettings& s, const CameraIntrinsics& k) {
  cv::Mat K = (cv::Mat_<double>(3, 3) << k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0);
  const auto min_depth = static_cast<float>(s.min_depth);
  const auto max_depth = static_cast<float>(s.max_depth);
  const auto diff = static_cast<float>(s.max_depth_diff);
  const auto part = static_cast<float>(s.max_points_part);
  // OpenCV's own motion bound turns a large motion into a failure; ours
  // (max_translation, max_rotation) makes it Implausible, so OpenCV's is lifted.
  constexpr double kUnbounded = 1e3;
  // OpenCV's default is 7, 7, 7, 10 from the finest level to the coarsest;
  // the ICP methods do finest_iterations at the finest.
  const int n = s.iterations;
  const std::vector<int> iterations = {n, n, n, n + n / 2};
  const std::vector<int> icp = {s.finest_iterations, n, n, n + n / 2};
  switch (s.method) {
    case OdometryMethod::Icp: {
      auto o = cv::rgbd::ICPOdometry::create(K, min_depth, max_depth, diff, part, icp);
      o->setMaxTranslation(kUnbounded);
      o->setMaxRotation(kUnbounded);
      return o;
    }
    case OdometryMethod::RgbdIcp: {
      auto o = cv::rgbd::RgbdICPOdometry::create(K, min_depth, max_depth, diff, part, icp);
      o->setMaxTranslation(kUnbounded);
      o->setMaxRotation(kUnbounded);
      return o;
    }
    case OdometryMethod::FastIcp:
      return cv::rgbd::FastICPOdometry::create(K, diff, static_cast<float>(30.0 * kDegree), 0.04f, 4.5f, 7,
                                               iterations);
    case OdometryMethod::Rgbd: {
      auto o = cv::rgbd::RgbdOdometry::create(K, min_depth, max_depth, diff, iterations, {}, part);
      o->setMaxTranslation(kUnbounded);
      o->setMaxRotation(kUnbounded);
      return o;
    }
  }
  throw std::invalid_argument("odometry: unknown method");
}

bool same(const CameraIntrinsics& a, const CameraIntrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx &&
         a.cy == b.cy;
}

/// The whole factor that brings the width within `max_width` (1: none, or
/// max_width 0), leaving at least one row.
int reduction(const CameraIntrinsics& k, int max_width) {
  const int f = max_width > 0 && k.width > max_width ? (k.width + max_width - 1) / max_width : 1;
  return std::max(1, std::min(f, k.height));
}

/// The intrinsics of every `factor`-th pixel of every `factor`-th row
/// (pixel u of the result is pixel factor·u of the frame).
CameraIntrinsics reduced(const CameraIntrinsics& k, int factor) {
  CameraIntrinsics r = k;
  r.width = k.width / factor;
  r.height = k.height / factor;
  r.fx = k.fx / factor;
  r.fy = k.fy / factor;
  r.cx = k.cx / factor;
  r.cy = k.cy / factor;
  return r;
}

/// The rotation's angle [rad].
double angle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

/// OpenCV's 4x4 motion as an isometry. OpenCV composes its increments
/// without re-orthonormalising: the rotation drifts off SO(3) and, composed
/// frame after frame, scales the pose; the nearest rotation is taken.
Eigen::Isometry3d isometry(const Eigen::Matrix4d& T) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.topLeftCorner<3, 3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0.0) {
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) = -U.col(2);
    R = U * svd.matrixV().transpose();
  }
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  M.linear() = R;
  M.translation() = T.topRightCorner<3, 1>();
  return M;
}

/// The share `s` of the motion M: the rotation's angle and the translation
/// scaled by it (the screw's for the small motions between frames).
Eigen::Isometry3d fraction(const Eigen::Isometry3d& M, double s) {
  const Eigen::AngleAxisd turn(M.linear());
  Eigen::Isometry3d F = Eigen::Isometry3d::Identity();
  F.linear() = Eigen::AngleAxisd(turn.angle() * s, turn.axis()).toRotationMatrix();
  F.translation() = M.translation() * s;
  return F;
}

}  // namespace

struct Odometry::Impl {
  OdometrySettings settings;
  cv::Ptr<cv::rgbd::Odometry> odometry;
  CameraIntrinsics input;       // the frames' (the first frame's)
  int factor = 1;               // OdometrySettings::max_width: matched at 1/factor of the frames' size
  CameraIntrinsics intrinsics;  // of the frames as matched
  bool started = false;
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  // the last good pose
  Eigen::Isometry3d wMk = Eigen::Isometry3d::Identity();  // the reference frame's pose
  Eigen::Isometry3d kMc = Eigen::Isometry3d::Identity();  // the last good pose in the reference frame
  Eigen::Isometry3d velocity = Eigen::Isometry3d::Identity();  // the last step's motion when it was Ok
  int unknown = 0;  // steps since the last Ok or first frame: the pose is that many frames old
  std::deque<double> residuals;  // of the last kResiduals Ok steps, oldest first
  cv::Ptr<cv::rgbd::OdometryFrame> reference;

  explicit Impl(const OdometrySettings& s) : settings(s) {}

  [[nodiscard]] bool needs_colour() const {
    return settings.method == OdometryMethod::Rgbd || settings.method == OdometryMethod::RgbdIcp;
  }

  /// The frame as OpenCV takes it: depth [m] with NaN where missing, the
  /// mask of the pixels used, grey image for the photometric methods.
  cv::Ptr<cv::rgbd::OdometryFrame> convert(const RgbdFrame& frame, const ObjectHint& object,
                                           OdometryDiagnostics& d) const {
    const int w = intrinsics.width;
    const int h = intrinsics.height;
    cv::Mat depth(h, w, CV_32FC1);
    cv::Mat mask(h, w, CV_8UC1);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::optional<double> object_depth = object.nearest_depth();
    const bool masking = settings.mask && object_depth && std::isfinite(*object_depth);
    const double nearest = masking ? *object_depth - settings.mask_margin : 0.0;
    // The support plane is still, however near: its pixels stay in (on it
    // and of its colour: an arm that touches the table is on it too).
    const bool colour = frame.rgb.size() == 3 * frame.depth.size();
    const auto on_plane = [&](int u, int v, float z) {
      if (!object.plane_c) return false;
      const Eigen::Vector4d& plane = object.plane_c->plane;
      const Eigen::Vector3d p((u - intrinsics.cx) / intrinsics.fx * z, (v - intrinsics.cy) / intrinsics.fy * z, z);
      if (std::abs(plane.head<3>().dot(p) + plane(3)) > settings.mask_plane_distance) return false;
      if (!colour) return true;
      const std::uint8_t* c = &frame.rgb[3 * frame.index(factor * u, factor * v)];
      const Eigen::Vector3f rgb(c[0], c[1], c[2]);
      return (chromaticity(rgb) - object.plane_c->chroma).norm() <= settings.mask_plane_chroma;
    };
    long used = 0;
    long masked = 0;
    for (int v = 0; v < h; ++v) {
      auto* drow = depth.ptr<float>(v);
      auto* mrow = mask.ptr<std::uint8_t>(v);
      for (int u = 0; u < w; ++u) {
        const float z = frame.depth[frame.index(factor * u, factor * v)];
        const bool valid = z >= settings.min_depth && z <= settings.max_depth;  // NaN fails
        drow[u] = valid ? z : nan;
        const bool hidden = valid && masking && z < nearest && !on_plane(u, v, z);
        mrow[u] = valid && !hidden ? 255 : 0;
        used += valid && !hidden ? 1 : 0;
        masked += hidden ? 1 : 0;
      }
    }
    const double pixels = static_cast<double>(w) * h;
    d.valid_fraction = static_cast<double>(used) / pixels;
    d.masked_fraction = static_cast<double>(masked) / pixels;
    cv::Mat grey;
    if (needs_colour()) {
      const int fw = frame.intrinsics.width;
      const int fh = frame.intrinsics.height;
      if (frame.rgb.size() == static_cast<std::size_t>(fw) * fh * 3) {
        const cv::Mat rgb(fh, fw, CV_8UC3, const_cast<std::uint8_t*>(frame.rgb.data()));
        cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
        // Pixel factor·u, as the depth (nearest: pixel floor(u·fw/w)).
        if (factor > 1) cv::resize(grey, grey, cv::Size(w, h), 0.0, 0.0, cv::INTER_NEAREST);
      } else {
        grey = cv::Mat::zeros(h, w, CV_8UC1);
      }
    }
    return cv::rgbd::OdometryFrame::create(grey, depth, mask);
  }

  /// OpenCV's motion of `current` in the reference's frame from the start
  /// `guess` (the same frames: OpenCV keeps what it computed of them), not
  /// yet re-orthonormalised; false when it finds none or throws.
  [[nodiscard]] bool match(cv::Ptr<cv::rgbd::OdometryFrame>& current, const Eigen::Isometry3d& guess,
                           Eigen::Matrix4d& T) {
    cv::Mat init(4, 4, CV_64FC1);
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) init.at<double>(r, c) = guess.matrix()(r, c);
    }
    cv::Mat Rt;
    if (!odometry->compute(current, reference, Rt, init) || Rt.rows != 4 || Rt.cols != 4) return false;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) T(r, c) = Rt.at<double>(r, c);
    }
    return true;
  }

  /// Matches `current` again from starts restart_distance from `motion` (in
  /// the reference's frame) along each of the camera's axes, and again
  /// around the best while one fits the reference better (a lower RMS of the
  /// matching pixels than `residual`, `motion`'s, with the overlap and
  /// inliers a step needs), as far as max_translation (kRestartRounds at
  /// most). Whether one did: the best is then in `motion`.
  bool restart(cv::Ptr<cv::rgbd::OdometryFrame>& current, Eigen::Isometry3d& motion, double residual) {
    const int rounds =
        static_cast<int>(std::min(kRestartRounds, std::ceil(settings.max_translation / settings.restart_distance)));
    bool better = false;
    for (int round = 0; round < rounds; ++round) {
      const Eigen::Isometry3d around = motion;
      bool moved = false;
      for (int axis = 0; axis < 3; ++axis) {
        for (const double side : {-1.0, 1.0}) {
          Eigen::Isometry3d start = around;
          start.translation()(axis) += side * settings.restart_distance;
          Eigen::Matrix4d T;
          try {
            if (!match(current, start, T) || !T.allFinite()) continue;
          } catch (const cv::Exception&) {
            continue;
          }
          const Eigen::Isometry3d other = isometry(T);
          OdometryDiagnostics fit;
          cv::Mat pixels;
          inliers(*current, *reference, other, fit, pixels);
          if (fit.overlap_fraction >= settings.min_overlap_fraction &&
              fit.inlier_fraction >= settings.min_inlier_fraction && fit.residual < residual) {
            motion = other;
            residual = fit.residual;
            moved = true;
          }
        }
      }
      if (!moved) break;
      better = true;
    }
    return better;
  }

  /// Whether a step's residual is more than max_residual_ratio times the
  /// median of the last Ok steps' (with at least 3 of them).
  [[nodiscard]] bool unlike_before(double residual) const {
    if (settings.max_residual_ratio <= 0.0 || residuals.size() < 3) return false;
    std::vector<double> r(residuals.begin(), residuals.end());
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    return residual > settings.max_residual_ratio * r[r.size() / 2];
  }

  /// The pixels `used` farther than object_radius from the object's points
  /// (discs around their projections): the scene apart from the object.
  [[nodiscard]] cv::Mat away_from(const cv::Mat& used, const ObjectHint& object) const {
    const CameraIntrinsics& k = intrinsics;
    cv::Mat away = used.clone();
    for (Eigen::Index i = 0; i < object.points_c.cols(); ++i) {
      const Eigen::Vector3d p = object.points_c.col(i);
      if (!(p.z() > 1e-6) || !p.allFinite()) continue;
      const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
      const double r = k.fx * settings.object_radius / p.z();
      if (u < -r || v < -r || u > k.width + r || v > k.height + r) continue;
      cv::circle(away, cv::Point(static_cast<int>(std::lround(u)), static_cast<int>(std::lround(v))),
                 static_cast<int>(std::ceil(r)), cv::Scalar(0), cv::FILLED);
    }
    return away;
  }

  /// OdometryDiagnostics::still_constraint (match_constraint) of the pixels
  /// `away` of a frame as matched (depth in metres): the normals of their
  /// flat patches.
  [[nodiscard]] double constraint(const cv::Mat& depth, const cv::Mat& away) const {
    const CameraIntrinsics& k = intrinsics;

    Eigen::Matrix3d normals = Eigen::Matrix3d::Zero();
    int patches = 0;
    std::vector<Eigen::Vector3d> points;
    points.reserve(kPatch * kPatch);
    for (int v0 = 0; v0 + kPatch <= k.height; v0 += kPatch) {
      for (int u0 = 0; u0 + kPatch <= k.width; u0 += kPatch) {
        points.clear();
        for (int v = v0; v < v0 + kPatch; ++v) {
          const auto* zrow = depth.ptr<float>(v);
          const auto* arow = away.ptr<std::uint8_t>(v);
          for (int u = u0; u < u0 + kPatch; ++u) {
            if (arow[u] == 0) continue;
            const double z = zrow[u];
            points.emplace_back((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
          }
        }
        if (static_cast<int>(points.size()) < kPatchUsed) continue;
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (const Eigen::Vector3d& p : points) mean += p;
        mean /= static_cast<double>(points.size());
        Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
        for (const Eigen::Vector3d& p : points) spread += (p - mean) * (p - mean).transpose();
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> patch(spread);
        if (patch.eigenvalues()(0) > kFlat * patch.eigenvalues()(1)) continue;  // an edge, a corner, a curve
        const Eigen::Vector3d n = patch.eigenvectors().col(0);
        normals += n * n.transpose();
        ++patches;
      }
    }
    if (patches < kMinPatches) return 0.0;
    return std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(normals / patches, Eigen::EigenvaluesOnly)
                             .eigenvalues()(0));
  }

  /// Of the used pixels of `src` (sampled) whose point, moved by `motion`
  /// (kMc), falls on a used pixel of the reference (the overlap: in view, depth
  /// in range, not masked there) and, with occlusion_aware, not behind what
  /// the reference saw there by more than max_depth_diff, those within
  /// max_depth_diff of it; and their RMS difference. What the reference did
  /// not see (it left the view, was masked there or hidden) tells nothing of
  /// the motion: counted as mismatches, the check failed a right motion
  /// whenever the mask changed (the object lost, no mask), the camera saw
  /// past the occluders or, in no-free-view's cage, moved along its bars.
  /// `matching` gets the pixels around the matching samples.
  void inliers(const cv::rgbd::OdometryFrame& src, const cv::rgbd::OdometryFrame& ref, const Eigen::Isometry3d& motion,
               OdometryDiagnostics& d, cv::Mat& matching) const {
    matching = cv::Mat::zeros(src.depth.size(), CV_8UC1);
    const CameraIntrinsics& k = intrinsics;
    const Eigen::Matrix3f R = motion.linear().cast<float>();
    const Eigen::Vector3f t = motion.translation().cast<float>();
    long pixels = 0;
    long samples = 0;
    long matched = 0;
    double sum = 0.0;
    for (int v = 0; v < k.height; v += kInlierStride) {
      const auto* zrow = src.depth.ptr<float>(v);
      const auto* mrow = src.mask.ptr<std::uint8_t>(v);
      for (int u = 0; u < k.width; u += kInlierStride) {
        ++pixels;
        if (mrow[u] == 0) continue;
        const float z = zrow[u];
        const Eigen::Vector3f p(static_cast<float>((u - k.cx) / k.fx) * z, static_cast<float>((v - k.cy) / k.fy) * z, z);
        const Eigen::Vector3f q = R * p + t;
        if (!(q.z() > 0.0f)) continue;
        const double uq = k.fx * q.x() / q.z() + k.cx;
        const double vq = k.fy * q.y() / q.z() + k.cy;
        const long ui = std::lround(uq);
        const long vi = std::lround(vq);
        if (!(ui >= 0 && ui < k.width && vi >= 0 && vi < k.height)) continue;
        if (ref.mask.at<std::uint8_t>(static_cast<int>(vi), static_cast<int>(ui)) == 0) continue;
        const double diff = ref.depth.at<float>(static_cast<int>(vi), static_cast<int>(ui)) - q.z();
        // A point behind what the reference saw there was hidden from it:
        // no evidence either way (thin near bars hide much of the scene
        // from one frame to the next). One in front of it contradicts it.
        if (settings.occlusion_aware && diff < -settings.max_depth_diff) continue;
        ++samples;
        if (std::abs(diff) <= settings.max_depth_diff) {
          ++matched;
          sum += diff * diff;
          matching(cv::Rect(u, v, std::min(kInlierStride, k.width - u), std::min(kInlierStride, k.height - v))) = 255;
        }
      }
    }
    d.overlap_fraction = pixels > 0 ? static_cast<double>(samples) / static_cast<double>(pixels) : 0.0;
    d.inlier_fraction = samples > 0 ? static_cast<double>(matched) / static_cast<double>(samples) : 0.0;
    d.residual = matched > 0 ? std::sqrt(sum / static_cast<double>(matched)) : 0.0;
  }
};

Odometry::Odometry(const OdometrySettings& settings) {
  validate(settings);
  impl_ = std::make_unique<Impl>(settings);
}
Odometry::~Odometry() = default;
Odometry::Odometry(Odometry&&) noexcept = default;
Odometry& Odometry::operator=(Odometry&&) noexcept = default;

void Odometry::reset() {
  impl_->started = false;
  impl_->reference.release();
  impl_->wMc = impl_->wMk = impl_->kMc = impl_->velocity = Eigen::Isometry3d::Identity();
  impl_->residuals.clear();
  impl_->unknown = 0;
}

const Eigen::Isometry3d& Odometry::wMc() const { return impl_->wMc; }
const OdometrySettings& Odometry::settings() const { return impl_->settings; }

OdometryResult Odometry::step(const RgbdFrame& frame, const ObjectHint& object) {
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  const CameraIntrinsics& k = frame.intrinsics;
  const std::size_t pixels = static_cast<std::size_t>(std::max(k.width, 0)) * static_cast<std::size_t>(std::max(k.height, 0));
  if (k.width <= 0 || k.height <= 0 || frame.depth.size() != pixels) {
    throw std::invalid_argument("odometry: the frame's depth has " + std::to_string(frame.depth.size()) +
                                " values, its intrinsics say " + std::to_string(k.width) + "x" +
                                std::to_string(k.height));
  }
  if (m.started && !same(k, m.input)) {
    throw std::invalid_argument("odometry: the frame's intrinsics differ from the first frame's");
  }
  OdometryResult result;
  const auto finish = [&](OdometryStatus status) {
    if (status != OdometryStatus::Ok) m.velocity = Eigen::Isometry3d::Identity();
    m.unknown = m.started && status != OdometryStatus::Ok && status != OdometryStatus::FirstFrame ? m.unknown + 1 : 0;
    result.status = status;
    result.wMc = m.wMc;
    result.diagnostics.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  OdometryDiagnostics& d = result.diagnostics;
  if (!m.started) {
    m.input = k;
    m.factor = reduction(k, m.settings.max_width);
    m.intrinsics = reduced(k, m.factor);
    m.odometry = make_odometry(m.settings, m.intrinsics);
  }
  cv::Ptr<cv::rgbd::OdometryFrame> current = m.convert(frame, object, d);
  if (!m.started) {
    // The first frame is a reference only if it can be one; until then
    // every frame is a first frame, at the source's pose.
    m.wMc = frame.wMc;
    if (d.valid_fraction < m.settings.min_valid_fraction) return finish(OdometryStatus::Failed);
    m.started = true;
    m.wMk = m.wMc;
    m.kMc = Eigen::Isometry3d::Identity();
    m.reference = current;
    d.keyframe = true;
    return finish(OdometryStatus::FirstFrame);
  }
  if (d.valid_fraction < m.settings.min_valid_fraction) return finish(OdometryStatus::Failed);

  // What the scene cannot fix is not matched (and before OpenCV's
  // compute(), which changes the frame's mask).
  const cv::Mat depth = current->depth;
  const bool constrain = m.settings.min_still_constraint > 0.0;
  const cv::Mat away = constrain ? m.away_from(current->mask, object) : cv::Mat();
  if (constrain && object.points_c.cols() > 0) {
    d.still_constraint = m.constraint(depth, away);
    if (d.still_constraint < m.settings.min_still_constraint) return finish(OdometryStatus::Degenerate);
  }

  // The first guess: the last step's motion again from the last pose (the
  // camera moves smoothly), or the last pose.
  const Eigen::Isometry3d guess = m.settings.constant_velocity ? m.kMc * m.velocity : m.kMc;
  Eigen::Matrix4d T;
  try {
    d.converged = m.match(current, guess, T);
  } catch (const cv::Exception&) {
    return finish(OdometryStatus::Failed);  // e.g. too few points for a level of the pyramid
  }
  // The frame had pixels enough: no motion that fits means it does not fit the reference.
  if (!d.converged) return finish(OdometryStatus::Implausible);
  if (!T.allFinite()) {
    d.translation = d.rotation = std::numeric_limits<double>::quiet_NaN();
    return finish(OdometryStatus::Implausible);
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  d.orthonormality = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  Eigen::Isometry3d kMc = isometry(T);
  // Whether the motion kMc is one the camera can have made and that fits
  // the reference (the checks' measures in d; `matching` its matching pixels).
  cv::Mat matching;
  const auto judge = [&]() {
    m.inliers(*current, *m.reference, kMc, d, matching);
    const Eigen::Isometry3d motion = m.wMc.inverse() * m.wMk * kMc;  // from the last good pose
    d.translation = motion.translation().norm();
    d.rotation = angle(motion.linear()) / kDegree;
    if (d.translation > m.settings.max_translation || d.rotation > m.settings.max_rotation ||
        d.overlap_fraction < m.settings.min_overlap_fraction || d.inlier_fraction < m.settings.min_inlier_fraction ||
        m.unlike_before(d.residual)) {
      return OdometryStatus::Implausible;
    }
    d.match_constraint = std::numeric_limits<double>::quiet_NaN();
    if (constrain) {
      cv::Mat standing;
      cv::bitwise_and(matching, away, standing);
      d.match_constraint = m.constraint(depth, standing);
      if (d.match_constraint < m.settings.min_still_constraint) return OdometryStatus::Degenerate;
    }
    return OdometryStatus::Ok;
  };
  OdometryStatus status = judge();
  // The camera may have moved on while the pose was not known: the match,
  // started far from the motion, can then stop in a wrong minimum that
  // passes. Made again from around it, the best fit is judged instead.
  if (status == OdometryStatus::Ok && m.unknown > 0 && m.settings.restart_distance > 0.0) {
    const Eigen::Vector3d first = kMc.translation();
    if (m.restart(current, kMc, d.residual)) status = judge();
    d.restart_shift = (kMc.translation() - first).norm();
  }
  if (status != OdometryStatus::Ok) return finish(status);
  const Eigen::Isometry3d wMc = m.wMk * kMc;
  const Eigen::Isometry3d motion = m.wMc.inverse() * wMc;
  m.wMc = wMc;
  m.kMc = kMc;
  m.velocity = m.unknown == 0 ? motion : fraction(motion, 1.0 / (m.unknown + 1));  // a frame's motion
  m.residuals.push_back(d.residual);
  if (m.residuals.size() > kResiduals) m.residuals.pop_front();
  if (!m.settings.keyframe || kMc.translation().norm() > m.settings.keyframe_translation ||
      angle(kMc.linear()) > m.settings.keyframe_rotation * kDegree) {
    m.reference = current;
    m.wMk = wMc;
    m.kMc = Eigen::Isometry3d::Identity();
    d.keyframe = true;
  }
  return finish(OdometryStatus::Ok);
}

const char* to_string(OdometryMethod method) {
  switch (method) {
    case OdometryMethod::Icp:
      return "icp";
    case OdometryMethod::RgbdIcp:
      return "rgbd_icp";
    case OdometryMethod::FastIcp:
      return "fast_icp";
    case OdometryMethod::Rgbd:
      return "rgbd";
  }
  return "?";
}

const char* to_string(OdometryStatus status) {
  switch (status) {
    case OdometryStatus::Ok:
      return "ok";
    case OdometryStatus::FirstFrame:
      return "first_frame";
    case OdometryStatus::Failed:
      return "failed";
    case OdometryStatus::Implausible:
      return "implausible";
    case OdometryStatus::Degenerate:
      return "degenerate";
  }
  return "?";
}

OdometryMethod parse_method(const std::string& what, const std::string& word) {
  return parse_word<OdometryMethod>(what, word,
                                    {{"icp", OdometryMethod::Icp},
                                     {"rgbd_icp", OdometryMethod::RgbdIcp},
                                     {"fast_icp", OdometryMethod::FastIcp},
                                     {"rgbd", OdometryMethod::Rgbd}});
}

FramePose frame_pose(const OdometryResult& r) {
  FramePose pose;
  pose.wMc = r.wMc;
  pose.ok = r.status == OdometryStatus::Ok || r.status == OdometryStatus::FirstFrame;
  pose.source = "odometry";
  pose.status = to_string(r.status);
  const OdometryDiagnostics& d = r.diagnostics;
  pose.diagnostics = {{"valid_fraction", d.valid_fraction}, {"masked_fraction", d.masked_fraction},
                      {"overlap_fraction", d.overlap_fraction}, {"inlier_fraction", d.inlier_fraction},
                      {"residual_m", d.residual},             {"still_constraint", d.still_constraint},
                      {"match_constraint", d.match_constraint}, {"restart_shift_m", d.restart_shift},
                      {"translation_m", d.translation},       {"rotation_deg", d.rotation},
                      {"keyframe", d.keyframe ? 1.0 : 0.0},   {"ms", d.ms}};
  return pose;
}

PoseSource odometry_pose_source(const OdometrySettings& settings) {
  // Shared: std::function copies the callable, and every copy is one sequence.
  auto odometry = std::make_shared<Odometry>(settings);
  return [odometry](const RgbdFrame& frame, const ObjectHint& object) {
    return frame_pose(odometry->step(frame, object));
  };
}

}  // namespace ofv::odometry
