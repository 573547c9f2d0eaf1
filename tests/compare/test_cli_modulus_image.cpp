// `material/youngs modulus image`: E from a CT's HU in both models, end to end.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "../cases/nifti_writer.hpp"
#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::count_lines;
using testing::read_text;
using testing::run_msfem;
using testing::small_sphere_case;
using testing::TemporaryDirectory;

// 12³ voxels of 10 mm about the origin (the 5 cm sphere with room), HU from `hu` of the world
// position in mm.
template <class Hu>
std::string write_ct(const TemporaryDirectory& dir, const std::string& name, Hu hu) {
  testing::NiftiImage image{12, 12, 12, {}};
  image.sform.leftCols<3>() = 10.0 * Eigen::Matrix3d::Identity();
  image.sform.col(3) = Eigen::Vector3d::Constant(-55.0);
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i)
        image.values.push_back(static_cast<std::int16_t>(
            hu(image.sform.leftCols<3>() * Eigen::Vector3d(i, j, k) + image.sform.col(3))));
  testing::write_nifti(dir / name, image);
  return (dir / name).string();
}

nlohmann::json run_summary(const TemporaryDirectory& dir, const std::string& name,
                           const std::string& sets) {
  const auto r = run_msfem("run " + small_sphere_case + " --quiet --no-timing --no-cache --out " +
                           (dir / name).string() + sets);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return nlohmann::json::parse(read_text(dir / name / "summary.json"));
}

std::string image_sets(const std::string& image, const std::string& table) {
  return " --set \"material/youngs modulus image=" + image +
         "\" --set \"material/hu to youngs=" + table + "\"";
}

TEST(CliModulusImage, AHomogeneousImageReproducesTheConstantModulusRunExactly) {
  TemporaryDirectory dir;
  const std::string ct = write_ct(dir, "ct.nii", [](const Eigen::Vector3d&) { return 40; });
  const auto constant = run_summary(dir, "constant", "");
  // HU 40 gives 3000 Pa, the case's E.
  const auto imaged = run_summary(dir, "imaged", image_sets(ct, "0:1000; 40:3000; 100:9000"));
  EXPECT_EQ(imaged["material"]["youngs_modulus_image"], ct);
  EXPECT_EQ(imaged["material"]["youngs_modulus_range_pa"], nlohmann::json::array({3000.0, 3000.0}));
  EXPECT_EQ(constant["material"]["youngs_modulus_range_pa"],
            nlohmann::json::array({3000.0, 3000.0}));
  EXPECT_EQ(imaged["fem"]["reaction_force_N"], constant["fem"]["reaction_force_N"]);
  ASSERT_EQ(imaged["variants"].size(), constant["variants"].size());
  for (std::size_t v = 0; v < constant["variants"].size(); ++v) {
    const auto& a = constant["variants"][v];
    const auto& b = imaged["variants"][v];
    for (const char* key : {"rel_l2_error", "max_error_m", "reaction_force_N", "force_depth"})
      EXPECT_EQ(b[key], a[key]) << a["name"] << " " << key;
    EXPECT_EQ(b["parameters"]["youngs_modulus_range_pa"], nlohmann::json::array({3000.0, 3000.0}))
        << a["name"];
  }
}

TEST(CliModulusImage, BothModelsSeeTheFieldAndReportItsRange) {
  TemporaryDirectory dir;
  // The upper half (z > 0, where the tool presses) at 100 HU: twice the stiffness below.
  const std::string ct =
      write_ct(dir, "ct.nii", [](const Eigen::Vector3d& x) { return x.z() > 0 ? 100 : 0; });
  const auto constant = run_summary(dir, "constant", "");
  const auto imaged = run_summary(dir, "imaged", image_sets(ct, "0:3000; 100:6000"));
  const auto& range = imaged["material"]["youngs_modulus_range_pa"];
  EXPECT_GE(range[0].get<double>(), 3000.0);
  EXPECT_LE(range[1].get<double>(), 6000.0);
  EXPECT_GT(range[1].get<double>() - range[0].get<double>(), 1500.0);
  // A prescribed indentation into stiffer tissue takes more force, in both models, by at most the
  // factor 2 of the tissue under the tool (a variant whose springs from the tool to the fixed core
  // all lie in the upper half is exactly twice as stiff).
  auto force = [](const nlohmann::json& j) { return -j["reaction_force_N"][2].get<double>(); };
  const double fem_ratio = force(imaged["fem"]) / force(constant["fem"]);
  EXPECT_GT(fem_ratio, 1.2);
  EXPECT_LT(fem_ratio, 2.0);
  for (std::size_t v = 0; v < imaged["variants"].size(); ++v) {
    const double ratio = force(imaged["variants"][v]) / force(constant["variants"][v]);
    EXPECT_GT(ratio, 1.1) << imaged["variants"][v]["name"];
    EXPECT_LT(ratio, 2.0 * (1 + 1e-6)) << imaged["variants"][v]["name"];
    const auto& seen = imaged["variants"][v]["parameters"]["youngs_modulus_range_pa"];
    EXPECT_GE(seen[0].get<double>(), 3000.0);
    EXPECT_LE(seen[1].get<double>(), 6000.0);
  }
  const std::string report = read_text(dir / "imaged" / "report.md");
  EXPECT_NE(report.find("E from the CT `ct.nii`"), std::string::npos) << report.substr(0, 600);
}

TEST(CliModulusImage, BadImagesAndTablesAreOneLineNamingTheKeyAndWriteNothing) {
  TemporaryDirectory dir;
  const std::string ct = write_ct(dir, "ct.nii", [](const Eigen::Vector3d&) { return 40; });
  std::ofstream(dir / "text.nii") << "not an image";
  testing::NiftiImage small{4, 4, 4, std::vector<std::int16_t>(64, 40)};  // 4 mm: misses the organ
  testing::write_nifti(dir / "small.nii", small);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {image_sets(ct, "40:3000; 0:4000"), "material/hu to youngs: HU 0 does not increase"},
      {image_sets(ct, "0:3000; 40:-1"), "gives E = -1 Pa"},
      {image_sets((dir / "absent.nii").string(), "0:3000"), "absent.nii: no such file"},
      {image_sets((dir / "text.nii").string(), "0:3000"), "not a NIfTI"},
      {image_sets((dir / "small.nii").string(), "0:3000"), "lies outside the image"},
  };
  for (const auto& [sets, named] : bad) {
    const auto out = dir / "out";
    const auto r =
        run_msfem("run " + small_sphere_case + " --quiet --no-cache --out " + out.string() + sets);
    EXPECT_EQ(r.exit_code, 2) << sets << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << sets;
  }
}

}  // namespace
}  // namespace msfem
