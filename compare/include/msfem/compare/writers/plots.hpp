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
};

/// One configuration on the accuracy-versus-speed plane.
struct ParetoPoint {
  std::string label;
  double steps_per_second = 0.0;
  double rel_error = 0.0;
};

/// Histograms of error magnitudes (one series per variant, metres), drawn as overlaid step outlines
/// over `bins` common bins spanning all series, counts on the y axis.
std::filesystem::path histogram(const std::filesystem::path& path, const std::string& title,
                                const std::string& xlabel,
                                const std::vector<std::pair<std::string, Eigen::VectorXd>>& series,
                                int bins);

/// Lines with points, one per series: the force-depth curve of the FEM and each variant, or a
/// calibration's convergence history. A log axis refuses values that are not positive.
std::filesystem::path xy_lines(const std::filesystem::path& path, const std::string& title,
                               const std::string& xlabel, const std::string& ylabel,
                               const std::vector<Series>& series, bool logx, bool logy);

/// Accuracy versus speed, log-log: x = steps per second, y = relative error, each point labelled,
/// the Pareto front (no other point both faster and more accurate) joined, and vertical lines at
/// 60 steps/s ("60 Hz", a rendered frame) and 1000 steps/s ("1 kHz", haptics).
std::filesystem::path pareto(const std::filesystem::path& path, const std::string& title,
                             const std::vector<ParetoPoint>& points);

}  // namespace msfem::compare
