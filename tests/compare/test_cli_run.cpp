#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "cli_runner.hpp"
#include "msfem/compare/writers/fields_h5.hpp"

namespace msfem {
namespace {

using testing::count_lines;
using testing::read_text;
using testing::run_msfem;
using testing::small_sphere_case;
using testing::TemporaryDirectory;

void expect_finite_numbers(const nlohmann::json& j, const std::string& where) {
  if (j.is_number()) {
    EXPECT_TRUE(std::isfinite(j.get<double>())) << where;
  } else if (j.is_object()) {
    for (const auto& [k, v] : j.items())
      expect_finite_numbers(v, where + "/" + k);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i)
      expect_finite_numbers(j[i], where + "/" + std::to_string(i));
  }
}

// One run shared by the checks below (a few seconds).
class RunSmallSphere : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TemporaryDirectory();
    result_ = new testing::CommandResult(run_msfem("run " + small_sphere_case + " --quiet --out " +
                                                   (dir_->path() / "run").string()));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete dir_;
  }
  static std::filesystem::path run_dir() { return dir_->path() / "run"; }
  static TemporaryDirectory* dir_;
  static testing::CommandResult* result_;
};
TemporaryDirectory* RunSmallSphere::dir_ = nullptr;
testing::CommandResult* RunSmallSphere::result_ = nullptr;

// The per-variant keys summary.json documents (docs/harness.md).
const char* const kVariantKeys[] = {"name",
                                    "nodes",
                                    "springs",
                                    "rel_l2_error",
                                    "rms_error_m",
                                    "max_error_m",
                                    "mean_error_over_max_disp",
                                    "contact_zone",
                                    "far_field",
                                    "reaction_force_N",
                                    "reaction_force_rel_error",
                                    "volume_change",
                                    "steps_per_second",
                                    "stable_dt_s",
                                    "realtime_factor",
                                    "settle_time_s",
                                    "ms_per_60hz_frame",
                                    "parameters",
                                    "force_depth_monotone",
                                    "inverted_elements"};

TEST_F(RunSmallSphere, SummaryHasTheDocumentedSchemaAndFiniteNumbers) {
  ASSERT_EQ(result_->exit_code, 0) << result_->err;
  EXPECT_NE(result_->out.find("| three_tier"), std::string::npos) << result_->out;
  const auto j = nlohmann::json::parse(read_text(run_dir() / "summary.json"));
  for (const char* key : {"case", "git_revision", "machine", "units", "fem", "variants"})
    EXPECT_TRUE(j.contains(key)) << key;
  for (const char* key :
       {"degree", "dofs", "cells", "solve_time_s", "iterations", "reaction_force_N"})
    EXPECT_TRUE(j["fem"].contains(key)) << key;
  // A tetrahedron's quality lies in (0, 1]; Gmsh's mesh of the small sphere is far from flat.
  const double worst = j["fem"]["worst_cell_quality"].get<double>();
  EXPECT_GT(worst, 0.05);
  EXPECT_LE(worst, 1.0);
  ASSERT_EQ(j["variants"].size(), 4u);
  for (const auto& v : j["variants"]) {
    for (const char* key : kVariantKeys)
      EXPECT_TRUE(v.contains(key)) << v["name"] << " lacks " << key;
    for (const char* zone : {"contact_zone", "far_field"}) {
      EXPECT_TRUE(v[zone].contains("rel_l2_error"));
      EXPECT_TRUE(v[zone].contains("max_error_m"));
    }
    EXPECT_GT(v["steps_per_second"].get<double>(), 0.0);
    EXPECT_GT(v["stable_dt_s"].get<double>(), 0.0);
  }
  expect_finite_numbers(j, "summary");
  EXPECT_EQ(j["variants"][0]["nodes"], 3 * 162);  // three tiers of the level-2 icosphere
}

