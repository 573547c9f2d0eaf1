#pragma once

// What the verification checks share (verification.cpp, contact_verification.cpp). Not installed.

#include <vector>

#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/verification.hpp"

namespace msfem::fem_reference::detail {

/// The mesh's effective cell size (volume / cells)^(1/3), the solve's statistics and `error`.
RefinementLevel level_of(const ElasticityProblem& problem, const VolumeMesh& mesh, double error);

/// log(e_coarse / e_fine) / log(h_coarse / h_fine) over the two finest levels.
double observed_order(const std::vector<RefinementLevel>& levels);

}  // namespace msfem::fem_reference::detail
