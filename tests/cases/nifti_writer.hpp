#pragma once
// Writes small NIfTI-1 and NIfTI-2 images by hand, byte by byte as the standard lays them out, so
// that the tests do not trust the reader they test. The header fields a hostile file would get
// wrong can be set to anything.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace msfem::testing {

struct NiftiImage {
  int nx = 0, ny = 0, nz = 0;
  std::vector<std::int16_t> values;  ///< stored (before slope and intercept)
  Eigen::Matrix<double, 3, 4> sform = Eigen::Matrix<double, 3, 4>::Identity();  ///< in mm
  float slope = 0.0f, intercept = 0.0f;
  std::vector<float> reals = {};  ///< when not empty, stored as FLOAT32 instead of values
  std::optional<Eigen::Vector3f> pixdim = {};  ///< default: the sform's column lengths
  std::optional<double> vox_offset = {};       ///< default: right after the header
  int sform_code = 1;
  int version = 1;  ///< NIfTI-1 (348-byte header) or NIfTI-2 (540 bytes)
  bool big_endian = false;
};

namespace detail {

// Field offsets of the two header layouts (nifti1.h, nifti2.h).
struct NiftiOffsets {
  std::size_t magic, datatype, bitpix, dim, pixdim, vox_offset, slope, intercept, xyzt_units,
      sform_code, srow;
};
constexpr NiftiOffsets nifti1_offsets{344, 70, 72, 40, 76, 108, 112, 116, 123, 254, 280};
constexpr NiftiOffsets nifti2_offsets{4, 12, 14, 16, 104, 168, 176, 184, 500, 348, 400};

}  // namespace detail

inline void write_nifti(const std::filesystem::path& path, const NiftiImage& image) {
  const bool v2 = image.version == 2;
  const detail::NiftiOffsets& at = v2 ? detail::nifti2_offsets : detail::nifti1_offsets;
  const std::size_t header_bytes = v2 ? 544 : 352;
  std::vector<char> header(header_bytes, 0);
  const auto put_into = [&](std::vector<char>& bytes, std::size_t offset, auto value) {
    char* p = bytes.data() + offset;
    std::memcpy(p, &value, sizeof value);
    if (image.big_endian) std::reverse(p, p + sizeof value);
  };
  const auto put = [&](std::size_t offset, auto value) { put_into(header, offset, value); };
  // NIfTI-1 stores integers in 16 bits and reals in 32, NIfTI-2 in 64 bits both.
  const auto put_int = [&](std::size_t offset, long value) {
    v2 ? put(offset, std::int64_t(value)) : put(offset, std::int16_t(value));
  };
  const auto put_real = [&](std::size_t offset, double value) {
    v2 ? put(offset, value) : put(offset, static_cast<float>(value));
  };
  const std::size_t int_bytes = v2 ? 8 : 2, real_bytes = v2 ? 8 : 4;

  put(0, std::int32_t(v2 ? 540 : 348));
  const long dims[8] = {3, image.nx, image.ny, image.nz, 1, 1, 1, 1};
  for (int d = 0; d < 8; ++d)
    put_int(at.dim + int_bytes * d, dims[d]);
  const bool real = !image.reals.empty();
  put(at.datatype, std::int16_t(real ? 16 : 4));  // FLOAT32 or INT16
  put(at.bitpix, std::int16_t(real ? 32 : 16));
  put_real(at.pixdim, 1.0);  // qfac
  for (int d = 0; d < 3; ++d)
    put_real(at.pixdim + real_bytes * (d + 1),
             image.pixdim ? double((*image.pixdim)(d)) : image.sform.col(d).norm());
  const double offset = image.vox_offset.value_or(double(header_bytes));
  v2 ? put(at.vox_offset, static_cast<std::int64_t>(offset))
     : put(at.vox_offset, static_cast<float>(offset));
  put_real(at.slope, image.slope);
  put_real(at.intercept, image.intercept);
  v2 ? put(at.xyzt_units, std::int32_t(2)) : put(at.xyzt_units, std::int8_t(2));  // millimetres
  v2 ? put(at.sform_code, std::int32_t(image.sform_code))
     : put(at.sform_code, std::int16_t(image.sform_code));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      put_real(at.srow + real_bytes * (4 * r + c), image.sform(r, c));
  std::memcpy(header.data() + at.magic, v2 ? "n+2\0\r\n\032\n" : "n+1", v2 ? 8 : 4);

  // The data go where vox_offset says when that is past the header, else right after it.
  const std::size_t start = offset > double(header_bytes) ? std::size_t(offset) : header_bytes;
  std::vector<char> data(start - header_bytes, 0);
  const std::size_t count = real ? image.reals.size() : image.values.size();
  const std::size_t size = real ? 4 : 2;
  data.resize(data.size() + count * size);
  for (std::size_t v = 0; v < count; ++v) {
    const std::size_t where = start - header_bytes + v * size;
    real ? put_into(data, where, image.reals[v]) : put_into(data, where, image.values[v]);
  }
  std::ofstream out(path, std::ios::binary);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

}  // namespace msfem::testing
