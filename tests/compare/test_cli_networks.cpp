// A user's network as a variant: msfem's own models exported (msfem export-network) and brought
// back through mass spring/networks give the built-in variants' numbers, and a bad network is
// refused before the FEM.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

// A shipped case, cheap: level 2, P1, no estimate.
std::string cheap(const std::string& name) {
  return std::string(MSFEM_CASES_DIR) + "/" + name +
         " --set geometry/source=icosphere:2:0.05 --set fem/degree=1 --set 'fem/error "
         "estimate=none'";
}
// Every variant under the bonded tool (tet_edges buckles under the frictionless one at 5 mm).
const std::string every = cheap("sphere_indent_bonded.prm") +
                          " --set 'mass spring/variants=three_tier,single_layer,tet_edges,"
                          "skeleton'";
const std::string quietly = " --quiet --no-timing";

const nlohmann::json& variant(const nlohmann::json& summary, const std::string& name) {
  for (const auto& v : summary["variants"])
    if (v["name"] == name) return v;
  static const nlohmann::json none;
  ADD_FAILURE() << "no variant " << name;
  return none;
}

void expect_same(const nlohmann::json& a, const nlohmann::json& b, const std::string& where,
                 double tolerance) {
  ASSERT_TRUE(a.is_number() && b.is_number()) << where;
  const double x = a.get<double>(), y = b.get<double>();
  EXPECT_LE(std::abs(x - y), tolerance * std::max({std::abs(x), std::abs(y), 1e-300})) << where;
}

// Every metric the tables show, the force (each component), the curve and the volume change.
void expect_same_variant(const nlohmann::json& a, const nlohmann::json& b,
                         const std::string& name) {
  for (const char* metric :
       {"rel_l2_error", "max_error_m", "reaction_force_rel_error", "volume_change"})
    expect_same(a[metric], b[metric], name + "/" + metric, 1e-10);
  // Each component against the force's size: the lateral ones are round-off on a symmetric press.
  const auto& f = a["reaction_force_N"];
  const double size = std::hypot(f[0].get<double>(), f[1].get<double>(), f[2].get<double>());
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(f[c].get<double>(), b["reaction_force_N"][c].get<double>(), 1e-9 * size) << name;
  ASSERT_EQ(a["force_depth"].size(), b["force_depth"].size()) << name;
  for (std::size_t i = 0; i < a["force_depth"].size(); ++i)
    expect_same(a["force_depth"][i]["force_N"][2], b["force_depth"][i]["force_N"][2],
                name + "/curve", 1e-9);
  EXPECT_EQ(a["nodes"], b["nodes"]) << name;
  EXPECT_EQ(a["springs"], b["springs"]) << name;
}

