// The files of a run: for scripts (summary.json), for people (report.md with plots), for ParaView
// (surface_<variant>.vtu + surfaces.pvd, fem.pvd; fem.xdmf + fem.h5 for XDMF readers) and for
// analysis (fields.h5).
#include "msfem/compare/writers/run_outputs.hpp"
#include "msfem/compare/writers/run_summary.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <sstream>

#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/writers/error_picture.hpp"
#include "msfem/compare/writers/fields_h5.hpp"
#include "msfem/compare/writers/plots.hpp"
#include "msfem/compare/writers/text_format.hpp"
#include "msfem/compare/writers/vtu.hpp"
#include "msfem/compare/writers/x3d_scene.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"

namespace msfem::compare {
namespace {

// The fields of the run's first load (the one its tables show).
void write_surfaces(const CaseRun& run, const std::filesystem::path& dir) {
  const auto& s = run.problem.surface;
  const FemSolution& fem_solution = run.loads.front().fem;
  std::vector<std::pair<std::string, std::string>> datasets;
  write_surface_vtu(dir / "surface_fem.vtu", s.vertices, s.triangles,
                    {{"displacement", fem_solution.surface_displacement}});
  datasets.emplace_back("surface_fem.vtu", "fem");
  for (const auto& v : run.variants) {
    const std::string file = "surface_" + v.name + ".vtu";
    const ToolLoadVariant& own = v.loads.front();
    write_surface_vtu(dir / file, s.vertices, s.triangles,
                      {{"displacement", own.surface_displacement},
                       {"fem_displacement", fem_solution.surface_displacement},
                       {"error", own.error},
                       {"error_magnitude", own.error.rowwise().norm()}});
    datasets.emplace_back(file, v.name);
  }
  write_pvd(dir / "surfaces.pvd", datasets);
  // The FEM volume with its vertex displacements (for P2 the edge-midpoint values are left out).
  write_volume_vtu(dir / "fem.vtu", run.mesh.vertices, run.mesh.tetrahedra,
                   {{"displacement", fem_solution.vertex_displacement}});
  write_pvd(dir / "fem.pvd", {{"fem.vtu", "fem"}});
  // The same volume field through deal.II's HDF5 + XDMF writer (also when the FEM came from the
  // cache: the vertex displacements are all it needs).
  fem_reference::write_vertex_displacement_hdf5(run.mesh, fem_solution.vertex_displacement, dir,
                                                "fem");
}

void write_fields(const CaseRun& run, const std::filesystem::path& dir) {
  FemField fem;
  fem.vertices = run.mesh.vertices;
  fem.tetrahedra = run.mesh.tetrahedra;
  fem.displacement = run.loads.front().fem.vertex_displacement;
  std::vector<VariantField> variants;
  for (const auto& v : run.variants)
    variants.push_back({v.name, v.loads.front().surface_displacement, v.loads.front().error});
  write_fields_h5(dir / "fields.h5", run.problem.surface.vertices, run.problem.surface.triangles,
                  fem, variants);
}

// The largest error of any variant at the first load (mm), the one scale the pictures and the
// scene colour by, and the tool as they draw it.
double largest_error_mm(const CaseRun& run) {
  double max_mm = 0.0;
  for (const auto& v : run.variants)
    max_mm = std::max(max_mm, 1e3 * v.loads.front().error.rowwise().norm().maxCoeff());
  return max_mm;
}
std::optional<PictureTool> picture_tool(const CaseRun& run) {
  if (const auto& placed = run.loads.front().tool)
    return PictureTool{placed->pushed_center(), placed->radius, placed->outward_normal};
  return std::nullopt;
}

// The undeformed surface and each variant's deformed one with its error, as scene.x3d/.html.
void write_scene(const CaseRun& run, const std::filesystem::path& dir) {
  const cases::Surface& s = run.problem.surface;
  std::vector<SceneSurface> surfaces{{"undeformed", s.vertices, std::nullopt}};
  for (const auto& v : run.variants)
    surfaces.push_back({v.name, s.vertices + v.loads.front().surface_displacement,
                        Eigen::VectorXd(1e3 * v.loads.front().error.rowwise().norm())});
  write_x3d_scene(dir, "msfem run: " + run.problem.parameters.name, s.triangles, surfaces,
                  largest_error_mm(run), picture_tool(run));
}

// Each variant's deformed surface coloured by its error at the first load, one scale for all.
std::vector<std::string> error_pictures(const CaseRun& run, const std::filesystem::path& dir) {
  std::vector<std::string> lines;
  const double max_mm = largest_error_mm(run);
  const std::optional<PictureTool> tool = picture_tool(run);
  for (const auto& v : run.variants) {
    const ToolLoadVariant& first = v.loads.front();
    const auto file = error_picture(
        dir / ("error_" + v.name + ".png"), v.name + ": error on the organ",
        run.problem.surface.vertices + first.surface_displacement, run.problem.surface.triangles,
        1e3 * first.error.rowwise().norm(), max_mm, tool);
    lines.push_back("![" + v.name + ": error on the organ](" + file.filename().string() + ")");
  }
  return lines;
}

// The report's pictures: the error on the organ (beside the table) and the plots below.
struct Plots {
  std::vector<std::string> organ, other;
};

// Plots are an addition to the numbers: without gnuplot the report says so instead.
Plots write_plots(const CaseRun& run, const std::filesystem::path& dir) {
  Plots plots;
  std::vector<std::string>& lines = plots.other;
  if (!gnuplot_available()) {
    lines.push_back("(plots skipped: gnuplot is not installed)");
    return plots;
  }
  plots.organ = error_pictures(run, dir);
  std::vector<std::pair<std::string, Eigen::VectorXd>> histogram_series;
  std::vector<std::string> colours;
  const std::vector<int>& compared = run.loads.front().compared_vertices;
  for (const auto& v : run.variants) {
    colours.push_back(variant_colour(colours.size()));
    Eigen::VectorXd e(compared.size());
    for (std::size_t i = 0; i < compared.size(); ++i)
      e[i] = 1e3 * v.loads.front().error.row(compared[i]).norm();
    histogram_series.emplace_back(v.name, e);
  }
  if (!histogram_series.empty()) {
    const auto file = histogram(dir / "error_histogram.png", "Surface error magnitude per variant",
                                "|u - u_FEM| (mm)", histogram_series, 30, colours);
    lines.push_back("![error histogram](" + file.filename().string() + ")");
  }
  if (!run.loads.front().force_depth.empty()) {
    std::vector<Series> series;
    Series fem{"FEM", {}, {}, "#000000"};
    for (const auto& p : run.loads.front().force_depth) {
      fem.x.push_back(1e3 * p.depth_m);
      fem.y.push_back(p.force_n.norm());
    }
    series.push_back(fem);
    for (std::size_t i = 0; i < run.variants.size(); ++i) {
      const VariantResult& v = run.variants[i];
      if (v.loads.front().force_depth.empty()) continue;  // an outside answer without a curve
      Series s{v.name, {}, {}, variant_colour(i)};
      for (const auto& p : v.loads.front().force_depth) {
        s.x.push_back(1e3 * p.depth_m);
        s.y.push_back(p.force_n.norm());
      }
      series.push_back(s);
    }
    const auto file = xy_lines(dir / "force_depth.png", "Tool force against indentation depth",
                               "depth (mm)", "|F| (N)", series, false, false);
    lines.push_back("![force-depth curve](" + file.filename().string() + ")");
  }
  return plots;
}

// Each tool position of the case as its own load: rel L2 and force error per variant, and means.
std::string tool_positions_table(const CaseRun& run) {
  if (run.loads.size() < 2) return "";
  std::ostringstream md;
  md << "\n## Every tool position (rel L2 / force err)\n\n| variant |";
  const int tools = static_cast<int>(run.loads.size());
  for (int t = 0; t < tools; ++t) {
    const Eigen::Vector3d d = run.problem.parameters.loads.tool.directions[t];
    char head[96];
    std::snprintf(head, sizeof head, " tool %d (%.2g, %.2g, %.2g) |", t, d.x(), d.y(), d.z());
    md << head;
  }
  md << " mean |\n|---|";
  for (int t = 0; t <= tools; ++t)
    md << "---|";
  md << "\n";
  for (const auto& v : run.variants) {
    double l2 = 0.0, force = 0.0;
    char cell[64];
    md << "| " << v.name << " |";
    for (const ToolLoadVariant& o : v.loads) {
      if (o.force_measured)
        std::snprintf(cell, sizeof cell, " %.3f / %.3f%s |", o.displacement.all.rel_l2_error,
                      o.reaction_force_rel_error, o.force_depth_monotone == false ? " †" : "");
      else
        std::snprintf(cell, sizeof cell, " %.3f / - |", o.displacement.all.rel_l2_error);
      md << cell;
      l2 += o.displacement.all.rel_l2_error;
      force += o.reaction_force_rel_error;
    }
    if (std::all_of(v.loads.begin(), v.loads.end(), [](const auto& o) { return o.force_measured; }))
      std::snprintf(cell, sizeof cell, " %.3f / %.3f |", l2 / tools, force / tools);
    else
      std::snprintf(cell, sizeof cell, " %.3f / - |", l2 / tools);
    md << cell << "\n";
  }
  md << "\nTool 0 is the load of the tables above; each other tool presses alone to the same depth "
        "along the same loading path, on the same FEM mesh (refined at every tool). † the force "
        "does not grow with depth along that tool's path (see the warnings).\n";
  return md.str();
}

// "`fast_explicit` (a, b); `fast_implicit` in float (c)": the code each variant was timed on, and
// its arithmetic where not double.
std::string steppers_timed(const CaseRun& run) {
  std::vector<std::pair<std::string, std::string>> groups;  // stepper, variants
  for (const auto& v : run.variants) {
    if (v.timing.stepper.empty()) continue;
    const std::string code =
        "`" + v.timing.stepper + "`" + (v.timing.precision == "float" ? " in float" : "");
    auto group =
        std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == code; });
    if (group == groups.end())
      groups.emplace_back(code, v.name);
    else
      group->second += ", " + v.name;
  }
  std::string text;
  for (const auto& [stepper, names] : groups)
    text += (text.empty() ? "" : "; ") + stepper + " (" + names + ")";
  return text.empty() ? "no stepper (not timed)" : text;
}

