#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::small_sphere_case;
using testing::TemporaryDirectory;

// sweep.json of `msfem sweep` on the small sphere at icosphere level 1 with `options`, written
// under `out`; fails the test where the sweep does not exit 0.
nlohmann::json level_one_sweep(const std::filesystem::path& out, const std::string& options) {
  const auto r = run_msfem("sweep " + small_sphere_case + " --quiet --resolutions 1 " + options +
                           " --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return r.exit_code == 0 ? nlohmann::json::parse(read_text(out / "sweep.json")) : nlohmann::json();
}

TEST(CliSweep, AResolutionThatCannotBeRunIsReportedAndTheOthersAreStillSwept) {
  // Icosphere level 10 is out of range: as a surface that self-intersects once simplified (the
  // brain below ~2,500 vertices) it is bad input at that resolution only.
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto r = run_msfem("sweep " + small_sphere_case +
                           " --quiet --resolutions 1,10 --integrators symplectic_euler "
                           "--max-error 10 --out " +
                           out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("resolution 10 failed"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(read_text(out / "sweep.json"));
  ASSERT_EQ(j["failed_resolutions"].size(), 1u);
  EXPECT_EQ(j["failed_resolutions"][0]["resolution"], 10);
  ASSERT_EQ(j["points"].size(), 4u);  // four variants, one integrator, level 1
  for (const auto& p : j["points"]) {
    EXPECT_EQ(p["resolution"], 1);
    EXPECT_GT(p["steps_per_second"].get<double>(), 0.0);
  }
  const std::string report = read_text(out / "report.md");
  EXPECT_NE(report.find("resolution 10 failed"), std::string::npos);
  // The report opens with its answer; every point is within rel L2 10, so there is a cheapest.
  EXPECT_LT(report.find("## Answer"), report.find("## Every configuration")) << report;
  EXPECT_NE(report.find("| cheapest with rel L2 <= 10 | "), std::string::npos) << report;
  EXPECT_EQ(report.find("| cheapest with rel L2 <= 10 | none"), std::string::npos) << report;
}

// Volume preservation as a sweep dimension: the variants with volume elements (three_tier and
// tet_edges) are swept with and without them, on the same FEM reference; the others once. At
// nu = 0.45 the volume elements stiffen the model (at 0.25 the springs alone have its bulk
// modulus and the elements none), so its error differs.
TEST(CliSweep, VolumePreservationIsSweptForTheVariantsThatHaveIt) {
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto j = level_one_sweep(out,
                                 "--integrators symplectic_euler --volume-preservation both "
                                 "--set \"material/poisson ratio=0.45\"");
  ASSERT_FALSE(j.is_null());
  std::map<std::string, std::vector<double>> errors;  // variant -> rel L2 without, with
  for (const auto& p : j["points"]) {
    EXPECT_EQ(p["stepper"], "fast_explicit");
    errors[p["variant"].get<std::string>()].push_back(p["rel_l2_error"].get<double>());
    if (p["volume_preservation"].get<bool>()) {
      EXPECT_TRUE(p["variant"] == "three_tier" || p["variant"] == "tet_edges") << p.dump();
    }
  }
  ASSERT_EQ(errors.size(), 4u);
  for (const char* volumetric : {"three_tier", "tet_edges"}) {
    ASSERT_EQ(errors[volumetric].size(), 2u) << volumetric;
    EXPECT_GT(std::abs(errors[volumetric][0] - errors[volumetric][1]), 1e-6) << volumetric;
  }
  EXPECT_EQ(errors["single_layer"].size(), 1u);
  EXPECT_NE(read_text(out / "report.md").find("three_tier+volume"), std::string::npos);
  const auto bad =
      run_msfem("sweep " + small_sphere_case + " --quiet --volume-preservation maybe --out " +
                (tmp / "bad").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--volume-preservation"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "bad"));
}

// The fast steppers' arithmetic as a sweep dimension: each variant and integrator timed in double
// and in float on the same statics (the same error), each point saying which it timed.
TEST(CliSweep, PrecisionIsSweptOnTheSameStatics) {
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto j = level_one_sweep(out,
                                 "--integrators symplectic_euler,implicit_euler --set \"mass "
                                 "spring/variants=three_tier,single_layer\" --precision both");
  ASSERT_FALSE(j.is_null());
  ASSERT_EQ(j["points"].size(), 8u);  // two variants, two integrators, two precisions
  std::map<std::string, std::map<std::string, nlohmann::json>> by;  // variant+integrator, precision
  for (const auto& p : j["points"]) {
    EXPECT_GT(p["steps_per_second"].get<double>(), 0.0) << p.dump();
    by[p["variant"].get<std::string>() + " " + p["integrator"].get<std::string>()]
      [p["precision"].get<std::string>()] = p;
  }
  ASSERT_EQ(by.size(), 4u);
  for (const auto& [model, points] : by) {
    ASSERT_EQ(points.size(), 2u) << model;
    EXPECT_EQ(points.at("float")["rel_l2_error"], points.at("double")["rel_l2_error"]) << model;
    EXPECT_EQ(points.at("float")["stepper"], points.at("double")["stepper"]) << model;
  }
  EXPECT_NE(read_text(out / "report.md").find("(fast_implicit, float)"), std::string::npos);
  const auto bad = run_msfem("sweep " + small_sphere_case + " --quiet --precision half --out " +
                             (tmp / "bad").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--precision"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "bad"));
}

// Contact refinement as a sweep dimension: off, and on at two edge lengths, each pass with its own
// refined surface and FEM; the finer the edge, the more nodes, and each point says its edge.
TEST(CliSweep, ContactRefinementIsSweptAtEachEdgeLength) {
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto j =
      level_one_sweep(out,
                      "--integrators symplectic_euler --set \"mass spring/variants=single_layer\" "
                      "--contact-refinement both --contact-edge-lengths 0.006,0.003");
  ASSERT_FALSE(j.is_null());
  ASSERT_EQ(j["points"].size(), 3u);
  const auto& points = j["points"];
  EXPECT_TRUE(points[0]["contact_refinement_edge_m"].is_null());
  EXPECT_DOUBLE_EQ(points[1]["contact_refinement_edge_m"].get<double>(), 0.006);
  EXPECT_DOUBLE_EQ(points[2]["contact_refinement_edge_m"].get<double>(), 0.003);
  EXPECT_LT(points[0]["nodes"].get<int>(), points[1]["nodes"].get<int>());
  EXPECT_LT(points[1]["nodes"].get<int>(), points[2]["nodes"].get<int>());
  const std::string report = read_text(out / "report.md");
  EXPECT_NE(report.find("single_layer+refined@3mm"), std::string::npos) << report;
  EXPECT_NE(report.find("single_layer+refined@6mm"), std::string::npos) << report;

  for (const std::string bad :
       {"--contact-refinement maybe", "--contact-refinement off --contact-edge-lengths 0.001",
        "--contact-edge-lengths -0.001",
        "--contact-refinement on --set \"loads/tool/enabled=false\" --set "
        "\"loads/gravity=0,0,-9.81\""}) {
    const auto refused = run_msfem("sweep " + small_sphere_case + " --quiet " + bad + " --out " +
                                   (tmp / "bad").string());
    EXPECT_EQ(refused.exit_code, 2) << bad << ": " << refused.err;
    EXPECT_NE(refused.err.find("--contact-"), std::string::npos) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(tmp / "bad"));
  }
}

// A variant whose statics fail at a resolution is reported (sweep.json, report.md, stderr, exit 1)
// and the others are still swept. The seed's three tiers refined to 1.7 mm edges at the tool have
// no stable equilibrium at the 5 mm press (results/BENCHMARKS.md, "Local point distribution").
TEST(CliSweep, AVariantThatFailsIsReportedAndTheOthersAreStillSwept) {
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto r =
      run_msfem("sweep " + std::string(MSFEM_CASES_DIR) +
                "/sphere_indent.prm --quiet --resolutions 2 --integrators "
                "symplectic_euler --contact-refinement on --set \"mass spring/"
                "variants=three_tier,single_layer\" --set fem/degree=1 --set \"fem/error "
                "estimate=none\" --out " +
                out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("variant three_tier+refined@1.67mm failed"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(read_text(out / "sweep.json"));
  ASSERT_EQ(j["failed_variants"].size(), 1u);
  EXPECT_EQ(j["failed_variants"][0]["variant"], "three_tier+refined@1.67mm");
  EXPECT_EQ(j["failed_variants"][0]["resolution"], 2);
  ASSERT_EQ(j["points"].size(), 1u);
  EXPECT_EQ(j["points"][0]["variant"], "single_layer");
  EXPECT_NE(read_text(out / "report.md").find("three_tier+refined@1.67mm failed at resolution 2"),
            std::string::npos);
}

TEST(CliSweep, AMaximumErrorThatIsNotAPositiveNumberIsRefusedBeforeAnySolve) {
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  for (const char* bad : {"0", "-0.1", "abc", "0.2x", "nan"}) {
    const auto r = run_msfem("sweep " + small_sphere_case + " --quiet --max-error " + bad +
                             " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--max-error"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

TEST(CliSweep, WhenNoResolutionCanBeRunItIsAnErrorAndNothingIsWritten) {
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto r =
      run_msfem("sweep " + small_sphere_case + " --quiet --resolutions 10 --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("level '10'"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace msfem