TEST(CliNetworks, ExportedVariantsRunBackAsTheBuiltInOnes) {
  TemporaryDirectory tmp;
  const auto exported = run_msfem("export-network " + every + " " + (tmp / "nets").string());
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  for (const char* file : {"three_tier.vtu", "single_layer.vtu", "tet_edges.vtu", "skeleton.vtu",
                           "three_tier.xs3", "skeleton.xs3"})
    EXPECT_TRUE(std::filesystem::exists(tmp / "nets" / file)) << file;
  // The single layer's anchors have no Xsp form, and it says so.
  EXPECT_FALSE(std::filesystem::exists(tmp / "nets" / "single_layer.xs3"));
  EXPECT_NE(exported.err.find("single_layer: no .xs3 (Xsp has no anchors)"), std::string::npos)
      << exported.err;
  const std::string nets = (tmp / "nets").string();
  const std::string networks = "f_three_tier=" + nets + "/three_tier.vtu; f_single_layer=" + nets +
                               "/single_layer.vtu; f_tet_edges=" + nets +
                               "/tet_edges.vtu; f_skeleton=" + nets +
                               "/skeleton.vtu; x_three_tier=" + nets +
                               "/three_tier.xs3; x_skeleton=" + nets + "/skeleton.xs3";
  const auto r = run_msfem("run " + every + quietly + " --set 'mass spring/networks=" + networks +
                           "' --out " + (tmp / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto s = nlohmann::json::parse(read_text(tmp / "run" / "summary.json"));
  ASSERT_EQ(s["variants"].size(), 10u);
  for (const char* name : {"three_tier", "single_layer", "tet_edges", "skeleton"})
    expect_same_variant(variant(s, name), variant(s, std::string("f_") + name), name);
  for (const char* name : {"three_tier", "skeleton"})
    expect_same_variant(variant(s, name), variant(s, std::string("x_") + name),
                        std::string("xsp ") + name);
}

// Three tiers under volume preservation: the shell prisms travel as wedge cells.
TEST(CliNetworks, TheThreeTiersVolumeElementsTravelAsWedges) {
  TemporaryDirectory tmp;
  const std::string volume =
      cheap("sphere_indent_volume.prm") + " --set 'mass spring/variants=three_tier'";
  const auto exported = run_msfem("export-network " + volume + " " + (tmp / "nets").string());
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_NE(exported.err.find("three_tier: no .xs3 (Xsp has no volume elements)"),
            std::string::npos)
      << exported.err;
  const auto r =
      run_msfem("run " + volume + " --set 'mass spring/networks=mine=" +
                (tmp / "nets" / "three_tier.vtu").string() + "' --out " + (tmp / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto s = nlohmann::json::parse(read_text(tmp / "run" / "summary.json"));
  expect_same_variant(variant(s, "three_tier"), variant(s, "mine"), "three_tier+volume");
}

// Pressed by frictionless contact, the tool touches the file's triangles as it touches the
// variant's surface.
TEST(CliNetworks, AFrictionlessToolPressesANetworkAsItsVariant) {
  TemporaryDirectory tmp;
  const std::string contact =
      cheap("sphere_indent.prm") + " --set 'mass spring/variants=three_tier,single_layer'";
  ASSERT_EQ(run_msfem("export-network " + contact + " " + (tmp / "nets").string()).exit_code, 0);
  const std::string nets = (tmp / "nets").string();
  const auto r = run_msfem("run " + contact + quietly + " --set 'mass spring/networks=a=" + nets +
                           "/three_tier.vtu; b=" + nets + "/single_layer.vtu' --out " +
                           (tmp / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto s = nlohmann::json::parse(read_text(tmp / "run" / "summary.json"));
  expect_same_variant(variant(s, "three_tier"), variant(s, "a"), "contact three_tier");
  expect_same_variant(variant(s, "single_layer"), variant(s, "b"), "contact single_layer");
}

// The network's own surface as the case's geometry: the FEM is meshed on it and compared node to
// node; the three tiers' outer tier is the sphere's surface, so the run is the sphere's.
TEST(CliNetworks, TheNetworksOwnSurfaceIsTheCasesGeometry) {
  TemporaryDirectory tmp;
  const std::string tiers = every + " --set 'mass spring/variants=three_tier'";
  ASSERT_EQ(run_msfem("export-network " + tiers + " " + (tmp / "nets").string()).exit_code, 0);
  const std::string file = (tmp / "nets" / "three_tier.vtu").string();
  const auto own =
      run_msfem("run " + tiers + quietly + " --set geometry/source=network:" + file +
                " --set 'mass spring/networks=mine=" + file + "' --out " + (tmp / "own").string());
  ASSERT_EQ(own.exit_code, 0) << own.err;
  const auto sphere = run_msfem("run " + tiers + quietly + " --out " + (tmp / "sphere").string());
  ASSERT_EQ(sphere.exit_code, 0) << sphere.err;
  const auto a = nlohmann::json::parse(read_text(tmp / "own" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(tmp / "sphere" / "summary.json"));
  expect_same_variant(variant(b, "three_tier"), variant(a, "mine"), "network surface");
  expect_same(a["fem"]["reaction_force_N"][2], b["fem"]["reaction_force_N"][2], "fem force", 1e-9);
  // Xsp has no triangles to be a surface.
  const auto xsp =
      run_msfem("run " + every + quietly + " --set geometry/source=network:" +
                (tmp / "nets" / "three_tier.xs3").string() + " --out " + (tmp / "xsp").string());
  EXPECT_EQ(xsp.exit_code, 2) << xsp.err;
  EXPECT_NE(xsp.err.find("three_tier.xs3: geometry/source = network: takes the file's surface"),
            std::string::npos)
      << xsp.err;
}

TEST(CliNetworks, ANetworkOfAnotherGeometryIsRefusedNamingTheVertex) {
  TemporaryDirectory tmp;
  ASSERT_EQ(run_msfem("export-network " + every + " " + (tmp / "nets").string()).exit_code, 0);
  // The level-2 network against the level-3 sphere: most level-3 vertices have no node.
  const auto r =
      run_msfem("run " + std::string(MSFEM_CASES_DIR) +
                "/sphere_indent.prm --no-timing --set 'mass spring/networks=n=" +
                (tmp / "nets" / "skeleton.vtu").string() + "' --out " + (tmp / "run").string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("mass spring/networks: n="), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("has no network node within"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("solving the FEM"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "run"));
}

// A sweep re-meshes the case at each resolution, which a user's network cannot follow: the
// network is swept at the case's own resolution only, equal there to the variant it came from,
// and the sweep says so.
TEST(CliNetworks, ASweepRunsANetworkAtTheCasesOwnResolutionOnlyAndSaysSo) {
  TemporaryDirectory tmp;
  const std::string bonded =
      cheap("sphere_indent_bonded.prm") + " --set 'mass spring/variants=three_tier'";
  ASSERT_EQ(run_msfem("export-network " + bonded + " " + (tmp / "nets").string()).exit_code, 0);
  const auto r =
      run_msfem("sweep " + bonded + " --quiet --resolutions 1,2 --integrators " +
                "symplectic_euler --set 'mass spring/networks=mine=" +
                (tmp / "nets" / "three_tier.vtu").string() + "' --out " + (tmp / "sweep").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto s = nlohmann::json::parse(read_text(tmp / "sweep" / "sweep.json"));
  std::map<std::pair<std::string, int>, double> error;
  for (const auto& p : s["points"])
    error[{p["variant"], p["resolution"]}] = p["rel_l2_error"];
  EXPECT_EQ(error.size(), 3u);  // three_tier at 1 and 2, mine at 2 only
  ASSERT_TRUE(error.count({"mine", 2}));
  expect_same(error[{"mine", 2}], error[{"three_tier", 2}], "mine at 2", 1e-10);
  EXPECT_EQ(s["networks_at_own_resolution"]["resolution"], 2);
  const std::string report = read_text(tmp / "sweep" / "report.md");
  EXPECT_NE(report.find("networks mine swept at the case's own resolution 2 only"),
            std::string::npos);
}

}  // namespace
}  // namespace msfem
