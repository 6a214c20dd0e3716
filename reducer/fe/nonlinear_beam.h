// Moderate-rotation (von Karman) beams: the beam part's elements (timoshenko_beam.h)
// with the axial strain u' + (v'^2 + w'^2) / 2 in element axes, the other strains (torsion,
// curvatures, shear) linear. The axial strain enters as its element mean (assumed constant
// membrane strain): pointwise, u' (constant per element) cannot balance v'^2 / 2 (quadratic), and
// the thin leaf of the tests locked by 5% at 40 elements (membrane locking). The strain is quadratic in the
// displacements, so the internal force is cubic and the reduced force is the same polynomial as for solids
// (nonlinear_solid.h):
//   W = sum over the elements of [EA L_e mean^2 + sum over 4 Gauss points w sum_i>0 D_i s_i^2] / 2,
//   mean = sum_g w_g (B_0 + v'^2/2 + w'^2/2) / L_e, g = (v', w') = S T u_e;
//   f and K_t are its exact derivatives (N = EA mean: K_t gets EA L_e grad grad^T + N L_e hess).
// 4-point Gauss integrates the linear stiffness exactly and the quartic energy to degree 7
// (exact would need 5 points for the v'^4 term); the full model and the reduced polynomial use
// the same points, so they agree exactly. Valid for moderate rotations inside a body: the
// floating frame carries the large ones.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/beam_model.h"
#include "reducer/fe/nonlinear_solid.h"

namespace femb {

/// A beam part's model DOFs (6 per node: u, theta in part axes, node order of BuildBeamModel).
class VonKarmanBeams : public NonlinearModel {
 public:
  explicit VonKarmanBeams(const PartSpec& part);
  long n_dofs() const override { return 6 * long(nodes_.size()); }
  double Energy(const Eigen::VectorXd& u) const override;
  Eigen::VectorXd Force(const Eigen::VectorXd& u) const override;
  SparseMatrix Tangent(const Eigen::VectorXd& u) const override;
  const std::vector<Eigen::Vector3d>& nodes() const { return nodes_; }
  friend ReducedPolynomial ReduceVonKarman(const VonKarmanBeams& beams, const Eigen::MatrixXd& shapes,
                                           const PolynomialRequest& request);

 private:
  struct Element {
    int n1, n2;
    Eigen::Matrix<double, 12, 12> T;  // global element DOFs -> local
    std::vector<TimoshenkoBeam::QuadraturePoint> points;
    Eigen::Matrix<double, 6, 1> D;
  };
  Eigen::Matrix<double, 12, 1> Gather(const Element& e, const Eigen::VectorXd& u) const;
  // Energy, force and (optionally) tangent of one element in global element DOFs.
  double ElementState(const Element& e, const Eigen::VectorXd& u, Eigen::Matrix<double, 12, 1>* f,
                      Eigen::Matrix<double, 12, 12>* K) const;
  std::vector<Eigen::Vector3d> nodes_;
  std::vector<Element> elements_;
};

/// The reduced polynomial (ReducedPolynomial) of the basis `shapes` (n_dofs x n) on this model.
/// No interface rotation completion (InterfaceRotationCompletion): on beam nodes it vanishes at
/// every interface, whose nodes carry their exact positions.
ReducedPolynomial ReduceVonKarman(const VonKarmanBeams& beams, const Eigen::MatrixXd& shapes,
                                  const PolynomialRequest& request = {});

}  // namespace femb
