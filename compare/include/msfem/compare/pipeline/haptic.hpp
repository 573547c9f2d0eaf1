#pragma once
// msfem haptic: a tool trajectory replayed against each variant as a haptic device would drive it,
// the force rendered at the device's rate on a thread of its own, and the FEM's quasi-static
// answer at points along the path. docs/haptics.md states the scheme and its source.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/compare/pipeline/fem_references.hpp"
#include "msfem/compare/pipeline/problem.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"

namespace msfem::compare {

/// A tool trajectory: the spherical tool's centre (m) against time (s), linear between samples and
/// held before the first and after the last.
class ToolPath {
 public:
  /// Times strictly increasing and finite, at least two samples (std::invalid_argument otherwise).
  ToolPath(std::vector<double> times, std::vector<Eigen::Vector3d> centers,
           bool had_orientation = false);
  Eigen::Vector3d at(double t) const;
  double start() const { return times_.front(); }
  double end() const { return times_.back(); }
  const std::vector<double>& times() const { return times_; }
  const std::vector<Eigen::Vector3d>& centers() const { return centers_; }
  /// The file gave orientation quaternions (read and checked; a sphere has no orientation).
  bool had_orientation() const { return had_orientation_; }

 private:
  std::vector<double> times_;
  std::vector<Eigen::Vector3d> centers_;
  bool had_orientation_ = false;
};

/// A device log as a CSV: `t_s, x_m, y_m, z_m` and optionally `qw, qx, qy, qz` per row, an
/// optional header row naming the columns, `#` comments. Throws cases::InputError naming the file
/// and line for anything else (a wrong column count, a number that is not one, time not
/// increasing, a quaternion that is not a unit one).
ToolPath read_tool_path(const std::filesystem::path& csv);
/// The same format, with its header.
void write_tool_path(const ToolPath& path, const std::filesystem::path& csv);

/// The default replay at the case's first tool: approach along its normal from 5 mm off, press to
/// the case's depth, hold, slide 10 mm along the surface at that depth, hold, release, retreat.
/// Throws cases::InputError naming the case file when the case has no tool.
ToolPath default_tool_path(const Problem& problem);

/// The tool at a path position as the FEM takes it: the surface point nearest its centre, the
/// surface's interpolated normal there, the depth it reaches past that point (≤ 0: not touching).
ToolPlacement placement_at(const Problem& problem, const Eigen::Vector3d& center, double radius);

/// Where the FEM answers along the path: up to `count` times evenly spread over the span the tool
/// touches the rest surface (in [0, seconds]), each with its placement. Throws cases::InputError
/// naming `path_name` when the tool never reaches the surface or touches it too briefly for any.
struct PathSample {
  double t_s = 0.0;
  ToolPlacement tool;
};
std::vector<PathSample> path_samples(const Problem& problem, const ToolPath& path, double seconds,
                                     int count, const std::string& path_name);

/// A value changed during the replay, as the seed's menu did: at `t_s`, the case's `key` takes
/// `value`; `after` is the case with this and every earlier change (what the model becomes).
struct ParameterChange {
  double t_s = 0.0;
  std::string key, value;
  cases::CaseParameters after;
};
/// The case keys a replay can change while it runs.
const std::vector<std::string>& changeable_keys();
/// Parses `--set-at T:KEY=VALUE` options against the case (each value checked as the case file
/// would check it, T in [0, last_tick_s]), sorted by time. Throws cases::InputError naming the
/// option at fault.
std::vector<ParameterChange> parse_parameter_changes(const std::vector<std::string>& options,
                                                     const std::filesystem::path& case_file,
                                                     std::vector<std::string> sets, double seconds);

struct HapticSettings {
  double rate_hz = 1000.0;
  double seconds = 0.0;  ///< replay length
  /// Threads the model steps on; the haptic thread has a core of its own (0: the cores less one).
  int model_threads = 0;
};

/// One haptic tick as the device saw it: the time it was due, the tool's centre, the force it
/// rendered (the tissue's on the tool, N).
struct HapticTick {
  double t_s = 0.0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
};

struct TickStatistics {
  double p50_ms = 0.0, p99_ms = 0.0, max_ms = 0.0;
};

/// A variant's replay: how the haptic thread kept its rate and what it rendered.
struct HapticReplay {
  std::string name;
  double rate_hz = 0.0;  ///< ticks rendered per wall second
  int ticks = 0;
  int deadline_misses = 0;           ///< ticks done after the next one was due
  std::vector<double> miss_times_s;  ///< when the first 100 of them were due
  /// From each tick's due time to its force being ready (wake-up latency included), ms.
  TickStatistics tick;
  bool realtime_priority = false;  ///< the haptic thread ran under SCHED_FIFO
  std::string integrator, stepper;
  std::string precision;  ///< the model's arithmetic: double or float (timing/precision)
  double model_dt_s = 0.0;
  double model_rate_hz = 0.0;  ///< model steps per wall second
  /// Model steps per second of its thread's stepping time: the rate it could run at (above
  /// model_rate_hz where it waits for the wall clock).
  double model_capacity_hz = 0.0;
  double model_busy_fraction = 0.0;  ///< of the wall time, spent stepping
  double model_update_hz = 0.0;      ///< local contact models handed to the haptic thread per s
  double realtime_factor = 0.0;      ///< simulated over wall seconds
  int model_threads = 0;
  int halvings = 0;  ///< times the model's step was halved after it diverged (at most 2)
  std::vector<std::pair<double, std::string>> changes_applied;  ///< wall time, KEY=VALUE
  std::vector<HapticTick> trace;
};

/// Replays `path` against the built variant (its tool made a moving frictionless contact), the
/// model stepping on its own thread with the case's integrator and the haptic thread rendering
/// the local contact model at settings.rate_hz. Throws std::runtime_error when the model diverges.
HapticReplay replay_variant(BuiltVariant& variant, const cases::CaseParameters& parameters,
                            const ToolPath& path, const HapticSettings& settings,
                            const std::vector<ParameterChange>& changes);

/// The force error at one FEM sample of the path.
struct PathForceError {
  double t_s = 0.0;
  Eigen::Vector3d fem_force = Eigen::Vector3d::Zero();
  std::optional<double> fem_force_rel_error;  ///< the reference's own error bar there
  /// The rendered force averaged over the ticks within force_window_s / 2 of t_s: the FEM's
  /// answer is quasi-static, and a hand feels no faster than that.
  Eigen::Vector3d haptic_force = Eigen::Vector3d::Zero();
  /// The variant's equilibrium there (none where its Newton failed).
  std::optional<Eigen::Vector3d> static_force;
};
inline constexpr double force_window_s = 0.05;
struct VariantAlongPath {
  HapticReplay replay;
  std::vector<PathForceError> samples;
  double rms_error_n = 0.0, max_error_n = 0.0;  ///< |haptic − FEM| over the samples
  double relative_error = 0.0;                  ///< rms error over the FEM force's rms
  /// The same for the variant's equilibrium (none unless it was found at every sample).
  std::optional<double> static_rms_error_n;
};

/// Measures a replay against the FEM at the path samples; `static_forces` are the variant's
/// equilibrium forces there, in the samples' order.
VariantAlongPath measure_along_path(
    HapticReplay replay, const std::vector<PathSample>& samples,
    const std::vector<LoadReference>& references,
    const std::vector<std::optional<Eigen::Vector3d>>& static_forces);

/// Everything msfem haptic measured, for its writers.
struct HapticRun {
  std::string case_name;
  std::filesystem::path case_file;
  HapticSettings settings;
  std::string path_source;  ///< "default" or the --path file
  std::optional<ToolPath> path;
  std::vector<ParameterChange> changes;
  std::vector<PathSample> samples;        ///< where the FEM answers
  std::vector<LoadReference> references;  ///< the FEM at each sample
  FemErrorEstimate fem_error;
  int fem_degree = 1;
  std::vector<VariantAlongPath> variants;
  std::vector<std::pair<std::string, std::string>> failed;  ///< variant, why
  std::vector<std::string> notes;
};

}  // namespace msfem::compare
