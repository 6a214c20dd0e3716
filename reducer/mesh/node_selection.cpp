#include "reducer/mesh/node_selection.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <limits>

#include "formats/input_error.h"

namespace femb {
namespace {

std::string Point(const Eigen::Vector3d& p) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.6g, %.6g, %.6g)", p.x(), p.y(), p.z());
  return b;
}

double DefaultTolerance(const Eigen::MatrixXd& nodes) {
  if (nodes.rows() == 0) return 0.0;
  return 1e-4 * (nodes.colwise().maxCoeff() - nodes.colwise().minCoeff()).norm();
}

}  // namespace

double SelectionDistance(const NodeSelectionSpec& s, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - s.point;
  if (s.shape == SelectionShape::kCylinder) {
    const double along = d.dot(s.axis);
    const double radial = std::abs((d - along * s.axis).norm() - s.radius);
    if (s.length <= 0) return radial;
    const double beyond = along < 0 ? -along : along > s.length ? along - s.length : 0.0;
    return std::hypot(radial, beyond);
  }
  if (s.shape == SelectionShape::kSphere) return std::abs(d.norm() - s.radius);
  if (s.shape == SelectionShape::kPlane) return std::abs(d.dot(s.axis));
  // box: min = point, max = axis
  const Eigen::Vector3d outside = (s.point - x).cwiseMax(x - s.axis).cwiseMax(0.0);
  return outside.norm();
}

std::vector<int> SelectNodes(const NodeSelectionSpec& s, const Eigen::MatrixXd& nodes, const std::string& interface) {
  const double tol = s.tolerance.value_or(DefaultTolerance(nodes));
  std::vector<int> selected;
  double nearest = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < nodes.rows(); ++i) {
    const double d = SelectionDistance(s, nodes.row(i).transpose());
    if (d <= tol) selected.push_back(int(i));
    nearest = std::min(nearest, d);
  }
  if (selected.empty()) {
    char b[200];
    std::snprintf(b, sizeof b,
                  "selects no node: the nearest of the %ld mesh nodes is %.4g from it, the tolerance is %.4g",
                  long(nodes.rows()), nearest, tol);
    throw InputError(s.where + ": interface '" + interface + "': the " + DescribeSelection(s) + " " + b +
                     " (check the units and the position, or set select.tolerance)");
  }
  return selected;
}

std::string DescribeSelection(const NodeSelectionSpec& s) {
  char b[64];
  if (s.shape == SelectionShape::kCylinder) {
    std::snprintf(b, sizeof b, "cylinder r = %.6g", s.radius);
    std::string out = std::string(b) + " through " + Point(s.point) + " along " + Point(s.axis);
    if (s.length > 0) {
      std::snprintf(b, sizeof b, ", length %.6g", s.length);
      out += b;
    }
    return out;
  }
  if (s.shape == SelectionShape::kSphere) {
    std::snprintf(b, sizeof b, "sphere r = %.6g", s.radius);
    return std::string(b) + " about " + Point(s.point);
  }
  if (s.shape == SelectionShape::kPlane) return "plane through " + Point(s.point) + " normal to " + Point(s.axis);
  return "box " + Point(s.point) + " .. " + Point(s.axis);
}

}  // namespace femb
