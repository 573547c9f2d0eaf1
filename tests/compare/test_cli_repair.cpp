#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::count_lines;
using testing::run_msfem;
using testing::TemporaryDirectory;

const std::string liver = std::string(MSFEM_CASES_DIR) + "/data/liver_sofa_smooth_cm.obj";

TEST(CliRepair, LiverBecomesASurfaceMeshInfoAcceptsInCentimetres) {
  TemporaryDirectory tmp;
  const auto out = (tmp / "liver.obj").string();
  const auto r = run_msfem("repair " + liver + " " + out + " --unit cm");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("wrapped                           yes (self_intersection)"),
            std::string::npos)
      << r.out;
  // Written in the input's unit, as simplify does: read back in cm it has the liver's volume.
  const auto info = run_msfem("mesh-info " + out + " --unit cm --json");
  ASSERT_EQ(info.exit_code, 0) << info.out;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_NEAR(j["volume_m3"].get<double>() / 3.92674e-05, 1.0, 0.03);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["genus"], 0);
}

TEST(CliRepair, OverridesAndAlwaysWrapAreObeyed) {
  TemporaryDirectory tmp;
  const auto out = (tmp / "sphere.off").string();
  std::ofstream(tmp / "tet.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                    "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 3 4\n";
  const auto r = run_msfem("repair " + (tmp / "tet.obj").string() + " " + out +
                           " --wrap --alpha 0.1 --offset 0.01");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("duplicate triangles removed       1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("alpha 0.1 m, offset 0.01 m"), std::string::npos) << r.out;
  EXPECT_EQ(run_msfem("mesh-info " + out).exit_code, 0);
}

// Each bad input: one line naming the file or option, exit code 2, and no OUT written.
TEST(CliRepair, BadInputIsOneLineExitsTwoAndWritesNothing) {
  TemporaryDirectory tmp;
  std::ofstream(tmp / "empty.obj") << "";
  std::ofstream(tmp / "flat.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 2\nf 3 3 1\n";
  std::ofstream(tmp / "bad.obj") << "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n";
  const auto out = tmp / "out.obj";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {(tmp / "missing.obj").string() + " " + out.string(), "missing.obj"},
      {(tmp / "empty.obj").string() + " " + out.string(), "empty.obj"},
      {(tmp / "flat.obj").string() + " " + out.string(), "flat.obj"},
      {(tmp / "bad.obj").string() + " " + out.string(), "bad.obj:2"},
      {liver + " " + (tmp / "out.xyz").string(), "out.xyz"},
      {liver + " " + out.string() + " --alpha -1", "--alpha"},
      {liver + " " + liver, "input file"},
  };
  for (const auto& [args, named] : cases) {
    const auto r = run_msfem("repair " + args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << args;
  }
}

}  // namespace
}  // namespace msfem
