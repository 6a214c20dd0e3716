#include "inspect/superelement_checks.h"

namespace femb {

bool SuperelementAnalysis::all_ok() const {
  for (const Check& c : checks) {
    if (!c.ok) return false;
  }
  return true;
}

SuperelementAnalysis AnalyzeSuperelement(const Superelement& se) {
  SuperelementChecks c = CheckSuperelement(se);
  SuperelementAnalysis a;
  a.checks = std::move(c.checks);
  a.rigid_body_mode_count = c.rigid_body_mode_count;
  a.free_free_frequencies_hz.resize(c.lambda.size());
  for (int k = 0; k < c.lambda.size(); ++k) a.free_free_frequencies_hz[k] = FrequencyHz(c.lambda[k]);
  a.rigid_mass_frame.setConstant(std::nan(""));
  if (a.checks.front().ok) a.rigid_mass_frame = RigidBodyMassMatrix(se, se.floating_frame.origin);
  return a;
}

}  // namespace femb
