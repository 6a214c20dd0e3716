// The midpoint scheme's iteration matrix through StepColumnMap (dynamic_step.h): Newton's
// increment at n+1 maps onto the mid configuration and the end velocities by the identity times a
// number but on the rotation nodes' triples, whose blocks these functions apply to the matrices'
// triplets without building a sparse map.
#include <Eigen/Dense>

#include "solver/analysis/dynamic_step.h"

namespace femb::dynamic_internal {

// The unknowns' places in a StepColumnMap's blocks (MidpointWorkspace::triple_of).
void TripleOf(const DofMap& dofs, const std::vector<RotationNode>& nodes, std::vector<int>& triple_of) {
  triple_of.assign(size_t(dofs.n_dofs()), -1);
  for (size_t i = 0; i < nodes.size(); ++i) {
    for (int m = 0; m < 3; ++m) {
      triple_of[size_t(nodes[i].rotation + m)] = int(2 * i);
      if (nodes[i].translation >= 0) triple_of[size_t(nodes[i].translation + m)] = int(2 * i + 1);
    }
  }
}

namespace {

// Row j of X as up to 6 entries (columns `cols`, values `vals`), their number returned: X's
// diagonal off the rotation nodes; on a rotation triple its block's row; on a free node's
// translation triple its block's row, then the coupling block's row onto the rotation triple.
int RowOf(const StepColumnMap& X, const std::vector<RotationNode>& nodes, const std::vector<int>& triple_of, int j,
          int (&cols)[6], double (&vals)[6]) {
  const int t = triple_of[size_t(j)];
  if (t < 0) {
    cols[0] = j;
    vals[0] = X.diagonal;
    return 1;
  }
  const size_t i = size_t(t / 2);
  const RotationNode& r = nodes[i];
  const bool translation = t % 2 == 1;
  const int own = translation ? r.translation : r.rotation;
  const Eigen::Matrix3d& B = translation ? X.translation[i] : X.rotation[i];
  for (int m = 0; m < 3; ++m) {
    cols[m] = own + m;
    vals[m] = B(j - own, m);
  }
  if (!translation) return 3;
  for (int m = 0; m < 3; ++m) {
    cols[3 + m] = r.rotation + m;
    vals[3 + m] = X.coupling[i](j - own, m);
  }
  return 6;
}

}  // namespace

// out += scale * A X for the matrix A of the triplets `in`: each entry (i, j, v) spreads over
// row j of X.
void AddTimesColumns(const Triplets& in, double scale, const StepColumnMap& X, const std::vector<RotationNode>& nodes,
                     const std::vector<int>& triple_of, Triplets& out) {
  int cols[6];
  double vals[6];
  for (const Eigen::Triplet<double>& e : in) {
    const int count = RowOf(X, nodes, triple_of, e.col(), cols, vals);
    const double v = scale * e.value();
    for (int m = 0; m < count; ++m) out.emplace_back(e.row(), cols[m], v * vals[m]);
  }
}

// out += B^T (K B T' + M B V' / h) for a body's K and M (local) and map B, T' = T - T_d 1 and
// V' = V - V_d 1 (StepColumnMap: nonzero on the rotation nodes' triples only): only the map's
// entries on such coordinates give columns. Every entry is kept, zero or not, so that the
// triplets come in the same sequence at every iteration (TripletAssembler).
void AddRotationColumns(const std::vector<MapEntry>& map, const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, double h,
                        const MidpointKinematics& k, const std::vector<RotationNode>& nodes,
                        const std::vector<int>& triple_of, Triplets& out) {
  int cols[6];
  double t_row[6], v_row[6];
  for (const MapEntry& col : map) {
    if (triple_of[size_t(col.coordinate)] < 0) continue;
    const int count = RowOf(k.T, nodes, triple_of, col.coordinate, cols, t_row);
    RowOf(k.V, nodes, triple_of, col.coordinate, cols, v_row);
    for (int m = 0; m < count; ++m) {
      if (cols[m] != col.coordinate) continue;
      t_row[m] -= k.T.diagonal;
      v_row[m] -= k.V.diagonal;
    }
    for (const MapEntry& row : map) {
      const double vk = row.coefficient * col.coefficient * K(row.local, col.local);
      const double vm = row.coefficient * col.coefficient * M(row.local, col.local) / h;
      for (int m = 0; m < count; ++m) out.emplace_back(row.coordinate, cols[m], vk * t_row[m] + vm * v_row[m]);
    }
  }
}

}  // namespace femb::dynamic_internal
