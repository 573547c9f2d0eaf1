#pragma once
// The report's plots (report.md links them), drawn by gnuplot run as a child process on a generated
// script and data file. A PNG (gnuplot's pngcairo terminal, 900 x 600) where the path ends in .png
// and gnuplot has pngcairo; an SVG where the path ends in .svg, or in place of the PNG (same name,
// .svg) where pngcairo is missing. Every function checks its input first (std::invalid_argument
// naming the series), writes atomically and returns the path it wrote; std::runtime_error carries
// gnuplot's own message if gnuplot is missing or fails.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace msfem::compare {

/// Whether a `gnuplot` program runs from PATH.
bool gnuplot_available();

/// One named curve of an x-y plot.
struct Series {
  std::string name;
  std::vector<double> x, y;
  std::string colour = {};  ///< "#rrggbb"; empty: gnuplot's next line colour
};

/// The colour of the i-th variant of a run in every plot of it (a variant keeps its colour however
/// many others a plot leaves out); the FEM is black.
std::string variant_colour(std::size_t i);

/// One configuration on the accuracy-versus-speed plane.
struct ParetoPoint {
  std::string label;
  double realtime_factor = 0.0;  ///< simulated seconds per wall second
  double rel_error = 0.0;
  std::string colour_group = {};  ///< one colour per group (the variant); empty: one group
  std::string marker_group = {};  ///< one marker per group (the integrator); empty: one marker
  bool ringed = false;            ///< marked with a ring (e.g. can run a 1 kHz loop in real time)
};

/// Histograms of error magnitudes (one series per variant, metres), drawn as overlaid step outlines
/// over `bins` common bins spanning all series, counts on the y axis; series i in `colours[i]`
/// where given.
std::filesystem::path histogram(const std::filesystem::path& path, const std::string& title,
                                const std::string& xlabel,
                                const std::vector<std::pair<std::string, Eigen::VectorXd>>& series,
                                int bins, const std::vector<std::string>& colours = {});

/// Lines with points, one per series: the force-depth curve of the FEM and each variant, or a
/// calibration's convergence history. A log axis refuses values that are not positive.
std::filesystem::path xy_lines(const std::filesystem::path& path, const std::string& title,
                               const std::string& xlabel, const std::string& ylabel,
                               const std::vector<Series>& series, bool logx, bool logy);

/// Accuracy versus speed, log-log: x = real-time factor, y = relative error, a colour per colour
/// group and a marker per marker group (both in the legend), the Pareto front (no other point both
/// faster and more accurate) joined and only its points labelled, ringed points marked, and a
/// vertical line at real time (x = 1).
std::filesystem::path pareto(const std::filesystem::path& path, const std::string& title,
                             const std::vector<ParetoPoint>& points);

}  // namespace msfem::compare
