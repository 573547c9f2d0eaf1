#include "msfem/compare/writers/x3d_scene.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

#include "msfem/cases/x3d.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"

namespace msfem::compare {
namespace {

constexpr double field_of_view = 0.785398;  // X3D's default Viewpoint fieldOfView (rad)

std::string triple(const Eigen::Vector3d& v) {
  char text[96];
  std::snprintf(text, sizeof text, "%.9g %.9g %.9g", v.x(), v.y(), v.z());
  return text;
}

// A Viewpoint seeing `view` as the pictures do: X3D's camera looks along -Z with +Y up, so its
// orientation is the rotation taking (X, Y, Z) to (right, up, depth).
std::string viewpoint(const View& view, const std::string& def) {
  Eigen::Matrix3d rotation;
  rotation << view.right, view.up, view.depth;
  const Eigen::AngleAxisd turn(rotation);
  const Eigen::Vector3d position =
      view.focus + view.depth * (view.half_width / std::tan(0.5 * field_of_view));
  char angle[32];
  std::snprintf(angle, sizeof angle, "%.9g", turn.angle());
  return "<Viewpoint DEF=\"" + def + "\" description=\"" + cases::xml_escaped(view.name) +
         "\" position=\"" + triple(position) + "\" orientation=\"" + triple(turn.axis()) + " " +
         angle + "\" centerOfRotation=\"" + triple(view.focus) + "\"></Viewpoint>";
}

// Every node of the scene (between <Scene> and </Scene>), each with its end tag so that scene.x3d
// and scene.html hold the same text; on the page each Shape also has an id (its DEF) and X3DOM's
// `render`, the first variant shown and the rest a click away (overlapping surfaces would hide
// each other).
std::string scene_nodes(const Eigen::MatrixX3i& triangles,
                        const std::vector<SceneSurface>& surfaces, double max_mm,
                        const std::optional<PictureTool>& tool, bool page) {
  const std::array<View, 2> views = organ_views(surfaces.front().points, tool);
  std::string out = "    " + viewpoint(views[0], "view_along") + "\n    " +
                    viewpoint(views[1], "view_side") + "\n";
  out += "    <Background skyColor=\"1 1 1\"></Background>\n";
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    const SceneSurface& s = surfaces[i];
    Eigen::MatrixX3d colours;
    std::string appearance =
        "<Appearance><Material diffuseColor=\"0.75 0.75 0.75\" transparency=\"0.6\">"
        "</Material></Appearance>";
    if (s.error_mm) {
      colours.resize(s.points.rows(), 3);
      for (Eigen::Index v = 0; v < s.points.rows(); ++v)
        colours.row(v) = error_colour(max_mm > 0 ? (*s.error_mm)[v] / max_mm : 0.0).transpose();
      appearance = "";  // no Material: unlit, each vertex exactly its colour on the scale
    }
    const std::string shown = i == 1 || surfaces.size() == 1 ? "true" : "false";
    out += cases::x3d_shape(
        s.name, s.points, triangles, colours, appearance, "    ",
        page ? " id=\"" + cases::xml_escaped(s.name) + "\" render=\"" + shown + "\"" : "");
  }
  if (tool)
    out += "    <Transform DEF=\"tool\" translation=\"" + triple(tool->center) +
           "\">\n      <Shape>\n        <Appearance><Material diffuseColor=\"0.8 0.2 0.2\" "
           "transparency=\"0.3\"></Material></Appearance>\n        <Sphere radius=\"" +
           std::to_string(tool->radius) + "\"></Sphere>\n      </Shape>\n    </Transform>\n";
  return out;
}

std::string html_page(const std::string& title, const std::vector<SceneSurface>& surfaces,
                      const std::string& nodes) {
  std::string switches;
  for (std::size_t i = 0; i < surfaces.size(); ++i)
    switches += "  <label><input type=\"checkbox\"" + std::string(i == 1 ? " checked" : "") +
                " onchange=\"show('" + surfaces[i].name + "', this.checked)\"> " +
                cases::xml_escaped(surfaces[i].name) + "</label>\n";
  // X3DOM takes the X3D nodes in the page itself: no request for scene.x3d, which a browser
  // refuses for a page opened from disk.
  return "<!DOCTYPE html>\n<html>\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         cases::xml_escaped(title) +
         "</title>\n<script src=\"x3dom.js\"></script>\n"
         "<link rel=\"stylesheet\" href=\"x3dom.css\">\n"
         "<style>body { font-family: sans-serif; } x3d { border: 1px solid #ccc; }</style>\n"
         "</head>\n<body>\n<h1>" +
         cases::xml_escaped(title) +
         "</h1>\n<p>Each variant's deformed surface coloured by its error against the FEM "
         "(viridis, 0 to the largest error of the run); the undeformed surface grey; the tool "
         "red. Drag to turn, wheel to zoom; switch surfaces on and off:</p>\n<div "
         "id=\"switches\">\n" +
         switches +
         "</div>\n<x3d id=\"scene\" width=\"1000px\" height=\"650px\">\n  <Scene>\n"
         // X3DOM's own node: colours as given, not gamma-corrected, so the page shows the scale.
         "    <Environment gammaCorrectionDefault=\"none\"></Environment>\n" +
         nodes +
         "  </Scene>\n</x3d>\n<script>\nfunction show(name, on) {\n"
         "  document.getElementById(name).setAttribute('render', on ? 'true' : 'false');\n}\n"
         "</script>\n</body>\n</html>\n";
}

}  // namespace

void write_x3d_scene(const std::filesystem::path& dir, const std::string& title,
                     const Eigen::MatrixX3i& triangles, const std::vector<SceneSurface>& surfaces,
                     double max_mm, const std::optional<PictureTool>& tool) {
  const std::filesystem::path x3dom = MSFEM_X3DOM_DIR;
  for (const char* file : {"x3dom.js", "x3dom.css"})
    if (!std::filesystem::is_regular_file(x3dom / file))
      throw std::runtime_error("scene.html: " + (x3dom / file).string() +
                               " is missing (msfem's vendored X3DOM)");
  const std::string nodes = scene_nodes(triangles, surfaces, max_mm, tool, false);
  write_text_atomically(
      dir / "scene.x3d",
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<!DOCTYPE X3D PUBLIC \"ISO//Web3D//DTD X3D 3.3//EN\" "
      "\"http://www.web3d.org/specifications/x3d-3.3.dtd\">\n"
      "<X3D profile=\"Interchange\" version=\"3.3\">\n  <head>\n    <meta name=\"title\" "
      "content=\"" +
          cases::xml_escaped(title) +
          "\"/>\n    <meta name=\"generator\" content=\"msfem\"/>\n  </head>\n  <Scene>\n" + nodes +
          "  </Scene>\n</X3D>\n");
  write_text_atomically(
      dir / "scene.html",
      html_page(title, surfaces, scene_nodes(triangles, surfaces, max_mm, tool, true)));
  for (const char* file : {"x3dom.js", "x3dom.css"})
    std::filesystem::copy_file(x3dom / file, dir / file,
                               std::filesystem::copy_options::overwrite_existing);
}

}  // namespace msfem::compare
