// The exact inertia for every kind of part: a free steel bar 1 m x 50 mm x 50 mm (TET10, RBE3
// interfaces on the end faces, 20 internal modes) spinning about a transverse axis at 200 rad/s
// from an undeformed start. References:
//  - the unreduced model's static centrifugal stretch (the same mesh and RBE3 couplings, solved
//    here with a sparse Cholesky factor in the rotating frame, (K - omega^2 M_xy) u =
//    omega^2 M_xy (x - c), held statically determinate: the load is self-equilibrated), and the
//    closed form rho omega^2 L^3 / (12 E) of the 1-D bar, printed beside it;
//  - femb's own part for the same mesh imported through femb-reduce's matrix export: the two
//    superelements' inertia invariants agree to 1e-8 and a dynamic run with rotation gives the
//    same motion to 1e-8 with either integrator;
//  - the midpoint scheme with the exact inertia: the same stretch as generalized-alpha, and the
//    free body's angular momentum kept to the Newton tolerance.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "formats/part_file.h"
#include "reducer/fe/imported_model.h"
#include "reducer/fe/solid_model.h"
#include "reducer/reduce_part.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/body/superelement_body.h"
#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

constexpr double kOmega = 200.0, kE = 2.1e11, kRho = 7850.0;

const char* kBar = R"(name: bar
type: solid
units: SI
material: {E: 2.1e11, nu: 0.3, rho: 7850}
geometry: {shape: box, size: [1.0, 0.05, 0.05]}
mesh: {size: 0.025, order: 2}
interfaces:
  - {name: A, group: xmin, coupling: rbe3}
  - {name: B, group: xmax, coupling: rbe3}
reduction: {internal_modes: 20, floating_frame: center_of_mass}
)";

