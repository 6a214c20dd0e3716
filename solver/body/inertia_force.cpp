// The body's inertia whichever kinetic energy it uses: force, matrices, mass, momenta, damping, weight.
#include "solver/body/inertia_force.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "solver/body/body_blocks.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

using body_blocks::TurnBlocksInto;

void InertiaForce(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity& wdot,
                  Eigen::VectorXd* f_in, Eigen::MatrixXd* mass, Eigen::MatrixXd* gyroscopic, Eigen::VectorXd* f_acc) {
  const int n = body.n_coordinates();
  if (body.has_exact_inertia()) {
    Eigen::VectorXd& zero = d.scratch.v4;
    if (!body.options_.quadratic_velocity_terms || (!f_in && f_acc)) zero.setZero(n);
    if (f_in) {
      ExactInertiaForce(body, d, body.options_.quadratic_velocity_terms ? w : zero, wdot, *f_in, f_acc);
    } else if (f_acc) {
      ExactInertiaForce(body, d, zero, wdot, *f_acc, nullptr);
    }
    if (mass) *mass = ExactMass(body, d);
    if (gyroscopic) {
      if (!body.options_.quadratic_velocity_terms) {
        gyroscopic->setZero(n, n);
        return;
      }
      ExactGyroscopic(body, d, w, *gyroscopic);
    }
    return;
  }
  const BodyVelocityMaps& maps = MapsOf(body, d);
  const Eigen::MatrixXd& U = maps.U;
  const Eigen::MatrixXd& Mg = maps.Mg;
  if (f_acc) f_acc->noalias() = Mg * wdot;
  if (f_in) {
    f_in->noalias() = Mg * wdot;
    if (body.options_.quadratic_velocity_terms) {
      Eigen::VectorXd& quadratic = d.scratch.v3;
      QuadraticInertia(body, U, Mg, w, quadratic, d.scratch);
      *f_in += quadratic;
    }
  }
  if (mass) *mass = Mg;
  if (gyroscopic) {
    if (!body.options_.quadratic_velocity_terms) {
      gyroscopic->setZero(n, n);
      return;
    }
    QuadraticInertiaDerivative(body, U, Mg, w, *gyroscopic, d.scratch);
  }
}

const Eigen::MatrixXd& Mass(const SuperelementBody& body, BodyData& d) {
  return body.has_exact_inertia() ? ExactMass(body, d) : MapsOf(body, d).Mg;
}

const Eigen::VectorXd& MassTimes(const SuperelementBody& body, BodyData& d, const BodyVelocity& w) {
  Eigen::VectorXd& p = d.scratch.v1;
  if (body.has_exact_inertia()) {
    // The exact inertia force's acceleration part at w: M_g w in O(n^2) (the n x n ExactMass
    // costs three n^3 products; the energy measurement of every step took it).
    Eigen::VectorXd& r = d.exact_scratch.r;
    body_blocks::TurnBlocksInto(d.frame.R.transpose(), w, 2 * body.n_nodes_, r);
    ExactMassTimesTurned(body, d, r, p);
  } else {
    p.noalias() = MapsOf(body, d).Mg * w;
  }
  return p;
}

double KineticEnergy(const SuperelementBody& body, BodyData& d, const BodyVelocity& w) {
  return 0.5 * w.dot(MassTimes(body, d, w));
}

void InertiaConfigurationTangent(const SuperelementBody& body, BodyData& d, const BodyVelocity& w,
                                 const BodyVelocity& wdot, bool quadratic, Eigen::MatrixXd& tangent) {
  // Exact inertia: the whole force by central differences with `quadratic`; without, the
  // corotational d(M_g wdot)/dq, which has its leading part (the turning of the frame; the exact
  // mass differs from it at the order of q_loc Omega) for a fraction of the cost.
  if (body.has_exact_inertia() && quadratic && body.options_.quadratic_velocity_terms) {
    tangent = ExactInertiaConfigurationTangent(body, d, w, wdot);
    return;
  }
  MomentumDerivative(body, MapsOf(body, d), wdot, tangent, d.scratch);
  if (!quadratic || !body.options_.quadratic_velocity_terms) return;
  const int n = body.n_coordinates();
  BodyScratch scratch;
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd g[2];
    double step = 1e-7;
    for (int side = 0; side < 2; ++side) {
      const BodyConfiguration p = Perturbed(body, d.c, i, side == 0 ? 1.0 : -1.0, &step);
      BodyData dp = Evaluate(body, p, SolveFrame(body, p, d.frame));
      const BodyVelocityMaps& maps = MapsOf(body, dp);
      QuadraticInertia(body, maps.U, maps.Mg, w, g[side], scratch);
    }
    tangent.col(i) += (g[0] - g[1]) / (2 * step);
  }
}

