#include "pipeline/builtin_variants.hpp"

#include <algorithm>
#include <stdexcept>

#include "msfem/cases/surface_simplification.hpp"

namespace msfem::compare::detail {
namespace {

namespace ms = msfem::massspring;

// --- three_tier: the surface and two inward copies (the brain seed) ---

ms::ThreeTierOptions three_tier_options(const cases::CaseParameters& p) {
  ms::ThreeTierOptions o;
  o.inner_tiers = p.mass_spring.inner_tiers;
  o.tier2_scale = p.mass_spring.middle_tier_scale;
  o.tier3_scale = p.mass_spring.inner_tier_scale;
  o.tier23_diagonals = p.mass_spring.inner_diagonals;
  return o;
}

ms::SpringNetwork three_tier_network(const Problem& problem, const fem_reference::VolumeMesh&,
                                     const ms::Material& material) {
  ms::ThreeTierOptions o = three_tier_options(problem.parameters);
  o.center = problem.centroid;  // the support's, which a refined surface's would miss
  o.material = material;
  return ms::build_three_tier(problem.surface.vertices, problem.surface.triangles, o);
}

// The shell prisms between tier 1 and tier 2 and between tier 2 and tier 3.
ms::VolumeElements three_tier_prisms(const Eigen::MatrixX3d& rest, const Problem& problem,
                                     const Eigen::MatrixX4i&, double modulus) {
  return ms::tier_prisms(rest, problem.surface.triangles,
                         static_cast<int>(problem.surface.num_vertices()), 3, modulus);
}

// --- single_layer: the surface's edges alone ---

ms::SingleLayerOptions single_layer_options() {
  ms::SingleLayerOptions o;
  // Every node not supported is tied to its rest position (as simulators' rest-shape springs
  // do; the supported ones are fixed, so their anchors do nothing). A bare membrane held only at
  // some nodes, like the brain's base, has no transverse stiffness at rest: Newton failed on it.
  o.anchor_to_rest = true;
  return o;
}

ms::SpringNetwork single_layer_network(const Problem& problem, const fem_reference::VolumeMesh&,
                                       const ms::Material& material) {
  ms::SingleLayerOptions o = single_layer_options();
  o.material = material;
  return ms::build_single_layer(problem.surface.vertices, problem.surface.triangles, o);
}

// --- tet_edges: a spring on every edge of the FEM's mesh (the volumetric baseline) ---

ms::TetEdgesOptions tet_edges_options(const cases::CaseParameters& p) {
  ms::TetEdgesOptions o;
  o.stiffness_rule = p.mass_spring.stiffness_model;
  return o;
}

ms::SpringNetwork tet_edges_network(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                                    const ms::Material& material) {
  ms::TetEdgesOptions o = tet_edges_options(problem.parameters);
  o.material = material;
  const Eigen::MatrixX4i tets = mesh.tetrahedra;
  return ms::build_tet_edges(mesh.vertices, tets, o);
}

ms::VolumeElements mesh_tetrahedra(const Eigen::MatrixX3d& rest, const Problem&,
                                   const Eigen::MatrixX4i& tetrahedra, double modulus) {
  return ms::tetrahedron_elements(rest, tetrahedra, modulus);
}

// --- skeleton: the surface and inner control points (the pancreas seed) ---

ms::SkeletonOptions skeleton_options(const cases::CaseParameters& p) {
  ms::SkeletonOptions o;
  o.control_scale = p.mass_spring.skeleton_draw_factor;
  return o;
}

ms::SpringNetwork skeleton_network(const Problem& problem, const fem_reference::VolumeMesh&,
                                   const ms::Material& material) {
  const auto& ms_p = problem.parameters.mass_spring;
  const auto& s = problem.surface;
  const int wanted = ms_p.skeleton_control_points > 0
                         ? ms_p.skeleton_control_points
                         : std::max(20, static_cast<int>(s.num_vertices() / 10));
  const cases::Surface control = cases::simplify(s, std::min<int>(wanted, s.num_vertices()));
  ms::SkeletonOptions o = skeleton_options(problem.parameters);
  o.center = problem.centroid;
  o.material = material;
  return ms::build_skeleton(s.vertices, s.triangles, control.vertices, control.triangles, o);
}

double surface_nodes(const Problem& problem) {
  return static_cast<double>(problem.surface.num_vertices());
}

const BuiltinVariant rows[] = {
    {cases::Variant::three_tier, three_tier_network,
     [](const cases::CaseParameters& p) { return ms::spring_groups(three_tier_options(p)); },
     [](const Problem& problem, const fem_reference::VolumeMesh&) {
       return 3.0 * surface_nodes(problem);
     },
     3, false, three_tier_prisms},
    {cases::Variant::single_layer, single_layer_network,
     [](const cases::CaseParameters&) { return ms::spring_groups(single_layer_options()); },
     [](const Problem& problem, const fem_reference::VolumeMesh&) {
       return surface_nodes(problem);
     },
     1, false, nullptr},
    {cases::Variant::tet_edges, tet_edges_network,
     [](const cases::CaseParameters& p) { return ms::spring_groups(tet_edges_options(p)); },
     [](const Problem&, const fem_reference::VolumeMesh& mesh) {
       return static_cast<double>(mesh.vertices.rows());
     },
     1, true, mesh_tetrahedra},
    {cases::Variant::skeleton, skeleton_network,
     [](const cases::CaseParameters& p) { return ms::spring_groups(skeleton_options(p)); },
     // The control points are about a tenth of the surface's vertices.
     [](const Problem& problem, const fem_reference::VolumeMesh&) {
       return 1.1 * surface_nodes(problem);
     },
     1, false, nullptr},
};

}  // namespace

const BuiltinVariant& builtin_variant(cases::Variant kind) {
  for (const BuiltinVariant& row : rows)
    if (row.kind == kind) return row;
  throw std::logic_error("builtin_variant: a variant without a row");
}

}  // namespace msfem::compare::detail