// The bar's own mesh written by femb-reduce's exporter (calculix: bar.inp, .sti, .mas, .dof),
// and two parts on it: femb's own (type solid, the exported mesh) and the imported matrices.
struct Files {
  fs::path dir;
  Files() {
    dir = fs::temp_directory_path() / ("femb_spinning_part_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    ExportPartMatrices(ParsePart(kBar, "bar.yaml"), MatrixFormat::kCalculix, dir.string());
    Write("native.yaml", test::Replace(kBar, "{shape: box, size: [1.0, 0.05, 0.05]}", "{file: bar.inp}"));
    Write("imported.yaml",
          "name: bar\ntype: imported\nunits: SI\ngeometry: {file: bar.inp}\n"
          "matrices: {format: calculix, stiffness: bar.sti, mass: bar.mas, dofs: bar.dof}\n"
          "interfaces:\n  - {name: A, group: xmin, coupling: rbe3}\n  - {name: B, group: xmax, coupling: rbe3}\n"
          "reduction: {internal_modes: 20, floating_frame: center_of_mass}\n");
  }
  ~Files() { fs::remove_all(dir); }
  void Write(const std::string& name, const std::string& text) const { std::ofstream(dir / name) << text; }
  Superelement Reduce(const std::string& name, const std::vector<std::string>& overrides = {}) const {
    const ReduceResult r = ReducePart(ReadPartFile((dir / name).string(), overrides), nullptr);
    EXPECT_TRUE(r.ok) << r.message;
    return r.superelement;
  }
};

// The unreduced model's centrifugal stretch between the end-face centroids (the RBE3 points) at
// kOmega about z through the centre of mass.
double FullModelStretch(const FeModel& full) {
  const long n = full.n_dofs();
  // Solid model with RBE3 interfaces only: 3 DOFs per mesh node.
  EXPECT_EQ(n, 3 * full.n_nodes());
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double mass = 0.0;
  {
    Eigen::VectorXd ones_x = Eigen::VectorXd::Zero(n), x = Eigen::VectorXd::Zero(n);
    for (long k = 0; k < full.n_nodes(); ++k) ones_x[3 * k] = 1.0;
    const Eigen::VectorXd m = full.M * ones_x;
    for (long k = 0; k < full.n_nodes(); ++k) {
      mass += m[3 * k];
      c += m[3 * k] * full.nodes.row(k).transpose();
    }
    c /= mass;
  }
  // The in-plane (x, y) part of M, and the load omega^2 M_xy (x - c).
  std::vector<Eigen::Triplet<double>> entries;
  for (int col = 0; col < full.M.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(full.M, col); it; ++it)
      if (it.row() % 3 < 2 && col % 3 < 2) entries.emplace_back(int(it.row()), col, it.value());
  SparseMatrix M_xy(n, n);
  M_xy.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd r(n);
  for (long k = 0; k < full.n_nodes(); ++k) r.segment<3>(3 * k) = full.nodes.row(k).transpose() - c;
  const Eigen::VectorXd f = kOmega * kOmega * (M_xy * r);
  // Held statically determinate (3-2-1 at three corner nodes of the root face): a rigid motion
  // away from the free-free solution, which the stretch does not see.
  auto nearest = [&](const Eigen::Vector3d& p) {
    long best = 0;
    for (long k = 1; k < full.n_nodes(); ++k)
      if ((full.nodes.row(k).transpose() - p).norm() < (full.nodes.row(best).transpose() - p).norm()) best = k;
    return best;
  };
  const long a = nearest({0, 0, 0}), b = nearest({0, 0.05, 0}), d = nearest({0, 0, 0.05});
  const std::vector<long> held = {3 * a, 3 * a + 1, 3 * a + 2, 3 * b + 0, 3 * b + 2, 3 * d + 0};
  std::vector<int> index(size_t(n), 0);
  for (long h : held) index[size_t(h)] = -1;
  int n_free = 0;
  for (long i = 0; i < n; ++i)
    if (index[size_t(i)] == 0) index[size_t(i)] = n_free++;
  const SparseMatrix A = SparseMatrix(full.K - kOmega * kOmega * M_xy);
  entries.clear();
  for (int col = 0; col < A.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(A, col); it; ++it)
      if (index[size_t(it.row())] >= 0 && index[size_t(col)] >= 0)
        entries.emplace_back(index[size_t(it.row())], index[size_t(col)], it.value());
  SparseMatrix A_free(n_free, n_free);
  A_free.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd f_free(n_free);
  for (long i = 0; i < n; ++i)
    if (index[size_t(i)] >= 0) f_free[index[size_t(i)]] = f[i];
  Eigen::SimplicialLDLT<SparseMatrix> solver(A_free);
  EXPECT_EQ(solver.info(), Eigen::Success);
  const Eigen::VectorXd u_free = solver.solve(f_free);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  for (long i = 0; i < n; ++i)
    if (index[size_t(i)] >= 0) u[i] = u_free[index[size_t(i)]];
  const Eigen::Vector3d u_A = (full.interface_weights[0] * u).head<3>(),
                        u_B = (full.interface_weights[1] * u).head<3>();
  const Eigen::Vector3d span = full.interface_positions[1] - full.interface_positions[0];
  return (span + u_B - u_A).norm() - span.norm();
}

// The bar free on its two end nodes, turning about z through its centre at kOmega (plus, with
// `tumble`, 5 rad/s about its axis x), undeformed: the model and its node velocities W.
SystemModel SpinningBar(const Superelement& se, bool exact, bool tumble, Eigen::VectorXd* W) {
  SystemModel model;
  const Eigen::Vector3d a(0, 0.025, 0.025), b(1, 0.025, 0.025), centre = 0.5 * (a + b);
  AddNode(model, "A", a);
  AddNode(model, "B", b);
  SuperelementOptions body_options;
  body_options.exact_inertia = exact;
  model.bodies.emplace_back(se, body_options);
  model.body_nodes.push_back({0, 1});
  model.Number();
  const DofMap& dofs = model.dofs();
  *W = Eigen::VectorXd::Zero(dofs.n_dofs());
  const Eigen::Vector3d omega(tumble ? 5.0 : 0.0, 0, kOmega);
  W->segment<3>(dofs.node_first(0)) = omega.cross(a - centre);
  W->segment<3>(dofs.node_first(0) + 3) = omega;
  W->segment<3>(dofs.node_first(1)) = omega.cross(b - centre);
  W->segment<3>(dofs.node_first(1) + 3) = omega;
  return model;
}

// The spinning bar (SpinningBar) from its undeformed start: the end-face centroids' positions
// at every step.
std::vector<std::array<Eigen::Vector3d, 2>> Spin(const Superelement& se, Integrator integrator, double end_time,
                                                 double step, bool tumble, bool exact = true) {
  Eigen::VectorXd W;
  const SystemModel model = SpinningBar(se, exact, tumble, &W);
  DynamicState s = InitialDynamicState(model, InitialState(model), W);
  DynamicOptions options;
  options.step = step;
  options.end_time = end_time;
  options.rho_inf = 0.9;
  options.tolerance = 1e-12;
  options.integrator = integrator;
  std::vector<std::array<Eigen::Vector3d, 2>> x;
  const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport&, const DynamicState& st) {
    x.push_back({st.config.x[0], st.config.x[1]});
  });
  EXPECT_TRUE(r.ok) << r.message;
  return x;
}

