// ofv::FeatureSphereView in a plain vpServo loop with vpSimulatorCamera (as in
// tutorials/tutorial-own-vpservo.cpp): the camera, 0.5 m from the object,
// must reach the view 60 degrees around it while staying on the sphere.
#include <ofv/servo/feature_sphere_view.h>

#include <visp3/robot/vpSimulatorCamera.h>
#include <visp3/vs/vpServo.h>

#include <algorithm>
#include <cmath>
#include <iostream>

int main() {
  const vpColVector centroid{0.0, 0.0, 0.5};
  const double r_sphere = 0.5, angle = 60.0 * M_PI / 180.0;
  const vpColVector tf{r_sphere * std::sin(angle), 0.0, 0.5 - r_sphere * std::cos(angle)};

  vpSimulatorCamera robot;
  robot.setSamplingTime(0.04);
  robot.setPosition(vpHomogeneousMatrix());  // wMc = identity, looking at the object

  ofv::FeatureSphereView s, s_star;
  vpServo task;
  task.setServo(vpServo::EYEINHAND_CAMERA);
  task.setInteractionMatrixType(vpServo::CURRENT);
  task.addFeature(s, s_star);
  task.setLambda(1.0);

  double worst = 0.0;
  for (int k = 0; k < 300; ++k) {
    const vpHomogeneousMatrix wMc = robot.getPosition();
    s.build(wMc.inverse(), centroid, tf, r_sphere);
    robot.setVelocity(vpRobot::CAMERA_FRAME, task.computeControlLaw());
    const double dist = (vpColVector(wMc.getTranslationVector()) - centroid).frobeniusNorm();
    worst = std::max(worst, std::abs(dist - r_sphere));
  }
  const vpColVector end(robot.getPosition().getTranslationVector());
  const double miss = (end - tf).frobeniusNorm();
  std::cout << "camera at " << end.t() << " (target " << tf.t() << "), " << 100 * miss
            << " cm away; at most " << 100 * worst << " cm off the sphere\n";
  return miss < 0.01 && worst < 0.02 ? 0 : 1;
}
