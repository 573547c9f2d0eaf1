// Young's modulus from a CT: the HU table and the trilinear field in world coordinates.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/modulus_image.hpp"
#include "nifti_writer.hpp"

namespace msfem::cases {
namespace {

using testing::NiftiImage;

std::string message_of(const std::string& table) {
  try {
    parse_hu_to_youngs(table, "material/hu to youngs");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(HuToYoungs, IsLinearBetweenItsPointsAndHeldBeyond) {
  const HuToYoungs table = parse_hu_to_youngs(" -100:3000; 40 : 3500;60:6000 ", "t");
  ASSERT_EQ(table.points.size(), 3u);
  EXPECT_DOUBLE_EQ(table(-1000), 3000);
  EXPECT_DOUBLE_EQ(table(-100), 3000);
  EXPECT_DOUBLE_EQ(table(-30), 3250);
  EXPECT_DOUBLE_EQ(table(50), 4750);
  EXPECT_DOUBLE_EQ(table(60), 6000);
  EXPECT_DOUBLE_EQ(table(3000), 6000);
  EXPECT_EQ(table.describe(), "-100:3000; 40:3500; 60:6000");
  // The default parses and gives the documented values.
  const HuToYoungs fallback = parse_hu_to_youngs(default_hu_to_youngs, "t");
  EXPECT_DOUBLE_EQ(fallback(40), 3500);
  EXPECT_DOUBLE_EQ(fallback(60), 6000);
}

TEST(HuToYoungs, BadTablesNameThePointAtFault) {
  EXPECT_NE(message_of("0:3000; 0:4000").find("HU 0 does not increase"), std::string::npos);
  EXPECT_NE(message_of("10:3000; -5:4000").find("HU -5 does not increase"), std::string::npos);
  EXPECT_NE(message_of("0:3000; 40:0").find("'40:0' gives E = 0 Pa"), std::string::npos);
  EXPECT_NE(message_of("0:-3").find("must be > 0"), std::string::npos);
  EXPECT_NE(message_of("0:3000; 40").find("'40' is not HU:E"), std::string::npos);
  EXPECT_NE(message_of("a:b").find("'a:b' is not HU:E"), std::string::npos);
  EXPECT_NE(message_of("0:nan").find("is not HU:E"), std::string::npos);
  EXPECT_NE(message_of(" ; ").find("no HU:E point"), std::string::npos);
  EXPECT_EQ(message_of("0:3000"), "");
}

class ModulusImage : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("msfem_modulus_" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const NiftiImage& image) {
    const auto path = dir_ / "ct.nii";
    testing::write_nifti(path, image);
    return path;
  }
  // The refusal's message, or "" when the image is accepted.
  std::string refusal(const std::filesystem::path& path) {
    try {
      YoungsModulusImage(path, parse_hu_to_youngs("0:3000; 100:7000", "t"));
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  std::filesystem::path dir_;
};

// HU 10 everywhere, stored as reals.
NiftiImage real_image() {
  NiftiImage image{3, 4, 2, {}};
  image.reals.assign(24, 10.0f);
  return image;
}

TEST_F(ModulusImage, InterpolatesEBetweenVoxelCentresInWorldCoordinates) {
  // HU = 10 i + 20 j + 40 k (stored as half of it, slope 2, intercept 0) on a rotated, anisotropic
  // grid; a linear table keeps E linear in HU, so the trilinear E is exact everywhere inside (to
  // the float precision NIfTI stores the transform in).
  NiftiImage image{5, 4, 3, {}};
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  image.sform.leftCols<3>() = rotation * Eigen::Vector3d(2.0, 3.0, 1.5).asDiagonal();
  image.sform.col(3) << 10.0, -20.0, 5.0;
  image.slope = 2.0f;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i)
        image.values.push_back(static_cast<std::int16_t>(5 * i + 10 * j + 20 * k));
  const YoungsModulusImage field(write(image), parse_hu_to_youngs("0:1000; 1000:11000", "t"));
  auto world_m = [&](const Eigen::Vector3d& ijk) {
    return Eigen::Vector3d(1e-3 * (image.sform.leftCols<3>() * ijk + image.sform.col(3)));
  };
  for (const Eigen::Vector3d& ijk :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 3, 2), Eigen::Vector3d(1.25, 2.5, 0.75),
        Eigen::Vector3d(3.9, 0.1, 1)}) {
    const double hu = 10 * ijk.x() + 20 * ijk.y() + 40 * ijk.z();
    EXPECT_NEAR(field(world_m(ijk)), 1000 + 10 * hu, 1e-6 * (1000 + 10 * hu)) << ijk.transpose();
  }
  // Beyond the voxel centres: the nearest face's values; beyond the extent: not contained.
  EXPECT_NEAR(field(world_m(Eigen::Vector3d(-0.4, 1, 1))), 1000 + 10 * (20 + 40), 1e-3);
  EXPECT_TRUE(field.contains(world_m(Eigen::Vector3d(-0.4, 1, 1))));
  EXPECT_FALSE(field.contains(world_m(Eigen::Vector3d(-1.2, 1, 1))));
  EXPECT_FALSE(field.contains(world_m(Eigen::Vector3d(2, 3.0, 2.6)), 0.0));
  const auto range = field.voxel_range();
  EXPECT_DOUBLE_EQ(range[0], 1000);
  EXPECT_DOUBLE_EQ(range[1], 1000 + 10 * (40 + 60 + 80));
}

TEST_F(ModulusImage, AHomogeneousImageGivesItsOneModulusExactly) {
  NiftiImage image{3, 3, 3, std::vector<std::int16_t>(27, 47)};
  const YoungsModulusImage field(write(image), parse_hu_to_youngs("-100:3000; 100:7000", "t"));
  const double expected = parse_hu_to_youngs("-100:3000; 100:7000", "t")(47);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> within(-0.5e-3, 2.5e-3);
  for (int n = 0; n < 200; ++n) {
    const Eigen::Vector3d x(within(random), within(random), within(random));
    ASSERT_EQ(field(x), expected) << x.transpose();
  }
}

TEST_F(ModulusImage, TheFingerprintFollowsTheVoxelsAndTheTable) {
  NiftiImage image{3, 3, 3, std::vector<std::int16_t>(27, 10)};
  const auto path = write(image);
  const HuToYoungs table = parse_hu_to_youngs("0:3000; 100:7000", "t");
  const std::string a = YoungsModulusImage(path, table).fingerprint();
  EXPECT_EQ(YoungsModulusImage(path, table).fingerprint(), a);
  EXPECT_NE(YoungsModulusImage(path, parse_hu_to_youngs("0:3000; 100:8000", "t")).fingerprint(), a);
  image.values[13] = 11;
  EXPECT_NE(YoungsModulusImage(write(image), table).fingerprint(), a);
}

TEST_F(ModulusImage, NanAndInfiniteVoxelsAreRefusedNamingTheFirst) {
  // niftilib would read them as 0 HU, the softest tissue, with nothing said.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  NiftiImage image = real_image();
  image.reals[2 + 3 * (1 + 4 * 1)] = nan;  // (2,1,1)
  image.reals[0 + 3 * (3 + 4 * 1)] = nan;  // (0,3,1), later in the file
  const auto path = write(image);
  EXPECT_EQ(refusal(path), path.string() + ": voxel (2,1,1) is NaN");
  image = real_image();
  image.reals[1 + 3 * 2] = inf;  // (1,2,0)
  EXPECT_EQ(refusal(write(image)), path.string() + ": voxel (1,2,0) is +inf");
  image.reals[1 + 3 * 2] = -inf;
  EXPECT_EQ(refusal(write(image)), path.string() + ": voxel (1,2,0) is -inf");
  // Finite as stored, but past single precision once scaled.
  image = NiftiImage{3, 3, 3, std::vector<std::int16_t>(27, 10)};
  image.values[26] = 32767;
  image.slope = 1e35f;
  EXPECT_EQ(refusal(write(image)), path.string() +
                                       ": voxel (2,2,2) = 32767 scaled by scl_slope = 1e+35, "
                                       "scl_inter = 0 is 3.2767e+39, beyond single precision");
  image.slope = 1.0f;
  EXPECT_EQ(refusal(write(image)), "");
}

TEST_F(ModulusImage, HeaderFieldsAtFaultAreNamed) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<std::pair<std::function<void(NiftiImage&)>, std::string>> cases = {
      {[](NiftiImage& i) { i.pixdim = Eigen::Vector3f(0, 1, 1); },
       "NIfTI header pixdim[1] = 0 (voxel size must be finite and > 0)"},
      {[](NiftiImage& i) { i.pixdim = Eigen::Vector3f(1, -1, 1); },
       "NIfTI header pixdim[2] = -1 (voxel size must be finite and > 0)"},
      {[&](NiftiImage& i) { i.pixdim = Eigen::Vector3f(1, 1, nan); },
       "NIfTI header pixdim[3] = nan (voxel size must be finite and > 0)"},
      {[](NiftiImage& i) { i.pixdim = Eigen::Vector3f(2000, 1, 1); },
       "NIfTI header pixdim[1] = 2000 (voxel size must be between 1 nm and 1 m)"},
      {[](NiftiImage& i) { i.vox_offset = -100; },
       "NIfTI header vox_offset = -100 (the data must start after the 352-byte header)"},
      {[](NiftiImage& i) { i.vox_offset = 0; },
       "NIfTI header vox_offset = 0 (the data must start after the 352-byte header)"},
      {[](NiftiImage& i) { i.vox_offset = 360.5; },
       "NIfTI header vox_offset = 360.5 (must be a whole number of bytes)"},
      {[](NiftiImage& i) {
         i.version = 2;
         i.vox_offset = 352;
       },
       "NIfTI header vox_offset = 352 (the data must start after the 544-byte header)"},
      {[&](NiftiImage& i) { i.slope = nan; }, "NIfTI header scl_slope = nan (must be finite)"},
      {[&](NiftiImage& i) { i.intercept = -inf; },
       "NIfTI header scl_inter = -inf (must be finite)"},
      {[&](NiftiImage& i) {
         i.sform(1, 2) = nan;
         i.pixdim = Eigen::Vector3f(1, 1, 1);
       },
       "NIfTI header srow_y[2] = nan (the sform must be finite)"},
      {[](NiftiImage& i) { i.sform_code = 9; }, "NIfTI header sform_code = 9 (must be 0 to 5)"},
      {[](NiftiImage& i) {
         i.sform.col(0) *= 1e7;
         i.pixdim = Eigen::Vector3f(1, 1, 1);
       },
       "the voxel-to-world transform (sform) steps 10000 m along i (a voxel must be between 1 nm "
       "and 1 m)"},
      {[](NiftiImage& i) { i.sform(2, 3) = 1e12; },
       "the voxel-to-world transform (sform) puts voxel (0,0,0) 1e+09 m from the origin (more "
       "than 1e6 m)"},
  };
  for (const auto& [change, expected] : cases) {
    NiftiImage image{3, 3, 3, std::vector<std::int16_t>(27, 10)};
    change(image);
    const auto path = write(image);
    EXPECT_EQ(refusal(path), path.string() + ": " + expected);
    // niftilib would take a bad voxel size as 1 mm where no sform overrides it: refused alike.
    image.sform_code = 0;
    if (expected.find("pixdim") != std::string::npos) {
      EXPECT_EQ(refusal(write(image)), path.string() + ": " + expected);
    }
  }
}

TEST_F(ModulusImage, DataBeyondTheEndOfTheFileIsRefused) {
  NiftiImage image{3, 3, 3, std::vector<std::int16_t>(27, 10)};
  image.vox_offset = 400;
  const auto path = write(image);
  EXPECT_EQ(refusal(path), "");
  std::filesystem::resize_file(path, 400 + 2 * 27 - 1);
  EXPECT_EQ(refusal(path), path.string() +
                               ": truncated: NIfTI header vox_offset = 400 and dims 3 x 3 x 3 of "
                               "INT16 need 454 bytes; the file holds 453");
  std::filesystem::resize_file(path, 200);
  EXPECT_EQ(refusal(path), path.string() + ": not a NIfTI-1 or NIfTI-2 image (.nii or .nii.gz)");
}

TEST_F(ModulusImage, BothByteOrdersAndBothVersionsReadAlike) {
  // Values a float holds exactly, so that NIfTI-1's single and NIfTI-2's double precision agree.
  NiftiImage image{5, 4, 3, {}};
  image.sform.leftCols<3>() = Eigen::Vector3d(0.75, 1.25, 2.5).asDiagonal();
  image.sform.col(3) << -30.0, 12.5, 7.0;
  image.slope = 0.5f;
  image.intercept = -20.0f;
  for (int v = 0; v < 60; ++v)
    image.values.push_back(static_cast<std::int16_t>(7 * v - 100));
  const HuToYoungs table = parse_hu_to_youngs(default_hu_to_youngs, "t");
  const std::string little_1 = YoungsModulusImage(write(image), table).fingerprint();
  for (int version : {1, 2})
    for (bool big_endian : {false, true}) {
      image.version = version;
      image.big_endian = big_endian;
      EXPECT_EQ(YoungsModulusImage(write(image), table).fingerprint(), little_1)
          << "NIfTI-" << version << (big_endian ? " big" : " little") << "-endian";
    }
  image.reals.assign(60, 42.0f);
  const std::string reals = YoungsModulusImage(write(image), table).fingerprint();
  image.big_endian = false;
  EXPECT_EQ(YoungsModulusImage(write(image), table).fingerprint(), reals);
}

TEST_F(ModulusImage, AFileThatIsNotAnImageIsNamed) {
  const auto path = dir_ / "ct.nii";
  std::ofstream(path) << "not an image";
  try {
    YoungsModulusImage(path, parse_hu_to_youngs("0:3000", "t"));
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace msfem::cases
