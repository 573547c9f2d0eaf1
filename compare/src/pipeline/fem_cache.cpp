#include "msfem/compare/pipeline/fem_cache.hpp"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/content_hash.hpp"
#include "msfem/compare/pipeline/json_values.hpp"

namespace msfem::compare {
namespace {

// Bump when the FEM's formulation or the entry layout changes: old entries then miss.
constexpr const char* cache_version = "msfem-fem-cache-8";

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  return {{"rows", m.rows()},
          {"cols", m.cols()},
          {"data", std::vector<double>(m.data(), m.data() + m.size())}};
}

Eigen::MatrixXd matrix_from(const nlohmann::json& j) {
  const auto data = j.at("data").get<std::vector<double>>();
  const Eigen::Index rows = j.at("rows"), cols = j.at("cols");
  if (static_cast<Eigen::Index>(data.size()) != rows * cols) throw std::runtime_error("bad matrix");
  return Eigen::Map<const Eigen::MatrixXd>(data.data(), rows, cols);
}

nlohmann::json vec(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
Eigen::Vector3d vec_from(const nlohmann::json& j) {
  return Eigen::Vector3d(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
}

std::optional<double> optional_from(const nlohmann::json& j) {
  return j.is_null() ? std::nullopt : std::optional<double>(j.get<double>());
}

nlohmann::json estimate_json(const FemErrorEstimate& e) {
  nlohmann::json loads = nlohmann::json::array();
  for (const auto& l : e.loads)
    loads.push_back({json_or_null(l.rel_l2_error), json_or_null(l.force_rel_error)});
  return {{"method", e.method},
          {"note", e.note},
          {"dofs", e.dofs},
          {"time_s", e.time_s},
          {"loads", loads}};
}

FemErrorEstimate estimate_from(const nlohmann::json& j) {
  FemErrorEstimate e;
  e.method = j.at("method");
  e.note = j.at("note");
  e.dofs = j.at("dofs");
  e.time_s = j.at("time_s");
  for (const auto& l : j.at("loads"))
    e.loads.push_back({optional_from(l.at(0)), optional_from(l.at(1))});
  return e;
}

nlohmann::json contact_json(const std::optional<fem_reference::ContactReport>& c) {
  if (!c) return nullptr;
  return {{"force", vec(c->force)},
          {"active_nodes", c->active_nodes},
          {"iterations", c->iterations},
          {"contact_radius", c->contact_radius},
          {"outermost_node_radius", c->outermost_node_radius},
          {"max_penetration", c->max_penetration}};
}

std::optional<fem_reference::ContactReport> contact_from(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || j.at(key).is_null()) return std::nullopt;
  const nlohmann::json& c = j.at(key);
  fem_reference::ContactReport r;
  r.force = vec_from(c.at("force"));
  r.active_nodes = c.at("active_nodes");
  r.iterations = c.at("iterations");
  r.contact_radius = c.at("contact_radius");
  r.outermost_node_radius = c.at("outermost_node_radius");
  r.max_penetration = c.at("max_penetration");
  return r;
}

}  // namespace

std::string reference_inputs_hash(const Problem& problem,
                                  const std::vector<ToolPlacement>& refine_near,
                                  const std::optional<ToolPlacement>& tool) {
  const auto& p = problem.parameters;
  ContentHash h;
  h.matrix(problem.surface.vertices);
  h.matrix(problem.surface.triangles);
  for (double x :
       {p.material.youngs_modulus_pa, p.material.poisson_ratio, p.material.density_kg_per_m3})
    h.number(x);
  h.text(problem.youngs_modulus_image ? problem.youngs_modulus_image->fingerprint() : "uniform E");
  h.matrix(p.loads.gravity_m_per_s2);
  h.number(static_cast<double>(p.support.kind));
  h.number(p.support.inner_core_scale);
  h.matrix(p.support.half_space_point);
  h.matrix(p.support.half_space_normal);
  h.matrix(p.support.sphere_center);
  h.number(p.support.sphere_radius_m);
  const auto& patch = p.loads.patch_force;
  h.number(patch.enabled);
  h.matrix(patch.direction);
  h.number(patch.radius_m);
  h.matrix(patch.force_n);
  h.number(p.fem.degree);
  h.number(p.fem.cell_size_m);
  h.text(cases::name_of(p.fem.solver));
  h.number(p.fem.relative_tolerance);
  h.number(p.fem.refine_at_tool);
  h.number(p.fem.tool_cell_size_m);
  h.text(cases::name_of(p.fem.error_estimate));
  h.text("mesh refined near");
  for (const auto& t : refine_near) {
    h.matrix(t.contact_point);
    h.number(t.radius);
  }
  h.text(tool ? "tool" : "no tool");
  if (tool) {
    h.matrix(tool->contact_point);
    h.matrix(tool->outward_normal);
    h.number(tool->radius);
    h.number(tool->depth);
    h.text(tool->frictionless ? "contact" : "bonded");
  }
  return h.hex();
}

std::string fem_cache_key(const Problem& problem, const std::vector<ToolPlacement>& refine_near,
                          const std::optional<ToolPlacement>& tool,
                          const std::vector<double>& curve_depths) {
  ContentHash h;
  h.text(cache_version);
  h.text(reference_inputs_hash(problem, refine_near, tool));
  for (double d : curve_depths)
    h.number(d);
  return h.hex();
}

std::optional<FemCacheEntry> load_fem_cache(const std::filesystem::path& directory,
                                            const std::string& key) {
  std::ifstream in(directory / (key + ".cbor"), std::ios::binary);
  if (!in) return std::nullopt;
  try {
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                          std::istreambuf_iterator<char>());
    const nlohmann::json j = nlohmann::json::from_cbor(bytes);
    if (j.at("version") != cache_version || j.at("key") != key) return std::nullopt;
    FemCacheEntry e;
    e.mesh.vertices = matrix_from(j.at("mesh_vertices"));
    e.mesh.tetrahedra = matrix_from(j.at("mesh_tetrahedra")).cast<int>();
    e.mesh.num_surface_vertices = j.at("num_surface_vertices");
    auto& s = e.solution;
    s.vertex_displacement = matrix_from(j.at("vertex_displacement"));
    s.surface_displacement = s.vertex_displacement.topRows(j.at("case_surface_vertices"));
    s.tool_force = vec_from(j.at("tool_force"));
    s.solver = j.at("solver");
    s.volume_change = j.at("volume_change");
    const auto& st = j.at("statistics");
    s.statistics.dofs = st.at("dofs");
    s.statistics.cells = st.at("cells");
    s.statistics.vertices = st.at("vertices");
    s.statistics.prescribed_dofs = st.at("prescribed_dofs");
    s.statistics.mpi_ranks = st.at("mpi_ranks");
    s.statistics.iterations = st.at("iterations");
    s.statistics.residual_norm = st.at("residual_norm");
    s.statistics.setup_time_s = st.at("setup_time_s");
    s.statistics.assemble_time_s = st.at("assemble_time_s");
    s.statistics.solve_time_s = st.at("solve_time_s");
    s.statistics.youngs_modulus_min = st.at("youngs_modulus_min_pa");
    s.statistics.youngs_modulus_max = st.at("youngs_modulus_max_pa");
    s.contact = contact_from(j, "contact");
    for (const auto& p : j.at("force_depth"))
      e.force_depth.push_back(
          {p.at("depth_m"), vec_from(p.at("force_N")), std::nullopt, contact_from(p, "contact")});
    e.error_estimate = estimate_from(j.at("error_estimate"));
    return e;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void store_fem_cache(const std::filesystem::path& directory, const std::string& key,
                     const FemCacheEntry& e) {
  const auto& s = e.solution;
  const auto& st = s.statistics;
  nlohmann::json fd = nlohmann::json::array();
  for (const auto& p : e.force_depth)
    fd.push_back({{"depth_m", p.depth_m},
                  {"force_N", vec(p.force_n)},
                  {"contact", contact_json(p.contact)}});
  nlohmann::json j = {{"version", cache_version},
                      {"key", key},
                      {"mesh_vertices", matrix_json(e.mesh.vertices)},
                      {"mesh_tetrahedra", matrix_json(e.mesh.tetrahedra.cast<double>())},
                      {"num_surface_vertices", e.mesh.num_surface_vertices},
                      {"vertex_displacement", matrix_json(s.vertex_displacement)},
                      {"case_surface_vertices", s.surface_displacement.rows()},
                      {"tool_force", vec(s.tool_force)},
                      {"solver", s.solver},
                      {"volume_change", s.volume_change},
                      {"statistics",
                       {{"dofs", st.dofs},
                        {"cells", st.cells},
                        {"vertices", st.vertices},
                        {"prescribed_dofs", st.prescribed_dofs},
                        {"mpi_ranks", st.mpi_ranks},
                        {"iterations", st.iterations},
                        {"residual_norm", st.residual_norm},
                        {"setup_time_s", st.setup_time_s},
                        {"assemble_time_s", st.assemble_time_s},
                        {"solve_time_s", st.solve_time_s},
                        {"youngs_modulus_min_pa", st.youngs_modulus_min},
                        {"youngs_modulus_max_pa", st.youngs_modulus_max}}},
                      {"force_depth", fd},
                      {"contact", contact_json(s.contact)},
                      {"error_estimate", estimate_json(e.error_estimate)}};
  std::filesystem::create_directories(directory);
  const std::vector<std::uint8_t> bytes = nlohmann::json::to_cbor(j);
  write_file_atomically(directory / (key + ".cbor"), [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    if (!out) throw std::runtime_error("write failed");
  });
}

}  // namespace msfem::compare
