#include "reducer/fe/beam_model.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>

#include "formats/input_error.h"
#include "reducer/fe/connectivity.h"
#include "reducer/fe/timoshenko_beam.h"

namespace femb {
namespace {

Eigen::Vector3d Orientation(const BeamSpec& beam, const Eigen::Vector3d& axis) {
  if (beam.orientation) return *beam.orientation;
  if (std::abs(axis.normalized().dot(Eigen::Vector3d::UnitY())) < 0.999) return Eigen::Vector3d::UnitY();
  return Eigen::Vector3d::UnitZ();
}

}  // namespace

std::vector<BeamElement> BeamElements(const PartSpec& part, std::vector<Eigen::Vector3d>* nodes_out) {
  const BeamSpec& spec = part.beam;
  std::vector<Eigen::Vector3d> nodes(spec.points.begin(), spec.points.end());
  std::vector<BeamElement> elements;
  for (const BeamSegmentSpec& seg : spec.segments) {
    const Eigen::Vector3d a = spec.points[seg.from], b = spec.points[seg.to];
    const Eigen::Vector3d v = Orientation(spec, b - a);
    if ((b - a).normalized().cross(v.normalized()).norm() < 1e-6) {
      throw InputError(seg.where +
                       ": beam.orientation is parallel to this segment; give a vector "
                       "that lies in the local x-y plane but not along the beam");
    }
    const Eigen::Matrix3d R = BeamFrame(a, b, v);
    const SectionProperties section =
        ComputeSectionProperties(seg.section ? *seg.section : spec.section, part.material.nu);
    const double Le = (b - a).norm() / seg.elements;
    auto beam = std::make_shared<const TimoshenkoBeam>(Le, part.material, section, spec.shear_deformation);
    int previous = seg.from;
    for (int e = 0; e < seg.elements; ++e) {
      int next = seg.to;
      if (e + 1 < seg.elements) {
        next = int(nodes.size());
        nodes.push_back(a + (b - a) * double(e + 1) / seg.elements);
      }
      elements.push_back({previous, next, R, beam});
      previous = next;
    }
  }
  *nodes_out = nodes;
  return elements;
}

FeModel BuildBeamModel(const PartSpec& part) {
  const BeamSpec& spec = part.beam;
  std::vector<Eigen::Vector3d> nodes;
  const std::vector<BeamElement> elements = BeamElements(part, &nodes);

  FeModel model;
  model.dofs_per_node = 6;
  model.element_type = spec.shear_deformation ? "timoshenko_beam" : "euler_bernoulli_beam";
  model.cell_type = CellType::kLine2;
  model.nodes.resize(long(nodes.size()), 3);
  for (size_t i = 0; i < nodes.size(); ++i) model.nodes.row(long(i)) = nodes[i].transpose();
  model.cells.resize(long(elements.size()), 2);

  const int n = 6 * int(nodes.size());
  std::vector<Eigen::Triplet<double>> k_entries, m_entries;
  k_entries.reserve(elements.size() * 144);
  m_entries.reserve(elements.size() * 144);
  for (size_t e = 0; e < elements.size(); ++e) {
    const BeamElement& el = elements[e];
    model.cells(long(e), 0) = el.n1;
    model.cells(long(e), 1) = el.n2;
    const Matrix12d T = BeamTransformation(el.R);
    const Matrix12d Ke = T.transpose() * el.beam->LocalStiffness() * T;
    const Matrix12d Me = T.transpose() * el.beam->LocalMass() * T;
    int dof[12];
    for (int i = 0; i < 6; ++i) {
      dof[i] = 6 * el.n1 + i;
      dof[6 + i] = 6 * el.n2 + i;
    }
    for (int i = 0; i < 12; ++i) {
      for (int j = 0; j < 12; ++j) {
        k_entries.emplace_back(dof[i], dof[j], Ke(i, j));
        m_entries.emplace_back(dof[i], dof[j], Me(i, j));
      }
    }
  }
  model.K.resize(n, n);
  model.M.resize(n, n);
  model.K.setFromTriplets(k_entries.begin(), k_entries.end());
  model.M.setFromTriplets(m_entries.begin(), m_entries.end());

  std::vector<int> interface_nodes;
  for (const InterfaceSpec& i : part.interfaces) interface_nodes.push_back(i.point);
  CheckRegionsHeldByInterfaces(model.cells, model.nodes, interface_nodes, part.file);
  for (const InterfaceSpec& i : part.interfaces) {
    model.interface_names.push_back(i.name);
    model.interface_positions.push_back(spec.points[i.point]);
    model.interface_node_sets.push_back({i.point});
    std::vector<FullDof> dofs;
    for (int c = 0; c < 6; ++c) dofs.push_back({6 * i.point + c});
    model.interface_dofs.push_back(dofs);
  }

  // Material point interpolation: the element whose axis passes through x (within 1e-9 of its
  // length), the element's own (IIE) interpolation there.
  model.interpolate_at = [elements, nodes, n](const Eigen::Vector3d& x) -> std::optional<SparseMatrix> {
    for (const BeamElement& el : elements) {
      const Eigen::Vector3d a = nodes[el.n1], b = nodes[el.n2];
      const double L = (b - a).norm();
      const double xi = (x - a).dot(b - a) / (L * L);
      if (xi < -1e-9 || xi > 1 + 1e-9 || (a + xi * (b - a) - x).norm() > 1e-9 * L) continue;
      const Matrix12d T = BeamTransformation(el.R);
      Eigen::Matrix3d Rt = el.R.transpose();
      Eigen::Matrix<double, 6, 6> back = Eigen::Matrix<double, 6, 6>::Zero();
      back.block<3, 3>(0, 0) = Rt;
      back.block<3, 3>(3, 3) = Rt;
      const Eigen::Matrix<double, 6, 12> N = back * el.beam->LocalInterpolation(std::clamp(xi, 0.0, 1.0)) * T;
      SparseMatrix S(6, n);
      std::vector<Eigen::Triplet<double>> entries;
      for (int r = 0; r < 6; ++r) {
        for (int c = 0; c < 6; ++c) {
          entries.emplace_back(r, 6 * el.n1 + c, N(r, c));
          entries.emplace_back(r, 6 * el.n2 + c, N(r, 6 + c));
        }
      }
      S.setFromTriplets(entries.begin(), entries.end());
      return S;
    }
    return std::nullopt;
  };
  return model;
}

}  // namespace femb
