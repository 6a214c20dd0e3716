// femb-inspect's views of a superelement: a readable summary and one JSON object.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "formats/superelement.h"
#include "inspect/superelement_checks.h"

namespace femb {

std::string TextSummary(const Superelement& se, const SuperelementAnalysis& a, const std::string& path);

/// Keys: format_version, name, units, n_interface_nodes, interface_names, n_internal_modes,
/// n_modal_derivatives, n_reduced_dofs, n_full_dofs, mass, center_of_mass, inertia_com,
/// floating_frame, internal_frequencies_hz, free_free_frequencies_hz,
/// full_free_free_frequencies_hz (when stored), checks, and more.
nlohmann::json JsonSummary(const Superelement& se, const SuperelementAnalysis& a);

}  // namespace femb
