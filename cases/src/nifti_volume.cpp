// NIfTI-1/2 input through niftilib, the reference implementation of the format: it reads both
// versions, gzip included, and computes the qform matrix from the quaternion as the standard says.
#include <nifti2_io.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "msfem/cases/errors.hpp"
#include "voxel_volume.hpp"

namespace msfem::cases::detail {
namespace {

using NiftiPointer = std::unique_ptr<nifti_image, void (*)(nifti_image*)>;

template <typename T>
void copy_values(const void* data, long count, std::vector<float>& values) {
  const T* in = static_cast<const T*>(data);
  for (long v = 0; v < count; ++v)
    values[v] = static_cast<float>(in[v]);
}

void convert_values(const nifti_image& image, const std::string& name, VoxelVolume& volume) {
  const long n = volume.grid.count();
  volume.values.resize(n);
  switch (image.datatype) {
    case NIFTI_TYPE_UINT8:
      return copy_values<std::uint8_t>(image.data, n, volume.values);
    case NIFTI_TYPE_INT8:
      return copy_values<std::int8_t>(image.data, n, volume.values);
    case NIFTI_TYPE_INT16:
      return copy_values<std::int16_t>(image.data, n, volume.values);
    case NIFTI_TYPE_UINT16:
      return copy_values<std::uint16_t>(image.data, n, volume.values);
    case NIFTI_TYPE_INT32:
      return copy_values<std::int32_t>(image.data, n, volume.values);
    case NIFTI_TYPE_UINT32:
      return copy_values<std::uint32_t>(image.data, n, volume.values);
    case NIFTI_TYPE_INT64:
      return copy_values<std::int64_t>(image.data, n, volume.values);
    case NIFTI_TYPE_UINT64:
      return copy_values<std::uint64_t>(image.data, n, volume.values);
    case NIFTI_TYPE_FLOAT32:
      return copy_values<float>(image.data, n, volume.values);
    case NIFTI_TYPE_FLOAT64:
      return copy_values<double>(image.data, n, volume.values);
    default:
      throw InputError(name + ": voxel type " + nifti_datatype_string(image.datatype) +
                       " is not supported (integer or real scalars only)");
  }
}

// Stored values are scaled when scl_slope is set (CT in Hounsfield units is often stored so).
void apply_scaling(const nifti_image& image, VoxelVolume& volume) {
  if (image.scl_slope == 0.0 || !std::isfinite(image.scl_slope)) return;
  if (image.scl_slope == 1.0 && image.scl_inter == 0.0) return;
  for (float& v : volume.values)
    v = static_cast<float>(image.scl_slope * v + image.scl_inter);
}

double metres_per_unit(const nifti_image& image, std::vector<std::string>& notes) {
  switch (image.xyz_units & 0x07) {
    case NIFTI_UNITS_METER:
      return 1.0;
    case NIFTI_UNITS_MICRON:
      return 1e-6;
    case NIFTI_UNITS_MM:
      return 1e-3;
    default:
      notes.push_back("the image gives no spatial unit: millimetres assumed, as scanners write");
      return 1e-3;
  }
}

// The sform is the scanner's or the registration's full affine; the qform a rigid map times the
// voxel size; with neither code set, niftilib's qform is the voxel size alone (ANALYZE's default).
Eigen::Matrix4d transform_of(const nifti_image& image, const std::string& name,
                             std::vector<std::string>& notes) {
  const nifti_dmat44& m = image.sform_code > 0 ? image.sto_xyz : image.qto_xyz;
  notes.push_back(image.sform_code > 0   ? "voxel to world: sform"
                  : image.qform_code > 0 ? "voxel to world: qform (no sform)"
                                         : "voxel to world: voxel size only (no sform or qform)");
  Eigen::Matrix4d t;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      t(r, c) = m.m[r][c];
  const double scale = metres_per_unit(image, notes);
  t.topRows<3>() *= scale;
  const double det = t.topLeftCorner<3, 3>().determinant();
  const double voxel = t.topLeftCorner<3, 3>().colwise().norm().prod();
  if (!std::isfinite(det) || !(std::abs(det) > 1e-9 * voxel) || !(voxel > 0))
    throw InputError(name + ": the voxel-to-world transform is singular (determinant " +
                     std::to_string(det) + ")");
  if (det < 0) notes.push_back("left-handed voxel-to-world transform: triangles reoriented");
  return t;
}

}  // namespace

VoxelVolume read_nifti(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(name + ": no such file");
  nifti_set_debug_level(0);
  if (is_nifti_file(name.c_str()) <= 0)
    throw InputError(name + ": not a NIfTI-1 or NIfTI-2 image (.nii or .nii.gz)");
  NiftiPointer image(nifti_image_read(name.c_str(), 1), nifti_image_free);
  if (!image || !image->data)
    throw InputError(name + ": cannot read the NIfTI image (truncated or corrupt data)");
  if (image->nx < 2 || image->ny < 2 || image->nz < 2)
    throw InputError(name + ": a " + std::to_string(image->dim[0]) +
                     "-D image; a volume needs at least 2 voxels along i, j and k");
  if (image->nvox != image->nx * image->ny * image->nz)
    throw InputError(name + ": holds " +
                     std::to_string(image->nvox / (image->nx * image->ny * image->nz)) +
                     " volumes; give a single 3-D volume");
  VoxelVolume volume;
  volume.grid.size = {static_cast<long>(image->nx), static_cast<long>(image->ny),
                      static_cast<long>(image->nz)};
  convert_values(*image, name, volume);
  apply_scaling(*image, volume);
  volume.voxel_to_world = transform_of(*image, name, volume.notes);
  return volume;
}

}  // namespace msfem::cases::detail
