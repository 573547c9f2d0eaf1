#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_from_image.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "nifti_writer.hpp"

namespace msfem::cases {
namespace {

using testing::NiftiImage;

// A rotated, anisotropic, translated grid: a reader that ignored any part of the sform would put
// the ball elsewhere or give it another volume.
Eigen::Matrix<double, 3, 4> skewed_sform() {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = rotation * Eigen::Vector3d(1.0, 1.25, 1.5).asDiagonal();
  m.col(3) << -120.0, 35.5, 210.0;
  return m;
}

Eigen::Vector3d world_mm(const NiftiImage& image, int i, int j, int k) {
  return image.sform.leftCols<3>() * Eigen::Vector3d(i, j, k) + image.sform.col(3);
}

// A ball of radius `radius` mm (a hollow of 3 mm inside it), and a 3 mm blob apart from it.
NiftiImage ball_image(std::int16_t inside, std::int16_t hollow, std::int16_t outside,
                      double radius) {
  NiftiImage image{48, 40, 32, {}, skewed_sform()};
  const Eigen::Vector3d centre = world_mm(image, 22, 20, 16), blob = world_mm(image, 42, 35, 27);
  for (int k = 0; k < image.nz; ++k)
    for (int j = 0; j < image.ny; ++j)
      for (int i = 0; i < image.nx; ++i) {
        const Eigen::Vector3d x = world_mm(image, i, j, k);
        const double r = (x - centre).norm();
        image.values.push_back(r < 3.0                   ? hollow
                               : r < radius              ? inside
                               : (x - blob).norm() < 3.0 ? inside
                                                         : outside);
      }
  return image;
}

bool has_note(const ImageSurface& s, const std::string& text) {
  for (const auto& n : s.notes)
    if (n.find(text) != std::string::npos) return true;
  return false;
}

class SurfaceFromImage : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("msfem_image_" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

// The centroid of the enclosed solid (tetrahedra from the origin to each triangle): unlike the
// vertex mean, it does not move where a simplification leaves vertices unevenly spread.
Eigen::Vector3d solid_centroid(const Surface& s) {
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  double volume = 0.0;
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t) {
    const Eigen::Vector3d a = s.vertices.row(s.triangles(t, 0)),
                          b = s.vertices.row(s.triangles(t, 1)),
                          c = s.vertices.row(s.triangles(t, 2));
    const double v = a.dot(b.cross(c)) / 6.0;
    moment += v * (a + b + c) / 4.0;
    volume += v;
  }
  return moment / volume;
}

void expect_ball(const ImageSurface& result, const NiftiImage& image, double radius_mm) {
  SurfaceReport report = validate(result.surface);
  EXPECT_TRUE(report.ok()) << (report.ok() ? "" : report.defects.front().message);
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.genus, 0);
  const double expected = 4.0 / 3.0 * M_PI * std::pow(radius_mm * 1e-3, 3);
  EXPECT_GT(report.volume, 0.0);  // outward
  EXPECT_NEAR(report.volume, expected, 0.04 * expected);
  const Eigen::Vector3d centre = 1e-3 * world_mm(image, 22, 20, 16);
  EXPECT_LT((solid_centroid(result.surface) - centre).norm(), 0.2e-3);
  EXPECT_TRUE(has_note(result, "dropped 1 smaller one")) << result.notes.size();
  EXPECT_TRUE(has_note(result, "filled"));
}

TEST_F(SurfaceFromImage, LabelledBallIsClosedOutwardWithItsVolumeAndCentreInTheWorld) {
  const NiftiImage image = ball_image(7, 0, 0, 10.0);
  testing::write_nifti(dir_ / "ball.nii", image);
  ImageSurfaceOptions options;
  options.selection.label = 7;
  const ImageSurface result = surface_from_image(dir_ / "ball.nii", options);
  expect_ball(result, image, 10.0);
  EXPECT_NEAR(result.voxel_volume_m3, 1.875e-9, 1e-12);
}

TEST_F(SurfaceFromImage, IntensityWindowAfterSlopeAndInterceptGivesTheBall) {
  // Stored 1074 / 24 / 2024 are 50, -1000 and 1000 HU after the intercept of -1024.
  NiftiImage image = ball_image(1074, 2024, 24, 10.0);
  image.slope = 1.0f;
  image.intercept = -1024.0f;
  testing::write_nifti(dir_ / "ct.nii", image);
  ImageSurfaceOptions options;
  options.selection = parse_threshold("0:100", "--threshold");
  options.target_vertices = 200;
  options.smoothing_iterations = 3;
  const ImageSurface result = surface_from_image(dir_ / "ct.nii", options);
  EXPECT_EQ(result.surface.num_vertices(), 200);
  EXPECT_GT(result.extracted_vertices, 200);
  expect_ball(result, image, 10.0);
}

TEST_F(SurfaceFromImage, AbsentLabelNamesTheFileAndTheLabelsPresent) {
  testing::write_nifti(dir_ / "ball.nii", ball_image(7, 0, 0, 10.0));
  ImageSurfaceOptions options;
  options.selection.label = 10;
  try {
    surface_from_image(dir_ / "ball.nii", options);
    FAIL() << "label 10 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ball.nii: label 10 is not in the image; labels present: "
                                         "0, 7"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(SurfaceFromImage, EmptyWindowGivesTheImagesRange) {
  testing::write_nifti(dir_ / "ball.nii", ball_image(7, 0, 0, 10.0));
  ImageSurfaceOptions options;
  options.selection = parse_threshold("100", "--threshold");
  EXPECT_THROW(surface_from_image(dir_ / "ball.nii", options), InputError);
  EXPECT_THROW(parse_threshold("5:1", "--threshold"), InputError);
  EXPECT_THROW(parse_threshold("x", "--threshold"), InputError);
}

TEST_F(SurfaceFromImage, NanVoxelsInALabelMapAreRefused) {
  // A NaN compares unequal to every label and outside every window: it would be background.
  const NiftiImage labels = ball_image(7, 0, 0, 10.0);
  NiftiImage image = labels;
  image.reals.assign(labels.values.begin(), labels.values.end());
  image.reals[static_cast<std::size_t>(5 + 48 * (6 + 40 * 7))] =
      std::numeric_limits<float>::quiet_NaN();
  testing::write_nifti(dir_ / "ball.nii", image);
  ImageSurfaceOptions options;
  options.selection.label = 7;
  try {
    surface_from_image(dir_ / "ball.nii", options);
    FAIL() << "a NaN voxel was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "ball.nii").string() + ": voxel (5,6,7) is NaN");
  }
}

TEST_F(SurfaceFromImage, AZeroVoxelSizeIsRefusedNotTakenAsOneMillimetre) {
  NiftiImage image = ball_image(7, 0, 0, 10.0);
  image.sform_code = 0;  // the voxel size alone places the voxels
  image.pixdim = Eigen::Vector3f(1.0f, 0.0f, 1.5f);
  testing::write_nifti(dir_ / "ball.nii", image);
  ImageSurfaceOptions options;
  options.selection.label = 7;
  try {
    surface_from_image(dir_ / "ball.nii", options);
    FAIL() << "pixdim 0 was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir_ / "ball.nii").string() +
                  ": NIfTI header pixdim[2] = 0 (voxel size must be finite and > 0)");
  }
}

TEST_F(SurfaceFromImage, NotNiftiAndMissingFilesAreInputErrors) {
  std::ofstream(dir_ / "text.nii") << "not an image\n";
  EXPECT_THROW(surface_from_image(dir_ / "text.nii", {}), InputError);
  EXPECT_THROW(surface_from_image(dir_ / "missing.nii.gz", {}), InputError);
}

TEST(ImageSource, ParsesLabelAndThresholdAndResolvesTheFile) {
  EXPECT_TRUE(is_image_source("image:a.nii.gz:label=10"));
  EXPECT_FALSE(is_image_source("icosphere:3"));
  const ImageSource label = parse_image_source("image:data/a.nii.gz:label=10");
  EXPECT_EQ(label.file, "data/a.nii.gz");
  EXPECT_EQ(label.selection.label, 10);
  const ImageSource window = parse_image_source("image:b.nii:threshold=-100:200.5");
  EXPECT_DOUBLE_EQ(window.selection.low, -100.0);
  EXPECT_DOUBLE_EQ(window.selection.high, 200.5);
  EXPECT_EQ(image_source_relative_to("image:data/a.nii.gz:label=10", "/cases"),
            "image:/cases/data/a.nii.gz:label=10");
  for (const char* bad : {"image:", "image:a.nii", "image:a.nii:label=x", "image:a.nii:size=3",
                          "image:a.nii:label=1:label=2"})
    EXPECT_THROW(parse_image_source(bad), InputError) << bad;
}

}  // namespace
}  // namespace msfem::cases