// The E each model saw: constant, or the image's field through the HU table.
std::string youngs_modulus_text(const CaseRun& run) {
  const auto& image = run.problem.youngs_modulus_image;
  if (!image) return "E = " + fmt("%g", run.problem.parameters.material.youngs_modulus_pa) + " Pa";
  const auto& st = run.loads.front().fem.statistics;
  std::string text = "E from the CT `" + image->file().filename().string() + "` (HU:E Pa " +
                     image->table().describe() + "): FEM " + fmt("%.4g", st.youngs_modulus_min) +
                     "-" + fmt("%.4g", st.youngs_modulus_max) + " Pa at its quadrature points";
  for (const auto& v : run.variants)
    if (!v.external)
      text += ", " + v.name + " " + fmt("%.4g", v.parameters.youngs_modulus_min_pa) + "-" +
              fmt("%.4g", v.parameters.youngs_modulus_max_pa) + " Pa";
  return text;
}

std::string report_markdown(const CaseRun& run, const Plots& plots) {
  const auto& p = run.problem.parameters;
  const LoadReference& first = run.loads.front();
  std::ostringstream md;
  md << "# msfem run: " << p.name << "\n\n"
     << "- case file: `" << p.file.string() << "`\n"
     << "- surface: `" << p.geometry.source << "`, " << run.problem.surface.num_vertices()
     << " vertices, " << run.problem.surface.num_triangles() << " triangles\n"
     << "- material: " << youngs_modulus_text(run) << ", ν = " << p.material.poisson_ratio
     << ", ρ = " << p.material.density_kg_per_m3 << " kg/m³\n"
     << "- FEM: P" << p.fem.degree << ", " << first.fem.statistics.dofs << " dofs, "
     << first.fem.statistics.cells << " cells, " << first.fem.statistics.iterations
     << " iterations, " << first.fem.statistics.solve_time_s << " s solve";
  if (run.worst_cell_quality) md << ", worst cell quality " << *run.worst_cell_quality;
  md << "\n"
     << "- errors over " << first.compared_vertices.size()
     << " surface vertices not prescribed by a support or the tool\n"
     << "- FEM result " << (run.fem_from_cache ? "reused from the cache" : "computed") << " (key "
     << first.cache_key << ")\n"
     << "- git " << git_revision() << ", " << machine_description() << "\n";
  // Variants of the same name differ with and without it: say which tables are which.
  std::string with_volume;
  for (const auto& v : run.variants)
    if (const auto& volume = v.parameters.volume_preservation)
      with_volume += (with_volume.empty() ? "" : ", ") + v.name + " (mean κ " +
                     std::to_string(volume->mean_modulus_pa) + " Pa)";
  md << "- volume preservation: " << (with_volume.empty() ? "off" : with_volume) << "\n\n";
  for (const auto& n : run.problem.notes)
    md << "> note: " << n << "\n";
  md << "\n## Variants\n\n"
     << variant_table(run) << "\n"
     << "rel L2 = ‖u − v‖₂/‖v‖₂ over the compared vertices; force = |tool reaction|; force err = "
        "|F − F_FEM|/|F_FEM|; steps/s of the `"
     << massspring::to_string(p.timing.integrator) << "` integrator (median after warm-up) on "
     << steppers_timed(run) << "; ms/frame = wall ms per 1/60 s of simulated time.\n\n";
  if (!plots.organ.empty()) {
    md << "### Where each variant is wrong\n\nThe deformed surface coloured by |u − u_FEM| on "
          "one scale for every variant, along the tool and from the side (the tool's sphere "
          "drawn as a circle).\n\n";
    for (const auto& l : plots.organ)
      md << l << "\n\n";
  }
  md << "| variant | contact zone rel L2 | far field rel L2 | mean err / max disp | volume change "
        "| "
        "settle time s |\n|---|---|---|---|---|---|\n";
  for (const auto& v : run.variants) {
    char row[320], settle[96] = "-";
    if (!v.timing.integrator.empty() && v.timing.settled)
      std::snprintf(settle, sizeof settle, "%.3f", v.timing.settle_time_s);
    else if (!v.timing.integrator.empty())
      std::snprintf(settle, sizeof settle, "%.3f (not settled: %.3g× the travel away)",
                    v.timing.settle_time_s, v.timing.settle_distance);
    const ToolLoadVariant& own = v.loads.front();
    std::snprintf(row, sizeof row, "| %s | %.4f | %.4f | %.4f | %.2e | %s |\n", v.name.c_str(),
                  own.displacement.contact_zone.rel_l2_error,
                  own.displacement.far_field.rel_l2_error,
                  own.displacement.all.mean_error_over_max_disp, own.volume_change, settle);
    md << row;
  }
  md << tool_positions_table(run);
  for (const auto& v : run.variants)
    for (const Warning& w : v.warnings)
      md << "\n> " << v.name << ": " << w.written() << "\n";
  for (const auto& [name, why] : run.failed_variants)
    md << "\n> **" << name << " failed** and is left out of the tables and plots: " << why << "\n";
  md << "\n## Plots\n\n";
  for (const auto& l : plots.other)
    md << l << "\n\n";
  md << "## Files\n\n- `summary.json`: every number above\n"
        "- `surfaces.pvd`: the surface of each variant with displacement, error vector and "
        "magnitude (ParaView)\n- `fem.pvd`: the FEM solution\n"
        "- `fem.xdmf` + `fem.h5`: the FEM solution for XDMF readers (ParaView, VisIt, h5py)\n"
        "- `fields.h5`: FEM volume field, per-variant surface displacement and error\n"
        "- `scene.x3d`: the undeformed surface, each variant's deformed one in its error colours "
        "and the tool (X3D 3.3); `scene.html` shows it in a browser (X3DOM, beside it)\n";
  return md.str();
}

}  // namespace

void write_run_outputs(const CaseRun& run, const std::filesystem::path& directory) {
  write_surfaces(run, directory);
  write_fields(run, directory);
  write_scene(run, directory);
  const auto plots = write_plots(run, directory);
  write_text_atomically(directory / "report.md", report_markdown(run, plots));
  write_text_atomically(directory / "summary.json", summary_json(run).dump(2) + "\n");
}

}  // namespace msfem::compare
