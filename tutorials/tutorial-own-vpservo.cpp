//! \example tutorial-own-vpservo.cpp
//! Tutorial 3: plug ofv's sphere feature into your own vpServo loop.
//!
//! A free-flying camera (vpSimulatorCamera) looks at an object 0.5 m away;
//! the occlusion-free view (from ofv::estimate_view, or any target you have)
//! lies 60 degrees around the object. FeatureSphereView moves the camera along
//! the sphere of radius 0.5 m to it, keeping the object centred.
#include <ofv/constants.h>
#include <ofv/estimator.h>
#include <ofv/servo/feature_sphere_view.h>

#include <visp3/robot/vpSimulatorCamera.h>
#include <visp3/vs/vpServo.h>

#include <cmath>
#include <iostream>

int main() {
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
  ofv::FeatureSphereView s, s_star;
  vpServo task;
  task.setServo(vpServo::EYEINHAND_CAMERA);
  task.setInteractionMatrixType(vpServo::CURRENT);
  task.addFeature(s, s_star);
  task.setLambda(1.0);

  double worst = 0.0;
  for (int k = 0; k < 300; ++k) {
    const vpHomogeneousMatrix wMc = robot.getPosition();
    s.build(wMc.inverse(), centroid, tf, r_sphere);  // re-set every frame: the target may move
    const vpColVector v = task.computeControlLaw();
    robot.setVelocity(vpRobot::CAMERA_FRAME, v);
    const double dist = (vpColVector(wMc.getTranslationVector()) - centroid).frobeniusNorm();
    worst = std::max(worst, std::abs(dist - r_sphere));
  }
  const vpColVector end(robot.getPosition().getTranslationVector());
  std::cout << "camera at " << end.t() << " (target " << tf.t() << ")\n"
            << "largest distance off the sphere on the way: " << 100 * worst << " cm\n";
  return (end - tf).frobeniusNorm() < 0.01 && worst < 0.02 ? 0 : 1;
}
