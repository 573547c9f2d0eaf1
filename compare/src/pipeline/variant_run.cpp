#include "msfem/compare/pipeline/variant_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/surface_simplification.hpp"
#include "msfem/compare/pipeline/progress.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/surface_contact.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "pipeline/builtin_variants.hpp"
#include "pipeline/cholmod_factor.hpp"

namespace msfem::compare {
namespace {

namespace ms = msfem::massspring;

ms::SpringNetwork build_network(cases::Variant variant, const Problem& problem,
                                const fem_reference::VolumeMesh& mesh) {
  ms::Material material;
  material.youngs_modulus = problem.parameters.material.youngs_modulus_pa;
  material.density = problem.parameters.material.density_kg_per_m3;
  return detail::builtin_variant(variant).network(problem, mesh, material);
}

std::string scientific(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

void apply_patch_force(ms::MassSpringModel& model, const Problem& problem) {
  const auto& patch = problem.parameters.loads.patch_force;
  if (!patch.enabled) return;
  const auto& s = problem.surface;
  const Eigen::VectorXd areas = ms::vertex_areas(s.vertices, s.triangles);
  const std::vector<int> nodes = patch_vertices(problem);
  double total_area = 0;
  for (int v : nodes)
    total_area += areas[v];
  const auto& surface_nodes = model.network().surface_nodes;
  for (int v : nodes)
    model.set_external_force(surface_nodes[v], patch.force_n * areas[v] / total_area);
}

ms::ModulusField youngs_modulus_field(const Problem& problem) {
  return [&problem](const Eigen::Vector3d& x) { return youngs_modulus_at(problem, x); };
}

// The variants whose builders give the volume elements volume preservation acts on.
bool has_volume_elements(cases::Variant variant) {
  return detail::builtin_variant(variant).volume_elements != nullptr;
}

// The volume elements of a variant that has them (three_tier's shell prisms, tet_edges'
// tetrahedra), κ = λ(E, ν) − λ(E, 1/4) times the case's `volume` group scale.

void set_volume_preservation(BuiltVariant& variant, const Problem& problem) {
  const auto& p = problem.parameters;
  ms::MassSpringModel& model = *variant.model;
  double modulus = ms::volume_modulus_for(p.material.youngs_modulus_pa, p.material.poisson_ratio);
  for (const auto& [group, factor] : p.mass_spring.group_scales)
    if (group == volume_group) modulus *= factor;
  const auto& rest = model.network().rest_positions;
  if (!variant.spec.builtin || !has_volume_elements(*variant.spec.builtin)) return;
  ms::VolumeElements elements = detail::builtin_variant(*variant.spec.builtin)
                                    .volume_elements(rest, problem, variant.tetrahedra, modulus);
  const int all = elements.num_elements();
  // The brain's offset inner tiers fold where the surface is concave: such prisms are inverted or
  // flat at rest, and with them Newton stalled (residual ~1e-7 N after 100 iterations).
  if (const int removed = ms::remove_degenerate_elements(elements, rest, 1e-3); removed > 0)
    variant.warnings.push_back({Warning::Kind::degenerate_volume_elements,
                                "volume preservation: " + std::to_string(removed) + " of " +
                                    std::to_string(all) +
                                    " volume elements are inverted or flat at rest (folded tiers, "
                                    "slivers) and are left out"});
  if (problem.youngs_modulus_image)
    variant.youngs_modulus_range.include(ms::apply_modulus_field(
        elements, rest, youngs_modulus_field(problem), p.material.youngs_modulus_pa));
  if (elements.num_elements() > 0)
    model.set_volume(ms::VolumeForceField(model.num_nodes(), std::move(elements)));
}

}  // namespace

std::vector<std::string> spring_groups_of(cases::Variant variant, const cases::CaseParameters& p) {
  std::vector<std::string> groups = detail::builtin_variant(variant).spring_groups(p);
  if (p.mass_spring.volume_preservation && has_volume_elements(variant))
    groups.emplace_back(volume_group);
  return groups;
}

void check_group_names(const cases::CaseParameters& p) {
  std::set<std::string> groups;
  for (const auto& v : p.mass_spring.variants) {
    const std::vector<std::string> of_variant = spring_groups_of(v, p);
    groups.insert(of_variant.begin(), of_variant.end());
  }
  if (!p.mass_spring.group_scales.empty())
    for (const auto& network : p.mass_spring.networks) {
      try {
        const std::vector<std::string> of_network = network_groups(network.file);
        groups.insert(of_network.begin(), of_network.end());
      } catch (const cases::InputError& e) {
        throw cases::InputError(p.file.string() + ": mass spring/networks: " + network.name + "=" +
                                network.file.string() + ": " + e.what());
      }
    }
  for (const auto& [group, factor] : p.mass_spring.group_scales)
    if (!groups.count(group)) {
      std::string list;
      for (const auto& g : groups)
        list += (list.empty() ? "" : ", ") + g;
      throw cases::InputError(
          p.file.string() + ": mass spring/group scales: no variant of the case has a group '" +
          group + "'" + (group == volume_group ? " (" + std::string(volume_hint) + ")" : "") +
          "; the case's groups: " + list);
    }
}

void check_variants_fit(const Problem& problem) {
  check_networks_fit(problem);
  const auto& p = problem.parameters;
  const auto& variants = p.mass_spring.variants;
  const int n = static_cast<int>(problem.surface.num_vertices());
  if (std::find(variants.begin(), variants.end(), cases::Variant::skeleton) != variants.end() &&
      p.mass_spring.skeleton_control_points > n)
    throw cases::InputError(p.file.string() + ": mass spring/skeleton/control points = " +
                            std::to_string(p.mass_spring.skeleton_control_points) +
                            " is more than the surface's " + std::to_string(n) +
                            " vertices (the control mesh is a simplified copy of the surface)");
}

void set_tool_depth(BuiltVariant& variant, const ToolPlacement& tool) {
  ms::MassSpringModel& model = *variant.model;
  for (int node : variant.tool_patch)
    model.release_node(node);
  variant.tool_patch.clear();
  if (tool.frictionless) {
    // The sphere against the surface's triangles, at the penalty activate_surface_contact picks
    // from the network's stiffness (the same at every depth of the loading path).
    ms::ToolIndentation indent;
    indent.contact_point = tool.contact_point;
    indent.inward_direction = -tool.outward_normal;
    indent.radius = tool.radius;
    indent.depth = tool.depth;
    variant.contact_pressure_penalty =
        ms::activate_surface_contact(model, indent, variant.contact_pressure_penalty);
    return;
  }
  const fem_reference::Support support = tool_patch_support(tool);
  // The very same patch and displacement as the FEM's tool support, node for node: the case's
  // surface vertices, and tet_edges' extra surface nodes where it shares the FEM's refined mesh.
  const auto& network = model.network();
  for (const int node : network.surface_nodes) {
    const Eigen::Vector3d x = network.rest_positions.row(node).transpose();
    if (!support.region(x)) continue;
    model.prescribe_displacement(node, support.displacement(x));
    variant.tool_patch.push_back(node);
  }
  // Supports win over the tool where both catch a node (as in the FEM, where the fixed region is
  // listed after the tool but a tool on a fixed node is refused by make_problem).
}

std::optional<int> inverted_tetrahedra(const BuiltVariant& variant, const Eigen::VectorXd& x) {
  if (variant.tetrahedra.rows() == 0) return std::nullopt;
  const auto& rest = variant.model->network().rest_positions;
  auto signed_volume = [&](auto&& position, Eigen::Index t) {
    const Eigen::Vector3d a = position(variant.tetrahedra(t, 0));
    return (position(variant.tetrahedra(t, 1)) - a)
        .cross(position(variant.tetrahedra(t, 2)) - a)
        .dot(position(variant.tetrahedra(t, 3)) - a);
  };
  const auto at_rest = [&](int n) -> Eigen::Vector3d { return rest.row(n).transpose(); };
  const auto moved = [&](int n) -> Eigen::Vector3d { return x.segment<3>(3 * n); };
  int inverted = 0;
  for (Eigen::Index t = 0; t < variant.tetrahedra.rows(); ++t)
    if (signed_volume(moved, t) * signed_volume(at_rest, t) <= 0.0) ++inverted;
  return inverted;
}

namespace {

// A built-in variant's network from the case: its builder, E (the case's or the CT's field), the
// shared supports, the case's group scales and volume preservation.
void build_builtin(BuiltVariant& variant, cases::Variant kind, const Problem& problem,
                   const fem_reference::VolumeMesh& mesh) {
  const auto& p = problem.parameters;
  ms::SpringNetwork network = build_network(kind, problem, mesh);
  variant.youngs_modulus_range.include(p.material.youngs_modulus_pa);
  if (problem.youngs_modulus_image)
    variant.youngs_modulus_range = ms::apply_modulus_field(network, youngs_modulus_field(problem),
                                                           p.material.youngs_modulus_pa);
  const detail::BuiltinVariant& row = detail::builtin_variant(kind);
  if (row.on_fem_mesh) variant.tetrahedra = mesh.tetrahedra;
  if (problem.local_refinement)
    variant.refinement_added_nodes = row.surface_copies * problem.local_refinement->added_vertices;
  for (const std::string& w : network.warnings)
    variant.warnings.push_back({Warning::Kind::network, w});
  variant.model = std::make_unique<ms::MassSpringModel>(std::move(network));
  ms::MassSpringModel& model = *variant.model;
  const auto& rest = model.network().rest_positions;
  for (int node = 0; node < model.num_nodes(); ++node)
    if (problem.fixed_region(rest.row(node).transpose())) model.fix_node(node);
  scale_groups(model, p);
  if (p.mass_spring.volume_preservation) set_volume_preservation(variant, problem);
  model.set_damping(ms::damping_for_ratio(model.network(), p.mass_spring.damping_ratio));
}

}  // namespace

BuiltVariant build_variant(const VariantSpec& spec, const Problem& problem,
                           const fem_reference::VolumeMesh& mesh,
                           const std::optional<ToolPlacement>& tool) {
  const auto& p = problem.parameters;
  BuiltVariant variant;
  variant.spec = spec;
  variant.name = spec.name;
  variant.case_surface_vertices = problem.surface.num_vertices();
  try {
    if (spec.builtin)
      build_builtin(variant, *spec.builtin, problem, mesh);
    else
      build_network_variant(variant, problem);
    ms::MassSpringModel& model = *variant.model;
    if (model.constrained_nodes().empty() && model.network().num_anchors() == 0)
      throw cases::InputError(p.file.string() + ": variant " + variant.name +
                              ": no node lies in the fixed region and nothing anchors it, so it "
                              "would float away (adjust the support or the variant's geometry)");
    model.set_gravity(p.loads.gravity_m_per_s2);
    apply_patch_force(model, problem);
    if (tool) set_tool_depth(variant, *tool);
  } catch (const ms::ModelError& e) {
    throw cases::InputError(p.file.string() + ": variant " + variant.name + ": " + e.what());
  }
  return variant;
}

BuiltVariant build_variant(cases::Variant kind, const Problem& problem,
                           const fem_reference::VolumeMesh& mesh,
                           const std::optional<ToolPlacement>& tool) {
  return build_variant(builtin_spec(kind), problem, mesh, tool);
}

void scale_groups(massspring::MassSpringModel& model, const cases::CaseParameters& p) {
  const auto& names = model.network().spring_group_names;
  for (const auto& [group, factor] : p.mass_spring.group_scales)
    if (std::find(names.begin(), names.end(), group) != names.end())
      model.scale_group_stiffness(group, factor);  // else a group of another variant
}

StaticSolution solve_variant_static(const BuiltVariant& variant, const Eigen::VectorXd& start) {
  const ms::MassSpringModel& model = *variant.model;
  const auto clock_start = Clock::now();
  ms::StaticOptions options;
  // A sparse factorisation's fill-in grows quickly with the brain-scale networks; CG does not.
  if (model.num_nodes() > 500000) options.linear_solver = ms::StaticLinearSolver::cg;
  // Supernodal: on the brain's tet_edges network SimplicialLDLT took ~90 % of the statics.
  options.factorization = cholmod_factorization();
  ms::StaticResult r;
  try {
    r = ms::solve_static(model, options, start);
  } catch (const ms::ModelError& e) {
    // A singular tangent at some Newton iterate is this load's solver failing (the supports were
    // checked when the variant was built): the variant fails, the run goes on.
    throw std::runtime_error("variant " + variant.name + ": " + e.what());
  }
  StaticSolution solution;
  solution.solve_time_s = seconds_since(clock_start);
  if (!r.converged)
    throw std::runtime_error("variant " + variant.name + ": Newton did not converge in " +
                             std::to_string(r.iterations) + " iterations (residual " +
                             scientific(r.residual_norm) + " N)");
  solution.x = r.x;
  solution.newton_iterations = r.iterations;
  solution.surface_displacement =
      model.surface_displacement(r.x).topRows(variant.case_surface_vertices);
  if (!variant.tool_patch.empty())
    solution.tool_force = ms::patch_reaction_force(model, r.x, variant.tool_patch);
  else if (model.contact())
    solution.tool_force = ms::contact_reaction_force(model, r.x);
  return solution;
}

}  // namespace msfem::compare
