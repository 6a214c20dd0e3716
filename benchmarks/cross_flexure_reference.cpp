// The full nonlinear reference of examples/cross_flexure: both leaves meshed in full (the mesh of
// the one-body leaf part, placed as make_variant.py places them), Green-Lagrange / St. Venant-
// Kirchhoff (reducer/fe/nonlinear_solid.h), lower end faces clamped, upper end faces moving with
// a rigid rotor turned by a prescribed angle theta about y through its centre: tip node i at
// c0 + t + R(theta) (X_i - c0), the rotor translation t free (the pivot's centre shift). Newton,
// continued in theta by increments of at most DTHETA (default 0.01 rad) from the previous state;
// the moment is the rotor's equilibrium,
// M = sum over the tip nodes of ((x_i - c) x f_i)_y with the internal nodal forces f_i.
// Writes CSV: theta,moment,shift_x,shift_z.
//
// usage: cross_flexure_reference LEAF_PART.yaml OUT.csv THETA[,THETA...] [DTHETA]
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "formats/input_error.h"
#include "formats/part_file.h"
#include "reducer/fe/nonlinear_solid.h"
#include "reducer/fe/solid_model.h"
#include "reducer/progress.h"

namespace femb {
namespace {

// The cross flexure's two leaves: the leaf mesh placed twice as in make_variant.py (position,
// rotation angle about y), with the clamped nodes (x = 0) and the tip nodes (x = L) of both.
struct TwoLeaves {
  long n1 = 0;  ///< nodes per leaf
  double width = 0, gap = 0.0005, a = 0;
  Eigen::MatrixXd nodes;
  Eigen::MatrixXi cells;
  std::vector<int> clamp, tip;
};

TwoLeaves PlaceTwoLeaves(const FeModel& leaf) {
  TwoLeaves m;
  const Eigen::MatrixXd& X = leaf.nodes;
  const long n1 = m.n1 = X.rows();
  const double L = X.col(0).maxCoeff();
  m.width = X.col(1).maxCoeff();
  const double a = m.a = L / (2 * std::sqrt(2.0));
  const std::vector<std::pair<Eigen::Vector3d, double>> placements = {
      {Eigen::Vector3d(-a, 0, -a), -M_PI / 4}, {Eigen::Vector3d(a, m.width + m.gap, -a), -3 * M_PI / 4}};
  m.nodes.resize(2 * n1, 3);
  m.cells.resize(2 * leaf.cells.rows(), leaf.cells.cols());
  for (int l = 0; l < 2; ++l) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(placements[l].second, Eigen::Vector3d::UnitY()).toRotationMatrix();
    for (long i = 0; i < n1; ++i) {
      m.nodes.row(l * n1 + i) = (placements[l].first + R * X.row(i).transpose()).transpose();
      if (std::abs(X(i, 0)) < 1e-9) m.clamp.push_back(int(l * n1 + i));
      if (std::abs(X(i, 0) - L) < 1e-9) m.tip.push_back(int(l * n1 + i));
    }
    m.cells.middleRows(l * leaf.cells.rows(), leaf.cells.rows()) = leaf.cells.array() + int(l * n1);
  }
  return m;
}

int Run(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: cross_flexure_reference LEAF_PART.yaml OUT.csv THETA[,THETA...] [DTHETA]\n");
    return 2;
  }
  const PartSpec part = ReadPartFile(argv[1]);
  const std::string out_path = argv[2];
  std::vector<double> thetas;
  {
    std::stringstream s(argv[3]);
    std::string item;
    while (std::getline(s, item, ',')) thetas.push_back(std::stod(item));
  }
  const double dtheta = argc > 4 ? std::atof(argv[4]) : 0.01;
  const FeModel leaf = BuildSolidModel(part);
  const TwoLeaves m = PlaceTwoLeaves(leaf);
  const long n1 = m.n1;
  const double width = m.width, gap = m.gap, a = m.a;
  const Eigen::MatrixXd& nodes = m.nodes;
  const Eigen::MatrixXi& cells = m.cells;
  const std::vector<int>&clamp = m.clamp, &tip = m.tip;
  const SolidType type = SolidTypeOf(leaf.cell_type).value_or(SolidType::kHex20);
  const SvkSolidMesh solid(type, nodes, cells, part.material);
  const Eigen::Vector3d c0(0, width + gap / 2, a);  // the rotor's centre, as in make_variant.py
  std::vector<char> is_tip(size_t(2 * n1), 0);
  for (int i : tip) is_tip[size_t(i)] = 1;
  // Model DOFs: 3 per non-tip node (the clamped ones prescribed to 0), then the rotor translation
  // t (3) and the rotation amplitude s (1, prescribed): tip node u = t + s u0.
  std::vector<long> first(size_t(2 * n1), -1);
  long n = 0;
  for (long i = 0; i < 2 * n1; ++i)
    if (!is_tip[size_t(i)]) first[size_t(i)] = (n += 3) - 3;
  const long t_dof = n, s_dof = n + 3;
  n += 4;
  std::vector<int> prescribed;
  for (int i : clamp)
    for (int d = 0; d < 3; ++d) prescribed.push_back(int(first[size_t(i)] + d));
  prescribed.push_back(int(s_dof));
  Eigen::VectorXd values = Eigen::VectorXd::Zero(long(prescribed.size()));
  values[values.size() - 1] = 1.0;

