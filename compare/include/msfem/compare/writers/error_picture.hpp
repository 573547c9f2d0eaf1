#pragma once
// Where on the organ a model is wrong: its deformed surface coloured by error magnitude, drawn
// headless by gnuplot (pm3d, depth-sorted triangles) so that CI draws it too.

#include <Eigen/Core>
#include <array>
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

/// A way of looking at the organ: `right` across, `up` up, `depth` toward the viewer (right × up =
/// depth), `focus` in the middle, everything within `half_width` of it across and up.
struct View {
  std::string name;
  Eigen::Vector3d right, up, depth, focus;
  double half_width = 0.0;
};

/// The two views of the pictures and the X3D scene: along the tool's axis (the tool's centre in the
/// middle) and from the side (the axis up); without a tool from +z and from +x.
std::array<View, 2> organ_views(const Eigen::MatrixX3d& deformed,
                                const std::optional<PictureTool>& tool);

/// The error colour scale (viridis) at t in [0, 1] (clamped), RGB in [0, 1].
Eigen::Vector3d error_colour(double t);

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
