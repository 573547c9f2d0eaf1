#pragma once

#include <stdexcept>
#include <string>

namespace msfem::fem_reference {

/// A failure of the FEM reference that is not a bad argument: meshing failed, the system is
/// singular (no support), the linear solver did not converge. The message is one line naming the
/// item at fault (and, for the solver, the iterations and the residual) so the `msfem` command can
/// print it as it is. Bad arguments (non-closed surface, E <= 0, nu out of range, a region that
/// catches no node) throw std::invalid_argument instead.
class FemError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The PETSc Krylov solver stopped without reaching its tolerance.
class SolverError : public FemError {
 public:
  using FemError::FemError;
};

}  // namespace msfem::fem_reference
