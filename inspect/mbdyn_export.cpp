// MBDyn's modal element file (inspect/mbdyn_export.h).
#include "inspect/mbdyn_export.h"

#include <unistd.h>

#include <Eigen/Dense>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "formats/input_error.h"

namespace femb {
namespace {

// The elastic basis E: Phi_CB E = 0, E^T M E = 1, E^T K E diagonal ascending.
Eigen::MatrixXd ElasticBasis(const Superelement& se) {
  const long n = se.n_reduced_dofs();
  const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(se.floating_frame.Phi_CB.transpose()).householderQ();
  const Eigen::MatrixXd N0 = Q.rightCols(n - 6);
  const Eigen::MatrixXd K0 = N0.transpose() * se.K * N0, M0 = N0.transpose() * se.M * N0;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (K0 + K0.transpose()),
                                                                  0.5 * (M0 + M0.transpose()));
  return N0 * eigen.eigenvectors();
}

// Skew-direction invariants turned to frame axes A (columns = frame axes in part axes):
// Gamma_f[a] = sum_c A(c, a) Gamma_c, Xi_f(a, b) = sum_cd A(c, a) A(d, b) Xi_cd, each projected on E.
struct FrameInvariants {
  std::vector<Eigen::MatrixXd> gamma;            // 3: E^T Gamma_fa E
  std::vector<Eigen::MatrixXd> gamma_full;       // 3: Gamma_fa E (n x N)
  std::vector<std::vector<Eigen::MatrixXd>> xi;  // 3 x 3: E^T Xi_fafb E
};

FrameInvariants TurnInvariants(const Superelement& se, const Eigen::Matrix3d& A, const Eigen::MatrixXd& E) {
  static const int kPair[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};  // xx yy zz xy xz yz
  auto xi = [&](int c, int d) -> Eigen::MatrixXd {
    const Eigen::MatrixXd& X = se.inertia_xi[size_t(kPair[c][d])];
    return c <= d ? X : Eigen::MatrixXd(X.transpose());
  };
  FrameInvariants f;
  for (int a = 0; a < 3; ++a) {
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(se.n_reduced_dofs(), se.n_reduced_dofs());
    for (int c = 0; c < 3; ++c) G += A(c, a) * se.inertia_gamma[size_t(c)];
    f.gamma_full.push_back(G * E);
    f.gamma.push_back(E.transpose() * f.gamma_full.back());
  }
  f.xi.resize(3);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      Eigen::MatrixXd X = Eigen::MatrixXd::Zero(se.n_reduced_dofs(), se.n_reduced_dofs());
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) X += A(c, a) * A(d, b) * xi(c, d);
      f.xi[size_t(a)].push_back(E.transpose() * X * E);
    }
  return f;
}

// Numbers of a record, six to a line: MBDyn reads them as a stream of numbers, but finds its
// record headers with a line buffer of BUFSIZ characters.
void Line(std::ostream& out, const Eigen::RowVectorXd& v) {
  char b[32];
  for (long i = 0; i < v.size(); ++i) {
    std::snprintf(b, sizeof b, "%.17g", v[i]);
    out << b << (i + 1 == v.size() || i % 6 == 5 ? "\n" : " ");
  }
}