double MeanStretch(const std::vector<std::array<Eigen::Vector3d, 2>>& x) {
  double sum = 0.0;
  for (const auto& p : x) sum += (p[1] - p[0]).norm() - 1.0;
  return sum / double(x.size());
}

// femb's own part and the same mesh and matrices imported: the inertia invariants agree to 1e-8
// of each kind's largest block: the static modes' blocks as they are, the whole matrices up to
// the signs of the fixed-interface modes (their magnitudes).
TEST(SpinningPart, ImportedPartHasFembsOwnInertiaInvariants) {
  const Files files;
  const Superelement native = files.Reduce("native.yaml"), imported = files.Reduce("imported.yaml");
  ASSERT_EQ(native.inertia_gamma.size(), 3u);
  ASSERT_EQ(imported.inertia_gamma.size(), 3u);
  ASSERT_EQ(imported.inertia_xi.size(), 6u);
  auto worst = [](const std::vector<Eigen::MatrixXd>& got, const std::vector<Eigen::MatrixXd>& want) {
    double scale = 0.0, error = 0.0;
    for (const Eigen::MatrixXd& w : want) scale = std::max(scale, w.cwiseAbs().maxCoeff());
    for (size_t k = 0; k < want.size(); ++k) {
      error = std::max(error, (got[k].topLeftCorner(12, 12) - want[k].topLeftCorner(12, 12)).cwiseAbs().maxCoeff());
      error = std::max(error, (got[k].cwiseAbs() - want[k].cwiseAbs()).cwiseAbs().maxCoeff());
    }
    return error / scale;
  };
  const double gamma = worst(imported.inertia_gamma, native.inertia_gamma);
  const double xi = worst(imported.inertia_xi, native.inertia_xi);
  std::printf("[ info ] imported against femb's own part: Gamma %.2e, Xi %.2e\n", gamma, xi);
  EXPECT_LT(gamma, 1e-8);
  EXPECT_LT(xi, 1e-8);
}

