#include "msfem/compare/writers/error_picture.hpp"

#include <Eigen/Geometry>
#include <algorithm>
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

// The scale's stops, shared by the pictures (gnuplot's palette) and the X3D scene's colours.
constexpr double stops[5][4] = {{0.00, 0x44, 0x01, 0x54},
                                {0.25, 0x3b, 0x52, 0x8b},
                                {0.50, 0x21, 0x91, 0x8c},
                                {0.75, 0x5e, 0xc9, 0x62},
                                {1.00, 0xfd, 0xe7, 0x25}};

std::string gnuplot_palette() {
  std::string text = "set palette defined (";
  char entry[48];
  for (int i = 0; i < 5; ++i) {
    std::snprintf(entry, sizeof entry, "%s%.2f '#%02x%02x%02x'", i ? ", " : "", stops[i][0],
                  int(stops[i][1]), int(stops[i][2]), int(stops[i][3]));
    text += entry;
  }
  return text + ")\n";
}

using detail::number;
using detail::quoted;

Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& n) {
  const Eigen::Vector3d other =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return n.cross(other).normalized();
}

// The triangles in camera coordinates, each as a pm3d patch of two scans (a b / c c) with its
// colour value, blocks separated by two blank lines.
std::string patches(const Eigen::MatrixX3d& x, const Eigen::MatrixX3i& triangles,
                    const Eigen::VectorXd& error_mm, const View& camera) {
  std::ostringstream out;
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

std::string panel_commands(const Panel& panel, const std::string& title, const View& camera,
                           const std::optional<PictureTool>& tool, const char* data,
                           bool colour_bar) {
  std::ostringstream c;
  c << "set lmargin at screen " << panel.left << "\nset rmargin at screen " << panel.right
    << "\nset tmargin at screen " << panel_top << "\nset bmargin at screen " << panel_bottom
    << "\nset title " << quoted(title) << "\nset xrange [" << -camera.half_width << ":"
    << camera.half_width << "]\nset yrange [" << -camera.half_width << ":" << camera.half_width
    << "]\nunset object\n";
  if (tool) {
    const Eigen::Vector3d d = tool->center - camera.focus;
    c << "set object 1 circle at " << number(d.dot(camera.right)) << "," << number(d.dot(camera.up))
      << " size " << number(tool->radius) << " front fillstyle empty border lc rgb 'black' lw 2\n";
  }
  c << (colour_bar ? "set colorbox user origin screen 0.91,0.08 size screen 0.02,0.8\n"
                   : "unset colorbox\n")
    << "splot " << data << " using 1:2:3:4 with pm3d notitle\n";
  return c.str();
}

}  // namespace

Eigen::Vector3d error_colour(double t) {
  t = std::clamp(t, 0.0, 1.0);
  int i = 0;
  while (i < 3 && t > stops[i + 1][0])
    ++i;
  const double s = (t - stops[i][0]) / (stops[i + 1][0] - stops[i][0]);
  Eigen::Vector3d rgb;
  for (int k = 0; k < 3; ++k)
    rgb[k] = ((1 - s) * stops[i][k + 1] + s * stops[i + 1][k + 1]) / 255.0;
  return rgb;
}

std::array<View, 2> organ_views(const Eigen::MatrixX3d& deformed,
                                const std::optional<PictureTool>& tool) {
  View along, side;
  if (tool) {
    const Eigen::Vector3d n = tool->axis.normalized();
    const Eigen::Vector3d u = any_perpendicular(n);
    along = {"along the tool", u, n.cross(u), n, tool->center, 0.0};
    // From the side the organ hangs below the tool: the middle of both is the view's middle.
    side = {"from the side (tool axis up)", n.cross(u), n, u, tool->center, 0.0};
    double low = 0.0, high = 0.0;
    for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
      const double up = (deformed.row(v).transpose() - tool->center).dot(n);
      low = std::min(low, up), high = std::max(high, up);
    }
    side.focus += 0.5 * (low + high) * n;
  } else {
    const Eigen::Vector3d centre = deformed.colwise().mean().transpose();
    along = {"from +z",
             Eigen::Vector3d::UnitX(),
             Eigen::Vector3d::UnitY(),
             Eigen::Vector3d::UnitZ(),
             centre,
             0.0};
    side = {"from +x",
            Eigen::Vector3d::UnitY(),
            Eigen::Vector3d::UnitZ(),
            Eigen::Vector3d::UnitX(),
            centre,
            0.0};
  }
  for (View* view : {&along, &side}) {
    for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
      const Eigen::Vector3d d = deformed.row(v).transpose() - view->focus;
      view->half_width =
          std::max({view->half_width, std::abs(d.dot(view->right)), std::abs(d.dot(view->up))});
    }
    view->half_width *= 1.05;
  }
  return {{along, side}};
}

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
    throw std::invalid_argument("error picture '" + path.string() +
                                "': " + std::to_string(error_mm.size()) + " errors for " +
                                std::to_string(deformed.rows()) + " vertices");
  if (!deformed.allFinite() || !error_mm.allFinite() || !std::isfinite(max_mm))
    throw std::invalid_argument("error picture '" + path.string() + "': a value is not finite");
  if (triangles.size() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= deformed.rows()))
    throw std::invalid_argument("error picture '" + path.string() + "': a vertex out of range");
  const std::array<View, 2> views = organ_views(deformed, tool);
  const std::string along_data = patches(deformed, triangles, error_mm, views[0]);
  const std::string side_data = patches(deformed, triangles, error_mm, views[1]);
  const double top = max_mm > 0 ? max_mm : 1.0;  // no error anywhere: one colour, a scale to 1
  std::ostringstream c;
  c << "unset grid\nunset key\nset view map\nset pm3d depthorder\nset pm3d corners2color c1\n"
    << "unset xtics\nunset ytics\nunset ztics\nunset border\n"
    << gnuplot_palette() << "set cbrange [0:" << number(top)
    << "]\nset cblabel 'error |u - u_FEM| (mm)'\n"
    << "set multiplot title " << quoted(title) << "\n"
    << panel_commands(along_panel, views[0].name, views[0], tool, "data", false)
    << panel_commands(side_panel, views[1].name, views[1], tool, "data2", true)
    << "unset multiplot\n";
  return detail::render(path, along_data, c.str(), error_picture_width, error_picture_height,
                        {side_data});
}

}  // namespace msfem::compare
