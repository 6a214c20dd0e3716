#include "formats/solid_shape.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace femb {
namespace {

// gmsh HEX8 corner signs and HEX20 edge nodes (pairs of corners).
constexpr int kHexCorner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
constexpr int kHex20Edge[12][2] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3},
                                   {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}};
// gmsh TET10 edge nodes 4..9.
constexpr int kTet10Edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};

}  // namespace

int SolidNodeCount(SolidType type) {
  switch (type) {
    case SolidType::kTet4:
      return 4;
    case SolidType::kTet10:
      return 10;
    case SolidType::kHex8:
      return 8;
    case SolidType::kHex20:
      return 20;
  }
  return 0;
}

CellType CellOf(SolidType type) {
  switch (type) {
    case SolidType::kTet4:
      return CellType::kTet4;
    case SolidType::kTet10:
      return CellType::kTet10;
    case SolidType::kHex8:
      return CellType::kHex8;
    case SolidType::kHex20:
      return CellType::kHex20;
  }
  return CellType::kTet4;
}

void SolidShapeFunctions(SolidType type, const Eigen::Vector3d& p, Eigen::VectorXd* N, Eigen::MatrixXd* dN) {
  const int n = SolidNodeCount(type);
  N->setZero(n);
  dN->setZero(n, 3);
  if (type == SolidType::kTet4 || type == SolidType::kTet10) {
    // Barycentric L = (1 - x - y - z, x, y, z) and dL/d(x, y, z).
    const double L[4] = {1 - p.x() - p.y() - p.z(), p.x(), p.y(), p.z()};
    const Eigen::Vector3d dL[4] = {Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ()};
    if (type == SolidType::kTet4) {
      for (int i = 0; i < 4; ++i) {
        (*N)[i] = L[i];
        dN->row(i) = dL[i].transpose();
      }
      return;
    }
    for (int i = 0; i < 4; ++i) {
      (*N)[i] = L[i] * (2 * L[i] - 1);
      dN->row(i) = ((4 * L[i] - 1) * dL[i]).transpose();
    }
    for (int e = 0; e < 6; ++e) {
      const int a = kTet10Edge[e][0], b = kTet10Edge[e][1];
      (*N)[4 + e] = 4 * L[a] * L[b];
      dN->row(4 + e) = (4 * (L[a] * dL[b] + L[b] * dL[a])).transpose();
    }
    return;
  }
  if (type == SolidType::kHex8) {
    for (int i = 0; i < 8; ++i) {
      const double a = kHexCorner[i][0], b = kHexCorner[i][1], c = kHexCorner[i][2];
      const double fa = 1 + a * p.x(), fb = 1 + b * p.y(), fc = 1 + c * p.z();
      (*N)[i] = fa * fb * fc / 8;
      dN->row(i) << a * fb * fc / 8, fa * b * fc / 8, fa * fb * c / 8;
    }
    return;
  }
  // HEX20 serendipity.
  for (int i = 0; i < 8; ++i) {
    const double a = kHexCorner[i][0], b = kHexCorner[i][1], c = kHexCorner[i][2];
    const double fa = 1 + a * p.x(), fb = 1 + b * p.y(), fc = 1 + c * p.z();
    const double s = a * p.x() + b * p.y() + c * p.z() - 2;
    (*N)[i] = fa * fb * fc * s / 8;
    dN->row(i) << a * fb * fc * (s + fa) / 8, b * fa * fc * (s + fb) / 8, c * fa * fb * (s + fc) / 8;
  }
  for (int e = 0; e < 12; ++e) {
    const int i = kHex20Edge[e][0], j = kHex20Edge[e][1];
    // Mid-edge node: the coordinate along the edge is 0, the two others are the corners' signs.
    double m[3];
    int along = 0;
    for (int d = 0; d < 3; ++d) {
      m[d] = 0.5 * (kHexCorner[i][d] + kHexCorner[j][d]);
      if (m[d] == 0) along = d;
    }
    double f[3], df[3];
    for (int d = 0; d < 3; ++d) {
      if (d == along) {
        f[d] = 1 - p[d] * p[d];
        df[d] = -2 * p[d];
      } else {
        f[d] = 1 + m[d] * p[d];
        df[d] = m[d];
      }
    }
    (*N)[8 + e] = f[0] * f[1] * f[2] / 4;
    dN->row(8 + e) << df[0] * f[1] * f[2] / 4, f[0] * df[1] * f[2] / 4, f[0] * f[1] * df[2] / 4;
  }
}

