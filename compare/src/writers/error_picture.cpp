#include "msfem/compare/writers/error_picture.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "plot_render.hpp"

namespace msfem::compare {
namespace {

// Each panel's plot area, in screen fractions: square in pixels (0.4 × 1200 = 0.8 × 600 = 480),
// so equal ranges on both axes keep the organ's proportions.
struct Panel {
  double left, right;
};
constexpr Panel along_panel{0.03, 0.43}, side_panel{0.48, 0.88};
constexpr double panel_bottom = 0.08, panel_top = 0.88;

// A camera: the organ seen looking along -depth, `right` across and `up` up (right × up = depth,
// so the picture is not mirrored).
struct Camera {
  Eigen::Vector3d right, up, depth;
  Eigen::Vector3d focus;  ///< drawn at the panel's middle
};

Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& n) {
  const Eigen::Vector3d other =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return n.cross(other).normalized();
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

std::string quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text)
    out += c == '\'' ? std::string("''") : std::string(1, c == '\n' ? ' ' : c);
  return out + "'";
}

// The triangles in camera coordinates, each as a pm3d patch of two scans (a b / c c) with its
// colour value, blocks separated by two blank lines.
std::string patches(const Eigen::MatrixX3d& x, const Eigen::MatrixX3i& triangles,
                    const Eigen::VectorXd& error_mm, const Camera& camera, double& half_width) {
  std::ostringstream out;
  half_width = 0.0;
  for (Eigen::Index v = 0; v < x.rows(); ++v) {
    const Eigen::Vector3d d = x.row(v).transpose() - camera.focus;
    half_width = std::max({half_width, std::abs(d.dot(camera.right)), std::abs(d.dot(camera.up))});
  }
  auto point = [&](int v, double value) {
    const Eigen::Vector3d d = x.row(v).transpose() - camera.focus;
    // pm3d's depth order in a map view draws the largest z first: nearer is lower z.
    out << number(d.dot(camera.right)) << ' ' << number(d.dot(camera.up)) << ' '
        << number(-d.dot(camera.depth)) << ' ' << number(value) << '\n';
  };
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const int a = triangles(t, 0), b = triangles(t, 1), c = triangles(t, 2);
    const double value = (error_mm[a] + error_mm[b] + error_mm[c]) / 3.0;
    point(a, value);
    point(b, value);
    out << '\n';
    point(c, value);
    point(c, value);
    out << "\n\n";
  }
  return out.str();
}

std::string panel_commands(const Panel& panel, const std::string& title, const Camera& camera,
                           double half_width, const std::optional<PictureTool>& tool,
                           const char* data, bool colour_bar) {
  std::ostringstream c;
  c << "set lmargin at screen " << panel.left << "\nset rmargin at screen " << panel.right
    << "\nset tmargin at screen " << panel_top << "\nset bmargin at screen " << panel_bottom
    << "\nset title " << quoted(title) << "\nset xrange [" << -half_width << ":" << half_width
    << "]\nset yrange [" << -half_width << ":" << half_width << "]\nunset object\n";
  if (tool) {
    const Eigen::Vector3d d = tool->center - camera.focus;
    c << "set object 1 circle at " << number(d.dot(camera.right)) << ","
      << number(d.dot(camera.up)) << " size " << number(tool->radius)
      << " front fillstyle empty border lc rgb 'black' lw 2\n";
  }
  c << (colour_bar ? "set colorbox user origin screen 0.91,0.08 size screen 0.02,0.8\n"
                   : "unset colorbox\n")
    << "splot " << data << " using 1:2:3:4 with pm3d notitle\n";
  return c.str();
}

}  // namespace

std::pair<int, int> error_picture_tool_pixel() {
  const double column = 0.5 * (along_panel.left + along_panel.right) * error_picture_width;
  const double row = (1.0 - 0.5 * (panel_bottom + panel_top)) * error_picture_height;
  return {static_cast<int>(std::lround(column)), static_cast<int>(std::lround(row))};
}

std::filesystem::path error_picture(const std::filesystem::path& path, const std::string& title,
                                    const Eigen::MatrixX3d& deformed,
                                    const Eigen::MatrixX3i& triangles,
                                    const Eigen::VectorXd& error_mm, double max_mm,
                                    const std::optional<PictureTool>& tool) {
  if (error_mm.size() != deformed.rows())
    throw std::invalid_argument("error picture '" + path.string() + "': " +
                                std::to_string(error_mm.size()) + " errors for " +
                                std::to_string(deformed.rows()) + " vertices");
  if (!deformed.allFinite() || !error_mm.allFinite() || !std::isfinite(max_mm))
    throw std::invalid_argument("error picture '" + path.string() + "': a value is not finite");
  if (triangles.size() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= deformed.rows()))
    throw std::invalid_argument("error picture '" + path.string() + "': a vertex out of range");
  Camera along, side;
  if (tool) {
    const Eigen::Vector3d n = tool->axis.normalized();
    const Eigen::Vector3d u = any_perpendicular(n);
    along = {u, n.cross(u), n, tool->center};
    // From the side the organ hangs below the tool: the middle of both is the panel's middle.
    side = {n.cross(u), n, u, tool->center};
    double low = 0.0, high = 0.0;
    for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
      const double up = (deformed.row(v).transpose() - tool->center).dot(n);
      low = std::min(low, up), high = std::max(high, up);
    }
    side.focus += 0.5 * (low + high) * n;
  } else {
    const Eigen::Vector3d centre = deformed.colwise().mean().transpose();
    along = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), centre};
    side = {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), centre};
  }
  double half_along = 0.0, half_side = 0.0;
  const std::string along_data = patches(deformed, triangles, error_mm, along, half_along);
  const std::string side_data = patches(deformed, triangles, error_mm, side, half_side);
  const double top = max_mm > 0 ? max_mm : 1.0;  // no error anywhere: one colour, a scale to 1
  std::ostringstream c;
  c << "unset grid\nunset key\nset view map\nset pm3d depthorder\nset pm3d corners2color c1\n"
    << "unset xtics\nunset ytics\nunset ztics\nunset border\n"
    << "set palette defined (0 '#440154', 0.25 '#3b528b', 0.5 '#21918c', 0.75 '#5ec962', "
       "1 '#fde725')\n"
    << "set cbrange [0:" << number(top) << "]\nset cblabel 'error |u - u_FEM| (mm)'\n"
    << "set multiplot title " << quoted(title) << "\n"
    << panel_commands(along_panel, tool ? "along the tool" : "from +z", along, 1.05 * half_along,
                      tool, "data", false)
    << panel_commands(side_panel, tool ? "from the side (tool axis up)" : "from +x", side,
                      1.05 * half_side, tool, "data2", true)
    << "unset multiplot\n";
  return detail::render(path, along_data, c.str(), error_picture_width, error_picture_height,
                        {side_data});
}

}  // namespace msfem::compare
