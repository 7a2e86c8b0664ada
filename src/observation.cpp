// The loop's input from one frame.
#include "ofv/observation.h"

namespace ofv {

const char* to_string(PoseStatus status) { return status == PoseStatus::Known ? "known" : "unknown"; }

Eigen::Matrix3Xd Observation::all_occluders() const {
  const Eigen::Index seen = problem ? problem->occluders.cols() : 0;
  Eigen::Matrix3Xd all(3, seen + presumed.cols());
  if (seen > 0) all.leftCols(seen) = problem->occluders;
  all.rightCols(presumed.cols()) = presumed;
  return all;
}

}  // namespace ofv