// Records 14-18 (see the header): the invariants in frame axes on the elastic basis E, with T and
// R the frame-axis rigid translation and rotation fields.
void WriteInvariants(std::ostream& out, const Superelement& se, const Eigen::Matrix3d& A, const Eigen::MatrixXd& E,
                     const Eigen::MatrixXd& T, const Eigen::MatrixXd& R) {
  const long N = E.cols();
  const FrameInvariants f = TurnInvariants(se, A, E);
  out << "**\n** RECORD GROUP 14, INVARIANT 3\n";
  for (int a = 0; a < 3; ++a) Line(out, T.col(a).transpose() * se.M * E);
  out << "**\n** RECORD GROUP 15, INVARIANT 4\n";
  for (int a = 0; a < 3; ++a) Line(out, R.col(a).transpose() * se.M * E);
  out << "**\n** RECORD GROUP 16, INVARIANT 8\n";
  for (int a = 0; a < 3; ++a) {
    Eigen::RowVectorXd row(3 * N);
    for (long j = 0; j < N; ++j)
      for (int c = 0; c < 3; ++c) row[3 * j + c] = R.col(a).dot(f.gamma_full[size_t(c)].col(j));
    Line(out, row);
  }
  out << "**\n** RECORD GROUP 17, INVARIANT 5\n";
  for (int a = 0; a < 3; ++a) {
    Eigen::RowVectorXd row(N * N);
    for (long j = 0; j < N; ++j)
      for (long k = 0; k < N; ++k) row[j * N + k] = f.gamma[size_t(a)](k, j);
    Line(out, row);
  }
  out << "**\n** RECORD GROUP 18, INVARIANT 9\n";
  for (int a = 0; a < 3; ++a) {
    Eigen::RowVectorXd row(3 * N * N);
    for (long j = 0; j < N; ++j)
      for (long k = 0; k < N; ++k)
        for (int c = 0; c < 3; ++c) row[3 * (j * N + k) + c] = -f.xi[size_t(a)][size_t(c)](j, k);
    Line(out, row);
  }
}

}  // namespace

