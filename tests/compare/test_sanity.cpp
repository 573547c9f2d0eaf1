// The harness's sanity claims that could fail, on the shipped sphere cases:
// - on the ν = 1/4 twin, where a spring network obeys the Cauchy relations, the volumetric
//   tet_edges network is closer to the FEM than one surface layer at every sweep resolution;
// - the FEM's and the spring models' reaction forces grow with the tool's depth.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

const std::string cases_dir = MSFEM_DEFAULT_CASES_DIR;

double along(const nlohmann::json& force, const nlohmann::json& normal) {
  double f = 0;
  for (int c = 0; c < 3; ++c)
    f += force[c].get<double>() * normal[c].get<double>();
  return f;
}

// Checks the curve itself rather than trusting the summary's own flag, and that the flag agrees.
void expect_force_grows(const nlohmann::json& model, const nlohmann::json& normal,
                        const std::string& name) {
  const auto& curve = model["force_depth"];
  ASSERT_GE(curve.size(), 4u) << name;
  for (std::size_t i = 1; i < curve.size(); ++i) {
    EXPECT_GT(curve[i]["depth_m"].get<double>(), curve[i - 1]["depth_m"].get<double>()) << name;
    EXPECT_GT(along(curve[i]["force_N"], normal), along(curve[i - 1]["force_N"], normal))
        << name << ": force at " << curve[i]["depth_m"] << " m";
  }
  EXPECT_EQ(model["force_depth_monotone"], true) << name;
}

TEST(Sanity, TetEdgesIsCloserThanSingleLayerAtNuQuarterOnEverySweepResolution) {
  TemporaryDirectory dir;
  const auto r = run_msfem("sweep " + cases_dir +
                           "/sphere_indent_nu025.prm --quiet --resolutions 2,3,4 "
                           "--integrators symplectic_euler --set timing/steps=200 "
                           "--set 'fem/error estimate=none' --out " +
                           (dir / "sweep").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text(dir / "sweep" / "sweep.json"));
  std::map<int, std::map<std::string, double>> error;  // resolution -> variant -> rel_l2_error
  for (const auto& p : j["points"])
    error[p["resolution"].get<int>()][p["variant"].get<std::string>()] =
        p["rel_l2_error"].get<double>();
  ASSERT_EQ(error.size(), 3u);
  for (const auto& [resolution, by_variant] : error) {
    ASSERT_TRUE(by_variant.count("tet_edges") && by_variant.count("single_layer"));
    EXPECT_LT(by_variant.at("tet_edges"), by_variant.at("single_layer"))
        << "icosphere level " << resolution;
  }
}

// At ν = 0.45 a central-spring network is too compressible (its Poisson's ratio is 1/4): the volume
// preservation energy has to bring the volumetric tet_edges network, which shares the FEM's
// mesh, much closer, and the three tiers closer too, on the same run (statics and timing).
TEST(Sanity, VolumePreservationBringsTheNetworksCloserAtNuPointFourFive) {
  TemporaryDirectory dir;
  std::map<std::string, std::map<std::string, nlohmann::json>> by_setting;
  for (const std::string setting : {"false", "true"}) {
    const auto out = dir / ("run-" + setting);
    const auto r = run_msfem("run " + cases_dir +
                             "/sphere_indent_bonded.prm --quiet --set timing/steps=100 "
                             "--set 'fem/error estimate=none' --set "
                             "'mass spring/variants=tet_edges,three_tier' --set 'mass "
                             "spring/volume preservation=" +
                             setting + "' --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(read_text(out / "summary.json"));
    for (const auto& v : j["variants"])
      by_setting[setting][v["name"].get<std::string>()] = v;
    const std::string said = setting == "true" ? "volume preservation: tet_edges (mean κ 8110"
                                               : "volume preservation: off";
    EXPECT_NE(read_text(out / "report.md").find(said), std::string::npos) << said;
  }
  const auto& off = by_setting["false"];
  const auto& on = by_setting["true"];
  for (const char* name : {"tet_edges", "three_tier"}) {
    ASSERT_TRUE(off.count(name) && on.count(name)) << name;
    EXPECT_FALSE(off.at(name)["parameters"].contains("volume_preservation")) << name;
    ASSERT_TRUE(on.at(name)["parameters"].contains("volume_preservation")) << name;
    EXPECT_GT(on.at(name)["steps_per_second"].get<double>(), 0.0) << name;
    EXPECT_TRUE(std::isfinite(on.at(name)["stable_dt_s"].get<double>())) << name;
  }
  EXPECT_LT(on.at("tet_edges")["rel_l2_error"].get<double>(),
            0.4 * off.at("tet_edges")["rel_l2_error"].get<double>());
  EXPECT_LT(on.at("three_tier")["rel_l2_error"].get<double>(),
            0.8 * off.at("three_tier")["rel_l2_error"].get<double>());
  // Bulk stiffness only adds resistance: the tool pushes back harder with it.
  EXPECT_GT(on.at("tet_edges")["reaction_force_N"][2].get<double>(),
            off.at("tet_edges")["reaction_force_N"][2].get<double>());
}

class ForceDepth : public ::testing::TestWithParam<const char*> {};

TEST_P(ForceDepth, FemAndEveryVariantPushBackHarderTheDeeperTheTool) {
  TemporaryDirectory dir;
  const auto r = run_msfem("run " + cases_dir + "/" + GetParam() +
                           ".prm --quiet --no-timing --set 'fem/error estimate=none' --out " +
                           (dir / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text(dir / "run" / "summary.json"));
  const auto& normal = j["tools"][0]["outward_normal"];
  expect_force_grows(j["fem"], normal, "FEM");
  ASSERT_GE(j["variants"].size(), 3u);
  for (const auto& v : j["variants"])
    expect_force_grows(v, normal, v["name"].get<std::string>());
}

// The default case presses by frictionless contact as deep as the tool's radius; its bonded twin
// too, where tet_edges comes closest to buckling; the nu = 0.25 twin stays nearly linear.
INSTANTIATE_TEST_SUITE_P(SphereCases, ForceDepth,
                         ::testing::Values("sphere_indent", "sphere_indent_bonded",
                                           "sphere_indent_nu025"));

}  // namespace
}  // namespace msfem
