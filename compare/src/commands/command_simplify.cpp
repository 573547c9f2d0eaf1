// msfem simplify: bring a scanned organ surface down to the resolution a real-time model can step.
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_simplification.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"

namespace msfem::compare {

int simplify_command(const Arguments& args) {
  const Options opt(args, {"binary"}, {"unit", "vertices", "smooth"});
  if (opt.positional().size() != 2 || !opt.value("vertices"))
    throw std::invalid_argument(
        "usage: msfem simplify IN OUT --vertices N [--unit m|cm|mm] [--smooth ITERATIONS]");
  const auto unit = cases::parse_length_unit(opt.value("unit").value_or("m"));
  const long target = opt.integer("vertices", 0);
  // As geometry/smoothing iterations: Taubin's shrink and inflate drift past about 1000 passes.
  const long smoothing = opt.integer("smooth", 0, 0, 1000);
  const std::string& in = opt.positional()[0];
  const std::string& out = opt.positional()[1];
  refuse_writing_over_input(in, out, "simplify");

  cases::Surface surface = cases::read_surface(in, unit);
  const auto before = cases::orient_and_validate(surface, /*check_self_intersections=*/false);
  for (const auto& f : before.fixes)
    std::fprintf(stderr, "%s: %s\n", in.c_str(), f.c_str());
  if (target > surface.num_vertices() || target < 4)
    throw std::invalid_argument("option --vertices " + std::to_string(target) + " must be in [4, " +
                                std::to_string(surface.num_vertices()) + "]");
  cases::Surface simplified = cases::simplify(surface, static_cast<int>(target));
  cases::smooth_taubin(simplified, static_cast<int>(smoothing));

  const auto after = cases::validate(simplified);
  // A surface no model can be built from is not a result: nothing is written.
  if (!after.ok())
    throw std::runtime_error("the simplified surface has " + std::to_string(after.defects.size()) +
                             " defect(s), first: " + after.defects.front().message +
                             "; nothing written to " + out +
                             " (fewer --smooth iterations or more --vertices)");
  cases::write_surface(out, simplified, {unit, opt.flag("binary")});
  std::printf("%s: %lld -> %lld vertices, %lld triangles, volume %.6g -> %.6g m^3, %zu defects\n",
              out.c_str(), static_cast<long long>(surface.num_vertices()),
              static_cast<long long>(simplified.num_vertices()),
              static_cast<long long>(simplified.num_triangles()), before.volume, after.volume,
              after.defects.size());
  return 0;
}

}  // namespace msfem::compare
