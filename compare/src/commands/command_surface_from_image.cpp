// msfem surface-from-image: an organ of a scan (a label map's label or a raw image's intensity
// window) as the closed surface the models are built from.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_from_image.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"

namespace msfem::compare {
namespace {

constexpr const char* usage =
    "usage: msfem surface-from-image IMAGE OUT (--label N | --threshold LO[:HI]) [--vertices N] "
    "[--smooth K] [--unit m|cm|mm]";

cases::ImageSurfaceOptions parse_options(const Options& opt) {
  if (opt.positional().size() != 2 ||
      (opt.value("label").has_value() == opt.value("threshold").has_value()))
    throw std::invalid_argument(usage);
  cases::ImageSurfaceOptions o;
  if (opt.value("label")) o.selection.label = opt.integer("label", 0);
  if (opt.value("threshold"))
    o.selection = cases::parse_threshold(*opt.value("threshold"), "option --threshold");
  const long vertices = opt.integer("vertices", 0);
  const long smoothing = opt.integer("smooth", 0, 0, 1000);
  if (opt.value("vertices") && vertices < 4)
    throw std::invalid_argument("option --vertices " + std::to_string(vertices) +
                                " is too small: a closed surface needs at least 4");
  o.target_vertices = static_cast<int>(vertices);
  o.smoothing_iterations = static_cast<int>(smoothing);
  return o;
}

// Everything about OUT that can be wrong is said before the image is read and meshed.
void check_output(const std::filesystem::path& image, const std::filesystem::path& out) {
  cases::surface_format_for(out);
  const auto folder = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw cases::InputError(out.string() + ": folder " + folder.string() + " does not exist");
  if (std::filesystem::weakly_canonical(image, ec) == std::filesystem::weakly_canonical(out, ec))
    throw std::invalid_argument("OUT '" + out.string() + "' is the image itself");
}

}  // namespace

int surface_from_image_command(const Arguments& args) {
  const Options opt(args, {}, {"label", "threshold", "vertices", "smooth", "unit"});
  const cases::ImageSurfaceOptions options = parse_options(opt);
  const auto unit = cases::parse_length_unit(opt.value("unit").value_or("m"));
  const std::filesystem::path image = opt.positional()[0], out = opt.positional()[1];
  check_output(image, out);

  const auto start = std::chrono::steady_clock::now();
  const cases::ImageSurface result = cases::surface_from_image(image, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  cases::write_surface(out, result.surface, {unit});

  const auto report = cases::validate(result.surface);
  for (const auto& note : result.notes)
    std::fprintf(stderr, "%s\n", note.c_str());
  std::printf(
      "%s: %s of %s: %lld voxels (%.6g m^3), extracted %lld vertices, written %lld "
      "vertices and %lld triangles, volume %.6g m^3, genus %d, %.2f s\n",
      out.string().c_str(), options.selection.describe().c_str(), image.string().c_str(),
      static_cast<long long>(result.voxels), result.voxels * result.voxel_volume_m3,
      static_cast<long long>(result.extracted_vertices),
      static_cast<long long>(result.surface.num_vertices()),
      static_cast<long long>(result.surface.num_triangles()), report.volume, report.genus, seconds);
  return 0;
}

}  // namespace msfem::compare
