#include "reducer/reduction/modal_stress.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "reducer/fe/beam_model.h"
#include "reducer/fe/timoshenko_beam.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"

namespace femb {
namespace {

// (xx, yy, zz, yz, xz, xy) of the part-axes tensor R^T S R of a fibre's element-axes stress:
// S = [s t_y t_z; t_y 0 0; t_z 0 0], R's rows the element axes.
Eigen::Matrix<double, 6, 3> FibreToPart(const Eigen::Matrix3d& R) {
  Eigen::Matrix<double, 6, 3> V;
  const int rows[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  for (int k = 0; k < 6; ++k) {
    const int i = rows[k][0], j = rows[k][1];
    // sigma_ij = sum_ab R_ai S_ab R_bj with S_00 = s, S_01 = S_10 = t_y, S_02 = S_20 = t_z.
    V(k, 0) = R(0, i) * R(0, j);
    V(k, 1) = R(0, i) * R(1, j) + R(1, i) * R(0, j);
    V(k, 2) = R(0, i) * R(2, j) + R(2, i) * R(0, j);
  }
  return V;
}

// One fibre of a section: where it is (y, z) and the map from the section forces
// (N, V_y, V_z, T, M_y, M_z) to its stresses (sigma_xx, tau_xy, tau_xz) in element axes.
struct Fibre {
  double y, z;
  Eigen::Matrix<double, 3, 6> map;
};

// Saint-Venant torsion of a rectangle with half sides a >= b (see the header): the shear stress
// per unit torque at the middle of the long sides and of the short sides.
void RectangleTorsion(double a, double b, double* tau_long, double* tau_short) {
  double s5 = 0, sech = 0, alt = 0;
  for (int n = 1; n < 400; n += 2) {
    const double x = n * M_PI * a / (2 * b);
    s5 += std::tanh(x) / std::pow(n, 5);
    sech += (x > 700 ? 0.0 : 1.0 / std::cosh(x)) / (double(n) * n);
    alt += ((n / 2) % 2 == 0 ? 1.0 : -1.0) * std::tanh(x) / (double(n) * n);
  }
  const double g_theta = 1.0 / ((16.0 / 3.0) * a * b * b * b * (1 - 192 / std::pow(M_PI, 5) * (b / a) * s5));
  *tau_long = 2 * g_theta * b - 16 * g_theta * b / (M_PI * M_PI) * sech;
  *tau_short = 16 * g_theta * b / (M_PI * M_PI) * alt;
}

std::vector<Fibre> SectionFibres(const BeamSectionSpec& s, const SectionProperties& p) {
  std::vector<Fibre> fibres;
  auto axial = [&](double y, double z) {
    Fibre f{y, z, Eigen::Matrix<double, 3, 6>::Zero()};
    f.map(0, 0) = 1 / p.A;
    f.map(0, 4) = z / p.Iy;
    f.map(0, 5) = -y / p.Iz;
    return f;
  };
  if (s.shape == SectionShape::kCircle || s.shape == SectionShape::kTube) {
    const double R = s.shape == SectionShape::kCircle ? 0.5 * s.diameter : s.outer_radius;
    const double r = s.shape == SectionShape::kCircle ? 0.0 : s.outer_radius - s.wall;
    const double jourawski = (4.0 / 3.0) * (R * R + R * r + r * r) / (R * R + r * r) / p.A;
    for (int k = 0; k < 8; ++k) {
      const double phi = k * M_PI / 4, c = std::cos(phi), sn = std::sin(phi);
      Fibre f = axial(R * c, R * sn);
      // Torsion: tangential, e_x x rho: tau_xy = -T z / J, tau_xz = T y / J.
      f.map(1, 3) = -R * sn / p.J;
      f.map(2, 3) = R * c / p.J;
      if (k % 4 == 2) f.map(1, 1) = jourawski;  // y = 0: the neutral axis of V_y
      if (k % 4 == 0) f.map(2, 2) = jourawski;  // z = 0: the neutral axis of V_z
      fibres.push_back(f);
    }
  } else if (s.shape == SectionShape::kRectangle) {
    const double hy = 0.5 * s.width, hz = 0.5 * s.height;
    double t_long = 0, t_short = 0;
    RectangleTorsion(std::max(hy, hz), std::min(hy, hz), &t_long, &t_short);
    // The long sides are the ones at y = +-hy when the section is taller than wide.
    const double t_at_y_sides = hz >= hy ? t_long : t_short, t_at_z_sides = hz >= hy ? t_short : t_long;
    for (int sy : {-1, 1})
      for (int sz : {-1, 1}) fibres.push_back(axial(sy * hy, sz * hz));
    for (int sy : {-1, 1}) {  // middle of the sides y = +-hy: tau_xz from torsion and from V_z
      Fibre f = axial(sy * hy, 0);
      f.map(2, 3) = sy * t_at_y_sides;
      f.map(2, 2) = 1.5 / p.A;
      fibres.push_back(f);
    }
    for (int sz : {-1, 1}) {  // middle of the sides z = +-hz: tau_xy from torsion and from V_y
      Fibre f = axial(0, sz * hz);
      f.map(1, 3) = -sz * t_at_z_sides;
      f.map(1, 1) = 1.5 / p.A;
      fibres.push_back(f);
    }
  }
  return fibres;
}

}  // namespace

namespace {

// The volume-weighted sums of the elements' projected values at the nodes (`rows` per node,
// node-major) and the nodes' volumes, over `cells`.
struct NodalSums {
  Eigen::MatrixXd sum;
  Eigen::VectorXd weight;
};

NodalSums SumOverElements(SolidType type, const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells,
                          const MaterialSpec& material, const Eigen::MatrixXd& mesh_shapes, bool gradients) {
  const long n_nodes = nodes.rows(), m = mesh_shapes.cols();
  const int n = SolidNodeCount(type);
  // Per point the rows projected: the 6 stresses D B u, then (with gradients) the 9 entries of
  // the displacement gradient du_i/dX_j (row 3 i + j).
  const int rows = gradients ? 15 : 6;
  const Eigen::Matrix<double, 6, 6> D = IsotropicElasticity(material.E, material.nu);
  NodalSums out{Eigen::MatrixXd::Zero(rows * n_nodes, m), Eigen::VectorXd::Zero(n_nodes)};
  Eigen::MatrixXd X(n, 3), U(3 * n, m), op(rows, 3 * n);
  for (long e = 0; e < cells.rows(); ++e) {
    for (int a = 0; a < n; ++a) {
      X.row(a) = nodes.row(cells(e, a));
      U.middleRows(3 * a, 3) = mesh_shapes.middleRows(3 * long(cells(e, a)), 3);
    }
    // E = sum_g dV N_g (x) op_g: (rows n) x (3 n), node-major; M_e = sum_g dV N_g N_g^T.
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(rows * n, 3 * n), Me = Eigen::MatrixXd::Zero(n, n);
    double volume = 0;
    for (const SolidPoint& p : SolidElementPoints(type, X, e + 1)) {
      op.topRows(6) = D * SolidStrainMatrix(p.dNdX);
      if (gradients) {
        op.bottomRows(9).setZero();
        for (int a = 0; a < n; ++a)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) op(6 + 3 * i + j, 3 * a + i) = p.dNdX(a, j);
      }
      for (int a = 0; a < n; ++a) E.middleRows(rows * a, rows) += (p.dV * p.N[a]) * op;
      Me.noalias() += p.dV * p.N * p.N.transpose();
      volume += p.dV;
    }
    const Eigen::MatrixXd S = E * U;  // (rows n) x m: int N_a (op u) dV per node a
    const Eigen::LLT<Eigen::MatrixXd> llt(Me);
    for (int c = 0; c < rows; ++c) {
      // The projection per component: nodal values = M_e^-1 (int N f_c dV).
      Eigen::MatrixXd rhs(n, m);
      for (int a = 0; a < n; ++a) rhs.row(a) = S.row(rows * a + c);
      const Eigen::MatrixXd nodal = llt.solve(rhs);
      for (int a = 0; a < n; ++a) out.sum.row(rows * long(cells(e, a)) + c) += volume * nodal.row(a);
    }
    for (int a = 0; a < n; ++a) out.weight[cells(e, a)] += volume;
  }
  return out;
}

// The result's points (every mesh node) and material.
void SetPoints(const Eigen::MatrixXd& nodes, const MaterialSpec& material, bool gradients, ModalStress& out) {
  out.method = "solid_nodal_l2";
  out.points = nodes;
  out.node.resize(nodes.rows());
  for (long i = 0; i < nodes.rows(); ++i) out.node[i] = int(i);
  if (gradients) {
    out.E = material.E;
    out.nu = material.nu;
  }
}

}  // namespace

ModalStress SolidModalStress(SolidType type, const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells,
                             const MaterialSpec& material, const Eigen::MatrixXd& mesh_shapes, bool gradients) {
  const NodalSums s = SumOverElements(type, nodes, cells, material, mesh_shapes, gradients);
  const long n_nodes = nodes.rows(), m = mesh_shapes.cols();
  const int rows = gradients ? 15 : 6;
  ModalStress out;
  SetPoints(nodes, material, gradients, out);
  out.modes.resize(6 * n_nodes, m);
  if (gradients) out.gradients.resize(9 * n_nodes, m);
  for (long i = 0; i < n_nodes; ++i) {
    // Nodes of no element (none in a meshed part) keep zero stress.
    const double w = s.weight[i] > 0 ? s.weight[i] : 1.0;
    out.modes.middleRows(6 * i, 6) = (s.sum.middleRows(rows * i, 6) / w).cast<float>();
    if (gradients) out.gradients.middleRows(9 * i, 9) = (s.sum.middleRows(rows * i + 6, 9) / w).cast<float>();
  }
  return out;
}

ModalStress SolidModalStressOnRanks(SolidType type, const Eigen::MatrixXd& points, const RankMesh& mesh,
                                    const MaterialSpec& material, const Eigen::MatrixXd& mesh_fields, bool gradients) {
  NodalSums s = SumOverElements(type, mesh.nodes, mesh.cells, material, mesh_fields, gradients);
  const long m = mesh_fields.cols();
  const int rows = gradients ? 15 : 6;
  std::vector<int> keys = mesh.node, weight_keys = mesh.node;
  Eigen::MatrixXd weight = s.weight;
  AddOnOwners(keys, s.sum, rows, mesh.owner);
  AddOnOwners(weight_keys, weight, 1, mesh.owner);  // (the same keys: the same owners)
  Eigen::MatrixXd modes(6 * long(keys.size()), m), slopes(gradients ? 9 * long(keys.size()) : 0, m);
  for (long i = 0; i < long(keys.size()); ++i) {
    const double w = weight(i, 0) > 0 ? weight(i, 0) : 1.0;
    modes.middleRows(6 * i, 6) = s.sum.middleRows(rows * i, 6) / w;
    if (gradients) slopes.middleRows(9 * i, 9) = s.sum.middleRows(rows * i + 6, 9) / w;
  }
  s = NodalSums();
  ModalStress out;
  const long n_nodes = points.rows();
  out.modes = GatherBlocksOnFirst(keys, modes, 6, n_nodes);
  if (gradients) out.gradients = GatherBlocksOnFirst(keys, slopes, 9, n_nodes);
  if (DistributedRank() == 0) SetPoints(points, material, gradients, out);
  return out;
}

ModalStress BeamModalStress(const PartSpec& part, const Eigen::MatrixXd& shapes, bool quadratic) {
  std::vector<Eigen::Vector3d> nodes;
  const std::vector<BeamElement> elements = BeamElements(part, &nodes);
  const long m = shapes.cols(), n_cells = long(elements.size());
  ModalStress out;
  out.method = "beam_fibres";
  out.section_forces.resize(12 * n_cells, m);
  out.element_axes.resize(n_cells, 9);
  if (quadratic) {
    out.element_quadratic.resize(n_cells, m * (m + 1) / 2);
    out.E = part.material.E;
    out.nu = part.material.nu;
  }
  std::vector<Eigen::Vector3d> points;
  std::vector<int> point_node, point_element;
  std::vector<Eigen::MatrixXd> point_modes;
  long e = 0;
  for (const BeamSegmentSpec& seg : part.beam.segments) {
    const BeamSectionSpec& section = seg.section ? *seg.section : part.beam.section;
    const SectionProperties props = ComputeSectionProperties(section, part.material.nu);
    const std::vector<Fibre> fibres = SectionFibres(section, props);
    for (int k = 0; k < seg.elements; ++k, ++e) {
      const BeamElement& el = elements[size_t(e)];
      Eigen::MatrixXd u(12, m);
      u.topRows(6) = shapes.middleRows(6 * long(el.n1), 6);
      u.bottomRows(6) = shapes.middleRows(6 * long(el.n2), 6);
      // End forces on the element, local axes; the section forces: minus those at the first
      // end (its cut face points along -x), those at the second.
      const Eigen::MatrixXd local = BeamTransformation(el.R) * u;
      const Eigen::MatrixXd f = el.beam->LocalStiffness() * local;
      if (quadratic) {
        // Q_e = (1 / L) sum_g w_g S_g^T S_g, S_g (2 x m) the slopes v', w' of the basis vectors.
        Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(m, m);
        double length = 0;
        for (const TimoshenkoBeam::QuadraturePoint& g : el.beam->QuadraturePoints()) {
          const Eigen::MatrixXd S = g.slope * local;
          Q.noalias() += g.weight * S.transpose() * S;
          length += g.weight;
        }
        Q /= length;
        long entry = 0;
        for (long i = 0; i < m; ++i)
          for (long j = i; j < m; ++j) out.element_quadratic(e, entry++) = float(Q(i, j));
      }
      Eigen::MatrixXd ends(12, m);
      ends.topRows(6) = -f.topRows(6);
      ends.bottomRows(6) = f.bottomRows(6);
      out.section_forces.middleRows(12 * e, 12) = ends.cast<float>();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) out.element_axes(e, 3 * r + c) = el.R(r, c);
      const Eigen::Matrix<double, 6, 3> to_part = FibreToPart(el.R);
      for (int end = 0; end < 2; ++end) {
        const int node = end == 0 ? el.n1 : el.n2;
        for (const Fibre& fb : fibres) {
          points.push_back(nodes[size_t(node)] + fb.y * el.R.row(1).transpose() + fb.z * el.R.row(2).transpose());
          point_node.push_back(node);
          point_element.push_back(int(e));
          point_modes.push_back(to_part * fb.map * ends.middleRows(6 * end, 6));
        }
      }
    }
  }
  out.points.resize(long(points.size()), 3);
  out.node.resize(long(points.size()));
  if (quadratic) out.point_element.resize(long(points.size()));
  out.modes.resize(6 * long(points.size()), m);
  for (size_t p = 0; p < points.size(); ++p) {
    out.points.row(long(p)) = points[p].transpose();
    out.node[long(p)] = point_node[p];
    if (quadratic) out.point_element[long(p)] = point_element[p];
    out.modes.middleRows(6 * long(p), 6) = point_modes[p].cast<float>();
  }
  return out;
}

}  // namespace femb
