// An outside simulator's answer as a variant: msfem export-load describes the loads, the answer
// comes back through mass spring/results, and is measured (and gated by regress) as any variant.
// Fed the FEM's own surface displacement and force, the errors are round-off; fed a variant's own
// answer, its metrics are that variant's; a bad result file is refused before the FEM.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "msfem/cases/vtk_surface.hpp"
#include "msfem/compare/writers/fields_h5.hpp"
#include "msfem/compare/writers/vtu.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

const std::string coarse_sphere_args =
    std::string(MSFEM_CASES_DIR) +
    "/sphere_indent.prm --set geometry/source=icosphere:2:0.05 --set "
    "fem/degree=1 --set 'fem/error estimate=none'";

// The answer as a simulator writes it: the case's surface (surface.vtu's points) with point data
// displacement, and the tool force in STEM.force.json beside it.
void write_answer(const std::filesystem::path& file, const Eigen::MatrixX3d& rest,
                  const Eigen::MatrixX3i& triangles, const Eigen::MatrixXd& displacement,
                  const nlohmann::json& force) {
  compare::write_surface_vtu(file, rest, triangles, {{"displacement", displacement}});
  if (!force.is_null())
    std::ofstream(file.parent_path() / (file.stem().string() + ".force.json"))
        << nlohmann::json{{"schema", "msfem-force"}, {"version", 1}, {"tool_force_n", force}};
}

class ExternalResults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TemporaryDirectory;
    ASSERT_EQ(
        run_msfem("export-load " + coarse_sphere_args + " " + path("load").string()).exit_code, 0);
    ASSERT_EQ(run_msfem("run " + coarse_sphere_args +
                        " --quiet --no-timing --set 'mass spring/variants=" + "three_tier' --out " +
                        path("run").string())
                  .exit_code,
              0);
    const auto h5 = path("run") / "fields.h5";
    const auto summary = nlohmann::json::parse(read_text(path("run") / "summary.json"));
    surface_ = new cases::VtkSurface(cases::read_vtk_surface(path("load") / "surface.vtu"));
    const Eigen::Index n = surface_->points.rows();
    const Eigen::MatrixXd fem = compare::read_h5_matrix(h5, "/fem/displacement").topRows(n);
    write_answer(path("fem.vtu"), surface_->points, surface_->triangles, fem,
                 summary["fem"]["reaction_force_N"]);
    const Eigen::MatrixXd tiers = compare::read_h5_matrix(h5, "/variants/three_tier/displacement");
    write_answer(path("tiers.vtu"), surface_->points, surface_->triangles, tiers,
                 summary["variants"][0]["reaction_force_N"]);
    write_answer(path("worse.vtu"), surface_->points, surface_->triangles, 1.1 * fem,
                 summary["fem"]["reaction_force_N"]);
    write_answer(path("no_force.vtu"), surface_->points, surface_->triangles, fem, nullptr);
    summary_ = new nlohmann::json(summary);
  }
  static void TearDownTestSuite() {
    delete summary_;
    delete surface_;
    delete dir_;
  }
  static std::filesystem::path path(const std::string& name) { return *dir_ / name; }
  static std::string results(const std::string& list) {
    return " --set 'mass spring/variants=three_tier' --set 'mass spring/results=" + list + "'";
  }
  static inline TemporaryDirectory* dir_ = nullptr;
  static inline cases::VtkSurface* surface_ = nullptr;
  static inline nlohmann::json* summary_ = nullptr;
};

const nlohmann::json& variant(const nlohmann::json& s, const std::string& name) {
  for (const auto& v : s["variants"])
    if (v["name"] == name) return v;
  static const nlohmann::json none;
  ADD_FAILURE() << "no variant " << name;
  return none;
}

TEST_F(ExternalResults, TheLoadsAreDescribedForAnOutsideSimulator) {
  const auto j = nlohmann::json::parse(read_text(path("load") / "loads.json"));
  EXPECT_EQ(j["schema"], "msfem-loads");
  EXPECT_EQ(j["version"], 1);
  ASSERT_EQ(j["loads"].size(), 1u);
  const auto& tool = j["loads"][0]["tool"];
  EXPECT_EQ(tool["mode"], "contact");
  EXPECT_DOUBLE_EQ(tool["radius_m"].get<double>(), 0.005);
  // The sphere's centre at full depth is radius − depth out from the touched point: at the pole.
  EXPECT_NEAR(tool["center_m"][2].get<double>(), 0.05, 1e-12);
  EXPECT_EQ(tool["curve"].size(), 4u);
  EXPECT_EQ(j["surface"]["vertices"], surface_->points.rows());
}