  std::ofstream out(out_path + ".tmp");
  out << "theta,moment,shift_x,shift_z\n";
  // Continuation in theta: angles up to each requested one in increments <= dtheta, each solved
  // from the previous state (one Newton solve, the tip faces placed at the new rotation).
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), u_previous = u;
  double current = 0.0, previous_step = 0.0;
  auto transform = [&](double angle) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    std::vector<Eigen::Triplet<double>> entries;
    for (long i = 0; i < 2 * n1; ++i) {
      for (int d = 0; d < 3; ++d) {
        if (!is_tip[size_t(i)]) {
          entries.emplace_back(int(3 * i + d), int(first[size_t(i)] + d), 1.0);
          continue;
        }
        entries.emplace_back(int(3 * i + d), int(t_dof + d), 1.0);
        const Eigen::Vector3d u0 = (R - Eigen::Matrix3d::Identity()) * (nodes.row(i).transpose() - c0);
        entries.emplace_back(int(3 * i + d), int(s_dof), u0[d]);
      }
    }
    SparseMatrix T(3 * 2 * n1, n);
    T.setFromTriplets(entries.begin(), entries.end());
    return T;
  };
  for (double theta : thetas) {
    Stopwatch clock;
    int iterations = 0;
    SparseMatrix T;
    while (current < theta - 1e-12) {
      const double step_size = std::min(theta, current + dtheta) - current;
      current += step_size;
      T = transform(current);
      // Secant predictor: without it the tip faces jump to the new angle alone, and Newton from
      // there can land on another equilibrium (seen at 0.05 rad steps: the rotor 1.4 mm lower).
      const Eigen::VectorXd guess =
          previous_step > 0 ? Eigen::VectorXd(u + (step_size / previous_step) * (u - u_previous)) : u;
      const NonlinearStaticResult step =
          SolveNonlinearStatic(solid, T, prescribed, values, Eigen::VectorXd::Zero(n), 1, 1e-9, 30, &guess);
      u_previous = u;
      previous_step = step_size;
      if (!step.converged) {
        std::fprintf(stderr, "cross_flexure_reference: theta = %g: %s\n", current, step.message.c_str());
        return 3;
      }
      u = step.u.back();
      iterations += step.iterations.back();
    }
    if (T.size() == 0) T = transform(current);
    NonlinearStaticResult r;
    r.u.push_back(u);
    const Eigen::VectorXd u_mesh = T * r.u.back();
    const Eigen::VectorXd f = solid.Force(u_mesh);
    const Eigen::Vector3d t = r.u.back().segment<3>(t_dof), c = c0 + t;
    double moment = 0.0;
    for (int i : tip) {
      const Eigen::Vector3d x = nodes.row(i).transpose() + u_mesh.segment<3>(3 * i);
      moment += (x - c).cross(Eigen::Vector3d(f.segment<3>(3 * i))).y();
    }
    // The moment the internal forces exert on the rotor is -M; the applied moment balances it.
    std::printf(
        "cross_flexure_reference: theta %.4f rad: moment %.6g N m, centre shift (%.4f, %.4f) mm, %d Newton "
        "iterations, %.1f s\n",
        theta, moment, 1e3 * t.x(), 1e3 * t.z(), iterations, clock.Seconds());
    out << theta << "," << moment << "," << t.x() << "," << t.z() << "\n";
  }
  out.close();
  std::rename((out_path + ".tmp").c_str(), out_path.c_str());
  return 0;
}

}  // namespace
}  // namespace femb

int main(int argc, char** argv) {
  try {
    return femb::Run(argc, argv);
  } catch (const femb::InputError& e) {
    std::fprintf(stderr, "cross_flexure_reference: %s\n", e.what());
    return 2;
  }
}
