// stand_in_simulator LOADDIR OUT.vtu: an outside simulator, as the tests stand one in. It reads
// only what msfem export-load wrote (surface.vtu, loads.json), builds msfem's single-layer network
// on that surface with the material given there, presses the first load's tool along its curve
// depths (contact, or the prescribed patch), and writes its answer as a simulator would: the
// deformed surface with point data `displacement` and the tool force in OUT.force.json.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "msfem/cases/vtk_surface.hpp"
#include "msfem/compare/writers/vtu.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/surface_contact.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace ms = msfem::massspring;

namespace {

Eigen::Vector3d vec(const nlohmann::json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: stand_in_simulator LOADDIR OUT.vtu\n";
    return 2;
  }
  const std::filesystem::path dir = argv[1], out = argv[2];
  const auto surface = msfem::cases::read_vtk_surface(dir / "surface.vtu");
  std::ifstream in(dir / "loads.json");
  const nlohmann::json loads = nlohmann::json::parse(in);
  if (loads.at("schema") != "msfem-loads" || loads.at("version") != 1) {
    std::cerr << "stand_in_simulator: loads.json of another schema\n";
    return 2;
  }
  ms::SingleLayerOptions options;
  options.anchor_to_rest = true;
  options.material.youngs_modulus = loads["material"]["youngs_modulus_pa"];
  options.material.density = loads["material"]["density_kg_per_m3"];
  ms::MassSpringModel model(ms::build_single_layer(surface.points, surface.triangles, options));
  const Eigen::MatrixXd& fixed = surface.point_data.at("fixed");
  for (Eigen::Index v = 0; v < fixed.rows(); ++v)
    if (fixed(v, 0) != 0) model.fix_node(static_cast<int>(v));
  model.set_gravity(vec(loads["gravity_m_per_s2"]));

  const nlohmann::json& tool = loads["loads"][0]["tool"];
  Eigen::VectorXd x;
  std::vector<int> patch;
  if (tool["mode"] == "contact") {
    double penalty = 0.0;  // picked at the first depth and kept, as a simulator fixes it once
    for (const auto& step : tool["curve"]) {
      ms::ToolIndentation indent;
      indent.contact_point = vec(tool["contact_point_m"]);
      indent.inward_direction = -vec(tool["outward_normal"]);
      indent.radius = tool["radius_m"];
      indent.depth = step["depth_m"];
      penalty = ms::activate_surface_contact(model, indent, penalty);
      x = ms::solve_static(model, {}, x).x;
    }
  } else {
    for (const auto& held : tool["prescribed"]) {
      patch.push_back(held["vertex"]);
      model.prescribe_displacement(patch.back(), vec(held["displacement_m"]));
    }
    x = ms::solve_static(model).x;
  }
  const Eigen::Vector3d force = patch.empty() ? ms::contact_reaction_force(model, x)
                                              : ms::patch_reaction_force(model, x, patch);
  const Eigen::MatrixXd u = model.surface_displacement(x);
  msfem::compare::write_surface_vtu(out, surface.points, surface.triangles, {{"displacement", u}});
  std::ofstream(out.parent_path() / (out.stem().string() + ".force.json"))
      << nlohmann::json{{"schema", "msfem-force"},
                        {"version", 1},
                        {"tool_force_n", {force.x(), force.y(), force.z()}}};
  return 0;
}
