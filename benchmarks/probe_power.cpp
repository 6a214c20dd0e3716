#include <Eigen/Dense>
#include <cstdio>
#include <iostream>
#include "formats/part_file.h"
#include "reducer/reduce_part.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
using namespace femb;
int main(int argc, char** argv) {
  std::string frame = argc > 1 ? argv[1] : "center_of_mass";
  const std::string yaml =
      "name: tube\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  theory: euler_bernoulli\n  points: {A: [0, 0, 0], B: [1, 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 40}]\ninterfaces: [{name: A}, {name: B}]\n"
      "reduction: {internal_modes: 4, geometric_stiffening: true, floating_frame: '" + frame + "'}\n";
  ReduceResult r = ReducePart(ParsePart(yaml, "tube.yaml", {}), nullptr);
  for (int exact = 0; exact < 2; ++exact) {
    SuperelementOptions o;
    o.exact_inertia = exact == 1;
    SuperelementBody body(r.superelement, o);
    const int n = body.n_coordinates(), N = body.n_nodes();
    std::srand(3);
    BodyConfiguration c = body.InitialConfiguration();
    for (int k = 0; k < N; ++k) {
      c.x[k] += 0.01 * Eigen::Vector3d::Random();
      c.R[k] = ExpSO3(0.5 * Eigen::Vector3d(0.3, 0.2, 0.5) + 0.02 * Eigen::Vector3d::Random()) * c.R[k];
    }
    c.x[1] = ExpSO3(0.5 * Eigen::Vector3d(0.3, 0.2, 0.5)) * c.x[1];
    c.eta = 0.01 * Eigen::VectorXd::Random(body.n_modes());
    Eigen::VectorXd w = Eigen::VectorXd::Random(n) * 10, wd = Eigen::VectorXd::Random(n) * 100;
    auto at = [&](double h) {
      BodyConfiguration p = c;
      for (int k = 0; k < N; ++k) {
        p.x[k] += h * w.segment<3>(6 * k) + 0.5 * h * h * wd.segment<3>(6 * k);
        p.R[k] = ExpSO3(Eigen::Vector3d(h * w.segment<3>(6 * k + 3) + 0.5 * h * h * wd.segment<3>(6 * k + 3))) * p.R[k];
      }
      p.eta += h * w.tail(body.n_modes()) + 0.5 * h * h * wd.tail(body.n_modes());
      return p;
    };
    FrameSolution f0 = body.SolveFrame(c, body.GuessFrame(c));
    Eigen::VectorXd fin;
    body.InertiaForce(c, f0, w, wd, &fin, nullptr, nullptr);
    for (double h : {1e-3, 1e-4, 1e-5}) {
      BodyConfiguration cp = at(h), cm = at(-h);
      const double Tp = body.KineticEnergy(cp, body.SolveFrame(cp, f0), w + h * wd);
      const double Tm = body.KineticEnergy(cm, body.SolveFrame(cm, f0), w - h * wd);
      std::printf("exact %d h %g: dT/dt %.10e  w.f_in %.10e  rel diff %.3e\n", exact, h, (Tp - Tm) / (2 * h), w.dot(fin),
                  ((Tp - Tm) / (2 * h) - w.dot(fin)) / std::abs(w.dot(fin)));
    }
  }
}
