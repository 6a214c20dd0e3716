#include "reducer/reduce_part.h"

#include <algorithm>
#include <cstdio>

#include "formats/input_error.h"
#include "reducer/fe/beam_model.h"
#include "reducer/fe/solid_model.h"
#include "reducer/linalg/sparse_cholesky.h"
#include "reducer/reduction/craig_bampton.h"
#include "reducer/reduction/floating_frame.h"
#include "reducer/reduction/full_modes.h"

#ifndef FEMB_VERSION
#define FEMB_VERSION "unknown"
#endif

namespace femb {

ReduceResult ReducePart(const PartSpec& part, const ProgressFn& progress) {
  ReduceResult result;
  Provenance& prov = result.superelement.provenance;
  auto report = [&](const std::string& stage, double seconds, const std::string& detail) {
    prov.stage_seconds.emplace_back(stage, seconds);
    if (progress) progress(stage, seconds, detail);
  };

  Stopwatch clock;
  char detail[200];
  FeModel model;
  if (part.type == "solid") {
    model = BuildSolidModel(part, report);
  } else {
    model = BuildBeamModel(part);
    std::snprintf(detail, sizeof detail, "%ld nodes, %ld %s elements, %ld DOFs", model.n_nodes(),
                  model.n_elements(), model.element_type.c_str(), model.n_dofs());
    report("mesh+assembly", clock.Seconds(), detail);
  }

  const long n_interior = long(InteriorDofs(model).size());
  if (part.reduction.internal_modes > n_interior) {
    throw InputError(part.file + ": reduction.internal_modes = " +
                     std::to_string(part.reduction.internal_modes) + " exceeds the " +
                     std::to_string(n_interior) + " interior DOFs of the mesh (refine it or keep fewer modes)");
  }
  // Memory for the factor of K_ii: what is left beside the dense blocks the reduction keeps
  // (constraint modes, Lanczos vectors, the mode shapes of the full model).
  const int n_b = 6 * int(model.interface_names.size()), m = part.reduction.internal_modes;
  const double dense_bytes = 8.0 * double(model.n_dofs()) * (2.0 * (n_b + m) + 2.0 * m + 20.0);
  const double limit = part.reduction.memory_limit_gb > 0 ? part.reduction.memory_limit_gb * 1e9
                                                          : AvailableMemoryBytes();
  const double factor_budget = limit > 0 ? std::max(limit - dense_bytes, 0.1 * limit) : 0.0;
  const CraigBamptonResult cb = CraigBamptonReduce(model, part.reduction.internal_modes, report, 200, factor_budget);
  if (!cb.ok) {
    result.too_big = cb.factorization.too_big;
    result.message = cb.message;
    if (result.too_big) {
      char why[160];
      std::snprintf(why, sizeof why, " (%s; %.3g GB kept for the dense blocks of the reduction)",
                    part.reduction.memory_limit_gb > 0 ? "reduction.memory_limit_gb" : "MemAvailable", dense_bytes / 1e9);
      result.message += std::string(why) +
                        ": coarsen the mesh (mesh.size), use first-order elements (mesh.order: 1), or run on a "
                        "machine with more memory";
    }
    return result;
  }

  clock.Restart();
  Superelement& se = result.superelement;
  se.name = part.name;
  se.units = part.units;
  for (size_t k = 0; k < model.interface_names.size(); ++k) {
    se.interfaces.push_back({model.interface_names[k], model.interface_positions[k],
                             Eigen::Matrix3d::Identity()});
  }
  se.K = cb.K;
  se.M = cb.M;
  se.internal_frequencies_hz.resize(cb.lambda.size());
  for (int k = 0; k < cb.lambda.size(); ++k) se.internal_frequencies_hz[k] = FrequencyHz(cb.lambda[k]);
  se.n_full_dofs = model.n_dofs();
  se.mass_properties = ComputeMassProperties(se);
  se.floating_frame = ComputeFloatingFrame(part.reduction.floating_frame,
                                           part.reduction.where_floating_frame, se, model, cb.shapes);
  const bool keep_mesh = part.reduction.keep_mesh.value_or(model.n_dofs() <= ReductionSpec::kKeepMeshMaxDofs);
  if (keep_mesh) {
    Visualization v;
    v.nodes = model.nodes;
    v.cells = model.cells;
    v.cell_type = model.cell_type;
    v.dofs_per_node = model.dofs_per_node;
    v.shapes = model.mesh_map.size() ? Eigen::MatrixXd(model.mesh_map * cb.shapes) : cb.shapes;
    se.visualization = std::move(v);
  }
  prov.femb_version = FEMB_VERSION;
  prov.input_file = part.file;
  prov.input_hash = part.text_hash;
  prov.element_type = model.element_type;
  prov.n_nodes = model.n_nodes();
  prov.n_elements = model.n_elements();
  report("frame+mass", clock.Seconds(), "floating frame " + se.floating_frame.type +
                                             (keep_mesh ? ", mesh and mode shapes kept" : ", mesh and mode shapes not kept (reduction.keep_mesh)"));

  if (part.reduction.full_modes > 0) {
    clock.Restart();
    double s = 0.0;
    if (cb.lambda.size() > 0) {
      s = 1e-2 * cb.lambda[0];
    } else {
      double max_ratio = 0.0;
      for (int j = 0; j < model.K.outerSize(); ++j) {
        const double m = model.M.coeff(j, j);
        if (m > 0) max_ratio = std::max(max_ratio, model.K.coeff(j, j) / m);
      }
      s = 1e-8 * max_ratio;
    }
    const FullModesResult full = FullFreeFreeFrequencies(model, part.reduction.full_modes, s);
    if (!full.ok) {
      result.message = "full-model free-free eigen solve failed: " + full.message;
      return result;
    }
    se.full_free_free_frequencies_hz = full.frequencies_hz;
    std::snprintf(detail, sizeof detail, "%d free-free frequencies of the full model, %ld linear solves",
                  int(full.frequencies_hz.size()), full.linear_solves);
    report("full modes", clock.Seconds(), detail);
  }
  result.ok = true;
  return result;
}

}  // namespace femb
