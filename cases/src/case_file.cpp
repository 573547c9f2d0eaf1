// The case file language, declared once with deal.II's ParameterHandler (step-44 style): every key
// has a pattern and a documentation string, so `msfem params` can print the whole language. This is
// the only translation unit of cases/ that includes deal.II.
#include <deal.II/base/exceptions.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/patterns.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

#include "case_consistency.hpp"
#include "case_file_text.hpp"
#include "case_lists.hpp"
#include "case_paths.hpp"
#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/cases/modulus_image.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/surface_from_image.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/massspring/integrators.hpp"

namespace msfem::cases {
namespace {

using dealii::ParameterHandler;
namespace Patterns = dealii::Patterns;

const char* const default_output_directory = "results/runs";

Patterns::List point_pattern() {
  return Patterns::List(Patterns::Double(), 3, 3, ",");
}

void declare_geometry(ParameterHandler& prm) {
  prm.enter_subsection("geometry");
  prm.declare_entry("source", "icosphere:3:0.05", Patterns::Anything(),
                    "Closed surface: a file (.obj .stl .off .ply; relative to the case file), "
                    "a generator, icosphere:LEVEL[:RADIUS_M] or ellipsoid:LEVEL:A:B:C (metres), "
                    "or an organ of a NIfTI image, image:FILE:label=N or "
                    "image:FILE:threshold=LO[:HI] (FILE relative to the case file; unit unused), "
                    "or a network's own surface triangles, network:FILE (.vtu, .vtk; metres).");
  prm.declare_entry("unit", "m", Patterns::Selection(selection_of<LengthUnit>()),
                    "Unit of the surface file's coordinates; msfem works in metres.");
  prm.declare_entry("simplify to vertices", "0", Patterns::Integer(0),
                    "Edge-collapse the surface to this many vertices (0 keeps it as read).");
  prm.declare_entry("smoothing iterations", "0", Patterns::Integer(0, 1000),
                    "Taubin smoothing iterations applied after simplification.");
  prm.leave_subsection();
}

void declare_material(ParameterHandler& prm) {
  prm.enter_subsection("material");
  // Bounded so that an E of 1e300 is a clear input error, not an overflowing solver; soft tissue
  // is 0.1-100 kPa, and 1 TPa is above diamond.
  prm.declare_entry("youngs modulus", "3000", Patterns::Double(0, 1e12),
                    "Young's modulus E in Pa (brain 1.4-3 kPa, pancreas 1.4-4 kPa); in (0, 1e12].");
  prm.declare_entry("poisson ratio", "0.45", Patterns::Double(-0.999, 0.4999),
                    "Poisson's ratio; a plain spring network is exact only at 0.25.");
  prm.declare_entry("density", "1040", Patterns::Double(0, 1e5), "Density in kg/m^3; in (0, 1e5].");
  prm.declare_entry(
      "youngs modulus image", "", Patterns::Anything(),
      "A CT in Hounsfield units (.nii, .nii.gz; relative to the case file) giving E "
      "per voxel through 'hu to youngs', interpolated trilinearly: the FEM takes E at "
      "its quadrature points, each spring the series (harmonic) mean along it, each "
      "volume element E at its centroid. 'youngs modulus' is then only the scale "
      "the spring rules start from. Empty: E = 'youngs modulus' everywhere.");
  prm.declare_entry("hu to youngs", default_hu_to_youngs, Patterns::Anything(),
                    "HU:E points (E in Pa), HU increasing, linear between them and held beyond: "
                    "fat -100 HU 3 kPa, pancreas 40 HU 3.5 kPa, liver 60 HU 6 kPa by default.");
  prm.leave_subsection();
}

void declare_support(ParameterHandler& prm) {
  prm.enter_subsection("support");
  prm.declare_entry("fixed region", "inner core",
                    Patterns::Selection(selection_of<SupportParameters::Kind>()),
                    "Which nodes are fixed: inside the surface scaled by 1/scale about its "
                    "centroid, in a half space, or in a sphere.");
  prm.declare_entry("inner core scale", "2.0", Patterns::Double(1.0),
                    "The inner core is the surface scaled by 1/scale (> 1).");
  prm.declare_entry("half space point", "0,0,0", point_pattern(),
                    "A point on the half space's plane (m).");
  prm.declare_entry("half space normal", "0,0,-1", point_pattern(),
                    "Normal pointing into the fixed half space.");
  prm.declare_entry("sphere center", "0,0,0", point_pattern(), "Centre of the fixed sphere (m).");
  prm.declare_entry("sphere radius", "0", Patterns::Double(0), "Radius of the fixed sphere (m).");
  prm.leave_subsection();
}

void declare_loads(ParameterHandler& prm) {
  prm.enter_subsection("loads");
  prm.declare_entry("gravity", "0,0,0", point_pattern(), "Gravitational acceleration (m/s^2).");
  prm.enter_subsection("tool");
  prm.declare_entry("enabled", "true", Patterns::Bool(), "Press a rigid spherical tool.");
  prm.declare_entry(
      "mode", "bonded", Patterns::Selection(selection_of<ToolParameters::Mode>()),
      "contact: frictionless contact in both models (the FEM's surface nodes may not enter the "
      "sphere and are pushed only; the springs' surface triangles feel its pressure), what a "
      "haptic device renders. bonded (alias prescribed): every surface node inside the pushed "
      "sphere is moved onto it and held, an adhesive patch that underestimates the force (0.5-0.7 "
      "of Hertz on a half-space, msfem verify hertz_bonded_p2).");
  prm.declare_entry(
      "directions", "0,0,1", Patterns::List(point_pattern(), 1, Patterns::List::max_int_value, ";"),
      "Where the tool presses, one indentation per entry (';'-separated): the surface "
      "vertex farthest from the centroid along each direction.");
  prm.declare_entry("radius", "0.005", Patterns::Double(0), "Tool radius (m).");
  prm.declare_entry("depth", "0.005", Patterns::Double(0),
                    "Indentation depth along the inward normal (m).");
  prm.declare_entry("curve depths", "", Patterns::List(Patterns::Double(0)),
                    "Depths (m) of the force-depth curve; empty: a quarter, half, three quarters "
                    "and all of the depth.");
  prm.declare_entry("path step", "0", Patterns::Double(0),
                    "Largest depth increment (m) of the spring variants' quasi-static loading "
                    "path through the curve depths: steps in between are solved, each from the "
                    "last, and are points of the variant's force-depth curve. 0: the curve "
                    "depths only.");
  prm.leave_subsection();
  prm.enter_subsection("patch force");
  prm.declare_entry("enabled", "false", Patterns::Bool(), "Pull a surface patch.");
  prm.declare_entry("direction", "1,0,0", point_pattern(),
                    "The patch is centred on the vertex farthest along this direction.");
  prm.declare_entry("radius", "0.01", Patterns::Double(0), "Patch radius (m).");
  prm.declare_entry("force", "0,0,0", point_pattern(), "Total force on the patch (N).");
  prm.leave_subsection();
  prm.leave_subsection();
}

void declare_mass_spring(ParameterHandler& prm) {
  prm.enter_subsection("mass spring");
  prm.declare_entry("variants", "three_tier, single_layer, tet_edges, skeleton",
                    Patterns::List(Patterns::Selection(selection_of<Variant>()), 0),
                    "Mass-spring variants to build and compare with the FEM (may be empty when "
                    "networks are given).");
  prm.declare_entry("networks", "", Patterns::Anything(),
                    "A user's own networks, NAME=FILE separated by ';' (.vtu, .vtk, .xs3; "
                    "relative to the case file), each compared as a variant named NAME "
                    "(docs/networks.md).");
  prm.declare_entry("results", "", Patterns::Anything(),
                    "An outside simulator's answers, NAME=FILE[,FILE...] separated by ';': one "
                    "deformed surface per load (docs/external.md).");
  prm.declare_entry("stiffness model", "lloyd",
                    Patterns::Selection(selection_of<massspring::TetStiffnessRule>()),
                    "Analytic starting stiffness: Lloyd et al. 2007 or van Gelder 1998.");
  prm.declare_entry("damping ratio", "0.5", Patterns::Double(0),
                    "Spring dampers as a fraction of critical damping.");
  prm.declare_entry("group scales", "", Patterns::List(Patterns::Anything()),
                    "Per spring group stiffness factors, GROUP:FACTOR, e.g. tier1_edges:1.5 "
                    "(volume:FACTOR scales the volume preservation modulus).");
  prm.declare_entry("volume preservation", "false", Patterns::Bool(),
                    "Add the energy 1/2 k (V - V0)^2 / |V0| of every shell prism (three_tier) and "
                    "tetrahedron (tet_edges), k = lambda(E, nu) - lambda(E, 1/4): the bulk "
                    "stiffness a network of central springs lacks (its Poisson's ratio is 1/4). "
                    "msfem calibrate can fit it as the group 'volume'.");
  prm.enter_subsection("three tier");
  prm.declare_entry("middle tier scale", "1.2", Patterns::Double(1.0),
                    "Tier 2 is the surface scaled by 1/scale about its centroid.");
  prm.declare_entry("inner tier scale", "2.0", Patterns::Double(1.0),
                    "Tier 3 (fixed) is the surface scaled by 1/scale.");
  prm.declare_entry("inner tiers", "scaled",
                    Patterns::Selection(selection_of<massspring::InnerTierMethod>()),
                    "scaled (the seed), offset along the inward normal, or distance_field (no "
                    "prism folds, no tier leaves the one above; shallow in thin folds).");
  prm.declare_entry("inner diagonals", "false", Patterns::Bool(),
                    "Crossing diagonals between tier 2 and tier 3 as between tiers 1 and 2 "
                    "(group tier23_diagonals). The seed links tier 2 to the fixed tier 3 by radial "
                    "springs only, so the outer shell turns about the core under any lateral "
                    "force; false keeps the seed's springs.");
  prm.leave_subsection();
  prm.enter_subsection("skeleton");
  prm.declare_entry("control points", "0", Patterns::Integer(0),
                    "Number of skeleton control points (0: a tenth of the surface vertices, at "
                    "least 20).");
  // 0.45, not 0.5: with the default support (the inner core at 1/2 scale) the control points then
  // lie inside the fixed core, and the default case runs as `msfem params` prints it.
  prm.declare_entry("draw factor", "0.45", Patterns::Double(0.0, 1.0),
                    "Control points are drawn toward the centroid by this factor.");
  prm.leave_subsection();
  prm.enter_subsection("contact refinement");
  prm.declare_entry("enabled", "false", Patterns::Bool(),
                    "Refine the case's surface around each tool before the models are built (a "
                    "local point distribution, after the layered brain paper's), so a tool "
                    "between the coarse surface's nodes meets several. Both models use the "
                    "refined surface; summary.json says how many nodes it added per variant.");
  prm.declare_entry("radius", "0", Patterns::Double(0),
                    "Radius (m) around each tool's contact point; 0: twice the tool radius.");
  prm.declare_entry("edge length", "0", Patterns::Double(0),
                    "Longest surface edge (m) inside that radius; 0: the tool radius / 3 (the "
                    "FEM's default tool cell size, so both share the surface nodes there).");
  prm.leave_subsection();
  prm.leave_subsection();
}

void declare_fem_timing_output(ParameterHandler& prm) {
  prm.enter_subsection("fem");
  prm.declare_entry("degree", "2", Patterns::Integer(1, 2),
                    "Polynomial degree of the simplex elements (P1 locks near ν = 0.5).");
  prm.declare_entry("cell size", "0", Patterns::Double(0),
                    "Target tetrahedron size (m); 0: the surface's mean edge length.");
  prm.declare_entry("solver", "cg_gamg", Patterns::Selection(selection_of<FemSolver>()),
                    "PETSc solver: CG with GAMG (rigid-body near-null space; at degree 2 GAMG "
                    "acts on the mesh's P1 level below a Chebyshev-smoothed P2 level), CG with "
                    "hypre BoomerAMG, or the MUMPS direct solver.");
  prm.declare_entry("relative tolerance", "1e-10", Patterns::Double(0, 1),
                    "Relative residual at which the iterative solver stops.");
  prm.declare_entry(
      "refine at tool", "true", Patterns::Bool(),
      "Bisect the FEM's surface triangles within 2 r of each tool (the case's own "
      "vertices are kept, so errors stay node to node) and grade the volume to match, "
      "so the reference resolves the contact patch even where the spring surface "
      "catches one node; without it a coarse surface makes the FEM a point load, "
      "whose answer depends on the mesh and the degree.");
  prm.declare_entry("tool cell size", "0", Patterns::Double(0),
                    "Edge length (m) of the refined surface at the tool; 0: tool radius / 3.");
  prm.declare_entry(
      "error estimate", "auto", Patterns::Selection(selection_of<FemParameters::ErrorEstimate>()),
      "The reference's own discretisation error, from a second solve of each tool load: refine "
      "(the same degree on the mesh with every tetrahedron split into eight), degree (degree 2 "
      "on the same mesh; needs degree = 1), lower_degree (degree 1 on the same mesh; needs "
      "degree = 2: the difference bounds the reference's error from above), none. auto: degree "
      "at degree 1; refine at degree 2 for every load if that costs at most 3x the reference's "
      "own solves (or the refined problem is small), else for as many loads as fit in that "
      "budget; lower_degree at degree 2 where no refined solve fits. Variants within 3x of it "
      "are flagged 'not resolved by this reference'.");
  prm.leave_subsection();
  prm.enter_subsection("timing");
  prm.declare_entry("integrator", "symplectic_euler",
                    Patterns::Selection(selection_of<massspring::IntegratorKind>()),
                    "Integrator whose steps are timed.");
  prm.declare_entry("dt", "0", Patterns::Double(0),
                    "Time step (s); 0: half the estimated stable step of each variant.");
  prm.declare_entry(
      "steps", "2000", Patterns::Integer(1, 100000000),
      "Dynamic steps timed, at least (five samples of a fifth of them and of 0.1 s each).");
  prm.declare_entry("precision", "double", Patterns::Selection("double|float"),
                    "Arithmetic of the fast steppers timed (and of msfem haptic's model thread): "
                    "double, or float (twice the vector lanes; positions kept as displacements "
                    "from the rest shape).");
  prm.leave_subsection();
  prm.enter_subsection("output");
  prm.declare_entry("directory", default_output_directory, Patterns::Anything(),
                    "Folder under which each run writes <case>-<time>/ (and its .fem-cache); "
                    "relative to the case file when set in it, to the working directory when "
                    "left at the default or given with --set.");
  prm.leave_subsection();
}

void declare_calibration(ParameterHandler& prm) {
  prm.enter_subsection("calibration");
  // The empty first choice is "not set".
  prm.declare_entry("variant", "", Patterns::Anything(),
                    "Variant msfem calibrate fits when --variant is not given: a built-in one (" +
                        selection_of<Variant>() +
                        ") or a NAME of mass spring/networks (empty: the first of mass "
                        "spring/variants, else the first network).");
  prm.declare_entry("fit groups", "", Patterns::List(Patterns::Anything()),
                    "Spring groups whose stiffness is fitted (empty: every group of the variant).");
  prm.declare_entry("train loads", "", Patterns::Anything(),
                    "Training tool loads, DX,DY,DZ@DEPTH separated by ';' (depth in m).");
  prm.declare_entry("test loads", "", Patterns::Anything(),
                    "Held-out tool loads (other positions or depths than the training ones).");
  prm.declare_entry("force weight", "1", Patterns::Double(0),
                    "Objective: mean over training loads of rel_l2_error^2 + w "
                    "reaction_force_rel_error^2.");
  prm.declare_entry("max evaluations", "400", Patterns::Integer(1, 1000000),
                    "Objective evaluations allowed (each is one static solve per training load).");
  prm.declare_entry("tolerance", "1e-5", Patterns::Double(0, 1),
                    "Converged when the log-coefficients move by less than this.");
  prm.declare_entry("bound factor", "100", Patterns::Double(1.0),
                    "Each fitted factor stays within [1/b, b] of its starting value.");
  prm.declare_entry("target damping ratio", "0.5", Patterns::Double(0),
                    "Damping ratio of the tool-response mode that the damping fit aims for.");
  prm.declare_entry("model", "nonlinear", Patterns::Selection(selection_of<CalibrationModel>()),
                    "Spring model the fit solves: nonlinear static equilibrium (Newton, as msfem "
                    "run), or linearised at rest (one Cholesky factorisation per load and "
                    "evaluation: large models, small indentations).");
  prm.leave_subsection();
}

void declare_all(ParameterHandler& prm) {
  declare_geometry(prm);
  declare_material(prm);
  declare_support(prm);
  declare_loads(prm);
  declare_mass_spring(prm);
  declare_fem_timing_output(prm);
  declare_calibration(prm);
}

// deal.II's messages span several indented lines and write "Line <12> of file <a.prm>"; users and
// scripts get one line in the compiler's "a.prm:12: ..." form.
std::string one_line(const dealii::ExceptionBase& e) {
  std::ostringstream info;
  e.print_info(info);
  std::string text = std::regex_replace(info.str(), std::regex("\\s+"), " ");
  // (ExcNoSubsection omits the '>' after the file name.)
  text = std::regex_replace(text, std::regex("^ *Line <(\\d+)> of file <(.*?)>?: *"), "$2:$1: ");
  return std::regex_replace(text, std::regex(" +$"), "");
}

Eigen::Vector3d parse_point(const std::string& text) {
  Eigen::Vector3d p;
  const auto parts = Patterns::Tools::Convert<std::vector<double>>::to_value(text, point_pattern());
  for (int k = 0; k < 3; ++k)
    p[k] = parts[k];
  return p;
}

Eigen::Vector3d unit_vector(const std::string& text, const std::string& key) {
  const Eigen::Vector3d v = parse_point(text);
  if (!(v.norm() > 0)) throw InputError(key + ": direction '" + text + "' has zero length");
  return v.normalized();
}

void apply_override(ParameterHandler& prm, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos)
    throw InputError("--set '" + assignment + "': expected SECTION/KEY=VALUE");
  std::string path = assignment.substr(0, eq);
  const std::string value = assignment.substr(eq + 1);
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const auto slash = path.find('/', start);
    parts.push_back(path.substr(start, slash - start));
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  const std::string key = parts.back();
  parts.pop_back();
  try {
    for (const auto& section : parts)
      prm.enter_subsection(section);
    // get() throws for an undeclared key; set() checks the value against the key's pattern.
    prm.get(key);
    prm.set(key, value);
  } catch (const dealii::ExceptionBase& e) {
    throw InputError("--set '" + assignment + "': " + one_line(e));
  }
  for (std::size_t i = 0; i < parts.size(); ++i)
    prm.leave_subsection();
}

// Each step of the loading path is a static solve per variant and load: a step so small that the
// path would take more than this many is refused before any solve, not run for hours.
constexpr int max_path_steps = 1000;

void check_path_step(const ToolParameters& tool) {
  if (!tool.enabled || !(tool.path_step_m > 0)) return;
  double deepest = tool.depth_m;
  for (double d : tool.curve_depths_m)
    deepest = std::max(deepest, d);
  const double steps = deepest / tool.path_step_m;
  if (steps > max_path_steps) {
    char message[256];
    std::snprintf(message, sizeof message,
                  "loads/tool/path step = %g m would press to %g m in %.3g steps, above the %d "
                  "msfem takes; use a larger step (or 0: the curve depths only)",
                  tool.path_step_m, deepest, steps, max_path_steps);
    throw InputError(message);
  }
}

// An enumerated key of the current subsection; its Selection pattern already refused other names.
template <typename Enum>
Enum setting(const ParameterHandler& prm, const std::string& key) {
  return parse_setting<Enum>(prm.get(key), key);
}

void extract_geometry(ParameterHandler& prm, CaseParameters& c) {
  prm.enter_subsection("geometry");
  c.geometry.source = prm.get("source");
  c.geometry.unit = setting<LengthUnit>(prm, "unit");
  c.geometry.simplify_to_vertices = prm.get_integer("simplify to vertices");
  c.geometry.smoothing_iterations = prm.get_integer("smoothing iterations");
  prm.leave_subsection();
}

void extract_material(ParameterHandler& prm, CaseParameters& c) {
  prm.enter_subsection("material");
  c.material = {prm.get_double("youngs modulus"), prm.get_double("poisson ratio"),
                prm.get_double("density"), prm.get("youngs modulus image"),
                prm.get("hu to youngs")};
  prm.leave_subsection();
  parse_hu_to_youngs(c.material.hu_to_youngs, "material/hu to youngs");
  if (!(c.material.youngs_modulus_pa > 0)) throw InputError("material/youngs modulus must be > 0");
  if (!(c.material.density_kg_per_m3 > 0)) throw InputError("material/density must be > 0");
}

void extract_support(ParameterHandler& prm, CaseParameters& c) {
  prm.enter_subsection("support");
  c.support.kind = setting<SupportParameters::Kind>(prm, "fixed region");
  c.support.inner_core_scale = prm.get_double("inner core scale");
  c.support.half_space_point = parse_point(prm.get("half space point"));
  c.support.half_space_normal =
      unit_vector(prm.get("half space normal"), "support/half space normal");
  c.support.sphere_center = parse_point(prm.get("sphere center"));
  c.support.sphere_radius_m = prm.get_double("sphere radius");
  prm.leave_subsection();
  if (c.support.kind == SupportParameters::Kind::inner_core && !(c.support.inner_core_scale > 1.0))
    throw InputError("support/inner core scale must be > 1");
  if (c.support.kind == SupportParameters::Kind::sphere && !(c.support.sphere_radius_m > 0))
    throw InputError("support/sphere radius must be > 0 for a fixed sphere");
}

void extract_loads(ParameterHandler& prm, CaseParameters& c) {
  prm.enter_subsection("loads");
  c.loads.gravity_m_per_s2 = parse_point(prm.get("gravity"));
  prm.enter_subsection("tool");
  auto& tool = c.loads.tool;
  tool.enabled = prm.get_bool("enabled");
  tool.mode = setting<ToolParameters::Mode>(prm, "mode");
  tool.directions.clear();
  for (const auto& d : dealii::Utilities::split_string_list(prm.get("directions"), ';'))
    tool.directions.push_back(unit_vector(d, "loads/tool/directions"));
  tool.radius_m = prm.get_double("radius");
  tool.depth_m = prm.get_double("depth");
  for (const auto& d : dealii::Utilities::split_string_list(prm.get("curve depths")))
    tool.curve_depths_m.push_back(std::stod(d));
  tool.path_step_m = prm.get_double("path step");
  prm.leave_subsection();
  if (tool.enabled && !(tool.radius_m > 0 && tool.depth_m > 0))
    throw InputError("loads/tool: radius and depth must be > 0 when the tool is enabled");
  check_path_step(tool);
  prm.enter_subsection("patch force");
  auto& patch = c.loads.patch_force;
  patch.enabled = prm.get_bool("enabled");
  patch.direction = unit_vector(prm.get("direction"), "loads/patch force/direction");
  patch.radius_m = prm.get_double("radius");
  patch.force_n = parse_point(prm.get("force"));
  prm.leave_subsection();
  prm.leave_subsection();
}

void extract_mass_spring(ParameterHandler& prm, CaseParameters& c) {
  prm.enter_subsection("mass spring");
  auto& ms = c.mass_spring;
  ms.variants.clear();
  for (const auto& name : dealii::Utilities::split_string_list(prm.get("variants")))
    ms.variants.push_back(parse_setting<Variant>(name, "mass spring/variants"));
  ms.networks = parse_networks(prm.get("networks"));
  ms.results = parse_results(prm.get("results"), ms.networks);
  ms.stiffness_model = setting<massspring::TetStiffnessRule>(prm, "stiffness model");
  ms.damping_ratio = prm.get_double("damping ratio");
  ms.group_scales =
      parse_group_scales(dealii::Utilities::split_string_list(prm.get("group scales")));
  ms.volume_preservation = prm.get_bool("volume preservation");
  prm.enter_subsection("three tier");
  ms.middle_tier_scale = prm.get_double("middle tier scale");
  ms.inner_tier_scale = prm.get_double("inner tier scale");
  ms.inner_tiers = setting<massspring::InnerTierMethod>(prm, "inner tiers");
  ms.inner_diagonals = prm.get_bool("inner diagonals");
  prm.leave_subsection();
  prm.enter_subsection("skeleton");
  ms.skeleton_control_points = prm.get_integer("control points");
  ms.skeleton_draw_factor = prm.get_double("draw factor");
  prm.leave_subsection();
  prm.enter_subsection("contact refinement");
  ms.contact_refinement.enabled = prm.get_bool("enabled");
  ms.contact_refinement.radius_m = prm.get_double("radius");
  ms.contact_refinement.edge_m = prm.get_double("edge length");
  prm.leave_subsection();
  prm.leave_subsection();
  if (!(ms.inner_tier_scale > ms.middle_tier_scale))
    throw InputError("mass spring/three tier: inner tier scale must exceed middle tier scale");
}

void extract_fem_timing_output(ParameterHandler& prm, CaseParameters& c) {
  prm.enter_subsection("fem");
  c.fem = {static_cast<int>(prm.get_integer("degree")),
           prm.get_double("cell size"),
           setting<FemSolver>(prm, "solver"),
           prm.get_double("relative tolerance"),
           prm.get_bool("refine at tool"),
           prm.get_double("tool cell size"),
           setting<FemParameters::ErrorEstimate>(prm, "error estimate")};
  if (c.fem.error_estimate == FemParameters::ErrorEstimate::degree && c.fem.degree != 1)
    throw InputError(
        "fem/error estimate = degree needs fem/degree = 1 (deal.II has no cubic tetrahedron to "
        "go above degree 2); use refine");
  if (c.fem.error_estimate == FemParameters::ErrorEstimate::lower_degree && c.fem.degree != 2)
    throw InputError(
        "fem/error estimate = lower_degree needs fem/degree = 2 (it solves degree 1 "
        "on the same mesh); use degree or refine");
  prm.leave_subsection();
  prm.enter_subsection("timing");
  c.timing = {setting<massspring::IntegratorKind>(prm, "integrator"), prm.get_double("dt"),
              static_cast<int>(prm.get_integer("steps")), prm.get("precision") == "float"};
  prm.leave_subsection();
  prm.enter_subsection("output");
  c.output.directory = prm.get("directory");
  prm.leave_subsection();
}

void extract_calibration(ParameterHandler& prm, CaseParameters& c) {
  prm.enter_subsection("calibration");
  auto& cal = c.calibration;
  if (const std::string variant = prm.get("variant"); !variant.empty()) {
    const auto& networks = c.mass_spring.networks;
    if (std::none_of(networks.begin(), networks.end(),
                     [&](const auto& n) { return n.name == variant; }))
      parse_setting<Variant>(variant, "calibration/variant");  // else a built-in one, or refused
    cal.variant = variant;
  }
  cal.groups = dealii::Utilities::split_string_list(prm.get("fit groups"));
  cal.train = parse_tool_loads(prm.get("train loads"), "calibration/train loads");
  cal.test = parse_tool_loads(prm.get("test loads"), "calibration/test loads");
  cal.force_weight = prm.get_double("force weight");
  cal.max_evaluations = static_cast<int>(prm.get_integer("max evaluations"));
  cal.tolerance = prm.get_double("tolerance");
  cal.bound_factor = prm.get_double("bound factor");
  cal.target_damping_ratio = prm.get_double("target damping ratio");
  cal.model = setting<CalibrationModel>(prm, "model");
  prm.leave_subsection();
  // calibration/variant is checked against mass spring/variants by msfem calibrate, so that
  // `msfem run --set "mass spring/variants=..."` can run any subset.
}

CaseParameters extract(ParameterHandler& prm) {
  CaseParameters c;
  extract_geometry(prm, c);
  extract_material(prm, c);
  extract_support(prm, c);
  extract_loads(prm, c);
  extract_mass_spring(prm, c);
  extract_fem_timing_output(prm, c);
  extract_calibration(prm, c);
  return c;
}

// Declares the language, parses the file and applies the overrides.
void load_case(const std::filesystem::path& file, const std::vector<std::string>& overrides,
               ParameterHandler& prm) {
  declare_all(prm);
  std::ostringstream language;
  prm.print_parameters(language, ParameterHandler::OutputStyle::ShortPRM);
  std::istringstream in(checked_case_text(file, subsection_paths(language.str())));
  try {
    prm.parse_input(in, file.string(), "", /*skip_undefined=*/false);
  } catch (const dealii::ExceptionBase& e) {
    throw InputError(one_line(e));
  }
  // A relative output/directory written in the case file is relative to the case file, as every
  // path in it is; one given with --set (or the default) is relative to the working directory.
  prm.enter_subsection("output");
  const std::string written = prm.get("directory");
  prm.leave_subsection();
  for (const auto& o : overrides)
    apply_override(prm, o);
  prm.enter_subsection("output");
  const std::filesystem::path directory = prm.get("directory");
  if (directory == written && written != default_output_directory && directory.is_relative())
    prm.set("directory", (file.parent_path() / directory).lexically_normal().string());
  prm.leave_subsection();
}

}  // namespace

CaseParameters read_case(const std::filesystem::path& file,
                         const std::vector<std::string>& overrides) {
  ParameterHandler prm;
  load_case(file, overrides, prm);
  CaseParameters c;
  try {
    c = extract(prm);
    check_consistency(c);
  } catch (const InputError& e) {
    throw InputError(file.string() + ": " + e.what());
  }
  c.file = file;
  c.name = file.stem().string();
  resolve_paths(c);
  return c;
}

std::string case_file_text(const std::filesystem::path& file,
                           const std::vector<std::string>& overrides) {
  ParameterHandler prm;
  load_case(file, overrides, prm);
  std::ostringstream out;
  prm.print_parameters(out, ParameterHandler::OutputStyle::ShortPRM |
                                ParameterHandler::OutputStyle::KeepDeclarationOrder);
  return out.str();
}

std::string describe_case_parameters() {
  ParameterHandler prm;
  declare_all(prm);
  std::ostringstream out;
  prm.print_parameters(out, ParameterHandler::OutputStyle::PRM);
  return out.str();
}

}  // namespace msfem::cases
