#include "msfem/compare/pipeline/problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/network_file.hpp"
#include "msfem/cases/surface_from_image.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_refinement.hpp"
#include "msfem/cases/surface_simplification.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "msfem/cases/units.hpp"
#include "msfem/fem_reference/closest_point.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"

namespace msfem::compare {
namespace {

// A surface in millimetres read as metres is a 100 m organ that meshes and solves without error:
// say so (on stderr and in the report) when the size is outside what an organ or a tissue sample
// can be.
void warn_if_not_organ_sized(const cases::CaseParameters& p, const cases::Surface& s,
                             std::vector<std::string>& notes) {
  const Eigen::Matrix<double, 2, 3> box = cases::bounding_box(s);
  const double size = (box.row(1) - box.row(0)).maxCoeff();
  if (size >= 1e-3 && size <= 1.0) return;
  char text[256];
  std::snprintf(text, sizeof text,
                "the surface spans %.3g m (geometry/unit = %s): organs are 1 mm to 1 m; is the "
                "unit right?",
                size, cases::to_string(p.geometry.unit).c_str());
  notes.push_back(text);
  std::cerr << "msfem: warning: " << p.file.string() << ": " << text << "\n";
}

// The organ of a NIfTI image, as extracted; the case's own simplification and smoothing follow.
// The extraction's refusals name the image; the case file and key are put before them.
cases::Surface surface_of_image(const cases::CaseParameters& p, std::vector<std::string>& notes) {
  const std::string& source = p.geometry.source;
  const cases::ImageSource image = cases::parse_image_source(source);
  cases::ImageSurface extracted;
  try {
    extracted = cases::surface_from_image(image.file, {image.selection, 0, 0});
  } catch (const cases::InputError& e) {
    throw cases::InputError(p.file.string() + ": geometry/source = " + source + ": " + e.what());
  }
  for (const auto& note : extracted.notes)
    notes.push_back(note);
  notes.push_back("extracted " + std::to_string(extracted.surface.num_vertices()) +
                  " vertices from " + image.selection.describe() + " of " + image.file.string());
  return std::move(extracted.surface);
}

cases::Surface load_surface(const cases::CaseParameters& p, std::vector<std::string>& notes) {
  const auto& g = p.geometry;
  cases::Surface s = source_surface(p, notes);
  if (g.simplify_to_vertices > s.num_vertices())
    throw cases::InputError(p.file.string() + ": geometry/simplify to vertices = " +
                            std::to_string(g.simplify_to_vertices) + " is more than the " +
                            std::to_string(s.num_vertices()) + " vertices of " + g.source +
                            " (simplification only removes vertices; 0 keeps the surface)");
  if (g.simplify_to_vertices > 0 && g.simplify_to_vertices < s.num_vertices()) {
    const auto before = s.num_vertices();
    try {
      s = cases::simplify(s, g.simplify_to_vertices);
    } catch (const std::exception& e) {
      throw cases::InputError(p.file.string() + ": geometry/simplify to vertices: " + e.what());
    }
    notes.push_back("simplified from " + std::to_string(before) + " to " +
                    std::to_string(s.num_vertices()) + " vertices");
  }
  if (g.smoothing_iterations > 0) cases::smooth_taubin(s, g.smoothing_iterations);
  const cases::SurfaceReport report = cases::orient_and_validate(s);
  for (const auto& f : report.fixes)
    notes.push_back(f);
  if (!report.ok())
    throw cases::InputError(p.file.string() + ": surface " + g.source + " is not a valid closed " +
                            "surface: " + report.defects.front().message);
  warn_if_not_organ_sized(p, s, notes);
  return s;
}

std::function<bool(const Eigen::Vector3d&)> fixed_region(const cases::CaseParameters& p,
                                                         const cases::Surface& s,
                                                         const Eigen::Vector3d& centroid) {
  using Kind = cases::SupportParameters::Kind;
  const auto& sp = p.support;
  switch (sp.kind) {
    case Kind::inner_core: {
      const auto inside = fem_reference::inner_core(s.vertices, s.triangles, sp.inner_core_scale);
      // Nodes exactly on the core's boundary (the layered model's inner tier, skeleton points drawn
      // to the same scale) count as inside: test a point a hair closer to the centroid.
      return [inside, centroid](const Eigen::Vector3d& x) {
        return inside(centroid + (1.0 - 1e-9) * (x - centroid));
      };
    }
    case Kind::half_space:
      return fem_reference::half_space(sp.half_space_point, sp.half_space_normal);
    case Kind::sphere:
      return fem_reference::ball(sp.sphere_center, sp.sphere_radius_m);
  }
  throw cases::InputError(p.file.string() + ": unknown support kind");
}

ToolPlacement place_tool(const cases::CaseParameters& p, const cases::Surface& s,
                         const Eigen::MatrixX3d& normals, const Eigen::Vector3d& centroid,
                         const Eigen::Vector3d& direction) {
  const int best = farthest_vertex(s, centroid, direction);
  ToolPlacement t;
  t.vertex = best;
  t.contact_point = s.vertices.row(best).transpose();
  t.outward_normal = normals.row(best).transpose();
  t.radius = p.loads.tool.radius_m;
  t.depth = p.loads.tool.depth_m;
  const Eigen::Vector3d extent = (cases::bounding_box(s).row(1) - cases::bounding_box(s).row(0));
  if (t.depth >= 0.5 * extent.minCoeff())
    throw cases::InputError(p.file.string() + ": loads/tool/depth " + std::to_string(t.depth) +
                            " m is not small against the model (smallest extent " +
                            std::to_string(extent.minCoeff()) + " m)");
  return t;
}

/// The closest approach of the surface to `center`.
double distance_to_surface(const cases::Surface& s, const Eigen::Vector3d& center) {
  return (closest_surface_point(s, center).point - center).norm();
}

}  // namespace

SurfacePoint closest_surface_point(const cases::Surface& s, const Eigen::Vector3d& x) {
  SurfacePoint best;
  double nearest = std::numeric_limits<double>::infinity();
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t) {
    const Eigen::Vector3d a = s.vertices.row(s.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = s.vertices.row(s.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = s.vertices.row(s.triangles(t, 2)).transpose();
    const Eigen::Vector3d q = fem_reference::closest_point_on_triangle(x, a, b, c);
    const double d = (q - x).squaredNorm();
    if (!(d < nearest)) continue;
    nearest = d;
    best.point = q;
    best.triangle = static_cast<int>(t);
    // Barycentric weights of q (Ericson 3.4), for interpolating vertex values there.
    const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = q - a;
    const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
    const double d20 = v2.dot(v0), d21 = v2.dot(v1), den = d00 * d11 - d01 * d01;
    const double wb = den > 0 ? (d11 * d20 - d01 * d21) / den : 0.0;
    const double wc = den > 0 ? (d00 * d21 - d01 * d20) / den : 0.0;
    best.weights = {1.0 - wb - wc, wb, wc};
  }
  return best;
}

namespace {

// A contact tool must start outside the body (touching it) and reach it at full depth: a sphere
// already inside would be pushed out, not in, and one that misses compares nothing.
void check_contact_start(const cases::CaseParameters& p, const cases::Surface& s,
                         const ToolPlacement& t, const Eigen::Vector3d& d) {
  const std::string where = p.file.string() + ": loads/tool: the contact tool at direction (" +
                            std::to_string(d.x()) + ", " + std::to_string(d.y()) + ", " +
                            std::to_string(d.z()) + ")";
  const double start = distance_to_surface(s, t.contact_point + t.radius * t.outward_normal);
  if (start < (1 - 1e-3) * t.radius)
    throw cases::InputError(where +
                            " starts inside the body: before it is pushed the surface comes " +
                            std::to_string(t.radius - start) + " m inside its sphere (radius " +
                            std::to_string(t.radius) +
                            " m; the surface is concave there: choose another direction "
                            "or a smaller radius)");
  if (distance_to_surface(s, t.pushed_center()) >= t.radius)
    throw cases::InputError(where + " misses the body at depth " + std::to_string(t.depth) + " m");
}

// A patch force that pulls only fixed nodes moves nothing in either model: the comparison would
// divide by a reference that does not move.
void check_patch_force(const Problem& problem) {
  const auto& p = problem.parameters;
  const std::vector<int> patch = patch_vertices(problem);
  const auto free = std::count_if(patch.begin(), patch.end(), [&](int v) {
    return !problem.fixed_region(problem.surface.vertices.row(v).transpose());
  });
  if (free == 0) {
    const Eigen::Vector3d& d = p.loads.patch_force.direction;
    throw cases::InputError(
        p.file.string() + ": loads/patch force/direction (" + std::to_string(d.x()) + ", " +
        std::to_string(d.y()) + ", " + std::to_string(d.z()) + "): all " +
        std::to_string(patch.size()) +
        " surface vertices of the patch lie in the fixed region (support/fixed region): the "
        "force would move nothing; point the patch at a free part of the surface");
  }
}

// A local point distribution at the tool: the surface both models are built on gets edges no longer
// than `edge` within `radius` of every tool, so a tool between the coarse nodes meets several.
void refine_at_tools(Problem& problem) {
  const auto& p = problem.parameters;
  const auto& r = p.mass_spring.contact_refinement;
  if (!r.enabled) return;
  if (problem.tools.empty())
    throw cases::InputError(p.file.string() +
                            ": mass spring/contact refinement/enabled = true refines around the "
                            "tool, but loads/tool is off");
  double tool_radius = 0;
  for (const ToolPlacement& t : problem.tools)
    tool_radius = std::max(tool_radius, t.radius);
  LocalRefinement local;
  local.radius_m = r.radius_m > 0 ? r.radius_m : 2 * tool_radius;
  local.edge_m = r.edge_m > 0 ? r.edge_m : tool_radius / 3;
  // Each ball's cap needs about its area over a triangle's (√3/4 h²) triangles, half as many
  // vertices: refuse before bisecting what no model could solve.
  const double per_tool = M_PI * local.radius_m * local.radius_m /
                          (std::sqrt(3.0) / 4 * local.edge_m * local.edge_m) / 2;
  if (per_tool * double(problem.tools.size()) > 2e6)
    throw cases::InputError(p.file.string() + ": mass spring/contact refinement: edge length " +
                            std::to_string(local.edge_m) + " m within " +
                            std::to_string(local.radius_m) + " m of " +
                            std::to_string(problem.tools.size()) + " tool(s) would add about " +
                            std::to_string(std::lround(per_tool * problem.tools.size())) +
                            " surface vertices (at most 2,000,000): choose a longer edge");
  std::vector<cases::RefinementBall> balls;
  for (const ToolPlacement& t : problem.tools)
    balls.push_back({t.contact_point, local.radius_m});
  cases::SurfaceRefinement refined = cases::refine_near(problem.surface, balls, local.edge_m);
  local.added_vertices = refined.added_vertices;
  char text[256];
  std::snprintf(text, sizeof text,
                "surface refined to edges <= %.3g m within %.3g m of each tool (mass spring/"
                "contact refinement): %d vertices added",
                local.edge_m, local.radius_m, local.added_vertices);
  problem.notes.push_back(text);
  problem.surface = std::move(refined.surface);
  problem.local_refinement = local;
}

// Below this fraction of the model's smallest extent a tool's depth moves the surface by about the
// solvers' own tolerance: the forces are round-off and every error reads 1.
constexpr double smallest_depth_fraction = 1e-4;
// A load whose small-strain estimate moves the surface by more than this many of the model's
// smallest extents is outside what a linear-elastic reference (or a comparison with it) can say.
constexpr double largest_strain_estimate = 5.0;

void check_tool_depths(const cases::CaseParameters& p, double extent) {
  const auto& tool = p.loads.tool;
  const double least = smallest_depth_fraction * extent;
  std::vector<std::pair<std::string, double>> depths = {{"loads/tool/depth", tool.depth_m}};
  for (double d : tool.curve_depths_m)
    depths.emplace_back("loads/tool/curve depths", d);
  for (const auto& [key, depth] : depths)
    if (!(depth >= least)) {
      char text[320];
      std::snprintf(text, sizeof text,
                    ": %s = %g m is below %g m (1e-4 of the model's smallest extent, %g m): the "
                    "tool would move the surface by about the solvers' tolerance",
                    key.c_str(), depth, least, extent);
      throw cases::InputError(p.file.string() + text);
    }
}

// Gravity and a patch force, estimated as linear elasticity would size them before anything is
// solved: self-weight sags about rho |g| L^2 / E (L the smallest extent), a pressure on a disc of
// radius a moves it about 2 (1 - nu^2) F / (pi a E) (Timoshenko & Goodier, the uniformly loaded
// circle).
void check_load_magnitudes(const cases::CaseParameters& p, double extent) {
  const auto& m = p.material;
  const double e = m.youngs_modulus_pa;
  const double gravity =
      m.density_kg_per_m3 * p.loads.gravity_m_per_s2.norm() * extent * extent / e;
  const auto& patch = p.loads.patch_force;
  const double pull = patch.enabled ? 2 * (1 - m.poisson_ratio * m.poisson_ratio) *
                                          patch.force_n.norm() / (M_PI * patch.radius_m * e)
                                    : 0.0;
  for (const auto& [key, estimate] : {std::pair<const char*, double>{"loads/gravity", gravity},
                                      {"loads/patch force/force", pull}})
    if (estimate > largest_strain_estimate * extent) {
      char text[400];
      std::snprintf(text, sizeof text,
                    ": %s would move the surface about %.3g m with material/youngs modulus = %g "
                    "Pa, %.3g times the model's smallest extent (%.3g m): far outside the small "
                    "strains a linear-elastic reference holds for",
                    key, estimate, e, estimate / extent, extent);
      throw cases::InputError(p.file.string() + text);
    }
}

void check_loads_in_range(const cases::CaseParameters& p, const cases::Surface& s) {
  const Eigen::Matrix<double, 2, 3> box = cases::bounding_box(s);
  const Eigen::Vector3d extent = (box.row(1) - box.row(0)).transpose();
  if (p.loads.tool.enabled) check_tool_depths(p, extent.minCoeff());
  check_load_magnitudes(p, extent.minCoeff());
}

// The CT whose HU give E, checked to cover the organ: a surface outside the scan (another
// patient's image, millimetres read as metres) would take E from the image's edge unnoticed.
void load_youngs_modulus_image(Problem& problem) {
  const auto& m = problem.parameters.material;
  if (m.youngs_modulus_image.empty()) return;
  const std::string key = problem.parameters.file.string() + ": material/youngs modulus image";
  try {
    problem.youngs_modulus_image = std::make_shared<const cases::YoungsModulusImage>(
        m.youngs_modulus_image, cases::parse_hu_to_youngs(m.hu_to_youngs, "material/hu to youngs"));
  } catch (const cases::InputError& e) {
    throw cases::InputError(key + ": " + e.what());
  }
  // One voxel of slack: an organ the scan clips is closed one voxel layer outside the scan.
  const cases::Surface& s = problem.surface;
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v)
    if (!problem.youngs_modulus_image->contains(s.vertices.row(v).transpose(), 1.0))
      throw cases::InputError(
          key + ": surface vertex " + std::to_string(v) + " at (" +
          std::to_string(s.vertices(v, 0)) + ", " + std::to_string(s.vertices(v, 1)) + ", " +
          std::to_string(s.vertices(v, 2)) +
          ") m lies outside the image (are the surface and the image in the same world "
          "coordinates?)");
}

}  // namespace

fem_reference::Support tool_patch_support(const ToolPlacement& tool) {
  const Eigen::Vector3d center = tool.pushed_center();
  const Eigen::Vector3d inward = -tool.outward_normal.normalized();
  const double r = tool.radius;
  fem_reference::Support support;
  support.name = "tool";
  support.boundary_nodes_only = true;
  support.region = [center, r](const Eigen::Vector3d& x) { return (x - center).norm() < r; };
  // Largest t with |x + t n − c| = r: t = −w·n + sqrt((w·n)² − |w|² + r²), w = x − c.
  support.displacement = [center, inward, r](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    const Eigen::Vector3d w = x - center;
    const double wn = w.dot(inward);
    const double t = -wn + std::sqrt(std::max(0.0, wn * wn - w.squaredNorm() + r * r));
    return t * inward;
  };
  return support;
}

int farthest_vertex(const cases::Surface& surface, const Eigen::Vector3d& centroid,
                    const Eigen::Vector3d& direction) {
  const Eigen::MatrixX3d from_centroid = surface.vertices.rowwise() - centroid.transpose();
  const Eigen::VectorXd along = from_centroid * direction;
  Eigen::Index best = 0;
  const double farthest = along.maxCoeff(&best);
  // On a flat face many vertices are as far (a box's side, a grid's end): the one nearest the
  // line through the centroid, the middle of the face, rather than whichever comes first.
  const double tie = 1e-12 * from_centroid.rowwise().norm().maxCoeff();
  const auto off_line = [&](Eigen::Index v) {
    return (from_centroid.row(v).transpose() - along[v] * direction).norm();
  };
  for (Eigen::Index v = 0; v < along.size(); ++v)
    if (along[v] >= farthest - tie && off_line(v) < off_line(best) - tie) best = v;
  return static_cast<int>(best);
}

std::vector<int> patch_vertices(const Problem& problem) {
  const auto& patch = problem.parameters.loads.patch_force;
  std::vector<int> vertices;
  if (!patch.enabled) return vertices;
  const auto& s = problem.surface;
  const int center = farthest_vertex(s, problem.centroid, patch.direction);
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v)
    if ((s.vertices.row(v) - s.vertices.row(center)).norm() <= patch.radius_m)
      vertices.push_back(int(v));
  return vertices;
}

