#pragma once

#include <optional>
#include <string>
#include <vector>

namespace msfem::fem_reference {

/// One mesh of a refinement sequence.
struct RefinementLevel {
  double cell_size = 0.0;  ///< effective h = (volume / cells)^(1/3), m
  std::size_t dofs = 0;
  std::size_t cells = 0;
  double rel_l2_error = 0.0;
  int iterations = 0;
  double solve_time_s = 0.0;
};

/// A verification check against a closed form (the rows of `msfem verify`).
struct VerificationCheck {
  std::string name;
  double rel_l2_error = 0.0;  ///< on the finest mesh (cantilever: relative tip-deflection error)
  std::optional<double> observed_order;  ///< from the two finest meshes of a sequence
  double tolerance = 0.0;                ///< on rel_l2_error
  std::optional<double> required_order;
  bool passed = false;
  std::string note;
  std::vector<RefinementLevel> levels;
};

/// Volumetric locking: relative L2 errors of the Lame sphere on one mesh as nu -> 0.5.
struct LockingRow {
  double poisson_ratio = 0.0;
  double p1_rel_l2_error = 0.0;
  double p2_rel_l2_error = 0.0;
};

struct VerificationReport {
  std::vector<VerificationCheck> checks;
  std::vector<LockingRow> locking;
  bool all_passed() const {
    for (const auto& c : checks)
      if (!c.passed) return false;
    return true;
  }
};

struct VerificationSettings {
  /// Target cell sizes of the Lame octant (a = 0.5 m, b = 1 m), coarse to fine.
  std::vector<double> lame_cell_sizes{0.2, 0.1, 0.05};
  /// Cantilever 1 m x 0.1 m x 0.1 m.
  double cantilever_cell_size = 0.05;
  bool locking_table = true;
};

/// Linear displacement u = c + B x imposed on the whole boundary of a ball, no body force: the
/// interior nodes must reproduce it to 1e-10 (relative to max |u|). For P1 and P2.
VerificationCheck check_patch();

/// Lame hollow sphere (see closed_forms.hpp), P1 or P2, on a refinement sequence. The octant
/// x, y, z >= 0 with symmetry conditions (u . n = 0) on the planes; the inner surface gets the
/// exact displacement at its nodes (0 at the vertices, which lie on r = a) and the outer surface
/// the exact traction sigma(x) n_h on its flat facets, so that the error measured is the finite
/// element error, not the faceting of the sphere (which would cap P2 at order 2).
VerificationCheck check_lame(unsigned int degree, double poisson_ratio,
                             const std::vector<double>& cell_sizes);

/// Cantilever 1 x 0.1 x 0.1 m, clamped at x = 0, uniform shear traction on x = L; the deflection
/// of the end section's centre against Timoshenko (P2, nu = 0.3), within 2 %.
VerificationCheck check_cantilever(double cell_size);

/// Lame sphere errors for P1 and P2 on one mesh for each Poisson's ratio.
std::vector<LockingRow> locking_table(double cell_size, const std::vector<double>& poisson_ratios);

/// All checks: patch, lame_{p1,p2}_nu{0.3,0.45}, cantilever_p2, and the locking table.
VerificationReport run_verification(const VerificationSettings& settings = {});

}  // namespace msfem::fem_reference