MbdynExport WriteMbdynFem(const Superelement& se, const std::string& path, bool mesh_nodes) {
  if (se.interface_constraint.rows() > 0) {
    throw InputError(path + ": " + se.name +
                     "'s basis moves only some interface directions (interface_constraint): MBDyn's modal element "
                     "has no place for that constraint");
  }
  for (const InterfaceNode& node : se.interfaces)
    if (node.name.find_first_of(" \t\"") != std::string::npos)
      throw InputError(path + ": interface '" + node.name + "' has a blank or a quote: MBDyn's labels cannot");
  MbdynExport result;
  const Eigen::Matrix3d A = se.floating_frame.orientation;
  const Eigen::Vector3d origin = se.floating_frame.origin;
  const Eigen::MatrixXd E = ElasticBasis(se);
  const long N = E.cols();
  result.modes = int(N);
  const Eigen::MatrixXd Rg = RigidBodyModes(se, origin);
  Eigen::MatrixXd T(se.n_reduced_dofs(), 3), R(se.n_reduced_dofs(), 3);  // frame-axis rigid fields
  for (int a = 0; a < 3; ++a) {
    T.col(a) = Rg.leftCols(3) * A.col(a);
    R.col(a) = Rg.rightCols(3) * A.col(a);
  }
  // FEM nodes: positions (frame axes, from the origin) and their 6 x N shapes.
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::MatrixXd> shape;
  for (int k = 0; k < se.n_interface_nodes(); ++k) {
    result.labels.push_back(se.interfaces[size_t(k)].name);
    x.push_back(A.transpose() * (se.interfaces[size_t(k)].position - origin));
    Eigen::MatrixXd s(6, N);
    s.topRows(3) = A.transpose() * E.middleRows(6 * k, 3);
    s.bottomRows(3) = A.transpose() * E.middleRows(6 * k + 3, 3);
    shape.push_back(s);
  }
  if (mesh_nodes && se.visualization) {
    const Visualization& v = *se.visualization;
    const int dpn = v.dofs_per_node;
    for (long s = 0; s < v.nodes.rows(); ++s) {
      result.labels.push_back(std::to_string(s + 1));
      x.push_back(A.transpose() * (v.nodes.row(s).transpose() - origin));
      const Eigen::MatrixXd field = v.shapes.middleRows(s * dpn, dpn) * E;
      Eigen::MatrixXd sh = Eigen::MatrixXd::Zero(6, N);
      sh.topRows(3) = A.transpose() * field.topRows(3);
      if (dpn == 6) sh.bottomRows(3) = A.transpose() * field.bottomRows(3);
      shape.push_back(sh);
    }
  }
  result.nodes = int(x.size());
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp);
    if (!out) throw InputError(path + ": cannot write the MBDyn file");
    char b[256];
    out << "** MBDyn MODAL DATA FILE written by femb-inspect --export-mbdyn from superelement " << se.name << "\n";
    std::snprintf(b, sizeof b, "** modal node: the floating frame (%s) at %.17g %.17g %.17g in part axes\n",
                  se.floating_frame.type.c_str(), origin.x(), origin.y(), origin.z());
    out << b;
    for (int a = 0; a < 3; ++a) {
      std::snprintf(b, sizeof b, "** frame axis %c in part axes: %.17g %.17g %.17g\n", "xyz"[a], A(0, a), A(1, a),
                    A(2, a));
      out << b;
    }
    out << "** units " << se.units.system << " (" << se.units.length << ", " << se.units.mass << ", " << se.units.time
        << "); nodes in frame axes from the frame origin\n";
    out << "** RECORD GROUP 1, HEADER\n**   REVISION, NODE, NORMAL, ATTACHMENT, CONSTRAINT, REJECTED MODES.\n";
    out << "REV0 " << x.size() << " " << N << " 0 0 0\n**\n** RECORD GROUP 2, FINITE ELEMENT NODE LIST\n";
    for (size_t i = 0; i < result.labels.size(); ++i) out << result.labels[i] << (i + 1 == x.size() ? "\n" : " ");
    for (int c = 0; c < 3; ++c) {
      out << "**\n** RECORD GROUP " << 5 + c << ", NODAL "
          << "XYZ"[c] << " COORDINATES\n";
      for (const Eigen::Vector3d& p : x) Line(out, p.segment(c, 1).transpose());
    }
    out << "**\n** RECORD GROUP 8, MODE SHAPES\n";
    for (long j = 0; j < N; ++j) {
      out << "**    NORMAL MODE SHAPE #  " << j + 1 << "\n";
      for (const Eigen::MatrixXd& s : shape) Line(out, s.col(j).transpose());
    }
    const Eigen::MatrixXd Mm = E.transpose() * se.M * E, Km = E.transpose() * se.K * E;
    out << "**\n** RECORD GROUP 9, MODAL MASS MATRIX.  COLUMN-MAJOR FORM\n";
    for (long j = 0; j < N; ++j) Line(out, Mm.col(j).transpose());
    out << "**\n** RECORD GROUP 10, MODAL STIFFNESS MATRIX.  COLUMN-MAJOR FORM\n";
    for (long j = 0; j < N; ++j) Line(out, Km.col(j).transpose());
    const MassProperties& mp = se.mass_properties;
    out << "**\n** RECORD GROUP 12, GLOBAL INERTIA\n";
    Line(out, Eigen::RowVectorXd::Constant(1, mp.mass));
    Line(out, (A.transpose() * (mp.center_of_mass - origin)).transpose());
    const Eigen::Matrix3d J = A.transpose() * mp.inertia_com * A;
    for (int r = 0; r < 3; ++r) Line(out, J.row(r));
    result.invariants = se.inertia_gamma.size() == 3 && se.inertia_xi.size() == 6;
    if (result.invariants) {
      WriteInvariants(out, se, A, E, T, R);
    } else {
      result.notes.push_back("no inertia invariants in the file: MBDyn gets the rigid-body inertia only");
    }
    out << "**\n";
    if (!out) throw InputError(path + ": cannot write the MBDyn file");
  }
  std::filesystem::rename(tmp, path);
  if (!se.inertia_stiffness.empty() || se.polynomial)
    result.notes.push_back("the file's geometric stiffening is not carried: MBDyn's modal element is linear inside");
  return result;
}

}  // namespace femb