TEST_F(RunSmallSphere, PrescribedPatchMovesIdenticallyInBothModels) {
  ASSERT_EQ(result_->exit_code, 0) << result_->err;
  const auto h5 = run_dir() / "fields.h5";
  const Eigen::MatrixXd fem = compare::read_h5_matrix(h5, "/fem/displacement");
  const auto j = nlohmann::json::parse(read_text(run_dir() / "summary.json"));
  const int pole = j["tools"][0]["vertex"];
  EXPECT_NEAR(fem.row(pole).norm(), 0.004, 1e-12);  // pushed the full depth
  for (const char* v : {"three_tier", "single_layer", "tet_edges", "skeleton"}) {
    const Eigen::MatrixXd ms =
        compare::read_h5_matrix(h5, std::string("/variants/") + v + "/displacement");
    EXPECT_LT((ms.row(pole) - fem.row(pole)).norm(), 1e-15) << v;  // the same function, rounding
  }
}

TEST_F(RunSmallSphere, VtuAndHdf5ReadBackConsistently) {
  ASSERT_EQ(result_->exit_code, 0) << result_->err;
  const std::string vtu = read_text(run_dir() / "surface_three_tier.vtu");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(vtu, m, std::regex("NumberOfPoints=\"(\\d+)\"")));
  EXPECT_EQ(std::stoi(m[1]), 162);
  ASSERT_TRUE(std::regex_search(vtu, m, std::regex("NumberOfCells=\"(\\d+)\"")));
  EXPECT_EQ(std::stoi(m[1]), 320);
  const Eigen::MatrixXd err =
      compare::read_h5_matrix(run_dir() / "fields.h5", "/variants/three_tier/error");
  const Eigen::MatrixXd u =
      compare::read_h5_matrix(run_dir() / "fields.h5", "/variants/three_tier/displacement");
  const Eigen::MatrixXd fem_surface =
      compare::read_h5_matrix(run_dir() / "fields.h5", "/fem/displacement").topRows(162);
  EXPECT_LT((err - (u - fem_surface)).norm(), 1e-15);
  for (const char* f : {"report.md", "surfaces.pvd", "fem.pvd"})
    EXPECT_TRUE(std::filesystem::exists(run_dir() / f)) << f;
}

TEST_F(RunSmallSphere, SpringNetworkBeatsSingleLayerAtCauchyPoissonRatio) {
  // ν = 0.25: a volumetric spring network can represent the material; a membrane cannot.
  ASSERT_EQ(result_->exit_code, 0) << result_->err;
  const auto j = nlohmann::json::parse(read_text(run_dir() / "summary.json"));
  double tet = 0, single = 0;
  for (const auto& v : j["variants"]) {
    if (v["name"] == "tet_edges") tet = v["rel_l2_error"];
    if (v["name"] == "single_layer") single = v["rel_l2_error"];
  }
  EXPECT_LT(tet, single);
  // And the FEM force grows with depth.
  const auto& curve = j["fem"]["force_depth"];
  ASSERT_EQ(curve.size(), 2u);
  EXPECT_GT(curve[1]["force_N"][2].get<double>(), curve[0]["force_N"][2].get<double>());
}

