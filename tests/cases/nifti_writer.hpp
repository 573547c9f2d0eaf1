#pragma once
// Writes small NIfTI-1 images by hand, byte by byte as the standard lays them out, so that the
// tests do not trust the reader they test.

#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace msfem::testing {

struct NiftiImage {
  int nx = 0, ny = 0, nz = 0;
  std::vector<std::int16_t> values;  ///< stored (before slope and intercept)
  Eigen::Matrix<double, 3, 4> sform = Eigen::Matrix<double, 3, 4>::Identity();  ///< in mm
  float slope = 0.0f, intercept = 0.0f;
};

inline void write_nifti(const std::filesystem::path& path, const NiftiImage& image) {
  std::vector<char> header(352, 0);
  const auto put = [&](std::size_t offset, auto value) {
    std::memcpy(header.data() + offset, &value, sizeof value);
  };
  put(0, std::int32_t{348});
  const std::int16_t dims[8] = {3,
                                static_cast<std::int16_t>(image.nx),
                                static_cast<std::int16_t>(image.ny),
                                static_cast<std::int16_t>(image.nz),
                                1,
                                1,
                                1,
                                1};
  for (int d = 0; d < 8; ++d)
    put(40 + 2 * d, dims[d]);
  put(70, std::int16_t{4});   // datatype: signed 16-bit integer
  put(72, std::int16_t{16});  // bits per voxel
  put(76, 1.0f);              // qfac
  for (int d = 0; d < 3; ++d)
    put(80 + 4 * d, static_cast<float>(image.sform.col(d).norm()));
  put(108, 352.0f);  // vox_offset
  put(112, image.slope);
  put(116, image.intercept);
  header[123] = 2;            // spatial unit: millimetres
  put(254, std::int16_t{1});  // sform_code: scanner anatomical
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      put(280 + 16 * r + 4 * c, static_cast<float>(image.sform(r, c)));
  std::memcpy(header.data() + 344, "n+1", 4);
  std::ofstream out(path, std::ios::binary);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(reinterpret_cast<const char*>(image.values.data()),
            static_cast<std::streamsize>(2 * image.values.size()));
}

}  // namespace msfem::testing
