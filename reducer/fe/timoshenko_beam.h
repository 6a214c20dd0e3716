// Two-node 3D Timoshenko beam with interdependent interpolation (IIE): the transverse
// displacement is cubic and the section rotation quadratic such that the shear strain is constant,
// which makes the element exact for end-loaded beams and free of shear locking. With shear
// parameter Phi = 12 E I / (k G A L^2) = 0 it is the Euler-Bernoulli (Hermite) element.
//
// Local DOFs (x along the beam, axes from BeamFrame): node 1 (u_x, u_y, u_z, th_x, th_y, th_z),
// node 2 (same). Bending in x-y uses (u_y, th_z) with th_z ~ du_y/dx; bending in x-z uses
// (u_z, -th_y) with th_y ~ -du_z/dx.
//   Stiffness: K = int EA u'^2 + GJ th_x'^2 + EI th'^2 + kGA (v' - th)^2 dx,
//   consistent mass: M = int rho A |u|^2 + rho Ip th_x^2 + rho I th^2 dx (rotary inertia included),
// both integrated exactly by 4-point Gauss quadrature of the interpolation functions.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/beam_section.h"

namespace femb {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Matrix6x12d = Eigen::Matrix<double, 6, 12>;

/// Local axes of a beam from x1 to x2: rows of the returned matrix are e1 (along the beam),
/// e2, e3, with e3 = e1 x v / |e1 x v| and e2 = e3 x e1, v the orientation vector (lies in the
/// local x-y plane). Precondition: v not parallel to x2 - x1.
Eigen::Matrix3d BeamFrame(const Eigen::Vector3d& x1, const Eigen::Vector3d& x2, const Eigen::Vector3d& v);

class TimoshenkoBeam {
 public:
  /// `shear` false forces Euler-Bernoulli (Phi = 0).
  TimoshenkoBeam(double L, const MaterialSpec& material, const SectionProperties& section, bool shear);

  /// Element matrices in local axes.
  Matrix12d LocalStiffness() const;
  Matrix12d LocalMass() const;
  /// Local displacement and rotation (u, theta) at xi = x/L in [0, 1] from the 12 local DOFs.
  Matrix6x12d LocalInterpolation(double xi) const;

  /// The quadrature of LocalStiffness (4 Gauss points): per point the strain rows B (axial u',
  /// torsion, bending t_z', shear, bending (-t_y)', shear), the slopes v', w' of the transverse
  /// displacements (2 x 12; the moderate-rotation axial strain is u' + (v'^2 + w'^2) / 2) and the
  /// weight (times L). SectionStiffness: the diagonal of D (EA, GJ, EIz, kGA, EIy, kGA).
  struct QuadraturePoint {
    Eigen::Matrix<double, 6, 12> B;
    Eigen::Matrix<double, 2, 12> slope;
    double weight = 0.0;
  };
  std::vector<QuadraturePoint> QuadraturePoints() const;
  Eigen::Matrix<double, 6, 1> SectionStiffness() const;

  double Phi_y() const { return Phi_y_; }  ///< shear parameter of bending in x-y (uses Iz, ky)
  double Phi_z() const { return Phi_z_; }  ///< shear parameter of bending in x-z (uses Iy, kz)

 private:
  // d/dx of the interpolation (strains) at xi: rows axial u', torsion th_x', bending th_z',
  // shear (u_y' - th_z), bending (-th_y)', shear (u_z' + th_y).
  Eigen::Matrix<double, 6, 12> StrainInterpolation(double xi) const;

  double L_;
  MaterialSpec material_;
  SectionProperties section_;
  double Phi_y_ = 0.0, Phi_z_ = 0.0;
};

/// 12 x 12 block-diagonal rotation taking global element DOFs to local ones (4 blocks of R).
Matrix12d BeamTransformation(const Eigen::Matrix3d& R);

}  // namespace femb
