#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::count_lines;
using testing::run_msfem;
using testing::TemporaryDirectory;

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

const std::string labels = std::string(MSFEM_CASES_DIR) + "/data/abdomen_ct_3mm_labels.nii.gz";

// The shipped CT's pancreas (label 10: its largest component, 318 voxels of 27 mm^3, 8.6 cm^3; the
// two smaller pieces are dropped), simplified and smoothed, passes mesh-info, within 15 % of its
// voxel volume.
TEST(CliSurfaceFromImage, PancreasOfTheShippedCtPassesMeshInfo) {
  TemporaryDirectory tmp;
  const auto out = (tmp / "pancreas.obj").string();
  const auto r = run_msfem("surface-from-image " + labels + " " + out +
                           " --label 10 --vertices 150 --smooth 5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("318 voxels"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("dropped 2 smaller ones"), std::string::npos) << r.err;
  const auto info = run_msfem("mesh-info " + out + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.out;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["vertices"], 150);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_NEAR(j["volume_m3"].get<double>(), 8.586e-6, 0.15 * 8.586e-6);
}

// Each bad input: one line naming the file or option, exit 2, and no OUT file.
TEST(CliSurfaceFromImage, BadInputIsOneLineExitTwoAndWritesNothing) {
  TemporaryDirectory tmp;
  write_file(tmp / "text.nii", "not an image\n");
  const auto out = tmp / "out.obj";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {labels + " " + out.string() + " --label 200",
       "label 200 is not in the image; labels present"},
      {(tmp / "text.nii").string() + " " + out.string() + " --label 1", "text.nii: not a NIfTI"},
      {(tmp / "none.nii.gz").string() + " " + out.string() + " --label 1", "none.nii.gz: no such"},
      {labels + " " + out.string() + " --threshold 200:300",
       "no voxel has intensity in [200, 300]"},
      {labels + " " + out.string() + " --label 10 --vertices 3", "--vertices 3 is too small"},
      {labels + " " + out.string() + " --label 10 --threshold 1", "usage"},
      {labels + " " + (tmp / "out.xyz").string() + " --label 10", "out.xyz"},
  };
  for (const auto& [args, expected] : cases) {
    const auto r = run_msfem("surface-from-image " + args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << args;
  }
}

}  // namespace
}  // namespace msfem