void AddModalDamping(const SuperelementBody& body, const BodyVelocity& w, Eigen::VectorXd& f, Eigen::MatrixXd* C) {
  if (body.options_.modal_damping <= 0.0) return;
  for (int m = 0; m < body.n_modes_; ++m) {
    const int i = 6 * body.n_nodes_ + m;
    // Internal modes are mass-normalized: K_ii = omega_i^2.
    const double c = 2.0 * body.options_.modal_damping * std::sqrt(std::max(body.K_(i, i), 0.0));
    f[i] += c * w[i];
    if (C) (*C)(i, i) += c;
  }
}

void Momentum(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, Eigen::Vector3d* linear,
              Eigen::Vector3d* angular) {
  MomentumFrom(body, d, MassTimes(body, d, w), linear, angular);
}

void MomentumFrom(const SuperelementBody& body, BodyData& d, const Eigen::VectorXd& p, Eigen::Vector3d* linear,
                  Eigen::Vector3d* angular) {
  const BodyConfiguration& c = d.c;
  linear->setZero();
  angular->setZero();
  for (int a = 0; a < body.n_nodes_; ++a) {
    *linear += p.segment<3>(6 * a);
    *angular += p.segment<3>(6 * a + 3) + c.x[a].cross(Eigen::Vector3d(p.segment<3>(6 * a)));
  }
}

void GravityForce(const SuperelementBody& body, BodyData& data, const Eigen::Vector3d& g, Eigen::VectorXd& f) {
  const FrameSolution& frame = data.frame;
  Eigen::VectorXd& yg = data.scratch.v1;
  const Eigen::Vector3d g_frame = frame.R.transpose() * g;
  yg.noalias() = body.Phi_rig0_.leftCols<3>() * g_frame;
  if (body.has_exact_inertia()) {
    // Virtual work of g on the field: y_g = Phi_rig0 [R_j^T g; 0] (a uniform field), delta of the
    // field = Phi (Phi_rig0 delta xi + delta q_loc) + delta theta_j x (Phi q):
    // f = Rbar (Y^T M y_g + Z_r^T H^T y_g).
    const ExactInertiaData& d = *data.exact;
    Eigen::VectorXd& Myg = data.scratch.v2;
    Myg.noalias() = body.M_ * yg;
    const Eigen::Vector3d Hty = d.H.transpose() * yg;
    f.noalias() = d.Y.transpose() * Myg;
    f.noalias() += data.kin.Z.bottomRows<3>().transpose() * Hty;
    TurnBlocksInto(frame.R, f, 2 * body.n_nodes_, f);
    return;
  }
  // P^T block by block (P is block diagonal: its 3 x 3 node blocks, then 1 on the modal rows).
  const Eigen::MatrixXd& P = MapsOf(body, data).P;
  f.noalias() = body.M_ * yg;
  for (int a = 0; a < 2 * body.n_nodes_; ++a)
    f.segment<3>(3 * a) = P.block<3, 3>(3 * a, 3 * a).transpose() * Eigen::Vector3d(f.segment<3>(3 * a));
}

Eigen::MatrixXd GravityTangent(const SuperelementBody& body, BodyData& d, const Eigen::Vector3d& g) {
  const int n = body.n_coordinates();
  if (!body.has_exact_inertia()) {
    // GravityForce = P^T M P wdot_g = M_g wdot_g with wdot_g = g on every node's translation rows
    // (P wdot_g = Phi_rig0 [R_j^T g; 0]): its configuration derivative is MomentumDerivative's.
    BodyVelocity wdot_g = Eigen::VectorXd::Zero(n);
    for (int a = 0; a < body.n_nodes_; ++a) wdot_g.segment<3>(6 * a) = g;
    Eigen::MatrixXd D;
    BodyScratch scratch;
    MomentumDerivative(body, MapsOf(body, d), wdot_g, D, scratch);
    return D;
  }
  // The exact inertia's field: central differences with the frame re-solved, as for its inertia
  // force (ExactInertiaConfigurationTangent).
  Eigen::MatrixXd tangent(n, n);
  Eigen::VectorXd f_plus, f_minus;
  for (int i = 0; i < n; ++i) {
    double step = 0.0;
    const BodyConfiguration plus = Perturbed(body, d.c, i, 1.0, &step), minus = Perturbed(body, d.c, i, -1.0, &step);
    BodyData at_plus = Evaluate(body, plus, SolveFrame(body, plus, d.frame)),
             at_minus = Evaluate(body, minus, SolveFrame(body, minus, d.frame));
    GravityForce(body, at_plus, g, f_plus);
    GravityForce(body, at_minus, g, f_minus);
    tangent.col(i) = (f_plus - f_minus) / (2 * step);
  }
  return tangent;
}

}  // namespace femb
