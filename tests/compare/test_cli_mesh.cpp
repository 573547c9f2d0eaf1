#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::count_lines;
using testing::run_msfem;
using testing::TemporaryDirectory;

const std::string data_dir = std::string(MSFEM_CASES_DIR) + "/data/";

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

TEST(CliMeshInfo, DefaultSphereHasTheSeedCountsAndNoDefect) {
  const auto r = run_msfem("mesh-info --generate icosphere:3:0.05 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["vertices"], 642);
  EXPECT_EQ(j["edges"], 1920);
  EXPECT_EQ(j["triangles"], 1280);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_NEAR(j["volume_m3"].get<double>(), 4.0 / 3.0 * M_PI * 1.25e-4, 0.01 * 5.2e-4);
  EXPECT_TRUE(j["defects"].empty());
}

TEST(CliMeshInfo, LiverDefectsGiveExitCodeOneAndTheTrianglePairs) {
  const auto r = run_msfem("mesh-info " + data_dir + "liver_sofa_smooth_cm.obj --unit cm");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("self_intersection"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("5 sharing no vertex"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("vertices     2194"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("genus        0"), std::string::npos) << r.out;
}

TEST(CliMeshInfo, UnitScalesTheReportedVolume) {
  const auto mm = nlohmann::json::parse(
      run_msfem("mesh-info " + data_dir + "brain_icbm152_lh_9177_mm.obj --unit mm --json").out);
  EXPECT_NEAR(mm["volume_m3"].get<double>(), 4.87e-4, 0.02e-4);  // ≈ 487 cm³ (SOURCES.md)
  EXPECT_EQ(mm["vertices"], 9177);
  EXPECT_TRUE(mm["defects"].empty());
}

// Each bad input: a one-line error naming the file (and line or element), exit code 2.
TEST(CliMeshInfo, BadInputIsOneLineNamingTheFileAndExitsTwo) {
  TemporaryDirectory tmp;
  write_file(tmp / "nonnumeric.obj", "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n");
  write_file(tmp / "nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  write_file(tmp / "mesh.xyz", "0 0 0\n");
  std::string truncated(84, '\0');
  truncated[80] = 12;  // header promises 12 triangles, none follow
  write_file(tmp / "truncated.stl", truncated);

  const std::vector<std::pair<std::string, std::string>> cases = {
      {(tmp / "missing.obj").string(), "missing.obj"},
      {(tmp / "mesh.xyz").string(), "mesh.xyz"},
      {(tmp / "truncated.stl").string(), "truncated.stl"},
      {(tmp / "nonnumeric.obj").string(), "nonnumeric.obj:3"},
      {(tmp / "nan.obj").string(), "nan.obj:3"},
  };
  for (const auto& [file, named] : cases) {
    const auto r = run_msfem("mesh-info " + file);
    EXPECT_EQ(r.exit_code, 2) << file << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  const auto bad_unit = run_msfem("mesh-info " + data_dir + "liver_sofa_smooth_cm.obj --unit inch");
  EXPECT_EQ(bad_unit.exit_code, 2);
  EXPECT_NE(bad_unit.err.find("inch"), std::string::npos) << bad_unit.err;
  EXPECT_EQ(run_msfem("mesh-info --typo").exit_code, 2);
  EXPECT_EQ(run_msfem("no-such-command").exit_code, 2);
}

TEST(CliSimplify, WritesExactlyTheTargetAndNothingOnBadInput) {
  TemporaryDirectory tmp;
  const auto out = tmp / "pancreas_446.obj";
  const auto r = run_msfem("simplify " + data_dir + "pancreas_vh_female_m.obj " + out.string() +
                           " --vertices 446 --smooth 3");
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const auto info = nlohmann::json::parse(run_msfem("mesh-info " + out.string() + " --json").out);
  EXPECT_EQ(info["vertices"], 446);
  EXPECT_TRUE(info["defects"].empty()) << info.dump();

  const auto never = tmp / "never.obj";
  write_file(tmp / "nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  EXPECT_EQ(
      run_msfem("simplify " + (tmp / "nan.obj").string() + " " + never.string() + " --vertices 3")
          .exit_code,
      2);
  EXPECT_EQ(run_msfem("simplify " + data_dir + "pancreas_vh_female_m.obj " + never.string() +
                      " --vertices 99999")
                .exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(never));
  for (const auto& entry : std::filesystem::directory_iterator(tmp.path()))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace msfem
