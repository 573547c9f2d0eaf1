// msfem repair: from an organ mesh as published (holes, duplicates, folds) to a surface both models
// can be built from.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_repair.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"

namespace msfem::compare {
namespace {

// A length option in the file's unit, returned in metres (repair bounds it against the surface).
std::optional<double> length_option(const Options& opt, const std::string& key, double metres) {
  if (!opt.value(key)) return std::nullopt;
  return opt.number(key, 0.0, 0.0, std::numeric_limits<double>::max()) * metres;
}

void print_report(const std::string& out, const cases::RepairReport& r, const char* unit,
                  double metres, double seconds) {
  std::printf("%s: %lld vertices, %lld triangles -> %lld vertices, %lld triangles\n", out.c_str(),
              static_cast<long long>(r.input_vertices), static_cast<long long>(r.input_triangles),
              static_cast<long long>(r.result.vertices),
              static_cast<long long>(r.result.triangles));
  std::printf("  merged or unused vertices removed %d\n", r.merged_vertices);
  std::printf("  degenerate triangles removed      %d\n", r.degenerate_triangles);
  std::printf("  duplicate triangles removed       %d\n", r.duplicate_triangles);
  std::printf("  border edges stitched             %d\n", r.stitched_edges);
  std::printf("  triangles flipped                 %d\n", r.flipped_triangles);
  std::printf("  components dropped                %d (%d triangles)\n", r.dropped_components,
              r.dropped_triangles);
  if (r.wrapped) {
    std::printf("  wrapped                           yes (%s): alpha %.4g %s, offset %.4g %s\n",
                r.wrap_reason.c_str(), r.alpha / metres, unit, r.offset / metres, unit);
  } else {
    std::printf("  wrapped                           no\n");
  }
  const double v3 = metres * metres * metres;
  if (r.input_volume && *r.input_volume > 0) {
    std::printf("  volume                            %.6g -> %.6g %s^3 (%+.2f %%)\n",
                *r.input_volume / v3, r.result.volume / v3, unit,
                100.0 * (r.result.volume / *r.input_volume - 1.0));
  } else {
    std::printf("  volume                            %.6g %s^3 (the input encloses none)\n",
                r.result.volume / v3, unit);
  }
  std::printf("  components %d, genus %d, defects %zu, %.2f s\n", r.result.components,
              r.result.genus, r.result.defects.size(), seconds);
}

}  // namespace

int repair_command(const Arguments& args) {
  const Options opt(args, {"all-components", "wrap", "binary"}, {"unit", "alpha", "offset"});
  if (opt.positional().size() != 2)
    throw std::invalid_argument(
        "usage: msfem repair IN OUT [--unit m|cm|mm] [--all-components] [--wrap] [--alpha A] "
        "[--offset D] [--binary]");
  const auto unit = cases::parse_length_unit(opt.value("unit").value_or("m"));
  const double metres = cases::metres_per(unit);
  cases::RepairOptions options;
  options.keep_all_components = opt.flag("all-components");
  options.always_wrap = opt.flag("wrap");
  options.alpha = length_option(opt, "alpha", metres);
  options.offset = length_option(opt, "offset", metres);
  const std::string& in = opt.positional()[0];
  const std::string& out = opt.positional()[1];
  refuse_writing_over_input(in, out, "repair");
  cases::surface_format_for(out);  // an unknown OUT extension fails before the work

  const auto start = std::chrono::steady_clock::now();
  const cases::Surface surface = cases::read_surface(in, unit);
  cases::RepairReport report;
  cases::Surface repaired;
  try {
    repaired = cases::repair_surface(surface, options, report);
  } catch (const cases::InputError& e) {
    throw cases::InputError(in + ": " + e.what());
  }
  cases::write_surface(out, repaired, {unit, opt.flag("binary")});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  print_report(out, report, cases::to_string(unit).c_str(), metres, seconds);
  for (const auto& d : report.result.defects)
    std::printf("  %-24s %s\n", cases::to_string(d.kind).c_str(), d.message.c_str());
  return 0;
}

}  // namespace msfem::compare
