#pragma once
// CHOLMOD's supernodal Cholesky plugged into the spring networks' static solver
// (massspring::StaticOptions::factorization): massspring stays Eigen-only for simulators, and the
// harness, which links SuiteSparse anyway, gets the faster factorisation.

#include <functional>
#include <memory>

#include "msfem/massspring/static_solver.hpp"

namespace msfem::compare {

/// A factory for StaticOptions::factorization.
std::function<std::unique_ptr<massspring::SparseSpdFactor>()> cholmod_factorization();

}  // namespace msfem::compare
