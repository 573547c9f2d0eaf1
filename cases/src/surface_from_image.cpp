// From a scan to a surface the models accept: select, clean up the voxels, extract, map to the
// world, then simplify and smooth as the skeleton paper did (marching cubes, 8,789 -> 446
// vertices, smoothed).
#include "msfem/cases/surface_from_image.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_simplification.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "voxel_volume.hpp"

namespace msfem::cases {
namespace {

using detail::Grid;
using detail::Mask;

double parse_real(const std::string& text, const std::string& what) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    throw InputError(what + ": '" + text + "' is not a finite number");
  return value;
}

std::string count_text(long n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// The voxels of the organ as one solid, with a note for everything that was changed.
Mask organ_mask(const detail::VoxelVolume& volume, const std::filesystem::path& file,
                const ImageSelection& selection, ImageSurface& result) {
  Mask mask = detail::select_voxels(volume, selection, file.string());
  const int dropped = detail::keep_largest_component(volume.grid, mask);
  if (dropped > 0)
    result.notes.push_back("kept the largest 6-connected component of " + selection.describe() +
                           ", dropped " + count_text(dropped, "smaller one", "smaller ones"));
  const long filled = detail::fill_cavities(volume.grid, mask);
  if (filled > 0)
    result.notes.push_back("filled " + count_text(filled, "cavity voxel", "cavity voxels"));
  if (detail::touches_border(volume.grid, mask))
    result.notes.push_back(file.string() + ": the organ touches the image border: its surface is " +
                           "closed one voxel outside the scan, where the scan clips it");
  result.voxels = std::accumulate(mask.begin(), mask.end(), 0L);
  return mask;
}

// The mesher extracts in voxel index coordinates of the padded grid; the affine transform keeps the
// surface closed, manifold and free of intersections (and reverses it when left-handed).
void to_world(const Eigen::Matrix4d& voxel_to_world, Surface& s) {
  const Eigen::Matrix3d a = voxel_to_world.topLeftCorner<3, 3>();
  const Eigen::Vector3d shift = voxel_to_world.topRightCorner<3, 1>() - a * Eigen::Vector3d::Ones();
  s.vertices = ((s.vertices * a.transpose()).rowwise() + shift.transpose()).eval();
}

// Mesh_3 may leave a sliver of the boundary as its own piece where voxels barely touch.
Surface largest_piece(const Surface& s, int& dropped) {
  std::vector<int> parent(static_cast<std::size_t>(s.num_vertices()));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int v) {
    while (parent[v] != v)
      v = parent[v] = parent[parent[v]];
    return v;
  };
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t)
    for (int c = 1; c < 3; ++c)
      parent[root(s.triangles(t, c))] = root(s.triangles(t, 0));
  std::vector<int> triangles_of(parent.size(), 0);
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t)
    ++triangles_of[root(s.triangles(t, 0))];
  const int keep = static_cast<int>(std::max_element(triangles_of.begin(), triangles_of.end()) -
                                    triangles_of.begin());
  dropped = static_cast<int>(std::count_if(triangles_of.begin(), triangles_of.end(),
                                           [](int n) { return n > 0; })) -
            1;
  std::vector<int> new_id(parent.size(), -1);
  Surface kept;
  std::vector<Eigen::Vector3i> rows;
  int next = 0;
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t) {
    if (root(s.triangles(t, 0)) != keep) continue;
    Eigen::Vector3i row;
    for (int c = 0; c < 3; ++c) {
      int& id = new_id[s.triangles(t, c)];
      if (id < 0) id = next++;
      row(c) = id;
    }
    rows.push_back(row);
  }
  kept.vertices.resize(next, 3);
  for (std::size_t v = 0; v < new_id.size(); ++v)
    if (new_id[v] >= 0) kept.vertices.row(new_id[v]) = s.vertices.row(static_cast<Eigen::Index>(v));
  kept.triangles.resize(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t t = 0; t < rows.size(); ++t)
    kept.triangles.row(static_cast<Eigen::Index>(t)) = rows[t].transpose();
  return kept;
}

Surface extract(const detail::VoxelVolume& volume, const Mask& mask, ImageSurface& result) {
  Grid grid;
  const Mask solid = detail::padded(volume.grid, mask, grid);
  const Eigen::Vector3d spacing_mm =
      1e3 * volume.voxel_to_world.topLeftCorner<3, 3>().colwise().norm().transpose();
  Surface s = detail::mesh_mask(grid, solid, spacing_mm);
  to_world(volume.voxel_to_world, s);
  int dropped = 0;
  s = largest_piece(s, dropped);
  if (dropped > 0)
    result.notes.push_back("dropped " + count_text(dropped, "sliver", "slivers") +
                           " of the extracted boundary apart from the organ's surface");
  return s;
}

// An extraction that fails the checks is msfem's fault (runtime_error, exit 1); a simplification
// that does is the options' (InputError, exit 2).
template <typename Error>
void check_valid(Surface& s, const std::string& what) {
  const SurfaceReport report = orient_and_validate(s);
  if (!report.ok()) throw Error(what + ": " + report.defects.front().message);
}

void simplify_and_smooth(const ImageSurfaceOptions& options, const std::string& name,
                         ImageSurface& result) {
  Surface& s = result.surface;
  if (options.target_vertices > s.num_vertices())
    throw InputError("--vertices " + std::to_string(options.target_vertices) +
                     " is more than the " + std::to_string(s.num_vertices()) +
                     " vertices extracted from " + name);
  if (options.target_vertices > 0 && options.target_vertices < s.num_vertices())
    s = simplify(s, options.target_vertices);
  smooth_taubin(s, options.smoothing_iterations);
  if (options.target_vertices > 0 || options.smoothing_iterations > 0)
    check_valid<InputError>(s, name + ": the surface simplified to --vertices " +
                                   std::to_string(options.target_vertices) + " and smoothed " +
                                   std::to_string(options.smoothing_iterations) +
                                   " times is not valid (take more vertices or fewer iterations)");
}

}  // namespace

std::string ImageSelection::describe() const {
  if (label) return "label " + std::to_string(*label);
  char text[96];
  std::snprintf(text, sizeof text, "intensity in [%g, %g]", low, high);
  return text;
}

ImageSelection parse_threshold(const std::string& text, const std::string& what) {
  const auto split = text.find_first_of(":,");
  ImageSelection s;
  s.low = parse_real(text.substr(0, split), what);
  if (split != std::string::npos) s.high = parse_real(text.substr(split + 1), what);
  if (s.high < s.low) throw InputError(what + ": the window '" + text + "' is empty (HI below LO)");
  return s;
}

ImageSurface surface_from_image(const std::filesystem::path& image,
                                const ImageSurfaceOptions& options) {
  ImageSurface result;
  const detail::VoxelVolume volume = detail::read_nifti(image);
  result.notes = volume.notes;
  result.voxel_volume_m3 = std::abs(volume.voxel_to_world.topLeftCorner<3, 3>().determinant());
  const Mask mask = organ_mask(volume, image, options.selection, result);
  result.surface = extract(volume, mask, result);
  result.extracted_vertices = result.surface.num_vertices();
  check_valid<std::runtime_error>(result.surface, image.string() + ": the surface extracted from " +
                                                      options.selection.describe() +
                                                      " is not valid");
  simplify_and_smooth(options, image.string(), result);
  return result;
}

}  // namespace msfem::cases