TEST_F(ExternalResults, TheFemsOwnAnswerHasNoErrorAndAVariantsOwnItsMetrics) {
  const auto r = run_msfem("run " + coarse_sphere_args + " --quiet --no-timing" +
                           results("fem=" + path("fem.vtu").string() +
                                   "; tiers=" + path("tiers.vtu").string() +
                                   "; bare=" + path("no_force.vtu").string()) +
                           " --out " + path("back").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto s = nlohmann::json::parse(read_text(path("back") / "summary.json"));
  EXPECT_LE(variant(s, "fem")["rel_l2_error"].get<double>(), 1e-12);
  EXPECT_LE(variant(s, "fem")["reaction_force_rel_error"].get<double>(), 1e-12);
  EXPECT_EQ(variant(s, "fem")["stepper"], "external");
  const auto& built = variant(s, "three_tier");
  for (const char* metric :
       {"rel_l2_error", "max_error_m", "reaction_force_rel_error", "volume_change"})
    EXPECT_NEAR(variant(s, "tiers")[metric].get<double>(), built[metric].get<double>(),
                1e-10 * std::abs(built[metric].get<double>()))
        << metric;
  // No force given: empty force columns, never a zero.
  EXPECT_TRUE(variant(s, "bare")["reaction_force_N"].is_null());
  EXPECT_TRUE(variant(s, "bare")["reaction_force_rel_error"].is_null());
  const std::string report = read_text(path("back") / "report.md");
  EXPECT_NE(report.find("| bare "), std::string::npos);
  EXPECT_NE(report.find("external"), std::string::npos);
}

// A second program (tests/compare/stand_in_simulator.cpp) that knows only export-load's files
// builds msfem's single layer there and presses it: its answer, brought back, is measured as the
// built-in single_layer is.
TEST_F(ExternalResults, ASecondProgramsAnswerFromTheExportedLoadsIsMeasuredAsTheBuiltInOne) {
  for (const char* mode : {"contact", "prescribed"}) {
    const std::string name = mode;
    const std::string setting = " --set loads/tool/mode=" + name;
    ASSERT_EQ(run_msfem("export-load " + coarse_sphere_args + setting + " " +
                        path("load_" + name).string())
                  .exit_code,
              0);
    const std::string answer = path("stand_in_" + name + ".vtu").string();
    ASSERT_EQ(std::system((std::string(MSFEM_STAND_IN_SIMULATOR) + " " +
                           path("load_" + name).string() + " " + answer)
                              .c_str()),
              0);
    const auto r = run_msfem("run " + coarse_sphere_args + setting +
                             " --quiet --no-timing --set 'mass spring/variants=single_layer'"
                             " --set 'mass spring/results=sim=" +
                             answer + "' --out " + path("stand_in_run_" + name).string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto s = nlohmann::json::parse(read_text(path("stand_in_run_" + name) / "summary.json"));
    const auto& built = variant(s, "single_layer");
    for (const char* metric :
         {"rel_l2_error", "max_error_m", "reaction_force_rel_error", "volume_change"})
      EXPECT_NEAR(variant(s, "sim")[metric].get<double>(), built[metric].get<double>(),
                  1e-8 * std::abs(built[metric].get<double>()))
          << mode << " " << metric;
  }
}

TEST_F(ExternalResults, AnAnswerTenPercentWorseFailsRegress) {
  const std::string baselines = " --baselines " + path("baselines").string();
  ASSERT_EQ(run_msfem("regress " + coarse_sphere_args + " --quiet --update" + baselines +
                      results("sim=" + path("fem.vtu").string()))
                .exit_code,
            0);
  EXPECT_EQ(run_msfem("regress " + coarse_sphere_args + " --quiet" + baselines +
                      results("sim=" + path("fem.vtu").string()))
                .exit_code,
            0);
  const auto worse = run_msfem("regress " + coarse_sphere_args + " --quiet" + baselines +
                               results("sim=" + path("worse.vtu").string()));
  EXPECT_EQ(worse.exit_code, 1) << worse.out << worse.err;
  EXPECT_NE(worse.out.find("WORSE"), std::string::npos) << worse.out;
}

// Each bad file: one line naming the file and the item, exit 2, nothing written.
TEST_F(ExternalResults, BadResultFilesAreRefusedNamingTheFileAndItem) {
  const Eigen::MatrixX3d& rest = surface_->points;
  const Eigen::MatrixX3i& triangles = surface_->triangles;
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(rest.rows(), 3);
  // A NaN, as a simulator that diverged writes it (the writer here refuses one: put it in after).
  Eigen::MatrixXd marked = zero;
  marked(7, 1) = 0.25;
  write_answer(path("nan.vtu"), rest, triangles, marked, {0, 0, 1});
  std::string text = read_text(path("nan.vtu"));
  text.replace(text.find(" 0.25"), 5, " nan");
  std::ofstream(path("nan.vtu")) << text;
  write_answer(path("mm.vtu"), 1000 * rest, triangles, zero, {0, 0, 1});
  write_answer(path("two.vtu"), rest, triangles, zero, {0, 1});
  const Eigen::Index last = rest.rows() - 1;
  Eigen::MatrixX3i kept(0, 3);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    if (triangles.row(t).maxCoeff() < last) {
      kept.conservativeResize(kept.rows() + 1, 3);
      kept.row(kept.rows() - 1) = triangles.row(t);
    }
  write_answer(path("fewer.vtu"), rest.topRows(last), kept, zero.topRows(last), {0, 0, 1});
  write_answer(path("version.vtu"), rest, triangles, zero, {0, 0, 1});
  std::ofstream(path("version.force.json"))
      << R"({"schema": "msfem-force", "version": 2, "tool_force_n": [0, 0, 1]})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"nan.vtu", "not finite"},
      {"mm.vtu", "not in metres"},
      {"two.vtu", "'tool_force_n' has 2 components"},
      {"fewer.vtu", "161 vertices where the case's surface has 162"},
      {"version.vtu", "schema version 2"}};
  for (const auto& [file, expected] : cases) {
    const auto out = path("refused_" + file);
    const auto r = run_msfem("run " + coarse_sphere_args + " --quiet --no-timing" +
                             results("sim=" + path(file).string()) + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << file;
    // The result file, or the force file beside it.
    EXPECT_NE(r.err.find(std::filesystem::path(file).stem().string() + "."), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << file;
  }
  // One file per load.
  const auto two =
      run_msfem("run " + coarse_sphere_args + " --quiet --no-timing" +
                results("sim=" + path("fem.vtu").string() + "," + path("fem.vtu").string()));
  EXPECT_EQ(two.exit_code, 2);
  EXPECT_NE(two.err.find("2 files for the case's 1 loads"), std::string::npos) << two.err;
}

}  // namespace
}  // namespace msfem