std::optional<SolidType> SolidTypeOf(CellType cell_type) {
  for (SolidType t : {SolidType::kTet4, SolidType::kTet10, SolidType::kHex8, SolidType::kHex20}) {
    if (CellOf(t) == cell_type) return t;
  }
  return std::nullopt;
}

bool LocateInCell(SolidType type, const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells, int cell,
                  const Eigen::Vector3d& x, Eigen::Vector3d* xi) {
  const int n = SolidNodeCount(type);
  Eigen::MatrixXd X(n, 3);
  for (int a = 0; a < n; ++a) X.row(a) = nodes.row(cells(cell, a));
  const bool tet = type == SolidType::kTet4 || type == SolidType::kTet10;
  Eigen::Vector3d p = tet ? Eigen::Vector3d(0.25, 0.25, 0.25) : Eigen::Vector3d::Zero();
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (int it = 0; it < 20; ++it) {
    SolidShapeFunctions(type, p, &N, &dN);
    const Eigen::Vector3d r = X.transpose() * N - x;
    const Eigen::Matrix3d J = X.transpose() * dN;
    if (std::abs(J.determinant()) < 1e-300) return false;
    const Eigen::Vector3d d = J.lu().solve(r);
    p -= d;
    if (d.norm() < 1e-12) break;
  }
  const double tol = 1e-9;
  const bool inside = tet ? (p.minCoeff() >= -tol && p.sum() <= 1 + tol) : (p.cwiseAbs().maxCoeff() <= 1 + tol);
  *xi = p;
  return inside;
}

MeshPoint LocateInMesh(const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells, CellType cell_type,
                       const Eigen::Vector3d& x) {
  MeshPoint out;
  if (nodes.rows() == 0) return out;
  Eigen::Index nearest = 0;
  out.distance = std::sqrt((nodes.rowwise() - x.transpose()).rowwise().squaredNorm().minCoeff(&nearest));
  out.nearest = int(nearest);
  // The local mesh size: the longest edge (node-to-node distance) of the cells at the nearest node.
  for (int c = 0; c < cells.rows(); ++c) {
    bool has = false;
    for (int a = 0; a < cells.cols(); ++a) has |= cells(c, a) == out.nearest;
    if (!has) continue;
    for (int a = 0; a < cells.cols(); ++a)
      for (int b = a + 1; b < cells.cols(); ++b)
        out.size = std::max(out.size, (nodes.row(cells(c, a)) - nodes.row(cells(c, b))).norm());
  }
  const std::optional<SolidType> type = SolidTypeOf(cell_type);
  if (type) {
    const double slack = 1e-9 * (nodes.colwise().maxCoeff() - nodes.colwise().minCoeff()).norm();
    Eigen::VectorXd N;
    Eigen::MatrixXd dN;
    for (int c = 0; c < cells.rows(); ++c) {
      // A cell whose bounding box misses the point cannot hold it (straight or curved edges:
      // the box of the nodes of an isoparametric cell of femb's meshes holds the cell).
      Eigen::Vector3d lo = nodes.row(cells(c, 0)).transpose(), hi = lo;
      for (int a = 1; a < cells.cols(); ++a) {
        lo = lo.cwiseMin(nodes.row(cells(c, a)).transpose());
        hi = hi.cwiseMax(nodes.row(cells(c, a)).transpose());
      }
      if ((x.array() < lo.array() - slack).any() || (x.array() > hi.array() + slack).any()) continue;
      Eigen::Vector3d xi;
      if (!LocateInCell(*type, nodes, cells, c, x, &xi)) continue;
      SolidShapeFunctions(*type, xi, &N, &dN);
      out.cell = c;
      for (int a = 0; a < cells.cols(); ++a) {
        out.nodes.push_back(cells(c, a));
        out.weights.push_back(N[a]);
      }
      out.distance = 0.0;
      return out;
    }
  }
  out.nodes = {out.nearest};
  out.weights = {1.0};
  return out;
}

}  // namespace femb
