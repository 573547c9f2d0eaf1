#pragma once

#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "msfem/cases/surface.hpp"

namespace msfem::cases {

/// Which voxels are the organ: those equal to a label of a label map, or those whose intensity
/// (after the file's scl_slope / scl_inter, e.g. Hounsfield units) lies in [low, high].
struct ImageSelection {
  std::optional<long> label;
  double low = -std::numeric_limits<double>::infinity();
  double high = std::numeric_limits<double>::infinity();

  /// "label 10" or "intensity in [LO, HI]".
  std::string describe() const;
};

/// "LO" or "LO:HI" (also "LO,HI"), as --threshold takes it. Throws InputError naming `what`.
ImageSelection parse_threshold(const std::string& text, const std::string& what);

struct ImageSurfaceOptions {
  ImageSelection selection;
  int target_vertices = 0;  ///< simplify to this many vertices afterwards; 0 keeps the extraction
  int smoothing_iterations = 0;  ///< Taubin iterations after the simplification
};

struct ImageSurface {
  Surface surface;                 ///< world coordinates (NIfTI RAS+), metres, outward, validated
  std::vector<std::string> notes;  ///< what was dropped, filled, padded or assumed, one line each
  long voxels = 0;                 ///< voxels of the organ after component selection and filling
  double voxel_volume_m3 = 0.0;
  Eigen::Index extracted_vertices = 0;  ///< before simplification
};

/// Reads a NIfTI-1 or NIfTI-2 image (.nii, .nii.gz), keeps the largest 6-connected component of the
/// selected voxels, fills its cavities and extracts its boundary as a closed, 2-manifold surface
/// (CGAL Mesh_3 on the labelled image with the manifold criterion), maps it to world coordinates
/// (sform if set, else qform; millimetres to metres), then simplifies and smooths it as asked. The
/// result is checked (closed, manifold, outward, no self-intersection) before it is returned.
/// Throws InputError naming the file or option at fault: a missing or non-NIfTI file, an absent
/// label (listing those present), an empty window (giving the image's range), a singular
/// transform, a target vertex count the surface cannot reach.
ImageSurface surface_from_image(const std::filesystem::path& image,
                                const ImageSurfaceOptions& options);

/// A case file's image source: "image:FILE:label=N" or "image:FILE:threshold=LO[:HI]".
struct ImageSource {
  std::filesystem::path file;
  ImageSelection selection;
};

/// Whether a geometry source names an image (starts with "image:").
bool is_image_source(const std::string& source);

/// Parses an image source; throws InputError naming the source and what is wrong with it.
ImageSource parse_image_source(const std::string& source);

/// The same source with a relative FILE taken relative to `folder` (a case file's folder).
std::string image_source_relative_to(const std::string& source,
                                     const std::filesystem::path& folder);

}  // namespace msfem::cases
