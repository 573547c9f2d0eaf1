// Seeds for fuzz_nifti: tiny images in each layout the reader takes (NIfTI-1 and NIfTI-2, either
// byte order, integer and real voxels, scaled, voxels after a gap of extensions, a voxel-size-only
// transform), so that the fuzzer starts from inputs that get past the header checks.
//   nifti_seeds OUTDIR
#include <cstdio>
#include <string>

#include "nifti_writer.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: nifti_seeds OUTDIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  using msfem::testing::NiftiImage;
  NiftiImage base{4, 3, 2, {}};
  for (int v = 0; v < 24; ++v)
    base.values.push_back(static_cast<std::int16_t>(40 * v - 500));
  base.sform.leftCols<3>() << 0.9, 0.1, 0.0, -0.1, 1.2, 0.0, 0.0, 0.0, 2.5;
  base.sform.col(3) << -20.0, 35.5, 110.0;
  int written = 0;
  const auto write = [&](const std::string& name, const NiftiImage& image) {
    msfem::testing::write_nifti(dir / (name + ".nii"), image);
    ++written;
  };
  for (int version : {1, 2})
    for (bool big_endian : {false, true}) {
      NiftiImage image = base;
      image.version = version;
      image.big_endian = big_endian;
      const std::string name = "v" + std::to_string(version) + (big_endian ? "_be" : "_le");
      write(name + "_int16", image);
      image.reals.assign({0.5f, -1.0f, 2.0f,  1e3f,  -7.25f, 0.0f,  3.0f,  9.0f,
                          1.0f, 2.0f,  3.0f,  4.0f,  5.0f,   6.0f,  7.0f,  8.0f,
                          9.0f, 10.0f, 11.0f, 12.0f, 13.0f,  14.0f, 15.0f, 16.0f});
      write(name + "_float32", image);
    }
  NiftiImage scaled = base;
  scaled.slope = 2.0f;
  scaled.intercept = -1024.0f;
  write("v1_le_scaled", scaled);
  NiftiImage gap = base;
  gap.vox_offset = 400;
  write("v1_le_extension_gap", gap);
  NiftiImage voxel_size_only = base;
  voxel_size_only.sform_code = 0;
  voxel_size_only.pixdim = Eigen::Vector3f(0.75f, 0.75f, 3.0f);
  write("v1_le_pixdim_only", voxel_size_only);
  std::printf("%d NIfTI seeds in %s\n", written, dir.c_str());
  return 0;
}
