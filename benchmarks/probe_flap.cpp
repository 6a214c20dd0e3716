#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cstdio>
#include <iostream>
#include <algorithm>
#include "formats/part_file.h"
#include "reducer/reduce_part.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
using namespace femb;
const double L = 1.0;
bool g_pinned = false;
// residual of free coords (B: 6, eta) for hub at origin rotating Om about z, t = 0
Eigen::VectorXd Residual(const SuperelementBody& body, double Om, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                         const Eigen::VectorXd& qdd) {
  BodyConfiguration c = body.InitialConfiguration();
  const int m = body.n_modes();
  const Eigen::Vector3d W(0, 0, Om);
  const int off = g_pinned ? 1 : 0;
  const Eigen::VectorXd qA = q, qdA = qd, qddA = qdd;
  const double thA = g_pinned ? q[0] : 0, thAd = g_pinned ? qd[0] : 0, thAdd = g_pinned ? qdd[0] : 0;
  {
    Eigen::VectorXd t;
    t = q.tail(q.size() - off); const_cast<Eigen::VectorXd&>(q) = t;
    t = qd.tail(qd.size() - off); const_cast<Eigen::VectorXd&>(qd) = t;
    t = qdd.tail(qdd.size() - off); const_cast<Eigen::VectorXd&>(qdd) = t;
  }
  c.R[0] = ExpSO3(Eigen::Vector3d(0, 0, thA)) * c.R[0];
  const Eigen::Vector3d XB = c.x[1];
  c.x[1] = XB + q.head<3>();
  c.R[1] = ExpSO3(Eigen::Vector3d(q.segment<3>(3))) * c.R[1];
  c.eta = q.tail(m);
  const int n = body.n_coordinates();
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n), a = Eigen::VectorXd::Zero(n);
  v.segment<3>(3) = W + Eigen::Vector3d(0, 0, thAd);
  a.segment<3>(3) = Eigen::Vector3d(0, 0, thAdd);
  v.segment<3>(6) = W.cross(c.x[1]) + qd.head<3>();
  v.segment<3>(9) = W + qd.segment<3>(3);
  v.tail(m) = qd.tail(m);
  a.segment<3>(6) = W.cross(W.cross(c.x[1])) + 2 * W.cross(Eigen::Vector3d(qd.head<3>())) + qdd.head<3>();
  a.segment<3>(9) = W.cross(Eigen::Vector3d(qd.segment<3>(3))) + qdd.segment<3>(3);
  a.tail(m) = qdd.tail(m);
  FrameSolution fr = body.SolveFrame(c, body.GuessFrame(c));
  Eigen::VectorXd fin, fel;
  body.InertiaForce(c, fr, v, a, &fin, nullptr, nullptr);
  const InertiaLoadFactors load = body.InertiaLoads(c, fr, v, a, Eigen::Vector3d::Zero());
  body.ElasticForce(c, fr, &fel, nullptr, &load);
  static int once = 0;
  if (Om > 60 && Om < 61 && once++ < 1) std::cout << "a = " << load.a.transpose() << "\n";
  Eigen::VectorXd res = (fin + fel).tail(n - 6);
  const_cast<Eigen::VectorXd&>(q) = qA; const_cast<Eigen::VectorXd&>(qd) = qdA; const_cast<Eigen::VectorXd&>(qdd) = qddA;
  if (!g_pinned) return res;
  Eigen::VectorXd out(res.size() + 1);
  out << (fin + fel)[5], res;
  return out;
}
int main(int argc, char** argv) {
  std::string frame = argc > 1 ? argv[1] : "interface:A";
  g_pinned = argc > 2;
  const std::string yaml =
      "name: tube\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  theory: euler_bernoulli\n  points: {A: [0, 0, 0], B: [1, 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 40}]\ninterfaces: [{name: A}, {name: B}]\n"
      "reduction: {internal_modes: 4, geometric_stiffening: true, floating_frame: '" + frame + "'}\n";
  ReduceResult r = ReducePart(ParsePart(yaml, "tube.yaml", {}), nullptr);
  {
    const Eigen::MatrixXd& Ks = r.superelement.inertia_stiffness[8];
    const double rhoA = 2700 * M_PI * (1e-4 - 0.81e-4);
    std::cout << "Ks8 flap block / rhoA:\n" << Ks(8, 8) / rhoA << " " << Ks(8, 10) / rhoA << "\n" << Ks(10, 8) / rhoA << " " << Ks(10, 10) / rhoA << "\n";
    std::cout << "Ks8 in-plane block / rhoA:\n" << Ks(7, 7) / rhoA << " " << Ks(7, 11) / rhoA << "\n" << Ks(11, 7) / rhoA << " " << Ks(11, 11) / rhoA << "\n";
    std::cout << "Ks8 axial / rhoA: " << Ks(6, 6) / rhoA << " A-B " << Ks(0, 6) / rhoA << "\n";
  }
  for (int opt = 0; opt < 3; ++opt) {
    SuperelementOptions o;
    Superelement se = r.superelement;
    if (opt == 1) se.inertia_stiffness.clear();
    if (opt == 2) se.polynomial.reset();
    SuperelementBody body(se, o);
    const int nf = body.n_coordinates() - 6 + (g_pinned ? 1 : 0);
    for (double ratio : {0.0, 0.5, 100 / 120.422, 1.0, 2.0}) {
      const double Om = ratio * 120.422;
      Eigen::VectorXd q = Eigen::VectorXd::Zero(nf), z = q;
      auto jac = [&](int which) {
        Eigen::MatrixXd J(nf, nf);
        for (int i = 0; i < nf; ++i) {
          const double h = 1e-6;
          Eigen::VectorXd p[3] = {q, z, z}, mm[3] = {q, z, z};
          p[which][i] += h;
          mm[which][i] -= h;
          J.col(i) = (Residual(body, Om, p[0], p[1], p[2]) - Residual(body, Om, mm[0], mm[1], mm[2])) / (2 * h);
        }
        return J;
      };
      for (int it = 0; it < 3; ++it) q -= jac(0).lu().solve(Residual(body, Om, q, z, z));
      const Eigen::MatrixXd K = jac(0), C = jac(1), M = jac(2);
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * nf, 2 * nf);
      A.topRightCorner(nf, nf).setIdentity();
      A.bottomLeftCorner(nf, nf) = -M.lu().solve(K);
      A.bottomRightCorner(nf, nf) = -M.lu().solve(C);
      Eigen::EigenSolver<Eigen::MatrixXd> es(A);
      std::vector<double> f;
      for (int i = 0; i < 2 * nf; ++i) if (es.eigenvalues()[i].imag() > 0) f.push_back(es.eigenvalues()[i].imag());
      std::sort(f.begin(), f.end());
      std::printf("opt %d Omega %.2f: u_s=%.2e  w:", opt, Om, q[0]);
      for (int i = 0; i < std::min<int>(4, f.size()); ++i) std::printf(" %.3f", f[i]);
      std::printf("\n");
      if (false) {
        Eigen::IOFormat fmt(3, 0, " ", "\n");
        std::printf("K-Ks:\n");
        Eigen::MatrixXd Ks = K; // print K, C
        std::cout << K.format(fmt) << "\nC:\n" << C.format(fmt) << "\nM:\n" << M.format(fmt) << "\n";
      }
    }
  }
}
