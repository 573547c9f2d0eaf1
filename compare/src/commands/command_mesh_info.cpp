// msfem mesh-info: what a closed surface is, and every defect that keeps it from bounding a solid.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"

namespace msfem::compare {
namespace {

nlohmann::json to_json(const std::string& source, const cases::SurfaceReport& r) {
  nlohmann::json defects = nlohmann::json::array();
  for (const auto& d : r.defects)
    defects.push_back(
        {{"kind", cases::to_string(d.kind)}, {"message", d.message}, {"elements", d.elements}});
  auto row = [&](int i) {
    return std::vector<double>{r.bounding_box(i, 0), r.bounding_box(i, 1), r.bounding_box(i, 2)};
  };
  return {{"source", source},
          {"units", "m"},
          {"vertices", r.vertices},
          {"edges", r.edges},
          {"triangles", r.triangles},
          {"volume_m3", r.volume},
          {"area_m2", r.area},
          {"bounding_box_m", {{"min", row(0)}, {"max", row(1)}}},
          {"components", r.components},
          {"genus", r.genus >= 0 ? nlohmann::json(r.genus) : nlohmann::json()},
          {"self_intersections_checked", r.self_intersections_checked},
          {"fixes", r.fixes},
          {"defects", defects},
          {"ok", r.ok()}};
}

void print_table(const std::string& source, const cases::SurfaceReport& r) {
  const auto& b = r.bounding_box;
  std::printf("surface      %s\n", source.c_str());
  std::printf("vertices     %lld\n", static_cast<long long>(r.vertices));
  std::printf("edges        %lld\n", static_cast<long long>(r.edges));
  std::printf("triangles    %lld\n", static_cast<long long>(r.triangles));
  std::printf("volume       %.6g m^3\n", r.volume);
  std::printf("area         %.6g m^2\n", r.area);
  std::printf("bounding box [%.6g, %.6g, %.6g] to [%.6g, %.6g, %.6g] m (size %.4g x %.4g x %.4g)\n",
              b(0, 0), b(0, 1), b(0, 2), b(1, 0), b(1, 1), b(1, 2), b(1, 0) - b(0, 0),
              b(1, 1) - b(0, 1), b(1, 2) - b(0, 2));
  std::printf("components   %d\n", r.components);
  if (r.genus >= 0) {
    std::printf("genus        %d\n", r.genus);
  } else {
    std::printf("genus        n/a (not a closed 2-manifold)\n");
  }
  std::printf("self-intersections %s\n",
              r.self_intersections_checked ? "checked" : "not checked (fix the topology first)");
  for (const auto& f : r.fixes)
    std::printf("fixed        %s\n", f.c_str());
  std::printf("defects      %zu\n", r.defects.size());
  for (const auto& d : r.defects)
    std::printf("  %-24s %s\n", cases::to_string(d.kind).c_str(), d.message.c_str());
}

}  // namespace

int mesh_info_command(const Arguments& args) {
  const Options opt(args, {"json", "no-self-intersections"}, {"unit", "generate"});
  cases::Surface surface;
  std::string source;
  if (const auto spec = opt.value("generate")) {
    if (!opt.positional().empty())
      throw std::invalid_argument("give either FILE or --generate, not both");
    surface = cases::generate_surface(*spec);
    source = *spec;
  } else {
    if (opt.positional().size() != 1)
      throw std::invalid_argument("usage: msfem mesh-info FILE [--unit m|cm|mm] [--json]");
    const auto unit = cases::parse_length_unit(opt.value("unit").value_or("m"));
    surface = cases::read_surface(opt.positional()[0], unit);
    source = opt.positional()[0] + " (unit " + cases::to_string(unit) + ")";
  }
  const auto report = cases::orient_and_validate(surface, !opt.flag("no-self-intersections"));
  if (opt.flag("json")) {
    std::cout << to_json(source, report).dump(2) << '\n';
  } else {
    print_table(source, report);
  }
  return report.ok() ? 0 : 1;
}

}  // namespace msfem::compare
