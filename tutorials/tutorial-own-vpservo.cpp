//! \example tutorial-own-vpservo.cpp
//! Tutorial 3: plug ofv's sphere feature into your own vpServo loop.
//!
//! A free-flying camera (vpSimulatorCamera) looks at an object 0.5 m away;
//! the occlusion-free view (from ofv::estimate_view, or any target you have)
//! lies 60 degrees around the object. FeatureSphereView moves the camera along
//! the sphere of radius 0.5 m to it, keeping the object centred.
//!
//!     tutorial-own-vpservo [--display]
//!
//! `--display` shows the loop live (ofv::LiveDisplay, in real time): the
//! feature's current value (C's projection) and desired one (the image
//! centre), the scene view, the velocity and the feature error. Left click
//! pauses, right click or q ends the loop.
#include <ofv/constants.h>
#include <ofv/estimator.h>
#include <ofv/servo/feature_sphere_view.h>
#if defined(OFV_HAVE_DISPLAY)
#include <ofv/display/live_display.h>
#include <ofv/servo/target_pose.h>
#endif

#include <visp3/robot/vpSimulatorCamera.h>
#include <visp3/vs/vpServo.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <memory>

int main(int argc, char** argv) {
  const bool display = argc > 1 && std::strcmp(argv[1], "--display") == 0;
  // The object's centroid and the target view, in the world frame.
  const vpColVector centroid{0.0, 0.0, 0.5};
  const double r_sphere = 0.5, angle = 60.0 * ofv::kPi / 180.0;
  const vpColVector tf{r_sphere * std::sin(angle), 0.0, 0.5 - r_sphere * std::cos(angle)};

  // The camera starts at the world origin, looking along +z at the object.
  vpSimulatorCamera robot;
  robot.setSamplingTime(0.04);
  robot.setPosition(vpHomogeneousMatrix());  // wMc = identity

  // The feature and its desired value (zero: on the sphere, on the target's
  // ray, object centred).
  ofv::servo::FeatureSphereView s, s_star;
  vpServo task;
  task.setServo(vpServo::EYEINHAND_CAMERA);
  task.setInteractionMatrixType(vpServo::CURRENT);
  task.addFeature(s, s_star);
  task.setLambda(1.0);

#if defined(OFV_HAVE_DISPLAY)
  // Optional live windows, fed what this loop knows (no sensor image here).
  std::unique_ptr<ofv::LiveDisplay> live;
  if (display) {
    try {
      ofv::LiveDisplayOptions options;
      options.title = "tutorial-own-vpservo";
      options.r_sphere = r_sphere;
      options.pace_rate = 1.0 / 0.04;  // real time
      live = std::make_unique<ofv::LiveDisplay>(options);
    } catch (const ofv::DisplayUnavailable& e) {
      std::cerr << "tutorial-own-vpservo: " << e.what() << '\n';
      return 2;
    }
  }
#else
  if (display) {
    std::cerr << "tutorial-own-vpservo: --display: this ofv was built without ofv::display\n";
    return 2;
  }
#endif

  double worst = 0.0;
  for (int k = 0; k < 300; ++k) {
    const vpHomogeneousMatrix wMc = robot.getPosition();
    s.build(wMc.inverse(), centroid, tf, r_sphere);  // re-set every frame: the target may move
    const vpColVector v = task.computeControlLaw();
#if defined(OFV_HAVE_DISPLAY)
    if (live) {
      ofv::DisplayInput in;
      in.time = 0.04 * k;
      in.wMc = ofv::servo::to_eigen(wMc);
      in.centroid = Eigen::Vector3d(centroid[0], centroid[1], centroid[2]);
      in.target = Eigen::Vector3d(tf[0], tf[1], tf[2]);
      in.velocity = v;
      if (!live->show(in)) break;  // right click or q: stop here
    }
#endif
    robot.setVelocity(vpRobot::CAMERA_FRAME, v);
    const double dist = (vpColVector(wMc.getTranslationVector()) - centroid).frobeniusNorm();
    worst = std::max(worst, std::abs(dist - r_sphere));
  }
  const vpColVector end(robot.getPosition().getTranslationVector());
  std::cout << "camera at " << end.t() << " (target " << tf.t() << ")\n"
            << "largest distance off the sphere on the way: " << 100 * worst << " cm\n";
#if defined(OFV_HAVE_DISPLAY)
  if (live && live->quit_requested()) return 0;  // ended early by the user
#endif
  return (end - tf).frobeniusNorm() < 0.01 && worst < 0.02 ? 0 : 1;
}
