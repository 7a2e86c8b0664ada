/**
 * \file feature_sphere_view.h
 * \brief A ViSP visual feature that moves an eye-in-hand camera along the
 *        sphere of radius R around an object towards a view on it, keeping
 *        the object centred: the servo law for the occlusion-free views of
 *        I. Cuiral-Zueco and G. López-Nicolás, "Dynamic Occlusion Handling
 *        for Real Time Object Perception" (2020), whose solution space is
 *        that sphere.
 *
 * Frames: the camera frame c (ViSP's: x right, y down, z optical axis) and
 * the world frame w; the camera velocity \f$ \mathbf{v} = (\boldsymbol{\upsilon}, \boldsymbol{\omega}) \f$
 * is expressed in c. Let \f$ \mathbf{c} = {}^c\mathbf{M}_w \mathbf{C} \f$ be the object
 * centroid in the camera frame, \f$ \rho = \|\mathbf{c}\| \f$,
 * \f$ \mathbf{d} = -\mathbf{c}/\rho \f$ the direction from C to the camera (camera frame),
 * \f$ \mathbf{P} = \mathbf{I} - \mathbf{d}\mathbf{d}^\top \f$, and in the world frame
 * \f$ \mathbf{d}_w = {}^w\mathbf{R}_c \mathbf{d} \f$ and
 * \f$ \mathbf{g}_w = (\mathbf{t}_f - \mathbf{C}) / \|\mathbf{t}_f - \mathbf{C}\| \f$ the
 * direction to the desired view. The feature is
 * \f[ \mathbf{s} = \left( x,\; y,\; \rho - R,\; \mathbf{f} \right) \in \mathbb{R}^6,
 *     \quad x = c_x / c_z,\; y = c_y / c_z,\; \mathbf{f} = \mathbf{g}_w - \mathbf{d}_w, \f]
 * with \f$ \mathbf{s}^* = \mathbf{0} \f$: C at the image centre, the camera on
 * the sphere, on the ray of \f$ \mathbf{t}_f \f$ (\f$ \|\mathbf{f}\| = 2\sin(\theta/2) \f$,
 * θ the angle between the two directions seen from C, monotonic up to π).
 * Since \f$ \dot{\mathbf{c}} = -\boldsymbol{\upsilon} + [\mathbf{c}]_\times \boldsymbol{\omega} \f$ and
 * \f$ \dot{\mathbf{d}}_w = {}^w\mathbf{R}_c \mathbf{P} \boldsymbol{\upsilon} / \rho \f$ (f does
 * not depend on the camera's orientation), the interaction matrix
 * \f$ \dot{\mathbf{s}} = \mathbf{L}_s \mathbf{v} \f$ is
 * \f[ \mathbf{L}_s = \begin{bmatrix}
 *   \mathbf{L}_{xy,\upsilon} & \mathbf{L}_{xy,\omega} \\
 *   \mathbf{d}^\top & \mathbf{0}_{1\times3} \\
 *   -{}^w\mathbf{R}_c \mathbf{P} / \rho & \mathbf{0}_{3\times3}
 * \end{bmatrix},\quad
 * \mathbf{L}_{xy,\upsilon} = \begin{bmatrix} -1/c_z & 0 & x/c_z \\
 *   0 & -1/c_z & y/c_z \end{bmatrix},\quad
 * \mathbf{L}_{xy,\omega} = \begin{bmatrix} xy & -(1+x^2) & y \\
 *   1+y^2 & -xy & -x \end{bmatrix}. \f]
 * The translation it asks for is tangent to the sphere (through P) plus a
 * radial term that holds ρ at R, so the camera travels along the sphere, not
 * along the chord through the occluders; the rotation only centres C. L has
 * rank 5: the roll about the optical axis is left free (a pseudo-inverse law
 * does not roll). At the antipode of the target (θ = π) every tangent
 * direction is as good and P f = 0; ViewController nudges the target there.
 *
 * \code
 * ofv::servo::FeatureSphereView s, s_star;        // s_star stays 0
 * s.build(cMw, centroid_w, tf_w, 0.5);
 * vpServo task;
 * task.setServo(vpServo::EYEINHAND_CAMERA);
 * task.setInteractionMatrixType(vpServo::CURRENT);
 * task.addFeature(s, s_star);
 * task.setLambda(1.0);
 * vpColVector v = task.computeControlLaw();  // camera twist
 * \endcode
 */
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/visual_features/vpBasicFeature.h>

namespace ofv::servo {

/// \brief The sphere-view feature (see the file documentation for L_s).
class FeatureSphereView : public vpBasicFeature {
 public:
  /// \brief A feature of dimension 6 with s = 0; build() sets its state.
  FeatureSphereView();

  /**
   * \brief Sets the state.
   * \param cMw       current camera pose (world in camera).
   * \param centroid  object centroid C, world frame [m]; must be in front of the camera.
   * \param target    desired view t_f, world frame [m] (only its direction from C matters).
   * \param r_sphere  sphere radius R [m].
   * \throws std::invalid_argument when C is not in front of the camera or t_f = C.
   */
  void build(const vpHomogeneousMatrix& cMw, const vpColVector& centroid, const vpColVector& target,
             double r_sphere);

  /// Selectors of the components, for interaction() and error().
  static unsigned int selectX();
  static unsigned int selectY();    ///< y = c_y / c_z, the vertical image coordinate of C
  static unsigned int selectRho();  ///< rho - R, the distance from C off the sphere
  static unsigned int selectTangent();  ///< the three components of e

  /// \brief Resets it to dimension 6, s = 0, not built (vpBasicFeature's contract).
  void init() override;
  /// \brief The rows of L_s (file documentation) that `select` picks.
  /// \throws std::logic_error when build() was not called.
  vpMatrix interaction(unsigned int select = FEATURE_ALL) override;
  /// \brief Prints the selected components of s (x, y, rho-R, f_x, f_y, f_z) to std::cout.
  void print(unsigned int select = FEATURE_ALL) const override;
  /// \brief A copy allocated with new (vpServo owns it).
  FeatureSphereView* duplicate() const override;
  /// Draws the projection of C (the centring part of the feature).
  void display(const vpCameraParameters& cam, const vpImage<unsigned char>& I,
               const vpColor& color = vpColor::green, unsigned int thickness = 1) const override;
  /// Draws the projection of C on a colour image.
  void display(const vpCameraParameters& cam, const vpImage<vpRGBa>& I,
               const vpColor& color = vpColor::green, unsigned int thickness = 1) const override;

 private:
  vpColVector c_ = vpColVector(3, 0.0);  // C in the camera frame
  vpRotationMatrix wRc_;                 // camera orientation
  double r_ = 0.5;
};

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using FeatureSphereView [[deprecated("use ofv::servo::FeatureSphereView")]] = servo::FeatureSphereView;
}  // namespace ofv
/// \endcond