// Mean stretch over 5 ms at 5 us (generalized-alpha, the exact inertia) within 0.5% of the
// unreduced model's static stretch, for femb's own part and the imported one, each with the
// Craig-Bampton and the free-interface basis. (With the corotational inertia, which the imported
// and free-interface parts had before they carried the invariants: +20.8% and +21.3%.)
TEST(SpinningPart, EveryPartStretchesAsTheUnreducedModel) {
  const Files files;
  const double full = FullModelStretch(BuildSolidModel(ReadPartFile((files.dir / "native.yaml").string())));
  const double closed_form = kRho * kOmega * kOmega / (12 * kE);
  std::printf("[ info ] unreduced model's static stretch %.5e m, closed form (1-D) %.5e m (%+.2f%%)\n", full,
              closed_form, 100 * (closed_form / full - 1));
  EXPECT_LT(std::abs(full / closed_form - 1), 0.01);
  for (const char* part : {"native.yaml", "imported.yaml"}) {
    for (const char* method : {"craig_bampton", "free_interface"}) {
      const Superelement se = files.Reduce(part, {std::string("reduction.method=") + method});
      for (const Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kMidpoint}) {
        const char* name = integrator == Integrator::kMidpoint ? "midpoint" : "generalized-alpha";
        const double stretch = MeanStretch(Spin(se, integrator, 5e-3, 5e-6, false));
        std::printf("[ info ] %s, %s, %s: mean stretch %.5e m (%+.2f%% of the unreduced model's)\n", part, method, name,
                    stretch, 100 * (stretch / full - 1));
        EXPECT_LT(std::abs(stretch / full - 1), 5e-3) << part << " " << method << " " << name;
      }
    }
  }
}

// femb's own part and the imported one spinning and tumbling for 2 ms: the end points' positions
// agree to 1e-8 of the bar's length at every step, with generalized-alpha (exact inertia) and
// the midpoint scheme (corotational); linear inside, and with the geometric stiffening (the
// imported part's from femb's elements on its mesh with the part's material).
TEST(SpinningPart, ImportedPartMovesAsFembsOwn) {
  const Files files;
  for (const bool stiffened : {false, true}) {
    const std::string on = stiffened ? "true" : "false";
    const Superelement native = files.Reduce("native.yaml", {"reduction.geometric_stiffening=" + on});
    const Superelement imported = files.Reduce(
        "imported.yaml", {"reduction.geometric_stiffening=" + on, "material={E: 2.1e11, nu: 0.3, rho: 7850}"});
    ASSERT_EQ(imported.inertia_stiffness.empty(), !stiffened);
    // With the material, the imported part also recovers stresses with femb's elements: the same
    // modal stresses as the own part's (single precision; up to the signs of the fixed-interface
    // modes), and the inertia load cases' with the stiffening.
    ASSERT_TRUE(imported.stress.has_value());
    ASSERT_TRUE(native.stress.has_value());
    const float scale = native.stress->modes.cwiseAbs().maxCoeff();
    EXPECT_LT((imported.stress->modes.cwiseAbs() - native.stress->modes.cwiseAbs()).cwiseAbs().maxCoeff(),
              1e-6f * scale);
    ASSERT_EQ(imported.stress->inertia_modes.size(), native.stress->inertia_modes.size());
    if (stiffened) {
      const float inertia_scale = native.stress->inertia_modes.cwiseAbs().maxCoeff();
      EXPECT_LT((imported.stress->inertia_modes - native.stress->inertia_modes).cwiseAbs().maxCoeff(),
                1e-6f * inertia_scale);
    }
    for (const Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kMidpoint}) {
      const auto a = Spin(native, integrator, 2e-3, 1e-5, true), b = Spin(imported, integrator, 2e-3, 1e-5, true);
      ASSERT_EQ(a.size(), b.size());
      double worst = 0.0, stretch = 0.0;
      for (size_t i = 0; i < a.size(); ++i) {
        for (int k = 0; k < 2; ++k) worst = std::max(worst, (a[i][size_t(k)] - b[i][size_t(k)]).norm());
        stretch = std::max(stretch, std::abs((a[i][1] - a[i][0]).norm() - 1.0));
      }
      std::printf(
          "[ info ] %s, %s: imported against femb's own part: largest position difference %.2e m (largest stretch "
          "%.2e m)\n",
          stiffened ? "stiffened" : "linear", integrator == Integrator::kMidpoint ? "midpoint" : "generalized-alpha",
          worst, stretch);
      EXPECT_LT(worst, 1e-8);
    }
  }
}

