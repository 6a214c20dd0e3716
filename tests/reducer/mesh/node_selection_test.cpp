// Interface nodes picked by geometry (reducer/mesh/node_selection.h) on a cloud of points whose
// membership is known by construction: rings on a cylinder (inside and beyond its length), points
// inside it, on a sphere and off it; the distance of a point from each surface against its closed
// form; and no node within the tolerance stops with one line naming the interface, the surface
// and the nearest distance.
#include "reducer/mesh/node_selection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.h"

namespace femb {
namespace {

struct Cloud {
  Eigen::MatrixXd nodes;
  std::vector<int> on_cylinder, on_cylinder_within_length, on_sphere, on_plane_z0, in_box;
};

// Rings of radius 10 mm about the z axis at z = 0, 10, ..., 50 mm; the same rings at 5 mm (inside
// the cylinder); 12 points on a sphere of radius 80 mm about (0, 0, 200 mm).
Cloud MakeCloud() {
  std::vector<Eigen::Vector3d> x;
  Cloud c;
  for (int ring = 0; ring <= 5; ++ring) {
    for (double r : {0.010, 0.005}) {
      for (int k = 0; k < 8; ++k) {
        const double a = 2 * M_PI * k / 8 + 0.1;
        const double z = 0.01 * ring;
        const int i = int(x.size());
        x.emplace_back(r * std::cos(a), r * std::sin(a), z);
        if (r == 0.010) c.on_cylinder.push_back(i);
        if (r == 0.010 && z <= 0.03 + 1e-12) c.on_cylinder_within_length.push_back(i);
        if (ring == 0) c.on_plane_z0.push_back(i);
        if (r == 0.005 && z <= 0.02 + 1e-12) c.in_box.push_back(i);
      }
    }
  }
  for (int k = 0; k < 12; ++k) {
    const double polar = M_PI * (k + 0.5) / 12, azimuth = 2.4 * k;
    c.on_sphere.push_back(int(x.size()));
    x.push_back(Eigen::Vector3d(0, 0, 0.2) + 0.08 * Eigen::Vector3d(std::sin(polar) * std::cos(azimuth),
                                                                    std::sin(polar) * std::sin(azimuth),
                                                                    std::cos(polar)));
  }
  c.nodes.resize(long(x.size()), 3);
  for (size_t i = 0; i < x.size(); ++i) c.nodes.row(long(i)) = x[i].transpose();
  return c;
}

NodeSelectionSpec Spec(SelectionShape shape, const Eigen::Vector3d& point, const Eigen::Vector3d& axis, double radius,
                       double length = 0.0) {
  NodeSelectionSpec s;
  s.shape = shape;
  s.point = point;
  s.axis = axis;
  s.radius = radius;
  s.length = length;
  s.where = "part.yaml:9: interfaces[0].select";
  return s;
}

TEST(NodeSelection, EachSurfacePicksTheNodesOnItAndNoOthers) {
  const Cloud c = MakeCloud();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ(), o = Eigen::Vector3d::Zero();
  EXPECT_EQ(SelectNodes(Spec(SelectionShape::kCylinder, o, z, 0.010), c.nodes, "bore"), c.on_cylinder);
  EXPECT_EQ(SelectNodes(Spec(SelectionShape::kCylinder, o, z, 0.010, 0.03), c.nodes, "bore"),
            c.on_cylinder_within_length);
  EXPECT_EQ(SelectNodes(Spec(SelectionShape::kSphere, Eigen::Vector3d(0, 0, 0.2), z, 0.08), c.nodes, "ball"),
            c.on_sphere);
  EXPECT_EQ(SelectNodes(Spec(SelectionShape::kPlane, o, z, 0.0), c.nodes, "face"), c.on_plane_z0);
  // Box: min in `point`, max in `axis`.
  EXPECT_EQ(SelectNodes(Spec(SelectionShape::kBox, Eigen::Vector3d(-0.006, -0.006, -0.001),
                             Eigen::Vector3d(0.006, 0.006, 0.021), 0.0),
                        c.nodes, "core"),
            c.in_box);
}

TEST(NodeSelection, DistancesAreTheSurfacesClosedForms) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2) / 3, p(0.1, -0.2, 0.3);
  const Eigen::Vector3d n = Eigen::Vector3d(2, -1, 0).normalized();  // perpendicular to the axis
  // 4 mm outside a 10 mm cylinder, 30 mm along it: radial distance; 20 mm beyond a 25 mm length:
  // the hypotenuse.
  const Eigen::Vector3d x = p + 0.030 * axis + 0.014 * n;
  EXPECT_NEAR(SelectionDistance(Spec(SelectionShape::kCylinder, p, axis, 0.010), x), 0.004, 1e-15);
  const Eigen::Vector3d beyond = p + 0.045 * axis + 0.014 * n;
  EXPECT_NEAR(SelectionDistance(Spec(SelectionShape::kCylinder, p, axis, 0.010, 0.025), beyond),
              std::hypot(0.004, 0.02), 1e-15);
  EXPECT_NEAR(SelectionDistance(Spec(SelectionShape::kSphere, p, axis, 0.05), p + 0.07 * n), 0.02, 1e-15);
  EXPECT_NEAR(SelectionDistance(Spec(SelectionShape::kPlane, p, axis, 0.0), p + 0.3 * n - 0.006 * axis), 0.006, 1e-15);
  const NodeSelectionSpec box = Spec(SelectionShape::kBox, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 0.0);
  EXPECT_EQ(SelectionDistance(box, Eigen::Vector3d(0.5, 0.5, 0.5)), 0.0);
  EXPECT_NEAR(SelectionDistance(box, Eigen::Vector3d(1.3, -0.4, 0.5)), 0.5, 1e-15);
}

TEST(NodeSelection, NoNodeWithinTheToleranceNamesTheNearestDistance) {
  // The rings alone (48 on the cylinder, 48 inside it). A bore of 10.5 mm where they have 10 mm:
  // 0.5 mm away, the default tolerance 1e-4 of their diagonal (about 5 um).
  const Cloud c = MakeCloud();
  const Eigen::MatrixXd rings = c.nodes.topRows(96);
  const std::string message = test::ThrownMessage([&] {
    SelectNodes(Spec(SelectionShape::kCylinder, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0105), rings,
                "bore");
  });
  EXPECT_NE(message.find("part.yaml:9: interfaces[0].select: interface 'bore': the cylinder r = 0.0105"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("is 0.0005 from it"), std::string::npos) << message;
  // With a tolerance of 1 mm the same bore picks the 10 mm rings.
  NodeSelectionSpec loose = Spec(SelectionShape::kCylinder, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0105);
  loose.tolerance = 1e-3;
  EXPECT_EQ(SelectNodes(loose, rings, "bore"), c.on_cylinder);
}

}  // namespace
}  // namespace femb
