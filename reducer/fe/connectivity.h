// Mesh regions held by no interface make K_ii singular; find them before factorizing and say
// where they are.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace femb {

/// Throws InputError "<where>: a mesh region of N nodes around (x, y, z) is connected to no
/// interface ..." when some connected component of the cells contains no node of
/// `interface_nodes`.
void CheckRegionsHeldByInterfaces(const Eigen::MatrixXi& cells, const Eigen::MatrixXd& nodes,
                                  const std::vector<int>& interface_nodes, const std::string& where);

}  // namespace femb