// The imported part's stiffening needs its material, and the material the matrices were made
// with: one line each.
TEST(SpinningPart, ImportedStiffeningRefusesAMissingOrWrongMaterial) {
  const Files files;
  const std::string missing =
      test::ThrownMessage([&] { files.Reduce("imported.yaml", {"reduction.geometric_stiffening=true"}); });
  EXPECT_NE(missing.find("geometric stiffening of imported matrices needs the part's material"), std::string::npos)
      << missing;
  const std::string wrong =
      test::ThrownMessage([&] { files.Reduce("imported.yaml", {"material={E: 2.0e11, nu: 0.3, rho: 7850}"}); });
  EXPECT_NE(
      wrong.find("imported.yaml: material: femb's elements on the imported mesh with this material differ from the "
                 "imported stiffness by 0.048"),
      std::string::npos)
      << wrong;
}

// The midpoint scheme on the free spinning bar with a slight tumble (5 rad/s about the bar's
// axis, so that the spin is no relative equilibrium), 20 periods at 100 steps per period (the
// axial mode, 2.6 kHz, not resolved: h omega_axial = 5): the angular momentum and the energy are
// kept to round-off with either inertia, the energy through the body's energy closure
// (solver/integrators/midpoint_energy.cpp; without it the energy's error was bounded, 2.5e-6
// exact and 1.0e-4 corotational over 20 periods), the momenta through what each step gives back
// of Newton's leftover and of the bodies' forces' round-off (solver/integrators/
// midpoint_momentum.cpp; without it 1.3e-12 and 1.1e-12 over 20 periods, 1.0e-10 and 7.6e-11 over
// 1 000). Measured at tolerance 1e-12 over 20 periods: energy 5.6e-14 exact, 5.6e-14
// corotational, angular momentum 1.5e-14 and 1.7e-14; over 1 000 periods energy 2.2e-12 and
// 2.3e-12, angular momentum 1.2e-13 and 6.3e-14, no step cut (docs/theory/integrators.md). The
// tolerance asks for less than the round-off of the positions here (RoundOffForce): the run also
// guards Newton's test at that floor, where a step stalled at 2.9x the floor was once cut. Newton
// takes 6.9 and 6.4 iterations per step (the matrix leaves out O(omega h) terms: linear
// convergence, midpoint_test.cpp).
TEST(SpinningPart, MidpointConservesMomentumWithTheExactInertia) {
  const Files files;
  const Superelement se = files.Reduce("native.yaml", {"reduction.geometric_stiffening=false"});
  for (const bool exact : {false, true}) {
    Eigen::VectorXd W;
    const SystemModel model = SpinningBar(se, exact, true, &W);
    DynamicState s = InitialDynamicState(model, InitialState(model), W);
    const DynamicStepReport r0 = Measure(model, s);
    const double period = 2 * M_PI / kOmega;
    DynamicOptions options;
    options.step = period / 100;
    options.end_time = 20 * period;
    options.tolerance = 1e-12;
    options.integrator = Integrator::kMidpoint;
    const double E0 = r0.kinetic_energy + r0.elastic_energy;
    double dE = 0, dH = 0;
    long iterations = 0;
    const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport& rep, const DynamicState&) {
      dE = std::max(dE, std::abs(rep.kinetic_energy + rep.elastic_energy - E0) / E0);
      dH = std::max(dH, (rep.angular_momentum - r0.angular_momentum).norm() / r0.angular_momentum.norm());
      iterations += rep.iterations;
    });
    EXPECT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.newton_cuts, 0);
    std::printf(
        "[ info ] midpoint, %s inertia, 20 periods: energy %.2e, angular momentum %.2e, %.2f Newton iterations per "
        "step\n",
        exact ? "exact" : "corotational", dE, dH, double(iterations) / 2000.0);
    EXPECT_LT(dH, 1e-11);  // a Newton tolerance of 1e-12 per step, 2 000 steps
    EXPECT_LT(dE, 1e-11);
    EXPECT_LT(iterations, 8 * 2000);
  }
}

}  // namespace
}  // namespace femb
