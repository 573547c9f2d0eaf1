#include "petsc_linear_system.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "msfem/fem_reference/errors.hpp"

namespace msfem::fem_reference::detail {

namespace {

// std::to_string prints 1e-10 as 0.000000.
std::string scientific(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// PETSc's own handler prints a traceback of dozens of lines (once per rank under mpirun); msfem
// reports a failure in one line, so the handler keeps the first message for check() to name.
thread_local std::string petsc_message;

PetscErrorCode keep_message(MPI_Comm, int, const char* function, const char*, PetscErrorCode code,
                            PetscErrorType type, const char* message, void*) {
  if (type == PETSC_ERROR_INITIAL)
    petsc_message = std::string(message ? message : "") + " in " + (function ? function : "?");
  return code;
}

void check(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  std::string what = std::string("PETSc call failed: ") + call + " (error " + std::to_string(code) +
                     (petsc_message.empty() ? "" : ": " + petsc_message) + ")";
  petsc_message.clear();
  throw FemError(what);
}
#define MSFEM_PETSC(call) check((call), #call)

/// Point-block Jacobi (the nodes' 3x3 blocks) instead of point Jacobi in the finest level's
/// Chebyshev smoother of GAMG. Only there: a coarse level's aggregate of one node (presumably a
/// prescribed node, isolated in the graph) has six coarse unknowns of which three have zero rows
/// (three rigid-body modes on one node span only three directions), so its 6x6 blocks are singular
/// and point-block Jacobi (or SOR) fails there, while point Jacobi replaces zero diagonals. The
/// finest level's index is known only once GAMG has built the hierarchy, hence after KSPSetUp, with
/// the smoother's eigenvalue bounds estimated again for the new preconditioner (GAMG's own estimate
/// is for point Jacobi). Skipped where the user's options chose a smoother (-mg_levels[_N]_pc_type,
/// -mg_levels[_N]_ksp_type; `-mg_levels_pc_type jacobi` gives PETSc's default) or where the set-up
/// failed (KSPSolve then reports the failure).
void finest_smoother_point_block_jacobi(KSP ksp, PC pc) {
  PetscBool user_choice = PETSC_FALSE, flag = PETSC_FALSE;
  for (const char* name : {"-mg_levels_pc_type", "-mg_levels_ksp_type"}) {
    PetscOptionsHasName(nullptr, nullptr, name, &flag);
    user_choice = PetscBool(user_choice || flag);
  }
  PetscBool gamg = PETSC_FALSE;  // not where the options chose another -pc_type
  MSFEM_PETSC(PetscObjectTypeCompare(PetscObject(pc), PCGAMG, &gamg));
  if (user_choice || !gamg) return;
  if (KSPSetUp(ksp) != 0) return;
  PetscInt levels = 0;
  MSFEM_PETSC(PCMGGetLevels(pc, &levels));
  if (levels < 2) return;
  for (const char* option : {"pc_type", "ksp_type"}) {
    const std::string name = "-mg_levels_" + std::to_string(levels - 1) + "_" + std::string(option);
    PetscOptionsHasName(nullptr, nullptr, name.c_str(), &flag);
    if (flag) return;
  }
  KSP smoother = nullptr;
  MSFEM_PETSC(PCMGGetSmoother(pc, levels - 1, &smoother));
  PC smoother_pc = nullptr;
  MSFEM_PETSC(KSPGetPC(smoother, &smoother_pc));
  PetscBool chebyshev = PETSC_FALSE, jacobi = PETSC_FALSE;
  MSFEM_PETSC(PetscObjectTypeCompare(PetscObject(smoother), KSPCHEBYSHEV, &chebyshev));
  MSFEM_PETSC(PetscObjectTypeCompare(PetscObject(smoother_pc), PCJACOBI, &jacobi));
  if (!chebyshev || !jacobi) return;
  Mat a = nullptr, p = nullptr;
  MSFEM_PETSC(KSPGetOperators(smoother, &a, &p));
  MSFEM_PETSC(PCSetType(smoother_pc, PCPBJACOBI));
  MSFEM_PETSC(KSPSetOperators(smoother, a, p));  // set-up again: new PC, new eigenvalue estimate
  MSFEM_PETSC(KSPChebyshevEstEigSet(smoother, 0.0, 0.1, 0.0, 1.1));  // PETSc's default targets
  KSPSetUp(smoother);  // a failure here shows in KSPSolve's converged reason (GAMG's fallback)
}

/// The three translations and three rotations, built by PETSc from the owned rows' node coordinates
/// (x, y, z per node, block size 3), as `matrix`'s near-null space: what makes smoothed
/// aggregation work for elasticity. The caller destroys `coordinates` and `modes`.
void set_rigid_body_modes(MPI_Comm communicator, Mat matrix,
                          const std::vector<double>& owned_node_coordinates, Vec& coordinates,
                          MatNullSpace& modes) {
  const auto rows = PetscInt(owned_node_coordinates.size());
  MSFEM_PETSC(VecCreateMPI(communicator, rows, PETSC_DETERMINE, &coordinates));
  MSFEM_PETSC(VecSetBlockSize(coordinates, 3));
  double* c = nullptr;
  MSFEM_PETSC(VecGetArray(coordinates, &c));
  std::copy(owned_node_coordinates.begin(), owned_node_coordinates.end(), c);
  MSFEM_PETSC(VecRestoreArray(coordinates, &c));
  MSFEM_PETSC(MatNullSpaceCreateRigidBody(coordinates, &modes));
  MSFEM_PETSC(MatSetNearNullSpace(matrix, modes));
}

}  // namespace

// Outside the anonymous namespace: PetscLinearSystem::KrylovState holds one.
/// What two_level_preconditioner creates, destroyed after the solve.
struct TwoLevel {
  Mat interpolation = nullptr, coarse = nullptr;
  Vec coordinates = nullptr;
  MatNullSpace rigid_body_modes = nullptr;
  ~TwoLevel() {
    MatNullSpaceDestroy(&rigid_body_modes);
    VecDestroy(&coordinates);
    MatDestroy(&coarse);
    MatDestroy(&interpolation);
  }
};

namespace {

/// p-multigrid for P2: GAMG on the P2 matrix needs 240 CG iterations on the 1.2 M-DoF brain (its
/// smoothed aggregates of P2 nodes see the badly shaped cells), GAMG on P1 about half as many. Two
/// levels: Chebyshev(2) with point-block Jacobi on the P2 matrix, and as coarse solve one GAMG
/// V-cycle on P^T K P, the P1 operator of the same mesh (P interpolates P1 to P2: vertices copied,
/// edge midpoints averaged), with the rigid-body modes of the P1 nodes. The Galerkin product is
/// formed here, after the prescribed DoFs were eliminated, so GAMG gets its near-null space.
void two_level_preconditioner(MPI_Comm communicator, Mat fine, const CoarseSpace& space, PC pc,
                              TwoLevel& t) {
  PetscInt first_fine = 0, end_fine = 0, first_coarse = 0;
  MSFEM_PETSC(MatGetOwnershipRange(fine, &first_fine, &end_fine));
  MPI_Exscan(&space.owned_coarse_rows, &first_coarse, 1, MPIU_INT, MPI_SUM, communicator);
  int rank = 0;
  MPI_Comm_rank(communicator, &rank);
  if (rank == 0) first_coarse = 0;
  const PetscInt end_coarse = first_coarse + space.owned_coarse_rows, rows = end_fine - first_fine;
  std::vector<PetscInt> diagonal(std::size_t(rows), 0), off_diagonal(std::size_t(rows), 0);
  for (PetscInt r = 0; r < rows; ++r)
    for (PetscInt k = space.row_begin[std::size_t(r)]; k < space.row_begin[std::size_t(r) + 1];
         ++k) {
      const PetscInt column = space.columns[std::size_t(k)];
      ++(column >= first_coarse && column < end_coarse ? diagonal : off_diagonal)[std::size_t(r)];
    }
  MSFEM_PETSC(MatCreate(communicator, &t.interpolation));
  MSFEM_PETSC(MatSetSizes(t.interpolation, rows, space.owned_coarse_rows, PETSC_DETERMINE,
                          PETSC_DETERMINE));
  MSFEM_PETSC(MatSetType(t.interpolation, MATAIJ));
  MSFEM_PETSC(MatSetBlockSizes(t.interpolation, 3, 3));
  MSFEM_PETSC(MatSeqAIJSetPreallocation(t.interpolation, 0, diagonal.data()));
  MSFEM_PETSC(
      MatMPIAIJSetPreallocation(t.interpolation, 0, diagonal.data(), 0, off_diagonal.data()));
  for (PetscInt r = 0; r < rows; ++r) {
    const PetscInt row = first_fine + r, begin = space.row_begin[std::size_t(r)];
    const PetscInt count = space.row_begin[std::size_t(r) + 1] - begin;
    if (count == 0) continue;
    MSFEM_PETSC(MatSetValues(t.interpolation, 1, &row, count, &space.columns[std::size_t(begin)],
                             &space.weights[std::size_t(begin)], INSERT_VALUES));
  }
  MSFEM_PETSC(MatAssemblyBegin(t.interpolation, MAT_FINAL_ASSEMBLY));
  MSFEM_PETSC(MatAssemblyEnd(t.interpolation, MAT_FINAL_ASSEMBLY));
  // PETSc 3.18 forms P^T K P for scalar (AIJ) storage only: a block-stored K is copied for it.
  PetscBool blocks = PETSC_FALSE;
  MSFEM_PETSC(PetscObjectTypeCompareAny(PetscObject(fine), &blocks, MATSEQBAIJ, MATMPIBAIJ, ""));
  Mat scalar_fine = fine;
  if (blocks) MSFEM_PETSC(MatConvert(fine, MATAIJ, MAT_INITIAL_MATRIX, &scalar_fine));
  const PetscErrorCode product =
      MatPtAP(scalar_fine, t.interpolation, MAT_INITIAL_MATRIX, 2.0, &t.coarse);
  if (blocks) MatDestroy(&scalar_fine);
  MSFEM_PETSC(product);
  MSFEM_PETSC(MatSetOption(t.coarse, MAT_SYMMETRIC, PETSC_TRUE));

  set_rigid_body_modes(communicator, t.coarse, space.node_coordinates, t.coordinates,
                       t.rigid_body_modes);

  MSFEM_PETSC(PCSetType(pc, PCMG));
  MSFEM_PETSC(PCMGSetLevels(pc, 2, nullptr));
  MSFEM_PETSC(PCMGSetGalerkin(pc, PC_MG_GALERKIN_NONE));
  MSFEM_PETSC(PCMGSetInterpolation(pc, 1, t.interpolation));
  KSP smoother = nullptr, coarse_solve = nullptr;
  PC smoother_pc = nullptr, coarse_pc = nullptr;
  MSFEM_PETSC(PCMGGetSmoother(pc, 1, &smoother));
  MSFEM_PETSC(KSPSetType(smoother, KSPCHEBYSHEV));
  MSFEM_PETSC(KSPSetOperators(smoother, fine, fine));
  MSFEM_PETSC(KSPGetPC(smoother, &smoother_pc));
  MSFEM_PETSC(PCSetType(smoother_pc, PCPBJACOBI));
  MSFEM_PETSC(KSPChebyshevEstEigSet(smoother, 0.0, 0.1, 0.0, 1.1));
  MSFEM_PETSC(KSPSetTolerances(smoother, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, 2));
  MSFEM_PETSC(KSPSetNormType(smoother, KSP_NORM_NONE));
  MSFEM_PETSC(PCMGGetCoarseSolve(pc, &coarse_solve));
  // One V-cycle: three (Richardson) cut the outer iterations by a third on the 248 k-DoF brain but
  // cost more than they saved at 1.2 M DoFs on two ranks (77 against 63 s).
  MSFEM_PETSC(KSPSetType(coarse_solve, KSPPREONLY));
  MSFEM_PETSC(KSPSetOperators(coarse_solve, t.coarse, t.coarse));
  MSFEM_PETSC(KSPGetPC(coarse_solve, &coarse_pc));
  MSFEM_PETSC(PCSetType(coarse_pc, PCGAMG));
}

bool mpi_initialized_here = false;

/// Called by MPI_Finalize (it frees MPI_COMM_SELF's attributes first, while MPI still works), so
/// PETSc is finalised before MPI whoever finalises MPI.
int finalize_petsc(MPI_Comm, int, void*, void*) {
  PetscBool finalized = PETSC_FALSE;
  PetscFinalized(&finalized);
  if (!finalized) PetscFinalize();
  return MPI_SUCCESS;
}

void finalize_mpi_if_ours() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (mpi_initialized_here && !finalized) MPI_Finalize();
}

const char* reason_text(KSPConvergedReason reason) {
  switch (reason) {
    case KSP_DIVERGED_ITS:
      return "iteration limit reached";
    case KSP_DIVERGED_DTOL:
      return "residual grew (divergence)";
    case KSP_DIVERGED_BREAKDOWN:
      return "breakdown";
    case KSP_DIVERGED_INDEFINITE_PC:
      return "indefinite preconditioner";
    case KSP_DIVERGED_INDEFINITE_MAT:
      return "indefinite matrix";
    case KSP_DIVERGED_NANORINF:
      return "NaN or Inf residual";
    case KSP_DIVERGED_PC_FAILED:
      return "preconditioner failed";
    default:
      return "not converged";
  }
}

const char* method_name(Preconditioner p) {
  switch (p) {
    case Preconditioner::gamg:
      return "CG+GAMG";
    case Preconditioner::boomer_amg:
      return "CG+BoomerAMG";
    case Preconditioner::mumps:
      return "MUMPS LU";
  }
  return "?";
}

}  // namespace

void ensure_mpi_initialized() {
  int mpi_ready = 0;
  MPI_Initialized(&mpi_ready);
  if (mpi_ready) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  mpi_initialized_here = true;
  static const bool registered = (std::atexit(finalize_mpi_if_ours), true);
  (void)registered;
}

void ensure_petsc_initialized() {
  ensure_mpi_initialized();
  PetscBool petsc_ready = PETSC_FALSE;
  PetscInitialized(&petsc_ready);
  if (petsc_ready) return;
  // PETSc's initialisation is collective on PETSC_COMM_WORLD. Each process starts it when it first
  // needs it (under mpirun one rank may write a cached reference's fields while another runs a
  // variant), so it is started on the process alone; every solve names its own communicator.
  PETSC_COMM_WORLD = MPI_COMM_SELF;
  MSFEM_PETSC(PetscInitializeNoArguments());
  MSFEM_PETSC(PetscPushErrorHandler(keep_message, nullptr));
  int key = MPI_KEYVAL_INVALID;
  MPI_Comm_create_keyval(MPI_COMM_NULL_COPY_FN, finalize_petsc, &key, nullptr);
  MPI_Comm_set_attr(MPI_COMM_SELF, key, nullptr);
}

PetscLinearSystem::PetscLinearSystem(MPI_Comm communicator, PetscInt global_rows,
                                     PetscInt first_owned_row, PetscInt owned_rows,
                                     const std::vector<PetscInt>& diagonal_block_nonzeros,
                                     const std::vector<PetscInt>& off_diagonal_block_nonzeros,
                                     MatrixStorage storage)
    : communicator_(communicator), first_owned_row_(first_owned_row), owned_rows_(owned_rows) {
  MSFEM_PETSC(MatCreate(communicator_, &matrix_));
  MSFEM_PETSC(MatSetSizes(matrix_, owned_rows, owned_rows, global_rows, global_rows));
  MSFEM_PETSC(MatSetType(matrix_, storage == MatrixStorage::node_blocks ? MATBAIJ : MATAIJ));
  // Block size 3 before preallocation: GAMG aggregates nodes, not single DoFs.
  MSFEM_PETSC(MatSetBlockSize(matrix_, 3));
  if (storage == MatrixStorage::node_blocks) {
    // Counts per block row, in blocks: a node's first row divided by its three components.
    std::vector<PetscInt> diagonal(std::size_t(owned_rows / 3)), off_diagonal(diagonal.size());
    for (std::size_t node = 0; node < diagonal.size(); ++node) {
      diagonal[node] = diagonal_block_nonzeros[3 * node] / 3;
      off_diagonal[node] = off_diagonal_block_nonzeros[3 * node] / 3;
    }
    MSFEM_PETSC(MatXAIJSetPreallocation(matrix_, 3, diagonal.data(), off_diagonal.data(), nullptr,
                                        nullptr));
  } else {
    MSFEM_PETSC(MatSeqAIJSetPreallocation(matrix_, 0, diagonal_block_nonzeros.data()));
    MSFEM_PETSC(MatMPIAIJSetPreallocation(matrix_, 0, diagonal_block_nonzeros.data(), 0,
                                          off_diagonal_block_nonzeros.data()));
  }
  MSFEM_PETSC(MatSetOption(matrix_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  MSFEM_PETSC(MatCreateVecs(matrix_, &solution_, &rhs_));
  MSFEM_PETSC(VecSet(solution_, 0.0));
  MSFEM_PETSC(VecSet(rhs_, 0.0));
}

PetscLinearSystem::~PetscLinearSystem() {
  kept_.reset();
  VecDestroy(&base_rhs_);
  MatDestroy(&base_matrix_);
  VecDestroy(&solution_);
  VecDestroy(&rhs_);
  MatDestroy(&matrix_);
}

void PetscLinearSystem::add_cell(const std::vector<PetscInt>& dofs,
                                 const std::vector<double>& matrix,
                                 const std::vector<double>& rhs) {
  // Rows and columns in increasing order: PETSc's AIJ insertion then walks each row once instead
  // of searching it for every entry (about twice as fast for P1 cells).
  const std::size_t n = dofs.size();
  order_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    order_[i] = i;
  std::sort(order_.begin(), order_.end(),
            [&dofs](std::size_t a, std::size_t b) { return dofs[a] < dofs[b]; });
  sorted_dofs_.resize(n);
  sorted_matrix_.resize(n * n);
  sorted_rhs_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    sorted_dofs_[i] = dofs[order_[i]];
    sorted_rhs_[i] = rhs[order_[i]];
    for (std::size_t j = 0; j < n; ++j)
      sorted_matrix_[i * n + j] = matrix[order_[i] * n + order_[j]];
  }
  const PetscInt size = PetscInt(n);
  MSFEM_PETSC(MatSetValues(matrix_, size, sorted_dofs_.data(), size, sorted_dofs_.data(),
                           sorted_matrix_.data(), ADD_VALUES));
  MSFEM_PETSC(VecSetValues(rhs_, size, sorted_dofs_.data(), sorted_rhs_.data(), ADD_VALUES));
}

void PetscLinearSystem::finish_assembly() {
  MSFEM_PETSC(MatAssemblyBegin(matrix_, MAT_FINAL_ASSEMBLY));
  MSFEM_PETSC(MatAssemblyEnd(matrix_, MAT_FINAL_ASSEMBLY));
  MSFEM_PETSC(VecAssemblyBegin(rhs_));
  MSFEM_PETSC(VecAssemblyEnd(rhs_));
  MSFEM_PETSC(MatSetOption(matrix_, MAT_SYMMETRIC, PETSC_TRUE));
}

void PetscLinearSystem::apply_prescribed_values(const std::vector<PetscInt>& rows,
                                                const std::vector<double>& values) {
  Vec diagonal = nullptr;
  MSFEM_PETSC(MatCreateVecs(matrix_, &diagonal, nullptr));
  MSFEM_PETSC(MatGetDiagonal(matrix_, diagonal));
  PetscReal diagonal_sum = 0.0;
  MSFEM_PETSC(VecNorm(diagonal, NORM_1, &diagonal_sum));
  VecDestroy(&diagonal);
  PetscInt global_rows = 0;
  MSFEM_PETSC(MatGetSize(matrix_, &global_rows, nullptr));
  const double mean_diagonal = diagonal_sum / double(global_rows);

  MSFEM_PETSC(
      VecSetValues(solution_, PetscInt(rows.size()), rows.data(), values.data(), INSERT_VALUES));
  MSFEM_PETSC(VecAssemblyBegin(solution_));
  MSFEM_PETSC(VecAssemblyEnd(solution_));
  // b -= A(:, rows) x(rows); rows and columns zeroed; b(rows) = diag * x(rows).
  MSFEM_PETSC(MatZeroRowsColumns(matrix_, PetscInt(rows.size()), rows.data(), mean_diagonal,
                                 solution_, rhs_));
}

void PetscLinearSystem::set_start(const std::vector<double>& start) {
  PetscInt first = 0, end = 0;
  MSFEM_PETSC(VecGetOwnershipRange(solution_, &first, &end));
  std::vector<PetscInt> rows;
  for (PetscInt i = first; i < end; ++i)
    rows.push_back(i);
  MSFEM_PETSC(VecSetValues(solution_, PetscInt(rows.size()), rows.data(), start.data() + first,
                           INSERT_VALUES));
  MSFEM_PETSC(VecAssemblyBegin(solution_));
  MSFEM_PETSC(VecAssemblyEnd(solution_));
}

void PetscLinearSystem::keep_base_system() {
  MatDestroy(&base_matrix_);
  VecDestroy(&base_rhs_);
  MSFEM_PETSC(MatDuplicate(matrix_, MAT_COPY_VALUES, &base_matrix_));
  MSFEM_PETSC(VecDuplicate(rhs_, &base_rhs_));
  MSFEM_PETSC(VecCopy(rhs_, base_rhs_));
}

std::vector<double> PetscLinearSystem::owned_diagonal() const {
  Vec diagonal = nullptr;
  MSFEM_PETSC(MatCreateVecs(base_matrix_ ? base_matrix_ : matrix_, &diagonal, nullptr));
  MSFEM_PETSC(MatGetDiagonal(base_matrix_ ? base_matrix_ : matrix_, diagonal));
  const double* values = nullptr;
  MSFEM_PETSC(VecGetArrayRead(diagonal, &values));
  std::vector<double> result(values, values + owned_rows_);
  MSFEM_PETSC(VecRestoreArrayRead(diagonal, &values));
  VecDestroy(&diagonal);
  return result;
}

void PetscLinearSystem::set_node_terms(const std::vector<PetscInt>& node_rows,
                                       const std::vector<std::array<double, 9>>& blocks,
                                       const std::vector<std::array<double, 3>>& rhs) {
  if (!base_matrix_) throw FemError("set_node_terms before keep_base_system");
  MSFEM_PETSC(MatCopy(base_matrix_, matrix_, SAME_NONZERO_PATTERN));
  MSFEM_PETSC(VecCopy(base_rhs_, rhs_));
  for (std::size_t k = 0; k < node_rows.size(); ++k) {
    const std::array<PetscInt, 3> rows{{node_rows[k], node_rows[k] + 1, node_rows[k] + 2}};
    MSFEM_PETSC(
        MatSetValues(matrix_, 3, rows.data(), 3, rows.data(), blocks[k].data(), ADD_VALUES));
    MSFEM_PETSC(VecSetValues(rhs_, 3, rows.data(), rhs[k].data(), ADD_VALUES));
  }
  finish_assembly();
}

/// A configured KSP with what its preconditioner refers to; kept between the solves of a sequence
/// (keep_base_system) so that the preconditioner is set up once.
struct PetscLinearSystem::KrylovState {
  KSP ksp = nullptr;
  MatNullSpace rigid_body_modes = nullptr;
  Vec coordinates = nullptr;
  TwoLevel two_level;
  ~KrylovState() {
    KSPDestroy(&ksp);
    MatNullSpaceDestroy(&rigid_body_modes);
    VecDestroy(&coordinates);
  }
};

std::unique_ptr<PetscLinearSystem::KrylovState> PetscLinearSystem::configure(
    const SolverSettings& settings, const std::vector<double>& owned_node_coordinates) {
  auto state = std::make_unique<KrylovState>();
  KSP& ksp = state->ksp;
  MSFEM_PETSC(KSPCreate(communicator_, &ksp));
  MSFEM_PETSC(KSPSetOperators(ksp, matrix_, matrix_));
  PC pc = nullptr;
  MSFEM_PETSC(KSPGetPC(ksp, &pc));
  if (settings.preconditioner == Preconditioner::mumps) {
    MSFEM_PETSC(KSPSetType(ksp, KSPPREONLY));
    MSFEM_PETSC(PCSetType(pc, PCLU));
    MSFEM_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  } else {
    MSFEM_PETSC(KSPSetType(ksp, KSPCG));
    MSFEM_PETSC(
        KSPSetTolerances(ksp, settings.relative_tolerance, 1e-300, 1e10, settings.max_iterations));
    set_rigid_body_modes(communicator_, matrix_, owned_node_coordinates, state->coordinates,
                         state->rigid_body_modes);
    if (settings.preconditioner == Preconditioner::gamg) {
      if (coarse_space_.row_begin.empty())
        MSFEM_PETSC(PCSetType(pc, PCGAMG));
      else
        two_level_preconditioner(communicator_, matrix_, coarse_space_, pc, state->two_level);
    } else {
      MSFEM_PETSC(PCSetType(pc, PCHYPRE));
      MSFEM_PETSC(PCHYPRESetType(pc, "boomeramg"));
      // 3D elasticity: a stronger threshold than hypre's 2D default 0.25.
      MSFEM_PETSC(PetscOptionsSetValue(nullptr, "-pc_hypre_boomeramg_strong_threshold", "0.7"));
    }
    MSFEM_PETSC(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE));
  }
  MSFEM_PETSC(KSPSetFromOptions(ksp));
  if (settings.preconditioner == Preconditioner::gamg) finest_smoother_point_block_jacobi(ksp, pc);
  return state;
}

KrylovReport PetscLinearSystem::solve(const SolverSettings& settings,
                                      const std::vector<double>& owned_node_coordinates) {
  std::unique_ptr<KrylovState> state;
  if (kept_) {
    // The matrix changed by a few nodal blocks since the preconditioner was built: it still
    // preconditions well, and its set-up costs more than the extra iterations.
    MSFEM_PETSC(KSPSetOperators(kept_->ksp, matrix_, matrix_));
    MSFEM_PETSC(KSPSetReusePreconditioner(kept_->ksp, PETSC_TRUE));
    if (settings.preconditioner != Preconditioner::mumps)
      MSFEM_PETSC(KSPSetTolerances(kept_->ksp, settings.relative_tolerance, 1e-300, 1e10,
                                   settings.max_iterations));
  } else {
    state = configure(settings, owned_node_coordinates);
  }
  KrylovState& s = kept_ ? *kept_ : *state;
  const PetscErrorCode solve_code = KSPSolve(s.ksp, rhs_, solution_);
  KSPConvergedReason reason;
  KSPGetConvergedReason(s.ksp, &reason);
  PetscInt iterations = 0;
  KSPGetIterationNumber(s.ksp, &iterations);
  PetscReal residual = 0.0;
  KSPGetResidualNorm(s.ksp, &residual);
  const std::string method = std::string(method_name(settings.preconditioner)) +
                             (s.two_level.interpolation ? " (P2 over a P1 level)" : "");
  if (base_matrix_ && !kept_) kept_ = std::move(state);
  if (solve_code != 0)  // PETSc has printed its own trace; name the failing stage here
    throw SolverError(method + " failed: PETSc error " + std::to_string(int(solve_code)) +
                      " in KSPSolve after " + std::to_string(iterations) + " iterations" +
                      (iterations == 0 ? " (in the preconditioner's set-up or an option)" : ""));
  if (reason < 0)
    throw SolverError(method + " did not converge: " + reason_text(reason) + " after " +
                      std::to_string(iterations) + " iterations, residual norm " +
                      scientific(double(residual)) + " (relative tolerance " +
                      scientific(settings.relative_tolerance) + ")");
  return {int(iterations), double(residual)};
}

std::vector<double> PetscLinearSystem::gathered_solution() const {
  VecScatter scatter = nullptr;
  Vec all = nullptr;
  MSFEM_PETSC(VecScatterCreateToAll(solution_, &scatter, &all));
  MSFEM_PETSC(VecScatterBegin(scatter, solution_, all, INSERT_VALUES, SCATTER_FORWARD));
  MSFEM_PETSC(VecScatterEnd(scatter, solution_, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscInt size = 0;
  MSFEM_PETSC(VecGetSize(all, &size));
  const double* values = nullptr;
  MSFEM_PETSC(VecGetArrayRead(all, &values));
  std::vector<double> result(values, values + size);
  MSFEM_PETSC(VecRestoreArrayRead(all, &values));
  VecScatterDestroy(&scatter);
  VecDestroy(&all);
  return result;
}

}  // namespace msfem::fem_reference::detail
