#include "reducer/fe/nonlinear_beam.h"

#include <Eigen/Dense>
#include <cmath>

namespace femb {

VonKarmanBeams::VonKarmanBeams(const PartSpec& part) {
  for (const BeamElement& b : BeamElements(part, &nodes_)) {
    Element e;
    e.n1 = b.n1;
    e.n2 = b.n2;
    e.T = BeamTransformation(b.R);
    e.points = b.beam->QuadraturePoints();
    e.D = b.beam->SectionStiffness();
    elements_.push_back(std::move(e));
  }
}

Eigen::Matrix<double, 12, 1> VonKarmanBeams::Gather(const Element& e, const Eigen::VectorXd& u) const {
  Eigen::Matrix<double, 12, 1> ue;
  ue << u.segment<6>(6 * e.n1), u.segment<6>(6 * e.n2);
  return ue;
}

double VonKarmanBeams::ElementState(const Element& e, const Eigen::VectorXd& u, Eigen::Matrix<double, 12, 1>* f,
                                    Eigen::Matrix<double, 12, 12>* K) const {
  const Eigen::Matrix<double, 12, 1> ul = e.T * Gather(e, u);
  Eigen::Matrix<double, 12, 1> fl = Eigen::Matrix<double, 12, 1>::Zero();
  Eigen::Matrix<double, 12, 12> Kl = Eigen::Matrix<double, 12, 12>::Zero();
  double energy = 0.0, length = 0.0, mean = 0.0;
  Eigen::Matrix<double, 1, 12> grad = Eigen::Matrix<double, 1, 12>::Zero();    // d mean / d ul
  Eigen::Matrix<double, 12, 12> hess = Eigen::Matrix<double, 12, 12>::Zero();  // d2 mean / d ul2
  Eigen::Matrix<double, 6, 1> D = e.D;
  D[0] = 0.0;  // the axial term is the element's mean strain, below
  for (const TimoshenkoBeam::QuadraturePoint& p : e.points) {
    const Eigen::Vector2d g = p.slope * ul;
    length += p.weight;
    mean += p.weight * (p.B.row(0).dot(ul) + 0.5 * g.squaredNorm());
    grad += p.weight * (p.B.row(0) + g.transpose() * p.slope);
    hess += p.weight * p.slope.transpose() * p.slope;
    const Eigen::Matrix<double, 6, 1> s = p.B * ul;
    const Eigen::Matrix<double, 6, 1> sigma = D.cwiseProduct(s);
    energy += 0.5 * p.weight * s.dot(sigma);
    fl.noalias() += p.weight * p.B.transpose() * sigma;
    if (K) Kl.noalias() += p.weight * p.B.transpose() * D.asDiagonal() * p.B;
  }
  mean /= length;
  grad /= length;
  hess /= length;
  const double N = e.D[0] * mean;  // axial force
  energy += 0.5 * length * N * mean;
  fl.noalias() += length * N * grad.transpose();
  if (K) Kl.noalias() += length * (e.D[0] * grad.transpose() * grad + N * hess);
  if (f) *f = e.T.transpose() * fl;
  if (K) *K = e.T.transpose() * Kl * e.T;
  return energy;
}

double VonKarmanBeams::Energy(const Eigen::VectorXd& u) const {
  double energy = 0.0;
  for (const Element& e : elements_) energy += ElementState(e, u, nullptr, nullptr);
  return energy;
}

Eigen::VectorXd VonKarmanBeams::Force(const Eigen::VectorXd& u) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n_dofs());
  Eigen::Matrix<double, 12, 1> fe;
  for (const Element& e : elements_) {
    ElementState(e, u, &fe, nullptr);
    f.segment<6>(6 * e.n1) += fe.head<6>();
    f.segment<6>(6 * e.n2) += fe.tail<6>();
  }
  return f;
}

SparseMatrix VonKarmanBeams::Tangent(const Eigen::VectorXd& u) const {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(elements_.size() * 144);
  Eigen::Matrix<double, 12, 12> Ke;
  for (const Element& e : elements_) {
    ElementState(e, u, nullptr, &Ke);
    Ke = 0.5 * (Ke + Ke.transpose()).eval();
    const int dof[2] = {6 * e.n1, 6 * e.n2};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        for (int i = 0; i < 6; ++i)
          for (int j = 0; j < 6; ++j) entries.emplace_back(dof[a] + i, dof[b] + j, Ke(6 * a + i, 6 * b + j));
  }
  SparseMatrix K(n_dofs(), n_dofs());
  K.setFromTriplets(entries.begin(), entries.end());
  return K;
}

ReducedPolynomial ReduceVonKarman(const VonKarmanBeams& beams, const Eigen::MatrixXd& shapes,
                                  const PolynomialRequest& request) {
  const int n = int(shapes.cols()), P = n * (n + 1) / 2;
  const int n_stress = request.stress_fields ? int(request.stress_fields->cols()) : 0;
  PolynomialAccumulator accumulator(n, request.cubic, n_stress);
  Eigen::MatrixXd L(6, n), Q(6, P), stress_local(12, n_stress), L_stress(6, n_stress);
  Eigen::MatrixXd local(12, n);
  for (const VonKarmanBeams::Element& e : beams.elements_) {
    local.topRows(6) = shapes.middleRows(6 * e.n1, 6);
    local.bottomRows(6) = shapes.middleRows(6 * e.n2, 6);
    local = e.T * local;
    if (n_stress > 0) {
      stress_local.topRows(6) = request.stress_fields->middleRows(6 * e.n1, 6);
      stress_local.bottomRows(6) = request.stress_fields->middleRows(6 * e.n2, 6);
      stress_local = e.T * stress_local;
    }
    // Per point: torsion, bending and shear (D without the axial term); per element: the mean
    // axial strain (weight = element length).
    Eigen::Matrix<double, 6, 1> c = e.D.cwiseSqrt();
    c[0] = 0.0;
    const Eigen::Matrix<double, 6, 6> C_points = c.asDiagonal();
    Eigen::Matrix<double, 6, 6> C_axial = Eigen::Matrix<double, 6, 6>::Zero();
    C_axial(0, 0) = std::sqrt(e.D[0]);
    Eigen::MatrixXd L_mean = Eigen::MatrixXd::Zero(6, n), Q_mean = Eigen::MatrixXd::Zero(6, P);
    Eigen::MatrixXd L_stress_mean = Eigen::MatrixXd::Zero(6, n_stress);
    double length = 0.0;
    for (const TimoshenkoBeam::QuadraturePoint& p : e.points) {
      L = p.B * local;
      if (n_stress > 0) L_stress = p.B * stress_local;
      const Eigen::MatrixXd G = p.slope * local;  // 2 x n: v', w' of each basis vector
      Q.setZero();
      int k = 0;
      for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j, ++k) Q(0, k) = G.col(i).dot(G.col(j));
      accumulator.Add(p.weight, C_points, L, Q, n_stress > 0 ? &L_stress : nullptr);
      length += p.weight;
      L_mean.row(0) += p.weight * L.row(0);
      Q_mean.row(0) += p.weight * Q.row(0);
      if (n_stress > 0) L_stress_mean.row(0) += p.weight * L_stress.row(0);
    }
    // The geometric stiffness of beams is the axial force's (von Karman): N = EA (mean strain).
    const Eigen::MatrixXd L_stress_axial = L_stress_mean / length;
    accumulator.Add(length, C_axial, L_mean / length, Q_mean / length, n_stress > 0 ? &L_stress_axial : nullptr);
  }
  return accumulator.Finish();
}

}  // namespace femb
