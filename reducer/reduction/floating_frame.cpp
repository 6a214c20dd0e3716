#include "reducer/reduction/floating_frame.h"

#include <Eigen/Dense>
#include <cstdio>
#include <optional>

#include "formats/input_error.h"
#include "reducer/linalg/shared_columns.h"
#include "reducer/reduction/craig_bampton.h"

namespace femb {

namespace {

// N(x_c) of the center_of_mass frame, or the refusal naming `where`.
std::optional<SparseMatrix> CenterOfMassInterpolation(const std::string& where, const FeModel& model,
                                                      const Eigen::Vector3d& c) {
  if (!model.interpolate_at) {
    throw InputError(where +
                     ": floating_frame center_of_mass interpolates the field at the centre of mass, and this "
                     "model's mesh has no volume cells to interpolate in (an imported surface or line mesh): use "
                     "floating_frame: mean_axes");
  }
  std::optional<SparseMatrix> interpolation = model.interpolate_at(c);
  if (!interpolation) {
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "(%.6g, %.6g, %.6g)", c.x(), c.y(), c.z());
    throw InputError(where + ": floating_frame center_of_mass: the centre of mass " + buffer +
                     " lies outside the material; use floating_frame: mean_axes");
  }
  return interpolation;
}

}  // namespace

void CheckFloatingFrame(const ReductionSpec& reduction, const FeModel& model) {
  if (reduction.floating_frame != FloatingFrameType::kCenterOfMass) return;
  // The centre of mass from the rigid fields R (translations, rotations about the part origin):
  // R^T M R = [m 1, -S~; S~, J], the first moment S = m c from its (translation, rotation) block.
  const Eigen::MatrixXd R = RigidFields(model);
  const Eigen::MatrixXd MR = SharedTimes(model.M, R, model.columns);  // (M shared by columns on MPI ranks)
  const Eigen::MatrixXd M_rig = R.transpose() * MR;
  const double m = M_rig(0, 0);
  if (!(m > 0)) return;  // (a massless model is refused elsewhere, with its own message)
  const Eigen::Vector3d c = Eigen::Vector3d(-M_rig(2, 4), -M_rig(0, 5), -M_rig(1, 3)) / m;
  CenterOfMassInterpolation(reduction.where_floating_frame, model, c);
}

FloatingFrame ComputeFloatingFrame(const ReductionSpec& reduction, const Superelement& se, const FeModel& model,
                                   const Eigen::MatrixXd& shapes) {
  const std::string& where = reduction.where_floating_frame;
  FloatingFrame frame;
  frame.type = reduction.FloatingFrameWord();
  const int n_r = se.n_reduced_dofs(), N = se.n_interface_nodes();
  const Eigen::Vector3d c = se.mass_properties.center_of_mass;
  frame.Phi_CB = Eigen::MatrixXd::Zero(6, n_r);

  switch (reduction.floating_frame) {
    case FloatingFrameType::kCenterOfMass: {
      const std::optional<SparseMatrix> interpolation = CenterOfMassInterpolation(where, model, c);
      frame.origin = c;
      frame.Phi_CB = TimesHeldRows(*interpolation, shapes, model.columns);
      break;
    }
    case FloatingFrameType::kMeanAxes: {
      frame.origin = c;
      const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, c);
      const Eigen::Matrix<double, 6, 6> M_rig = RigidBodyMassMatrix(se, c);
      frame.Phi_CB = M_rig.ldlt().solve(Phi_rig0.transpose() * se.M);
      break;
    }
    case FloatingFrameType::kInterface: {
      const std::string& name = reduction.floating_frame_interface;
      int k = -1;
      for (int i = 0; i < N; ++i) {
        if (se.interfaces[i].name == name) k = i;
      }
      if (k < 0) throw InputError(where + ": floating frame interface '" + name + "' not found");
      frame.origin = se.interfaces[k].position;
      frame.Phi_CB.block(0, 6 * k, 6, 6).setIdentity();
      break;
    }
    case FloatingFrameType::kCardona: {
      Eigen::MatrixXd X(3, N);
      for (int k = 0; k < N; ++k) X.col(k) = se.interfaces[k].position - c;
      Eigen::MatrixXd A(N + 1, N);
      A.topRows(N) = X.transpose() * X;
      A.row(N).setOnes();
      Eigen::VectorXd v = Eigen::VectorXd::Zero(N + 1);
      v[N] = 1.0;
      const Eigen::VectorXd alpha = A.completeOrthogonalDecomposition().solve(v);
      frame.cardona_weights = alpha;
      frame.origin = c + X * alpha;
      for (int k = 0; k < N; ++k) {
        frame.Phi_CB.block(0, 6 * k, 6, 6) = alpha[k] * Eigen::Matrix<double, 6, 6>::Identity();
      }
      break;
    }
  }
  return frame;
}

}  // namespace femb
