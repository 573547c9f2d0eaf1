#pragma once

#include <mpi.h>
#include <petscksp.h>

#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "msfem/fem_reference/elasticity_problem.hpp"

namespace msfem::fem_reference::detail {

/// Initialises MPI unless the program already did; what this function initialised is finalised at
/// exit.
void ensure_mpi_initialized();

/// Initialises MPI and PETSc unless the program already did (deal.II's MPI_InitFinalize, a test's
/// main); what this function initialised is finalised at exit. Not collective: PETSc is started on
/// this process alone.
void ensure_petsc_initialized();

struct KrylovReport {
  int iterations = 0;
  double residual_norm = 0.0;
};

/// The distributed stiffness system K u = f in raw PETSc, for what deal.II 9.4 does not wrap:
/// block size 3 (DoFs interleaved x, y, z per node) and the rigid-body near-null space for GAMG,
/// symmetric elimination of prescribed DoFs (MatZeroRowsColumns) and the KSP set-up. Each rank owns
/// the contiguous rows [first_owned_row, first_owned_row + owned_rows).
/// A coarser space on the same mesh (P1 below P2) for a two-level preconditioner: the
/// interpolation's owned rows in CSR form (fine DoF -> coarse DoFs and weights, DoFs interleaved
/// x, y, z per node in both spaces), the number of coarse DoFs this rank owns (whole nodes, in
/// rank order), and x, y, z of each owned coarse node (for GAMG's rigid-body modes on it).
struct CoarseSpace {
  PetscInt owned_coarse_rows = 0;
  std::vector<PetscInt> row_begin, columns;
  std::vector<double> weights;
  std::vector<double> node_coordinates;
};

/// How the stiffness matrix is stored. node_blocks (PETSc's BAIJ, 3x3 blocks of a node pair)
/// stores one column index per block instead of per entry: the two-level P2 solve, bound by
/// memory bandwidth, ran 1.4-1.6x faster (results/BENCHMARKS.md). GAMG and hypre need scalar
/// (AIJ) storage, so the other methods keep it.
enum class MatrixStorage { scalar, node_blocks };

class PetscLinearSystem {
 public:
  /// The nonzero counts are per row (a node's three rows have the same counts).
  PetscLinearSystem(MPI_Comm communicator, PetscInt global_rows, PetscInt first_owned_row,
                    PetscInt owned_rows, const std::vector<PetscInt>& diagonal_block_nonzeros,
                    const std::vector<PetscInt>& off_diagonal_block_nonzeros,
                    MatrixStorage storage = MatrixStorage::scalar);
  ~PetscLinearSystem();
  PetscLinearSystem(const PetscLinearSystem&) = delete;
  PetscLinearSystem& operator=(const PetscLinearSystem&) = delete;

  /// Adds a dense cell matrix (row-major) and cell vector at the given global DoFs.
  void add_cell(const std::vector<PetscInt>& dofs, const std::vector<double>& matrix,
                const std::vector<double>& rhs);
  void finish_assembly();

  /// Eliminates the prescribed DoFs symmetrically: u_i = value_i, the columns moved to the
  /// right-hand side, the diagonal set to the matrix's mean diagonal so the preconditioner sees a
  /// well-scaled row. `rows` are this rank's owned prescribed rows.
  void apply_prescribed_values(const std::vector<PetscInt>& rows,
                               const std::vector<double>& values);

  /// Keeps the present (eliminated) matrix and right-hand side as the base that set_node_terms adds
  /// to: a sequence of solves that differ by per-node terms (contact penalties).
  void keep_base_system();

  /// The base matrix's diagonal on the owned rows.
  std::vector<double> owned_diagonal() const;

  /// matrix = base + a 3x3 block (row-major) on each listed node's diagonal, rhs = base rhs + a
  /// 3-vector there. `node_rows` are the nodes' first (x) rows, owned by this rank; rows and
  /// columns of prescribed components must be zero in the blocks. The solution is kept as the next
  /// start.
  void set_node_terms(const std::vector<PetscInt>& node_rows,
                      const std::vector<std::array<double, 9>>& blocks,
                      const std::vector<std::array<double, 3>>& rhs);

  /// The next solve's first iterate: `start` holds every DoF (this rank's owned ones are used);
  /// prescribed rows must already hold their values.
  void set_start(const std::vector<double>& start);

  /// With a coarse space, CG + GAMG becomes CG + a two-level V-cycle: Chebyshev with point-block
  /// Jacobi on this matrix, one GAMG V-cycle on the Galerkin product P^T K P as the coarse solve.
  void set_coarse_space(CoarseSpace space) { coarse_space_ = std::move(space); }

  /// Solves with the chosen method (after keep_base_system, every solve reuses the first one's
  /// preconditioner); `owned_node_coordinates` holds x, y, z of the node of each
  /// owned DoF triple (for the rigid-body modes). Throws SolverError when not converged.
  KrylovReport solve(const SolverSettings& settings,
                     const std::vector<double>& owned_node_coordinates);

  /// The whole solution on every rank.
  std::vector<double> gathered_solution() const;

 private:
  struct KrylovState;
  std::unique_ptr<KrylovState> configure(const SolverSettings& settings,
                                         const std::vector<double>& owned_node_coordinates);

  MPI_Comm communicator_;
  PetscInt first_owned_row_, owned_rows_;
  Mat matrix_ = nullptr;
  CoarseSpace coarse_space_;
  Vec rhs_ = nullptr, solution_ = nullptr;
  Mat base_matrix_ = nullptr;
  Vec base_rhs_ = nullptr;
  std::unique_ptr<KrylovState> kept_;
  // Scratch of add_cell.
  std::vector<std::size_t> order_;
  std::vector<PetscInt> sorted_dofs_;
  std::vector<double> sorted_matrix_, sorted_rhs_;
};

}  // namespace msfem::fem_reference::detail
