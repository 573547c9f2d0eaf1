#include "msfem/compare/writers/x3d_scene.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

#include "msfem/cases/x3d.hpp"
#include "msfem/compare/writers/atomic_file.hpp"

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
         angle + "\" centerOfRotation=\"" + triple(view.focus) + "\"/>";
}

// Every node of the scene (between <Scene> and </Scene>), shared by scene.x3d and scene.html.
std::string scene_nodes(const Eigen::MatrixX3i& triangles,
                        const std::vector<SceneSurface>& surfaces, double max_mm,
                        const std::optional<PictureTool>& tool) {
  const std::array<View, 2> views = organ_views(surfaces.front().points, tool);
  std::string out = "    " + viewpoint(views[0], "view_along") + "\n    " +
                    viewpoint(views[1], "view_side") + "\n";
  out += "    <Background skyColor=\"1 1 1\"/>\n";
  for (const SceneSurface& s : surfaces) {
    Eigen::MatrixX3d colours;
    std::string appearance =
        "<Appearance><Material diffuseColor=\"0.75 0.75 0.75\" transparency=\"0.6\"/></Appearance>";
    if (s.error_mm) {
      colours.resize(s.points.rows(), 3);
      for (Eigen::Index v = 0; v < s.points.rows(); ++v)
        colours.row(v) = error_colour(max_mm > 0 ? (*s.error_mm)[v] / max_mm : 0.0).transpose();
      appearance = "";  // no Material: unlit, each vertex exactly its colour on the scale
    }
    out += cases::x3d_shape(s.name, s.points, triangles, colours, appearance, "    ");
  }
  if (tool)
    out += "    <Transform DEF=\"tool\" translation=\"" + triple(tool->center) +
           "\">\n      <Shape>\n        <Appearance><Material diffuseColor=\"0.8 0.2 0.2\" "
           "transparency=\"0.3\"/></Appearance>\n        <Sphere radius=\"" +
           std::to_string(tool->radius) + "\"/>\n      </Shape>\n    </Transform>\n";
  return out;
}

// HTML has no self-closing elements but its void ones: <Coordinate .../> would stay open and
// swallow what follows, so every <Name .../> becomes <Name ...></Name>.
std::string with_closing_tags(const std::string& xml) {
  std::string out;
  std::size_t at = 0;
  while (true) {
    const std::size_t close = xml.find("/>", at);
    if (close == std::string::npos) break;
    const std::size_t open = xml.rfind('<', close);
    const std::size_t name_end = xml.find_first_of(" \n/>", open + 1);
    out += xml.substr(at, close - at) + "></" + xml.substr(open + 1, name_end - open - 1) + ">";
    at = close + 2;
  }
  return out + xml.substr(at);
}

std::string html_page(const std::string& title, const std::vector<SceneSurface>& surfaces,
                      const std::string& nodes) {
  // The first variant shown, the rest (and the undeformed surface) a click away: overlapping
  // surfaces would hide each other.
  std::string switches;
  for (std::size_t i = 0; i < surfaces.size(); ++i)
    switches += "  <label><input type=\"checkbox\"" + std::string(i == 1 ? " checked" : "") +
                " onchange=\"show('" + surfaces[i].name + "', this.checked)\"> " +
                cases::xml_escaped(surfaces[i].name) + "</label>\n";
  // X3DOM takes the X3D nodes in the page itself (no request for scene.x3d, which a browser
  // refuses for a page opened from disk); a Shape's DEF is its id, `render` shows or hides it.
  std::string page_nodes = with_closing_tags(nodes);
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    const std::string def = "<Shape DEF=\"" + cases::xml_escaped(surfaces[i].name) + "\"";
    page_nodes.replace(page_nodes.find(def), def.size(),
                       def + " id=\"" + cases::xml_escaped(surfaces[i].name) + "\" render=\"" +
                           (i == 1 || surfaces.size() == 1 ? "true" : "false") + "\"");
  }
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
         page_nodes +
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
  const std::string nodes = scene_nodes(triangles, surfaces, max_mm, tool);
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
  write_text_atomically(dir / "scene.html", html_page(title, surfaces, nodes));
  for (const char* file : {"x3dom.js", "x3dom.css"})
    std::filesystem::copy_file(x3dom / file, dir / file,
                               std::filesystem::copy_options::overwrite_existing);
}

}  // namespace msfem::compare