Eigen::Vector3d mean_displacement(const Eigen::MatrixX3d& displacement,
                                  const std::vector<int>& vertices) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int v : vertices)
    sum += displacement.row(v).transpose();
  return vertices.empty() ? sum : Eigen::Vector3d(sum / double(vertices.size()));
}

double volume_change(const cases::Surface& surface, const Eigen::MatrixX3d& displacement) {
  cases::Surface deformed = surface;
  deformed.vertices += displacement;
  return cases::signed_volume(deformed) / cases::signed_volume(surface) - 1.0;
}

ToolPlacement at_depth(ToolPlacement tool, double depth) {
  tool.depth = depth;
  return tool;
}

cases::Surface source_surface(const cases::CaseParameters& p, std::vector<std::string>& notes) {
  const auto& g = p.geometry;
  if (cases::is_network_source(g.source))
    return cases::network_surface(cases::network_source_file(g.source));
  return cases::is_surface_generator(g.source) ? cases::generate_surface(g.source)
         : cases::is_image_source(g.source)    ? surface_of_image(p, notes)
                                               : cases::read_surface(g.source, g.unit);
}

double youngs_modulus_at(const Problem& problem, const Eigen::Vector3d& x) {
  return problem.youngs_modulus_image ? (*problem.youngs_modulus_image)(x)
                                      : problem.parameters.material.youngs_modulus_pa;
}