TEST(CliRun, BadInputIsOneLineWithFileAndLineAndLeavesNoRunFolder) {
  TemporaryDirectory tmp;
  const std::string base = read_text(small_sphere_case);
  auto write_case = [&](const std::string& name, const std::string& text) {
    std::ofstream(tmp / name) << text;
    return (tmp / name).string();
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {write_case("typo.prm", base + "subsection fem\n  set degre = 2\nend\n"), "typo.prm:35:"},
      {write_case("range.prm", base + "subsection material\n  set poisson ratio = 0.7\nend\n"),
       "range.prm:35:"},
      {write_case("mesh.prm", "subsection geometry\n  set source = nowhere.obj\nend\n"),
       "nowhere.obj"},
      {write_case("fixedtool.prm",
                  std::regex_replace(base, std::regex("subsection support[^]*?end"),
                                     "subsection support\n  set fixed region = half space\n"
                                     "  set half space point = 0,0,0.04\n"
                                     "  set half space normal = 0,0,1\nend")),
       "fixed node"},
      {write_case("mode.prm", base + "subsection loads\n  subsection tool\n"
                                     "    set mode = sliding\n  end\nend\n"),
       "mode.prm:36:"},
      {(tmp / "absent.prm").string(), "absent.prm"},
  };
  for (const auto& [file, named] : cases) {
    const auto out = tmp / "out";
    const auto r = run_msfem("run " + file + " --quiet --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << file << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << file;
    for (const auto& entry : std::filesystem::directory_iterator(tmp.path()))
      EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }
  const auto bad_set = run_msfem("run " + small_sphere_case + " --quiet --out " +
                                 (tmp / "o").string() + " --set 'mass spring/variants=four_tier'");
  EXPECT_EQ(bad_set.exit_code, 2);
  EXPECT_NE(bad_set.err.find("four_tier"), std::string::npos) << bad_set.err;
}

TEST(CliRun, AnInterruptedRunLeavesNeitherItsFolderNorItsTemporary) {
  TemporaryDirectory tmp;
  const auto out = tmp / "run";
  // Start a run, wait until its temporary folder exists, then send SIGTERM as a batch system would.
  const std::string script =
      std::string(MSFEM_EXECUTABLE) + " run " + small_sphere_case + " --quiet --no-cache --out " +
      out.string() + " >/dev/null 2>&1 & pid=$!; for i in $(seq 1 300); do " + "ls -d " +
      out.string() + ".tmp.* >/dev/null 2>&1 && break; sleep 0.02; done; kill -TERM $pid; " +
      "wait $pid; echo $? >" + (tmp / "status").string();
  ASSERT_EQ(std::system(("bash -c '" + script + "'").c_str()), 0);
  EXPECT_EQ(read_text(tmp / "status"), "143\n");  // 128 + SIGTERM: the signal still ends it
  EXPECT_FALSE(std::filesystem::exists(out));
  for (const auto& entry : std::filesystem::directory_iterator(tmp.path()))
    EXPECT_TRUE(entry.path().filename().string().find("run.tmp.") == std::string::npos &&
                entry.path().filename() != "run.lock")
        << entry.path();
}

// A second run given the folder another run is filling is refused before any work; a claim left by
// a process that no longer exists is taken over, and released at the end.
TEST(CliRun, AFolderAnotherRunIsFillingIsRefusedAtOnce) {
  TemporaryDirectory tmp;
  const auto out = tmp / "run";
  std::ofstream(tmp / "run.lock") << ::getpid() << "\n";
  const auto taken =
      run_msfem("run " + small_sphere_case + " --quiet --no-timing --out " + out.string());
  EXPECT_EQ(taken.exit_code, 2) << taken.err;
  EXPECT_NE(taken.err.find("another msfem (process " + std::to_string(::getpid()) +
                           ") is writing this output folder"),
            std::string::npos)
      << taken.err;
  EXPECT_EQ(taken.err.find("solving the FEM"), std::string::npos) << taken.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  std::ofstream(tmp / "run.lock") << "4194303\n";  // above Linux's largest process id
  const auto stale = run_msfem("run " + small_sphere_case +
                               " --quiet --no-timing --no-curve --out " + out.string());
  EXPECT_EQ(stale.exit_code, 0) << stale.err;
  EXPECT_TRUE(std::filesystem::exists(out / "summary.json"));
  EXPECT_FALSE(std::filesystem::exists(tmp / "run.lock"));
}

TEST(CliRun, AVariantThatFailsIsReportedAndTheOthersAreStillCompared) {
  // dt = 1.5 ms: about 4x tet_edges' stable step on its mesh refined at the tool (0.37 ms) and
  // below the surface variants' (2.3-2.5 ms), so only tet_edges' time stepping blows up.
  TemporaryDirectory tmp;
  const auto out = tmp / "run";
  const auto r = run_msfem("run " + small_sphere_case +
                           " --quiet --no-curve --set timing/dt=0.0015 --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("variant tet_edges failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stable dt"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(read_text(out / "summary.json"));
  ASSERT_EQ(j["failed_variants"].size(), 1u);
  EXPECT_EQ(j["failed_variants"][0]["name"], "tet_edges");
  ASSERT_EQ(j["variants"].size(), 3u);
  for (const auto& v : j["variants"]) {
    EXPECT_NE(v["name"], "tet_edges");
    EXPECT_TRUE(std::isfinite(v["rel_l2_error"].get<double>()));
  }
  EXPECT_NE(read_text(out / "report.md").find("tet_edges failed"), std::string::npos);
}

TEST(CliRun, PathStepsArePointsOfEachVariantsCurveAndTheLastIsTheTablesRow) {
  TemporaryDirectory tmp;
  const auto out = tmp / "run";
  const auto r = run_msfem("run " + small_sphere_case +
                           " --quiet --no-timing --set \"loads/tool/path step=0.0005\" --set "
                           "\"mass spring/variants=tet_edges,three_tier\" --out " +
                           out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(j["fem"]["force_depth"].size(), 2u);  // the FEM at the curve depths only
  ASSERT_EQ(j["variants"].size(), 2u);
  for (const auto& v : j["variants"]) {
    const auto& curve = v["force_depth"];
    ASSERT_EQ(curve.size(), 8u) << v["name"];  // 0.5, 1, ..., 4 mm
    for (std::size_t i = 0; i < curve.size(); ++i)
      EXPECT_NEAR(curve[i]["depth_m"].get<double>(), 0.0005 * (i + 1), 1e-15);
    EXPECT_EQ(curve.back()["force_N"], v["reaction_force_N"]) << v["name"];
    const bool volumetric = v["name"] == "tet_edges";
    EXPECT_EQ(v["inverted_elements"].is_number_integer(), volumetric) << v["name"];
    EXPECT_EQ(curve.back()["inverted_elements"], v["inverted_elements"]) << v["name"];
  }
}

TEST(CliRun, EveryToolPositionIsItsOwnLoadAndCentralSymmetryHoldsAcrossThem) {
  // Tools 0 and 1 at two icosahedron vertices opposite each other: the sphere, its core, the
  // three-tier network and the tool patches map onto each other under x -> -x, so three_tier's
  // force at the second tool is minus the first; the FEM's differs only by its unsymmetric
  // tetrahedra. A third tool makes the two workers share the other tools.
  TemporaryDirectory tmp;
  const auto out = tmp / "run";
  const auto r = run_msfem(
      "run " + small_sphere_case +
      " --quiet --no-timing --set \"loads/tool/directions=0,1,1.618034; "
      "0,-1,-1.618034; 1.618034,0,1\" --set \"mass spring/variants=three_tier,tet_edges\" "
      "--out " +
      out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text(out / "summary.json"));
  const auto force = [](const nlohmann::json& f) {
    return Eigen::Vector3d(f[0].get<double>(), f[1].get<double>(), f[2].get<double>());
  };
  const auto& fem = j["fem"]["loads"];
  ASSERT_EQ(fem.size(), 3u);
  const Eigen::Vector3d f0 = force(fem[0]["reaction_force_N"]);
  const Eigen::Vector3d f1 = force(fem[1]["reaction_force_N"]);
  EXPECT_EQ(f0, force(j["fem"]["reaction_force_N"]));
  EXPECT_LT((f1 + f0).norm(), 0.05 * f0.norm());
  for (const auto& v : j["variants"]) {
    const auto& loads = v["loads"]["per_tool"];
    ASSERT_EQ(loads.size(), 3u) << v["name"];
    EXPECT_EQ(loads[0]["rel_l2_error"], v["rel_l2_error"]);
    EXPECT_EQ(loads[1]["tool"], 1);
    EXPECT_EQ(loads[2]["force_depth"].size(), v["force_depth"].size());  // the same path
    expect_finite_numbers(v["loads"], v["name"]);
    const double mean =
        (loads[0]["rel_l2_error"].get<double>() + loads[1]["rel_l2_error"].get<double>() +
         loads[2]["rel_l2_error"].get<double>()) /
        3;
    EXPECT_DOUBLE_EQ(v["loads"]["mean_rel_l2_error"].get<double>(), mean);
    if (v["name"] == "three_tier") {
      const Eigen::Vector3d m0 = force(loads[0]["reaction_force_N"]);
      const Eigen::Vector3d m1 = force(loads[1]["reaction_force_N"]);
      EXPECT_LT((m1 + m0).norm(), 1e-6 * m0.norm());
    }
  }
  EXPECT_NE(read_text(out / "report.md").find("## Every tool position"), std::string::npos);
}

// Frictionless contact in both models: the FEM's active set and the springs' surface contact,
// force-depth curves with their power-law exponents, and contact pushing harder than the adhesive
// patch releases (the patch holds the surface up around the tool).
TEST(CliRun, ContactModePressesBothModelsByFrictionlessContact) {
  TemporaryDirectory tmp;
  const std::string variants = " --set \"mass spring/variants=three_tier,single_layer\"";
  const auto contact =
      run_msfem("run " + small_sphere_case + " --quiet --no-timing --no-cache" + variants +
                " --set loads/tool/mode=contact --out " + (tmp / "contact").string());
  ASSERT_EQ(contact.exit_code, 0) << contact.err;
  const auto j = nlohmann::json::parse(read_text(tmp / "contact" / "summary.json"));
  EXPECT_EQ(j["tools"][0]["mode"], "contact");
  const auto& fem = j["fem"];
  ASSERT_TRUE(fem["contact"].is_object()) << fem.dump();
  EXPECT_GT(fem["contact"]["active_nodes"].get<int>(), 3);
  EXPECT_LE(fem["contact"]["active_set_iterations"].get<int>(), 10);
  EXPECT_LT(fem["contact"]["max_penetration_m"].get<double>(), 0.01 * 0.004);
  // The contact radius lies inside the overlap's sqrt(2 R d - d^2).
  EXPECT_LT(fem["contact"]["contact_radius_m"].get<double>(), std::sqrt(2 * 0.01 * 0.004));
  for (const auto& point : fem["force_depth"])
    EXPECT_TRUE(point["contact"].is_object());
  // Contact is stiffer than linear, softer than the bonded patch's stretch: between 1 and 2.
  const double fem_exponent = fem["force_depth_exponent"].get<double>();
  EXPECT_GT(fem_exponent, 1.0);
  EXPECT_LT(fem_exponent, 2.0);
  for (const auto& v : j["variants"]) {
    EXPECT_GT(v["reaction_force_N"][2].get<double>(), 0.0) << v["name"];
    EXPECT_TRUE(v["force_depth_exponent"].is_number()) << v["name"];
  }
  const auto bonded =
      run_msfem("run " + small_sphere_case + " --quiet --no-timing --no-cache" + variants +
                " --set loads/tool/mode=bonded --out " + (tmp / "bonded").string());
  ASSERT_EQ(bonded.exit_code, 0) << bonded.err;
  const auto b = nlohmann::json::parse(read_text(tmp / "bonded" / "summary.json"));
  EXPECT_EQ(b["tools"][0]["mode"], "bonded");
  EXPECT_TRUE(b["fem"]["contact"].is_null());
  EXPECT_NE(b["fem"]["cache_key"], fem["cache_key"]);
}

// A frictionless tool whose only curve depth is the case's is still pressed in steps of a quarter
// of its radius: pressed there from rest at once, the sphere's centre sat on the pole node and
// three_tier reported 0 N. The equilibrium is the default path's, to the solver's precision.
TEST(CliRun, AContactToolWithOneCurveDepthIsPressedAsTheDefaultPathPressesIt) {
  TemporaryDirectory tmp;
  const std::string cheap =
      "run " + std::string(MSFEM_CASES_DIR) +
      "/sphere_indent.prm --quiet --no-timing --set geometry/source=icosphere:2:0.05 --set "
      "fem/degree=1 --set 'fem/error estimate=none' --set 'mass spring/variants=three_tier' ";
  const auto one =
      run_msfem(cheap + "--set 'loads/tool/curve depths=0.005' --out " + (tmp / "one").string());
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const auto quarters = run_msfem(cheap + "--out " + (tmp / "quarters").string());
  ASSERT_EQ(quarters.exit_code, 0) << quarters.err;
  const auto a = nlohmann::json::parse(read_text(tmp / "one" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(tmp / "quarters" / "summary.json"));
  const double fem = a["fem"]["reaction_force_N"][2].get<double>();
  const double force = a["variants"][0]["reaction_force_N"][2].get<double>();
  EXPECT_GT(force, 0.5 * fem);
  EXPECT_NEAR(force, b["variants"][0]["reaction_force_N"][2].get<double>(), 1e-9 * force);
  // (The two runs' FEM references are separate solves, equal to their tolerance.)
  const double error = b["variants"][0]["rel_l2_error"].get<double>();
  EXPECT_NEAR(a["variants"][0]["rel_l2_error"].get<double>(), error, 1e-8 * error);
}

// The local point distribution refines the one surface both models are built on: the case's
// vertices first, every variant following it, and the counts in summary.json.
TEST(CliRun, ContactRefinementRefinesTheSurfaceEveryModelIsBuiltOn) {
  TemporaryDirectory tmp;
  const auto r = run_msfem("run " + small_sphere_case + " --quiet --no-timing --no-cache" +
                           " --set \"mass spring/variants=three_tier,single_layer\"" +
                           " --set \"mass spring/contact refinement/enabled=true\"" + " --out " +
                           (tmp / "refined").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text(tmp / "refined" / "summary.json"));
  const auto& refinement = j["contact_refinement"];
  ASSERT_TRUE(refinement.is_object()) << j.dump();
  // Defaults: twice the tool radius, a third of it.
  EXPECT_DOUBLE_EQ(refinement["radius_m"].get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(refinement["edge_length_m"].get<double>(), 0.01 / 3);
  const int added = refinement["added_surface_vertices"].get<int>();
  const int icosphere_level_2 = 162;
  EXPECT_EQ(j["surface"]["vertices"].get<int>(), icosphere_level_2 + added);
  // The cap within 2 cm holds at least its area over a triangle of edge 3.3 mm, halved, vertices
  // (~130); triangles reaching into it from outside (edges of 15 mm on the level-2 sphere) and
  // bisected edges shorter than the limit add more, but not a whole sphere's worth.
  EXPECT_GT(added, 130);
  EXPECT_LT(added, 2000);
  for (const auto& v : j["variants"]) {
    const int copies = v["name"] == "three_tier" ? 3 : 1;
    EXPECT_EQ(v["contact_refinement_added_nodes"].get<int>(), copies * added) << v["name"];
    EXPECT_EQ(v["nodes"].get<int>(), copies * (icosphere_level_2 + added)) << v["name"];
  }

  // Without a tool there is nothing to refine around: a clear error, nothing written.
  const auto no_tool = run_msfem(
      "run " + small_sphere_case + " --quiet --no-timing --no-cache" +
      " --set \"mass spring/contact refinement/enabled=true\"" + " --set loads/tool/enabled=false" +
      " --set \"loads/gravity=0,0,-9.81\" --out " + (tmp / "no_tool").string());
  EXPECT_EQ(no_tool.exit_code, 2) << no_tool.err;
  EXPECT_NE(no_tool.err.find("mass spring/contact refinement/enabled"), std::string::npos)
      << no_tool.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "no_tool"));
}

// A U of two towers 2 cm wide, extruded 2 cm, with a middle layer of vertices (listed first): the
// left tower's top rises toward the gap, so its highest vertex is the middle of its inner top
// edge, and its normal leans over the gap toward the right tower.
std::string write_u_shape(const std::filesystem::path& file) {
  const double p[10][2] = {{0, 0},   {1, 0},   {2, 0},   {3, 0},   {3, 1},
                           {2, 1.1}, {2, 0.3}, {1, 0.3}, {1, 1.2}, {0, 1}};
  const int cap[8][3] = {{0, 1, 7}, {0, 7, 8}, {0, 8, 9}, {1, 2, 6},
                         {1, 6, 7}, {3, 4, 5}, {3, 5, 6}, {3, 6, 2}};
  std::ofstream out(file);
  for (double y : {0.5, 0.0, 1.0})  // OBJ ids: middle 1-10, front 11-20, back 21-30
    for (const auto& v : p)
      out << "v " << 0.02 * v[0] << " " << 0.02 * y << " " << 0.02 * v[1] << "\n";
  for (const auto& t : cap) {  // the back cap turned over (msfem orients the whole anyway)
    out << "f " << t[0] + 11 << " " << t[1] + 11 << " " << t[2] + 11 << "\n";
    out << "f " << t[0] + 21 << " " << t[2] + 21 << " " << t[1] + 21 << "\n";
  }
  for (const auto& [a, b] : {std::pair{10, 0}, std::pair{0, 20}})
    for (int i = 0; i < 10; ++i) {
      const int j = (i + 1) % 10;
      out << "f " << i + a + 1 << " " << i + b + 1 << " " << j + b + 1 << "\n";
      out << "f " << i + a + 1 << " " << j + b + 1 << " " << j + a + 1 << "\n";
    }
  return file.string();
}

// A contact tool must start outside the body (a sphere already inside would be pushed out):
// refused before any meshing, naming
// the key, with nothing written.
TEST(CliRun, ContactToolStartingInsideAConcaveSurfaceIsRefused) {
  TemporaryDirectory tmp;
  const std::string u = write_u_shape(tmp / "u.obj");
  const std::string common = "run " + small_sphere_case + " --quiet --no-timing --no-cache" +
                             " --set loads/tool/mode=contact --set geometry/source=" + u +
                             " --set \"support/fixed region=half space\"" +
                             " --set \"support/half space point=0,0,0.002\"";
  // A 3 cm sphere resting on the left tower's inner edge reaches over the gap into the right
  // tower (2 mm lower, 2 cm away): its centre is 2.7 cm from it.
  const auto inside = run_msfem(common + " --set loads/tool/radius=0.03" +
                                " --set loads/tool/depth=0.001 --set \"loads/tool/curve depths=\"" +
                                " --out " + (tmp / "inside").string());
  EXPECT_EQ(inside.exit_code, 2) << inside.err;
  EXPECT_NE(inside.err.find("loads/tool"), std::string::npos) << inside.err;
  EXPECT_NE(inside.err.find("starts inside the body"), std::string::npos) << inside.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "inside"));
  // A 2 mm sphere there is clear of the right tower and presses the corner.
  const auto small_tool =
      run_msfem(common + " --set loads/tool/radius=0.002" +
                " --set loads/tool/depth=0.001 --set \"loads/tool/curve depths=\"" +
                " --set \"mass spring/variants=single_layer\" --out " + (tmp / "small").string());
  EXPECT_EQ(small_tool.exit_code, 0) << small_tool.err;
}

TEST(CliParams, PrintsTheWholeLanguage) {
  const auto r = run_msfem("params");
  ASSERT_EQ(r.exit_code, 0);
  for (const char* s : {"subsection geometry", "youngs modulus", "subsection tool", "variants"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
}

// --no-curve skips the curve's solves and output, not the loading path: the variants end on the
// same equilibrium, and msfem regress (which runs that way) measures what msfem run prints.
TEST(RunOptions, NoCurveGivesTheSameEquilibrium) {
  TemporaryDirectory dir;
  const std::string common = "run " + small_sphere_case + " --quiet --no-timing --no-cache --out ";
  const auto full = run_msfem(common + (dir / "full").string());
  const auto lean = run_msfem(common + (dir / "lean").string() + " --no-curve");
  ASSERT_EQ(full.exit_code, 0) << full.err;
  ASSERT_EQ(lean.exit_code, 0) << lean.err;
  const auto a = nlohmann::json::parse(read_text(dir / "full" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(dir / "lean" / "summary.json"));
  ASSERT_EQ(a["variants"].size(), b["variants"].size());
  for (std::size_t i = 0; i < a["variants"].size(); ++i) {
    const auto& va = a["variants"][i];
    const auto& vb = b["variants"][i];
    for (const char* key : {"rel_l2_error", "max_error_m", "reaction_force_rel_error"})
      EXPECT_NEAR(va[key].get<double>(), vb[key].get<double>(),
                  1e-12 * std::max(1.0, std::abs(va[key].get<double>())))
          << va["name"] << " " << key;
    EXPECT_FALSE(va["force_depth"].empty());
    EXPECT_TRUE(vb["force_depth"].empty());  // the curve is not written
    EXPECT_EQ(va["force_depth_monotone"], vb["force_depth_monotone"]) << va["name"];
  }
}

// The reference is cached per load: a run that changes one load's reference (--no-curve drops the
// first load's force-depth curve) solves that load again and reads the other from the cache, with
// the very numbers it had; the same run again reads every load from the cache.
TEST(RunOptions, EachLoadsReferenceIsCachedOnItsOwn) {
  TemporaryDirectory dir;
  const std::string common = "run " + small_sphere_case + " --quiet --no-timing" +
                             " --set \"loads/tool/directions=0,0,1; 1,0,0\"" +
                             " --set \"mass spring/variants=three_tier\" --out ";
  const auto first = run_msfem(common + (dir / "first").string());
  const auto lean = run_msfem(common + (dir / "lean").string() + " --no-curve");
  const auto again = run_msfem(common + (dir / "again").string());
  for (const auto* r : {&first, &lean, &again})
    ASSERT_EQ(r->exit_code, 0) << r->err;
  const auto a = nlohmann::json::parse(read_text(dir / "first" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(dir / "lean" / "summary.json"));
  const auto c = nlohmann::json::parse(read_text(dir / "again" / "summary.json"));
  ASSERT_EQ(a["fem"]["loads"].size(), 2u);
  EXPECT_FALSE(a["fem"]["loads"][0]["from_cache"]);
  EXPECT_FALSE(a["fem"]["loads"][1]["from_cache"]);
  EXPECT_FALSE(b["fem"]["loads"][0]["from_cache"]);
  EXPECT_TRUE(b["fem"]["loads"][1]["from_cache"]);
  EXPECT_FALSE(b["fem"]["from_cache"]);
  EXPECT_TRUE(c["fem"]["from_cache"]);
  EXPECT_EQ(c["fem"]["cache_key"], a["fem"]["cache_key"]);
  EXPECT_NE(b["fem"]["cache_key"], a["fem"]["cache_key"]);
  for (const auto* other : {&b, &c}) {
    EXPECT_EQ((*other)["fem"]["loads"][1]["reaction_force_N"],
              a["fem"]["loads"][1]["reaction_force_N"]);
    // The first load is solved again without its curve, along a different path of steps, so
    // its force agrees to the solver's tolerance, not bit for bit; read from the cache it is exact.
    const auto& f0 = (*other)["fem"]["loads"][0]["reaction_force_N"];
    const auto& a0 = a["fem"]["loads"][0]["reaction_force_N"];
    const double scale = std::abs(a0[2].get<double>());
    for (std::size_t k = 0; k < 3; ++k) {
      if (other == &c)
        EXPECT_EQ(f0[k], a0[k]) << k;
      else
        EXPECT_NEAR(f0[k].get<double>(), a0[k].get<double>(), 1e-9 * scale) << k;
    }
    const auto& tools = (*other)["variants"][0]["loads"]["per_tool"];
    for (std::size_t t = 0; t < 2; ++t)
      EXPECT_DOUBLE_EQ(tools[t]["rel_l2_error"].get<double>(),
                       a["variants"][0]["loads"]["per_tool"][t]["rel_l2_error"].get<double>())
          << "tool " << t;
  }
}

}  // namespace
}  // namespace msfem
