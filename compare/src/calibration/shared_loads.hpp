#pragma once
// msfem calibrate under mpirun: the loads are dealt out round-robin; each rank solves its own (and
// keeps their warm starts), and every rank gets every load's errors, so that the optimiser takes
// the same steps on all of them. On one rank these just run every load.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <vector>

#include "msfem/compare/calibration/calibration.hpp"

namespace msfem::compare {

/// Whether this rank solves load i (i mod ranks).
bool owns_load(std::size_t i);

/// Every load's errors, each computed by `one` on the rank that owns it. A load that fails there
/// fails the evaluation on every rank (the first such load's failure, as a cases::InputError if it
/// was one, else as a std::runtime_error), so that no rank waits in a collective the others have
/// left.
std::vector<CalibrationErrors> shared_errors(
    std::size_t loads, const std::function<CalibrationErrors(std::size_t)>& one);

/// Every load's equilibrium on every rank, from `mine`, where the loads this rank owns are set.
std::vector<Eigen::VectorXd> shared_equilibria(const std::vector<Eigen::VectorXd>& mine);

}  // namespace msfem::compare
