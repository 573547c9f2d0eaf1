// The error drawn on the organ: a known error field on the icosphere, drawn as msfem run draws each
// variant's, read back pixel by pixel (the PNG decoded here with zlib).
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/compare/writers/error_picture.hpp"
#include "msfem/compare/writers/plots.hpp"
#include "png_reader.hpp"

namespace msfem {
namespace {

TEST(ErrorPicture, TheToolsPixelHasTheColourOfTheLargestError) {
  if (!compare::gnuplot_available()) GTEST_SKIP() << "gnuplot is not installed";
  const cases::Surface ball = cases::generate_surface("icosphere:3:0.05");
  // 5 mm within 1.5 cm of the pole the tool presses, 1 mm on a band about the equator, 0 elsewhere.
  Eigen::VectorXd error = Eigen::VectorXd::Zero(ball.num_vertices());
  for (Eigen::Index v = 0; v < ball.num_vertices(); ++v) {
    const Eigen::Vector3d x = ball.vertices.row(v).transpose();
    if ((x - Eigen::Vector3d(0, 0, 0.05)).norm() < 0.015) error[v] = 5.0;
    if (std::abs(x.z()) < 0.01) error[v] = 1.0;
  }
  compare::PictureTool tool;
  tool.radius = 0.005;
  tool.center = {0, 0, 0.05};
  tool.axis = {0, 0, 1};
  testing::TemporaryDirectory dir;
  const auto file = compare::error_picture(dir / "error.png", "known field", ball.vertices,
                                           ball.triangles, error, 5.0, tool);
  const testing::Image image = testing::read_png(file);
  EXPECT_EQ(image.width, compare::error_picture_width);
  EXPECT_EQ(image.height, compare::error_picture_height);
  std::set<std::array<int, 3>> colours;
  for (int row = 0; row < image.height; row += 4)
    for (int column = 0; column < image.width; column += 4)
      colours.insert(image.at(column, row));
  EXPECT_GT(colours.size(), 20u);  // not blank: the organ, its three colours, the bar, the text
  // The largest error is the top of the scale: viridis' yellow, #fde725.
  const auto [column, row] = compare::error_picture_tool_pixel();
  const auto pixel = image.at(column, row);
  EXPECT_NEAR(pixel[0], 0xfd, 8);
  EXPECT_NEAR(pixel[1], 0xe7, 8);
  EXPECT_NEAR(pixel[2], 0x25, 8);
  // Off the organ, in the panel's corner: the white page.
  EXPECT_EQ(image.at(column - 230, row - 230), (std::array<int, 3>{{255, 255, 255}}));
}

}  // namespace
}  // namespace msfem
