#pragma once

#include <filesystem>
#include <string>

#include "msfem/cases/surface.hpp"
#include "msfem/cases/units.hpp"

namespace msfem::cases {

/// File formats for closed surfaces, chosen by extension (.obj, .stl, .off, .ply, .x3d: the
/// file's first IndexedFaceSet, cases/x3d.hpp).
enum class SurfaceFormat { obj, stl, off, ply, x3d };

/// The format for a path's extension (case-insensitive); throws InputError naming the file for an
/// unknown extension.
SurfaceFormat surface_format_for(const std::filesystem::path& path);

/// Reads a triangulated surface whose coordinates are in `unit` and returns it in metres.
/// Polygons with more than three corners are fan-triangulated. Throws InputError with one line
/// naming the file and the line (text formats) or the element (binary formats) at fault: missing
/// file, unknown extension, truncated binary data, a non-numeric or non-finite coordinate, an index
/// out of range.
Surface read_surface(const std::filesystem::path& path, LengthUnit unit = LengthUnit::metre);

struct SurfaceWriteOptions {
  LengthUnit unit = LengthUnit::metre;  ///< coordinates are converted from metres to this unit
  bool binary = false;  ///< binary STL / binary little-endian PLY; ignored for OBJ, OFF
};

/// Writes the surface in the format of the path's extension. Written to a temporary name in the
/// same folder and renamed, so a failure never leaves a half-written file at `path`.
void write_surface(const std::filesystem::path& path, const Surface& surface,
                   const SurfaceWriteOptions& options = {});

}  // namespace msfem::cases
