// The sphere-view feature and its interaction matrix (see the header).
#include "ofv/servo/feature_sphere_view.h"

#include <visp3/core/vpImagePoint.h>
#include <visp3/core/vpMeterPixelConversion.h>
#include <visp3/core/vpDisplay.h>

#include <cmath>
#include <iostream>
#include <stdexcept>

namespace ofv::servo {

FeatureSphereView::FeatureSphereView() { init(); }

void FeatureSphereView::init() {
  dim_s = 6;
  nbParameters = 3;
  s.resize(dim_s, true);
  if (flags == nullptr) flags = new bool[nbParameters];
  for (unsigned int i = 0; i < nbParameters; ++i) flags[i] = false;
}

void FeatureSphereView::build(const vpHomogeneousMatrix& cMw, const vpColVector& centroid,
                              const vpColVector& target, double r_sphere) {
  if (centroid.size() != 3 || target.size() != 3) throw std::invalid_argument("FeatureSphereView: points must be 3-vectors");
  const vpColVector c = cMw.getRotationMatrix() * centroid + vpColVector(cMw.getTranslationVector());
  const vpColVector to_target = target - centroid;
  const double rho = c.frobeniusNorm(), g_len = to_target.frobeniusNorm();
  if (!(c[2] > 0.0) || !(rho > 0.0) || !(g_len > 0.0) || !std::isfinite(rho + g_len) || !(r_sphere > 0.0)) {
    throw std::invalid_argument("FeatureSphereView: the centroid must be in front of the camera, t_f != C, R > 0");
  }
  c_ = c;
  wRc_ = cMw.getRotationMatrix().inverse();
  r_ = r_sphere;
  const vpColVector d_w = wRc_ * (-c_ / rho);
  const vpColVector f = to_target / g_len - d_w;
  s[0] = c_[0] / c_[2];
  s[1] = c_[1] / c_[2];
  s[2] = rho - r_;
  for (unsigned i = 0; i < 3; ++i) s[3 + i] = f[i];
  for (unsigned int i = 0; i < nbParameters; ++i) flags[i] = true;
}

unsigned int FeatureSphereView::selectX() { return FEATURE_LINE[0]; }
unsigned int FeatureSphereView::selectY() { return FEATURE_LINE[1]; }
unsigned int FeatureSphereView::selectRho() { return FEATURE_LINE[2]; }
unsigned int FeatureSphereView::selectTangent() { return FEATURE_LINE[3] | FEATURE_LINE[4] | FEATURE_LINE[5]; }

vpMatrix FeatureSphereView::interaction(unsigned int select) {
  for (unsigned int i = 0; i < nbParameters; ++i) {
    if (!flags[i]) throw std::logic_error("FeatureSphereView: build() was not called");
  }
  const double z = c_[2], x = s[0], y = s[1];
  const double rho = c_.frobeniusNorm();
  const vpColVector d = -c_ / rho;
  vpMatrix full(6, 6, 0.0);
  const double lx[6] = {-1.0 / z, 0.0, x / z, x * y, -(1.0 + x * x), y};
  const double ly[6] = {0.0, -1.0 / z, y / z, 1.0 + y * y, -x * y, -x};
  for (unsigned int j = 0; j < 6; ++j) {
    full[0][j] = lx[j];
    full[1][j] = ly[j];
  }
  for (unsigned int j = 0; j < 3; ++j) full[2][j] = d[j];
  vpMatrix P;
  P.eye(3);
  for (unsigned int a = 0; a < 3; ++a) {
    for (unsigned int b = 0; b < 3; ++b) P[a][b] -= d[a] * d[b];
  }
  const vpMatrix lv = static_cast<vpMatrix>(wRc_) * P * (-1.0 / rho);
  for (unsigned int a = 0; a < 3; ++a) {
    for (unsigned int b = 0; b < 3; ++b) full[3 + a][b] = lv[a][b];
  }
  vpMatrix L;
  for (unsigned int i = 0; i < 6; ++i) {
    if (select & FEATURE_LINE[i]) {
      vpMatrix row(1, 6);
      for (unsigned int j = 0; j < 6; ++j) row[0][j] = full[i][j];
      L.stack(row);
    }
  }
  return L;
}

void FeatureSphereView::print(unsigned int select) const {
  std::cout << "FeatureSphereView:";
  const char* names[6] = {"x", "y", "rho-R", "f_x", "f_y", "f_z"};
  for (unsigned int i = 0; i < 6; ++i) {
    if (select & FEATURE_LINE[i]) std::cout << ' ' << names[i] << '=' << s[i];
  }
  std::cout << '\n';
}

FeatureSphereView* FeatureSphereView::duplicate() const { return new FeatureSphereView(*this); }

void FeatureSphereView::display(const vpCameraParameters& cam, const vpImage<unsigned char>& I,
                                const vpColor& color, unsigned int thickness) const {
  vpImagePoint ip;
  vpMeterPixelConversion::convertPoint(cam, s[0], s[1], ip);
  vpDisplay::displayCross(I, ip, 15, color, thickness);
}

void FeatureSphereView::display(const vpCameraParameters& cam, const vpImage<vpRGBa>& I,
                                const vpColor& color, unsigned int thickness) const {
  vpImagePoint ip;
  vpMeterPixelConversion::convertPoint(cam, s[0], s[1], ip);
  vpDisplay::displayCross(I, ip, 15, color, thickness);
}

}  // namespace ofv::servo
