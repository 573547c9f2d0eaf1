#pragma once
// `msfem sweep`: accuracy against speed over variants × resolutions × integrators.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/compare/pipeline/metrics.hpp"

namespace msfem::compare {

struct SweepSettings {
  /// Icosphere levels (generator cases) or target vertex counts (file cases); empty: levels 2-5,
  /// or 2k, 5k, 9.2k, 20k and 40k vertices capped at the surface's own count.
  std::vector<int> resolutions;
  std::vector<massspring::IntegratorKind> integrators = {
      massspring::IntegratorKind::symplectic_euler, massspring::IntegratorKind::central_difference,
      massspring::IntegratorKind::rk4, massspring::IntegratorKind::implicit_euler};
  /// Volume preservation off and/or on for the variants that have it (three_tier, tet_edges);
  /// empty: as the case sets it.
  std::vector<bool> volume_preservation;
  /// Contact refinement (a local point distribution at the tool) per pass: none for off, else on
  /// with that edge length (m; 0: the case's). Empty: as the case sets it.
  std::vector<std::optional<double>> contact_refinement;
  /// The fast steppers timed in double (false) and/or float (true); empty: as the case sets it
  /// (timing/precision).
  std::vector<bool> single_precision;
  bool quiet = false;
};

struct SweepPoint {
  std::string variant, integrator;
  std::string stepper;               ///< the code timed (Timing::stepper)
  std::string precision;             ///< its arithmetic (Timing::precision)
  bool volume_preservation = false;  ///< the variant's volume elements on
  /// With contact refinement on: the longest surface edge (m) within its radius of the tool.
  std::optional<double> contact_edge_m;
  /// The variant as the report names it: "variant", then "+volume" with volume preservation and
  /// "+refined@E mm" with contact refinement.
  std::string model() const { return model_name(variant, volume_preservation, contact_edge_m); }
  static std::string model_name(const std::string& variant, bool volume_preservation,
                                std::optional<double> contact_edge_m);
  int resolution = 0;  ///< level or vertex target, as given
  int surface_vertices = 0;
  int nodes = 0, springs = 0;
  double rel_l2_error = 0.0, reaction_force_rel_error = 0.0;
  double stable_dt_s = 0.0, steps_per_second = 0.0, realtime_factor = 0.0;
  double dt_s =
      0.0;  ///< the step steps/s was timed at (half the stable one; implicit Euler's 1 ms)
  double ms_per_60hz_frame = 0.0;
  /// The resolution's FEM reference's own error (fem/error estimate; none where not estimated)
  /// and the variant's metrics within 3x of it.
  std::optional<double> fem_estimated_rel_l2_error, fem_estimated_force_rel_error;
  std::vector<Metric> not_resolved_by_reference;
};

struct SweepResult {
  std::vector<SweepPoint> points;
  /// Resolutions that could not be run (e.g. the brain simplified below ~2,500 vertices
  /// self-intersects in its sulci), with the reason; the others are still swept.
  std::vector<std::pair<int, std::string>> failed_resolutions;
  /// Variants whose statics failed at a resolution (a solver, not the input: e.g. a shell with no
  /// stable equilibrium at the tool's depth), as msfem run reports them; the others are swept.
  struct FailedVariant {
    int resolution = 0;
    std::string model, error;  ///< the model as SweepPoint::model() names it
  };
  std::vector<FailedVariant> failed_variants;
  /// A user's networks (mass spring/networks) are of the case's own surface: msfem cannot re-mesh
  /// them, so they are swept at that resolution only (and not in the other passes' settings).
  struct OwnResolution {
    int resolution = 0;  ///< the case's own icosphere level or surface vertex count
    std::vector<std::string> networks;
    std::string note;  ///< what the report and the command say
  };
  std::optional<OwnResolution> networks;
};

/// Runs the sweep (the FEM once per resolution, through the cache when given). Throws when no
/// resolution can be run (the first one's error).
SweepResult run_sweep(const cases::CaseParameters& parameters, const SweepSettings& settings,
                      const std::filesystem::path& fem_cache_directory);

/// Whether the point keeps a loop of `rate_hz` in real time at the step it was timed at: each
/// tick of 1/rate s takes ceil(1 / (rate dt)) steps, which must fit in the tick.
bool keeps_real_time(const SweepPoint& point, double rate_hz);

/// A variant's error at each swept resolution (the error does not depend on the integrator) and
/// its observed order p, e ∝ h^p with h ∝ N^(-1/2) for N surface vertices, from the coarsest to
/// the finest resolution; none with fewer than two resolutions.
struct VariantConvergence {
  std::string variant;
  std::vector<std::pair<int, double>>
      error_at_vertices;  ///< (surface vertices, rel L2), coarse first
  std::optional<double> observed_order;
};
std::vector<VariantConvergence> convergence_by_variant(const std::vector<SweepPoint>& points);

}  // namespace msfem::compare
