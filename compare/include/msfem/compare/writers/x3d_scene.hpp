#pragma once
// The run as a scene to turn in a browser: scene.x3d (X3D 3.3) and scene.html, which shows the same
// scene through X3DOM (vendored in compare/share/x3dom, copied beside it) with a switch per
// variant.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/writers/error_picture.hpp"

namespace msfem::compare {

/// One surface of the scene: its DEF, positions and, for a variant, its error per vertex (mm).
struct SceneSurface {
  std::string name;
  Eigen::MatrixX3d points;
  std::optional<Eigen::VectorXd> error_mm;
};

/// Writes `dir`/scene.x3d and `dir`/scene.html (with x3dom.js and x3dom.css beside it): the
/// surfaces on `triangles` (the first drawn grey, the others in error colours on one scale to
/// `max_mm`), the tool as a Sphere, a Viewpoint per picture view. Throws std::runtime_error where
/// the vendored X3DOM files are missing.
void write_x3d_scene(const std::filesystem::path& dir, const std::string& title,
                     const Eigen::MatrixX3i& triangles, const std::vector<SceneSurface>& surfaces,
                     double max_mm, const std::optional<PictureTool>& tool);

}  // namespace msfem::compare
