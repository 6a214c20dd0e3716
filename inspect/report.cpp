#include "inspect/report.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "formats/superelement_file.h"

namespace femb {
namespace {

std::string F(const char* fmt, ...) {
  char buffer[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buffer, sizeof buffer, fmt, args);
  va_end(args);
  return buffer;
}

std::string Vec(const Eigen::Vector3d& v) { return F("(%.6g, %.6g, %.6g)", v.x(), v.y(), v.z()); }

nlohmann::json ToJson(const Eigen::MatrixXd& A) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < A.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < A.cols(); ++j) row.push_back(A(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json ToJson(const Eigen::VectorXd& v) {
  nlohmann::json out = nlohmann::json::array();
  for (int i = 0; i < v.size(); ++i) out.push_back(v[i]);
  return out;
}

// Thesis 8.2 case 4: the interface constraint's line, each row named by the interface coordinate
// it weighs most (rotation columns are lengths times the part's size, so compare them as such).
std::string InterfaceConstraintLine(const Superelement& se) {
  static const char* kNames[6] = {"u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"};
  const Eigen::MatrixXd& C = se.interface_constraint;
  std::string rows;
  for (long i = 0; i < C.rows(); ++i) {
    const Eigen::VectorXd w = C.row(i).cwiseAbs().transpose();
    rows += i ? "; " : "";
    bool first = true;
    for (long k = 0; k < w.size(); ++k) {
      if (w[k] < 0.5 * w.maxCoeff()) continue;
      rows += F("%s%s.%s", first ? "" : " & ", se.interfaces[size_t(k / 6)].name.c_str(), kNames[k % 6]);
      first = false;
    }
  }
  return F("  interface constraint (basis moves %ld of %d interface directions; femb-solve holds the others): %s\n",
           long(se.n_interface_dofs() - C.rows()), se.n_interface_dofs(), rows.c_str());
}

// The file's name, units, provenance, sizes and what it holds beyond K and M.
std::string HeaderLines(const Superelement& se, const std::string& path) {
  const Units& u = se.units;
  std::string s;
  s += F("Superelement '%s'  (%s, format %ld.%ld)\n", se.name.c_str(), path.c_str(), kSuperelementFormatMajor,
         kSuperelementFormatMinor);
  s += F("  units: %s (length %s, mass %s, time %s, force %s, stress %s, angle %s)\n", u.system.c_str(),
         u.length.c_str(), u.mass.c_str(), u.time.c_str(), u.force.c_str(), u.stress.c_str(), u.angle.c_str());
  const Provenance& p = se.provenance;
  s += F("  from %s (hash %s), femb %s: %ld nodes, %ld %s elements\n", p.input_file.c_str(), p.input_hash.c_str(),
         p.femb_version.c_str(), p.n_nodes, p.n_elements, p.element_type.c_str());
  s += F("  %ld full DOFs -> %d reduced: %d interface DOFs (%d nodes) + %d internal modes + %ld modal derivatives\n",
         se.n_full_dofs, se.n_reduced_dofs(), se.n_interface_dofs(), se.n_interface_nodes(), se.n_internal_modes(),
         se.n_modal_derivatives);
  if (se.polynomial && se.polynomial->cubic()) {
    const long n = se.n_reduced_dofs(), P = n * (n + 1) / 2;
    s +=
        F("  nonlinear internal force: cubic in the reduced coordinates (Green-Lagrange), quadratic coefficients A "
          "%ld x %ld, cubic B %ld x %ld (%.3g MB)\n",
          n, P, P, P, 8.0 * double(n * P + P * P) / 1e6);
  } else if (se.polynomial) {
    const long n = se.n_reduced_dofs(), P = n * (n + 1) / 2;
    s += F("  geometric stiffening: the basis vectors' stress geometric stiffness (A %ld x %ld, %.3g MB)\n", n, P,
           8.0 * double(n * P) / 1e6);
  }
  if (!se.inertia_stiffness.empty()) {
    s += F("  geometric stiffening: 12 inertia load cases (a, alpha, omega products), %d x %d each\n",
           se.n_reduced_dofs(), se.n_reduced_dofs());
  }
  if (se.interface_constraint.rows() > 0) s += InterfaceConstraintLine(se);
  if (!se.inertia_gamma.empty()) {
    s += F("  inertia invariants: Gamma (3) and Xi (6), %d x %d each (exact kinetic energy in the floating frame)\n",
           se.n_reduced_dofs(), se.n_reduced_dofs());
  }
  s += "  in dynamics: " + DynamicsSummary(se) + "\n";
  if (!p.stage_seconds.empty()) {
    s += "  reduction time:";
    for (const auto& [stage, sec] : p.stage_seconds) s += F(" %s %.3g s;", stage.c_str(), sec);
    s += "\n";
  }
  return s;
}

// The interface nodes, the floating frame, the mass properties and the reduced coordinates.
std::string BodyLines(const Superelement& se, const SuperelementAnalysis& a) {
  const Units& u = se.units;
  std::string s;
  s += F("\nInterface nodes (%d):\n", se.n_interface_nodes());
  for (const InterfaceNode& n : se.interfaces) {
    s += F("  %-12s position %s %s\n", n.name.c_str(), Vec(n.position).c_str(), u.length.c_str());
  }

  const FloatingFrame& f = se.floating_frame;
  s += F("\nFloating frame: %s, origin %s %s\n", f.type.c_str(), Vec(f.origin).c_str(), u.length.c_str());
  if (f.cardona_weights.size()) {
    s += "  Cardona weights alpha:";
    for (int k = 0; k < f.cardona_weights.size(); ++k)
      s += F(" %s=%.6g", se.interfaces[k].name.c_str(), f.cardona_weights[k]);
    s += "\n";
  }

  const MassProperties& m = se.mass_properties;
  s +=
      F("\nMass properties:\n  mass %.8g %s\n  centre of mass %s %s\n  inertia about the centre of mass (part axes) "
        "[%s %s^2]:\n",
        m.mass, u.mass.c_str(), Vec(m.center_of_mass).c_str(), u.length.c_str(), u.mass.c_str(), u.length.c_str());
  for (int i = 0; i < 3; ++i)
    s += F("    %14.8g %14.8g %14.8g\n", m.inertia_com(i, 0), m.inertia_com(i, 1), m.inertia_com(i, 2));
  s += "  6x6 rigid-body mass matrix about the floating frame origin, thesis (3.21):\n";
  for (int i = 0; i < 6; ++i) {
    s += "   ";
    for (int j = 0; j < 6; ++j) s += F(" %13.6g", a.rigid_mass_frame(i, j));
    s += "\n";
  }

  s += "\nReduced coordinates (rows/columns of K and M):\n";
  for (int i = 0; i < se.n_reduced_dofs(); ++i) {
    s += F("  %4d  %s\n", i, ReducedCoordinateLabel(se, i).c_str());
  }
  return s;
}

// The free-free frequencies of the reduced model, beside the full model's where the file has them.
std::string FrequencyLines(const Superelement& se, const SuperelementAnalysis& a) {
  std::string s;
  s += F("\nFree-free frequencies [Hz] (%d rigid-body):\n", a.rigid_body_mode_count);
  const Eigen::VectorXd& full = se.full_free_free_frequencies_hz;
  if (full.size()) {
    if (!se.full_rigid_couplings.empty()) {
      std::string rigid;
      for (const std::string& name : se.full_rigid_couplings) rigid += (rigid.empty() ? "" : ", ") + name;
      s += "  full: the unreduced model with the RBE2 couplings of " + rigid +
           " (their node sets rigid: stiffer than the bare part; RBE3 couplings add no stiffness)\n";
    }
    s += "     #        reduced           full     rel. error\n";
  } else {
    s += "     #        reduced   (no full-model frequencies stored: femb-reduce --full-modes K)\n";
  }
  const int rows = std::max<int>(a.free_free_frequencies_hz.size(), full.size());
  for (int k = 0; k < rows; ++k) {
    const bool has_r = k < a.free_free_frequencies_hz.size(), has_f = k < full.size();
    std::string line = F("  %4d", k + 1);
    line += has_r ? F(" %14.6g", a.free_free_frequencies_hz[k]) : F(" %14s", "-");
    if (full.size()) {
      line += has_f ? F(" %14.6g", full[k]) : F(" %14s", "-");
      const bool rigid = k < 6;
      if (has_r && has_f && !rigid && full[k] != 0.0) {
        line += F(" %14.3e", (a.free_free_frequencies_hz[k] - full[k]) / full[k]);
      } else {
        line += F(" %14s", rigid ? "(rigid)" : "-");
      }
    }
    s += line + "\n";
  }
  return s;
}

}  // namespace

std::string TextSummary(const Superelement& se, const SuperelementAnalysis& a, const std::string& path) {
  std::string s = HeaderLines(se, path) + BodyLines(se, a) + FrequencyLines(se, a);
  s += "\nChecks:\n";
  for (const Check& c : a.checks) s += F("  %-24s %-4s %s\n", c.name.c_str(), c.ok ? "ok" : "FAIL", c.detail.c_str());
  return s;
}

nlohmann::json JsonSummary(const Superelement& se, const SuperelementAnalysis& a) {
  nlohmann::json j;
  j["format_version"] = std::to_string(kSuperelementFormatMajor) + "." + std::to_string(kSuperelementFormatMinor);
  j["name"] = se.name;
  j["units"] = {{"system", se.units.system}, {"length", se.units.length}, {"mass", se.units.mass},
                {"time", se.units.time},     {"force", se.units.force},   {"stress", se.units.stress},
                {"angle", se.units.angle}};
  j["n_interface_nodes"] = se.n_interface_nodes();
  nlohmann::json names = nlohmann::json::array();
  nlohmann::json positions = nlohmann::json::array();
  for (const auto& n : se.interfaces) {
    names.push_back(n.name);
    positions.push_back({n.position.x(), n.position.y(), n.position.z()});
  }
  j["interface_names"] = names;
  j["interface_positions"] = positions;
  j["n_internal_modes"] = se.n_internal_modes();
  j["n_modal_derivatives"] = se.n_modal_derivatives;
  j["polynomial_internal_force"] = se.polynomial.has_value() && se.polynomial->cubic();
  j["geometric_stiffening"] = !se.inertia_stiffness.empty();
  j["inertia_invariants"] = !se.inertia_gamma.empty();
  j["n_reduced_dofs"] = se.n_reduced_dofs();
  j["n_full_dofs"] = se.n_full_dofs;
  j["mass"] = se.mass_properties.mass;
  j["center_of_mass"] = ToJson(Eigen::VectorXd(se.mass_properties.center_of_mass));
  j["inertia_com"] = ToJson(Eigen::MatrixXd(se.mass_properties.inertia_com));
  j["rigid_body_mass_matrix"] = ToJson(Eigen::MatrixXd(a.rigid_mass_frame));
  j["floating_frame"] = {{"type", se.floating_frame.type},
                         {"origin", ToJson(Eigen::VectorXd(se.floating_frame.origin))}};
  if (se.floating_frame.cardona_weights.size()) {
    j["floating_frame"]["cardona_weights"] = ToJson(se.floating_frame.cardona_weights);
  }
  nlohmann::json labels = nlohmann::json::array();
  for (int i = 0; i < se.n_reduced_dofs(); ++i) labels.push_back(ReducedCoordinateLabel(se, i));
  j["reduced_coordinates"] = labels;
  j["internal_frequencies_hz"] = ToJson(se.internal_frequencies_hz);
  j["free_free_frequencies_hz"] = ToJson(a.free_free_frequencies_hz);
  if (se.full_free_free_frequencies_hz.size()) {
    j["full_free_free_frequencies_hz"] = ToJson(se.full_free_free_frequencies_hz);
    j["full_rigid_couplings"] = se.full_rigid_couplings;
  }
  j["rigid_body_mode_count"] = a.rigid_body_mode_count;
  nlohmann::json checks = nlohmann::json::object();
  for (const Check& c : a.checks) checks[c.name] = {{"ok", c.ok}, {"detail", c.detail}};
  j["checks"] = checks;
  j["provenance"] = {{"input_file", se.provenance.input_file},     {"input_hash", se.provenance.input_hash},
                     {"femb_version", se.provenance.femb_version}, {"element_type", se.provenance.element_type},
                     {"n_nodes", se.provenance.n_nodes},           {"n_elements", se.provenance.n_elements}};
  return j;
}

}  // namespace femb
