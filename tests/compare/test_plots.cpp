#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "msfem/compare/writers/plots.hpp"

namespace msfem::compare {
namespace {

namespace fs = std::filesystem;

class Plots : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device random;
    dir_ = fs::temp_directory_path() / ("msfem_plots_" + std::to_string(random()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Whatever the plot function wrote must be a whole PNG or SVG picture, alone in the folder.
  void expect_picture(const fs::path& written) const {
    ASSERT_TRUE(fs::is_regular_file(written)) << written;
    EXPECT_GT(fs::file_size(written), 100u);
    std::ifstream in(written, std::ios::binary);
    std::string head(8, '\0');
    in.read(head.data(), 8);
    const bool png = head == "\x89PNG\r\n\x1a\n";
    const bool svg = head.rfind("<?xml", 0) == 0 || head.rfind("<svg", 0) == 0;
    EXPECT_TRUE(png || svg) << written << " starts with " << head;
    EXPECT_EQ(png, written.extension() == ".png");
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_))
      ++files;
    EXPECT_EQ(files, 1u) << "a temporary was left beside " << written;
  }

  template <typename F>
  void expect_invalid_naming(F&& plot, const std::string& name) const {
    try {
      plot();
      ADD_FAILURE() << "bad input accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::is_empty(dir_));
  }

  fs::path dir_;
};

#define REQUIRE_GNUPLOT() \
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot is not installed (gnuplot-nox)"

Eigen::VectorXd error_magnitudes(int n, double scale) {
  std::mt19937 random(7);
  std::exponential_distribution<double> error(1.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i)
    v[i] = scale * error(random);
  return v;
}

TEST_F(Plots, HistogramOfTwoVariants) {
  REQUIRE_GNUPLOT();
  const fs::path written = histogram(dir_ / "error_histogram.png", "Error at the surface vertices",
                                     "error magnitude (m)",
                                     {{"single_layer", error_magnitudes(642, 2e-4)},
                                      {"three_tier 'refined'", error_magnitudes(642, 1e-4)}},
                                     30);
  expect_picture(written);
}

TEST_F(Plots, HistogramOfOneValueEverywhere) {
  REQUIRE_GNUPLOT();
  expect_picture(histogram(dir_ / "h.png", "no error", "error magnitude (m)",
                           {{"exact", Eigen::VectorXd::Zero(10)}}, 5));
}

TEST_F(Plots, ForceDepthCurves) {
  REQUIRE_GNUPLOT();
  Series fem{"FEM (P2)", {}, {}}, springs{"three_tier", {}, {}};
  for (int i = 1; i <= 10; ++i) {
    const double depth = 0.5e-3 * i;
    fem.x.push_back(depth);
    fem.y.push_back(0.02 * std::pow(depth / 5e-3, 1.5));  // Hertz-like, newtons
    springs.x.push_back(depth);
    springs.y.push_back(0.018 * depth / 5e-3);
  }
  expect_picture(xy_lines(dir_ / "force_depth.png", "Reaction force", "indentation depth (m)",
                          "force (N)", {fem, springs}, false, false));
}

TEST_F(Plots, ConvergenceHistoryOnLogAxes) {
  REQUIRE_GNUPLOT();
  Series history{"objective", {}, {}};
  for (int i = 1; i <= 40; ++i) {
    history.x.push_back(i);
    history.y.push_back(std::exp(-0.3 * i) + 1e-6);
  }
  expect_picture(xy_lines(dir_ / "calibration.png", "Calibration", "iteration", "objective",
                          {history}, true, true));
}

TEST_F(Plots, ParetoAgainstFrameAndHapticRates) {
  REQUIRE_GNUPLOT();
  const fs::path written = pareto(dir_ / "pareto.png", "Accuracy versus speed",
                                  {{"single_layer 642", 21000, 0.31},
                                   {"three_tier 642", 9000, 0.12},
                                   {"three_tier 2562", 900, 0.07},
                                   {"tet \"fine\"", 45, 0.02},
                                   {"skeleton", 15000, 0.4}});
  expect_picture(written);
}

TEST_F(Plots, SvgOnRequest) {
  REQUIRE_GNUPLOT();
  const fs::path written = pareto(dir_ / "pareto.svg", "one point", {{"only", 120, 0.1}});
  EXPECT_EQ(written, dir_ / "pareto.svg");
  expect_picture(written);
}

TEST_F(Plots, ReplacesAnEarlierPlot) {
  REQUIRE_GNUPLOT();
  const fs::path path = dir_ / "pareto.png";
  std::ofstream(path) << "stale";
  expect_picture(pareto(path, "again", {{"a", 100, 0.1}, {"b", 2000, 0.3}}));
}

// A gnuplot that fails (here a stand-in found first on PATH) is reported with its own message, and
// leaves no picture and no temporary behind.
TEST_F(Plots, GnuplotFailureCarriesItsMessage) {
  REQUIRE_GNUPLOT();  // also fixes gnuplot_available()'s answer before PATH changes
  const fs::path bin = dir_ / "bin";
  fs::create_directories(bin);
  std::ofstream(bin / "gnuplot") << "#!/bin/sh\necho 'line 3: simulated failure' >&2\nexit 1\n";
  fs::permissions(bin / "gnuplot", fs::perms::owner_all);
  const std::string old_path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", (bin.string() + ":" + old_path).c_str(), 1);
  const fs::path svg = dir_ / "out" / "pareto.svg";  // SVG: no terminal probe through the stand-in
  fs::create_directories(svg.parent_path());
  try {
    pareto(svg, "t", {{"a", 100, 0.1}});
    ADD_FAILURE() << "a failing gnuplot went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("simulated failure"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(svg.string()), std::string::npos) << e.what();
  }
  setenv("PATH", old_path.c_str(), 1);
  EXPECT_TRUE(fs::is_empty(svg.parent_path()));
}

TEST_F(Plots, BadInputIsRefusedNamingTheSeries) {
  const fs::path png = dir_ / "p.png";
  expect_invalid_naming(
      [&] {
        histogram(png, "t", "x", {{"empty_one", Eigen::VectorXd()}}, 10);
      },
      "empty_one");
  Eigen::VectorXd with_nan = Eigen::VectorXd::Ones(4);
  with_nan[1] = std::nan("");
  expect_invalid_naming([&] { histogram(png, "t", "x", {{"nan_one", with_nan}}, 10); }, "nan_one");
  expect_invalid_naming([&] { histogram(png, "t", "x", {{"ok", with_nan.head(1)}}, 0); }, "bins");
  expect_invalid_naming(
      [&] {
        xy_lines(png, "t", "x", "y", {{"no_points", {}, {}}}, false, false);
      },
      "no_points");
  expect_invalid_naming(
      [&] {
        xy_lines(png, "t", "x", "y", {{"ragged", {1, 2}, {1}}}, false, false);
      },
      "ragged");
  expect_invalid_naming(
      [&] {
        xy_lines(png, "t", "x", "y", {{"zero_on_log", {0, 1}, {1, 2}}}, true, false);
      },
      "zero_on_log");
  expect_invalid_naming(
      [&] {
        xy_lines(png, "t", "x", "y", {{"negative_y", {1, 2}, {1, -2}}}, false, true);
      },
      "negative_y");
  expect_invalid_naming([&] { pareto(png, "t", {{"stalled", 0, 0.1}}); }, "stalled");
  expect_invalid_naming([&] { pareto(png, "t", {{"perfect", 100, 0}}); }, "perfect");
  expect_invalid_naming([&] { pareto(png, "t", {}); }, "no points");
  expect_invalid_naming([&] { pareto(dir_ / "p.pdf", "t", {{"a", 1, 1}}); }, ".png or .svg");
}

}  // namespace
}  // namespace msfem::compare
