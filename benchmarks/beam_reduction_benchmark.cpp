// Beam reduction: run time per stage against model size, and frequency error against the
// number of internal modes. Prints what it measured on this run.
#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <string>

#include "formats/part_file.h"
#include "reducer/reduce_part.h"

namespace {

std::string Part(int elements) {
  return "name: bench\ntype: beam\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7870}\n"
         "section: {shape: circle, diameter: 0.006}\n"
         "beam:\n  points: {A: [0, 0, 0], B: [0.3, 0, 0]}\n"
         "  segments: [{from: A, to: B, elements: " +
         std::to_string(elements) +
         "}]\n"
         "interfaces: [{name: A}, {name: B}]\n";
}

Eigen::VectorXd ReducedFrequencies(const femb::Superelement& se) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(se.K, se.M, Eigen::EigenvaluesOnly);
  Eigen::VectorXd f(eig.eigenvalues().size());
  for (int k = 0; k < f.size(); ++k) f[k] = femb::FrequencyHz(eig.eigenvalues()[k]);
  return f;
}

}  // namespace

int main() {
  std::printf("Beam reduction benchmark (steel rod 0.3 m, d = 6 mm, 2 interfaces, 10 internal modes)\n\n");
  std::printf("%9s %9s | %10s %10s %10s %10s %10s %10s | %10s | %s\n", "elements", "DOFs", "assembly", "factorize",
              "static", "eigen", "projection", "full modes", "total [s]", "max rel. error, flexible modes 1-4");
  for (int elements : {10, 100, 1000, 10000, 50000}) {
    const femb::PartSpec part =
        femb::ParsePart(Part(elements), "bench.yaml",
                        {"reduction.internal_modes=10", "reduction.full_modes=4", "reduction.keep_mesh=false"});
    femb::Stopwatch clock;
    const femb::ReduceResult r = femb::ReducePart(part, nullptr);
    const double total = clock.Seconds();
    if (!r.ok) {
      std::printf("failed: %s\n", r.message.c_str());
      return 3;
    }
    double t[6] = {0, 0, 0, 0, 0, 0};
    const char* names[6] = {"mesh+assembly", "factorize K_ii", "static modes",
                            "eigen solve",   "projection",     "full modes"};
    for (const auto& [stage, sec] : r.superelement.provenance.stage_seconds) {
      for (int i = 0; i < 6; ++i) {
        if (stage == names[i]) t[i] = sec;
      }
    }
    const Eigen::VectorXd f = ReducedFrequencies(r.superelement), full = r.superelement.full_free_free_frequencies_hz;
    double err = 0;
    for (int k = 6; k < 10; ++k) err = std::max(err, std::abs(f[k] - full[k]) / full[k]);
    std::printf("%9d %9ld | %10.4f %10.4f %10.4f %10.4f %10.4f %10.4f | %10.4f | %.3e\n", elements,
                r.superelement.n_full_dofs, t[0], t[1], t[2], t[3], t[4], t[5], total, err);
  }

  std::printf("\nConvergence with internal modes (200 elements): relative error of free-free flexible modes\n");
  std::printf("%6s %10s |", "modes", "time [s]");
  for (int k = 1; k <= 8; ++k) std::printf("   mode %d", k);
  std::printf("\n");
  for (int m : {0, 2, 4, 8, 16, 32}) {
    const femb::PartSpec part = femb::ParsePart(
        Part(200), "bench.yaml",
        {"reduction.internal_modes=" + std::to_string(m), "reduction.full_modes=8", "reduction.keep_mesh=false"});
    femb::Stopwatch clock;
    const femb::ReduceResult r = femb::ReducePart(part, nullptr);
    const double total = clock.Seconds();
    const Eigen::VectorXd f = ReducedFrequencies(r.superelement), full = r.superelement.full_free_free_frequencies_hz;
    std::printf("%6d %10.4f |", m, total);
    for (int k = 6; k < 14; ++k) {
      if (k < f.size())
        std::printf(" %8.1e", std::abs(f[k] - full[k]) / full[k]);
      else
        std::printf(" %8s", "-");
    }
    std::printf("\n");
  }
  return 0;
}
