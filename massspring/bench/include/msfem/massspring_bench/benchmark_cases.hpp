#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring_bench/stepping_benchmark.hpp"

namespace msfem::massspring {

/// Geodesic sphere of the given frequency m: every icosahedron face split into m² triangles, the
/// points pushed to the sphere. 10 m² + 2 vertices, 30 m² edges, 20 m² triangles, outward (CCW).
/// m = 2ⁿ is the level-n icosphere's size (m = 8: 642 vertices).
void geodesic_sphere(int frequency, double radius, Eigen::MatrixX3d& vertices,
                     Eigen::MatrixX3i& triangles);

/// One speed case: a three-tier model with brain material (E = 3 kPa, ρ = 1040 kg/m³, spring
/// damping 0.01 N·s/m), built from `description`'s surface. No gravity: at 3 kPa a 7 cm sphere
/// held only by its inner tier sags by a quarter of its radius and, lightly damped, folds onto
/// itself after a few hundred steps, which would end a long timing run.
struct BenchmarkCase {
  std::string name;         ///< seed_sphere, brain_scale, brain_scale_volume, brain_10x
  std::string description;  ///< where the surface came from
  SpringNetwork network;
  /// Volume preservation on the shell prisms between the tiers (κ = λ(E, 0.45) − λ(E, 1/4), the
  /// harness's analytic start), those inverted or flat at rest left out.
  bool volume_preservation = false;
  /// A model built elsewhere (by a case's own pipeline, e.g. tet_edges on the FEM's mesh, which
  /// needs a mesher massspring does not have): stepped as it is, `network` and
  /// `volume_preservation` only describing it.
  std::shared_ptr<const MassSpringModel> model = nullptr;
  /// The steps its explicit integrators are timed at (SteppingBenchmarkOptions::timed_dt); 0: the
  /// bench's own rule.
  ExplicitTimedSteps timed_dt = {};
};

/// The three cases of `msfem bench massspring`:
///  - seed_sphere: icosphere level 3 (m = 8), R = 5 cm: 1,926 nodes, 8,964 springs;
///  - brain_scale: the given brain surface (metres) if any, else a geodesic sphere m = 30
///    (9,002 vertices, close to the 9,177-vertex brain): ≈ 27 k nodes, ≈ 126 k springs;
///  - brain_scale_volume: brain_scale with volume preservation (the accurate model);
///  - brain_10x: geodesic sphere m = 96, R = 8 cm (92,162 vertices): 276,486 nodes, 1,290,244
///    springs, 10 × the brain.
std::vector<BenchmarkCase> benchmark_cases(const std::optional<Eigen::MatrixX3d>& brain_vertices,
                                           const std::optional<Eigen::MatrixX3i>& brain_triangles,
                                           bool include_10x = true);

/// A case's model: its network, with volume preservation on the shell prisms where the case asks
/// for it (those inverted or flat at rest left out; `note`, where given, says how many were kept).
/// A case that carries a model built elsewhere gets a copy of it.
std::unique_ptr<MassSpringModel> benchmark_model(const BenchmarkCase& benchmark_case,
                                                 std::string* note = nullptr);

/// Builds the model of a case and runs the stepping benchmark on it.
SteppingBenchmarkResult run_benchmark_case(const BenchmarkCase& benchmark_case,
                                           const SteppingBenchmarkOptions& options = {});

}  // namespace msfem::massspring
