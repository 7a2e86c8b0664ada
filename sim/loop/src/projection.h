// Pinhole projection of world points for the pictures (OpenCV drawing).
#pragma once

#include "ofv/rgbd_frame.h"

#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include <cmath>
#include <optional>

namespace ofv::detail {

/// The pixel of world point `p` seen from `wMc`; nullopt behind the camera.
inline std::optional<cv::Point> project(const Eigen::Isometry3d& wMc, const CameraIntrinsics& k,
                                        const Eigen::Vector3d& p) {
  const Eigen::Vector3d c = wMc.inverse() * p;
  if (c.z() <= 1e-3) return std::nullopt;
  return cv::Point(static_cast<int>(std::lround(k.fx * c.x() / c.z() + k.cx)),
                   static_cast<int>(std::lround(k.fy * c.y() / c.z() + k.cy)));
}

}  // namespace ofv::detail
