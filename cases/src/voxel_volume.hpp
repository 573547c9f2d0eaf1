#pragma once
// Voxel images inside cases/: the NIfTI reader fills a VoxelVolume, the mask operations turn a
// selection into the one solid the mesher extracts. Private to cases/.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "msfem/cases/surface.hpp"
#include "msfem/cases/surface_from_image.hpp"

namespace msfem::cases::detail {

/// Voxel (i, j, k) is at index i + nx * (j + ny * k), NIfTI's and CGAL's Image_3's order.
struct Grid {
  std::array<long, 3> size{0, 0, 0};
  long count() const { return size[0] * size[1] * size[2]; }
  long index(long i, long j, long k) const { return i + size[0] * (j + size[1] * k); }
};

struct VoxelVolume {
  Grid grid;
  std::vector<float> values;  ///< scaled by the file's scl_slope / scl_inter when it sets one
  /// Voxel indices (i, j, k, 1) to world metres, NIfTI RAS+ (x to the right, y anterior, z up).
  Eigen::Matrix4d voxel_to_world = Eigen::Matrix4d::Identity();
  std::vector<std::string> notes;  ///< which transform, which unit was assumed
};

/// Reads a single-file 3-D NIfTI-1 or NIfTI-2 image, gzipped or not. Throws InputError naming the
/// file and the header field or the voxel at fault: missing, not NIfTI or truncated, more than one
/// volume, an unsupported voxel type, a voxel size, scale factor, vox_offset or transform that is
/// not finite or out of bounds, a NaN or infinite voxel; so every value returned is finite.
VoxelVolume read_nifti(const std::filesystem::path& file);

using Mask = std::vector<std::uint8_t>;

/// The selected voxels. Throws InputError naming `file` if none is selected: for a label, the
/// labels present; for a window, the image's range.
Mask select_voxels(const VoxelVolume& volume, const ImageSelection& selection,
                   const std::string& file);

/// Keeps the largest 6-connected component; returns how many smaller ones were dropped.
int keep_largest_component(const Grid& grid, Mask& mask);

/// Sets every background voxel that is not 6-connected to the image border; returns how many.
long fill_cavities(const Grid& grid, Mask& mask);

/// Whether a selected voxel lies on a face of the image (the organ is clipped by the scan).
bool touches_border(const Grid& grid, const Mask& mask);

/// The mask with one background voxel added on every side, so that a clipped organ still has a
/// closed boundary (at the first voxel layer outside the scan).
Mask padded(const Grid& grid, const Mask& mask, Grid& padded_grid);

/// The boundary of the solid the mask covers, as a closed 2-manifold surface in voxel index
/// coordinates of `grid` (CGAL Mesh_3, labelled-image domain, manifold criterion). `spacing` is the
/// voxel size along i, j, k, so that the facet size and distance bounds are isotropic in the world.
Surface mesh_mask(const Grid& grid, const Mask& mask, const Eigen::Vector3d& spacing);

}  // namespace msfem::cases::detail
