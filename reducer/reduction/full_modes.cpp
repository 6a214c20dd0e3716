#include "reducer/reduction/full_modes.h"

#include <cmath>

#include "formats/superelement.h"
#include "reducer/linalg/generalized_eigen.h"

namespace femb {

FullModesResult FullFreeFreeFrequencies(const FeModel& model, int n_flexible, double s, Eigen::MatrixXd* vectors,
                                        Eigen::VectorXd* lambda) {
  FullModesResult r;
  const int nev = std::min<int>(n_flexible + 6, int(model.n_dofs()));
  SparseMatrix shifted = model.K + s * model.M;
  SparseCholesky factor;
  r.factorization = factor.Compute(shifted);
  if (!r.factorization.ok) {
    r.message = "K + s M is not positive definite: " + r.factorization.message;
    return r;
  }
  EigenResult eig = LowestEigenpairs(model.K, model.M, nev, -s, factor);
  r.linear_solves = eig.linear_solves;
  if (!eig.ok) {
    r.message = eig.message;
    return r;
  }
  r.frequencies_hz.resize(nev);
  for (int k = 0; k < nev; ++k) r.frequencies_hz[k] = FrequencyHz(eig.lambda[k]);
  if (vectors) *vectors = std::move(eig.vectors);
  if (lambda) *lambda = eig.lambda;
  r.ok = true;
  return r;
}

}  // namespace femb
