// Isoparametric solid elements for linear elasticity: TET4, TET10, HEX8, HEX20 (node order of
// gmsh), consistent mass, full integration:
//   K = int B^T D B dV,  M = int rho N^T N dV  (3 DOFs per node: u_x, u_y, u_z; node-major)
// with D the isotropic elasticity matrix (Voigt order xx, yy, zz, yz, xz, xy; engineering
// shear strains). Quadrature: Gauss-Legendre 2^3 (HEX8), 3^3 (HEX20); tetrahedra by a collapsed
// (Duffy) 4^3 Gauss rule, exact to degree 5 on the reference tetrahedron (TET10 mass: 4).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "formats/part_file.h"
#include "formats/solid_shape.h"

namespace femb {

struct SolidElementMatrices {
  Eigen::MatrixXd K, M;  ///< (3 n) x (3 n)
  double volume = 0.0;
};

/// `X`: n x 3 node coordinates. Throws InputError "element <id>: inverted or degenerate
/// (det J = ... at a quadrature point)" when the mapping is not orientation-preserving.
SolidElementMatrices ComputeSolidElement(SolidType type, const Eigen::MatrixXd& X, const MaterialSpec& material,
                                         long element_id);

/// The quadrature of one element in physical coordinates: per point the shape functions N (n),
/// their gradient dN/dX (n x 3) and the volume weight dV = det J w. Throws InputError "element
/// <id>: inverted or degenerate (det J = ... at a quadrature point)" when det J <= 1e-10 size^3.
struct SolidPoint {
  Eigen::VectorXd N;
  Eigen::MatrixXd dNdX;
  double dV = 0.0;
};
std::vector<SolidPoint> SolidElementPoints(SolidType type, const Eigen::MatrixXd& X, long element_id);

/// The strain-displacement matrix (6 x 3n; xx, yy, zz, yz, xz, xy with engineering shear
/// strains) of shape-function gradients dN/dX (n x 3).
Eigen::MatrixXd SolidStrainMatrix(const Eigen::MatrixXd& dNdX);

/// Reference-element quadrature (points, weights).
void SolidQuadrature(SolidType type, std::vector<Eigen::Vector3d>* points, std::vector<double>* weights);

/// 6 x 6 isotropic elasticity matrix.
Eigen::Matrix<double, 6, 6> IsotropicElasticity(double E, double nu);

}  // namespace femb