Problem make_problem(const cases::CaseParameters& parameters) {
  Problem problem;
  problem.parameters = parameters;
  problem.surface = load_surface(parameters, problem.notes);
  const cases::Surface& s = problem.surface;
  problem.centroid = cases::vertex_centroid(s);
  problem.fixed_region = fixed_region(parameters, s, problem.centroid);

  int fixed_surface_nodes = 0;
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v)
    fixed_surface_nodes += problem.fixed_region(s.vertices.row(v).transpose());
  if (fixed_surface_nodes == s.num_vertices())
    throw cases::InputError(parameters.file.string() +
                            ": support: the fixed region contains the whole surface");

  check_loads_in_range(parameters, s);
  if (parameters.loads.tool.enabled) {
    const Eigen::MatrixX3d normals = cases::vertex_normals(s);
    for (const auto& d : parameters.loads.tool.directions) {
      ToolPlacement t = place_tool(parameters, s, normals, problem.centroid, d);
      if (problem.fixed_region(t.contact_point))
        throw cases::InputError(parameters.file.string() + ": loads/tool: the tool at direction (" +
                                std::to_string(d.x()) + ", " + std::to_string(d.y()) + ", " +
                                std::to_string(d.z()) + ") presses on a fixed node");
      t.frictionless = parameters.loads.tool.mode == cases::ToolParameters::Mode::contact;
      if (t.frictionless) check_contact_start(parameters, s, t, d);
      problem.tools.push_back(t);
    }
  }
  refine_at_tools(problem);
  load_youngs_modulus_image(problem);
  if (parameters.loads.patch_force.enabled) check_patch_force(problem);
  if (problem.tools.empty() && !parameters.loads.patch_force.enabled &&
      !(parameters.loads.gravity_m_per_s2.norm() > 0))
    throw cases::InputError(parameters.file.string() +
                            ": loads: no tool, patch force or gravity: nothing deforms the model");
  return problem;
}

}  // namespace msfem::compare
