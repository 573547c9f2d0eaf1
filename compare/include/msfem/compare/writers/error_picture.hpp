#pragma once
// Where on the organ a model is wrong: its deformed surface coloured by error magnitude, drawn
// headless by gnuplot (pm3d, depth-sorted triangles) so that CI draws it too.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

namespace msfem::compare {

/// The tool as the picture draws it: its sphere (centre at full depth, radius) and the axis it
/// presses along (the outward normal where it touches).
struct PictureTool {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
};

/// Writes `path` (PNG, error_picture_size): the surface at positions `deformed` (m) with each
/// triangle coloured by the mean of its vertices' `error_mm` on one scale from 0 to `max_mm`
/// (viridis; a colour bar in mm), seen along the tool's axis (left panel; the tool's centre in the
/// panel's middle) and from the side (right panel; the axis pointing up), the tool's sphere drawn
/// as a circle on both. Without a tool, from +z and from +x about the surface's centre. Throws
/// std::invalid_argument for sizes that disagree or a value that is not finite, std::runtime_error
/// where gnuplot fails.
std::filesystem::path error_picture(const std::filesystem::path& path, const std::string& title,
                                    const Eigen::MatrixX3d& deformed,
                                    const Eigen::MatrixX3i& triangles,
                                    const Eigen::VectorXd& error_mm, double max_mm,
                                    const std::optional<PictureTool>& tool);

/// The picture's width and height in pixels.
inline constexpr int error_picture_width = 1200, error_picture_height = 600;
/// The pixel (column, row from the top) at the middle of the along-the-tool panel: where the tool's
/// centre is drawn.
std::pair<int, int> error_picture_tool_pixel();

}  // namespace msfem::compare
