#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "msfem/compare/writers/fields_h5.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

// A copy of the small case in its own folder, with a baseline made from it.
class Regress : public ::testing::Test {
 protected:
  void SetUp() override {
    case_file_ = (tmp_ / "small_sphere.prm").string();
    std::ofstream(case_file_) << read_text(std::string(MSFEM_TEST_DATA_DIR) + "/small_sphere.prm");
    const auto r =
        run_msfem("regress " + case_file_ + " --quiet --update --baselines " + baselines());
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  }
  std::string baselines() const { return (tmp_ / "baselines").string(); }
  std::filesystem::path baseline_file() const { return tmp_ / "baselines" / "small_sphere.json"; }
  testing::CommandResult regress(const std::string& extra = "") const {
    return run_msfem("regress " + case_file_ + " --quiet --baselines " + baselines() + " " + extra);
  }

  TemporaryDirectory tmp_;
  std::string case_file_;
};

TEST_F(Regress, UnchangedModelPassesAndPrintsTheTable) {
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("0 failed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("surface_displacement"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(read_text(baseline_file()));
  for (const char* key : {"format_version", "case_file_hash", "mesh_hash", "reference_hash",
                          "units", "degree", "git_revision", "date", "fields_file", "variants"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST_F(Regress, SofterSpringGroupFailsAndNamesTheMetric) {
  const auto r = regress("--set 'mass spring/group scales=tier1_edges:0.8'");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  bool named = false;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);)
    named = named || (line.find("three_tier") != std::string::npos &&
                      line.find("WORSE") != std::string::npos &&
                      line.find("max_error_m") != std::string::npos);
  EXPECT_TRUE(named) << r.out;
}

TEST_F(Regress, ImprovementPassesAndSaysSo) {
  // As if the baseline had been made by a worse model: a larger error on record.
  auto j = nlohmann::json::parse(read_text(baseline_file()));
  auto& value = j["variants"]["three_tier"]["metrics"]["rel_l2_error"]["value"];
  value = value.get<double>() * 1.5;
  std::ofstream(baseline_file()) << j.dump();
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("improved"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 improved"), std::string::npos) << r.out;
}

TEST_F(Regress, MissingBaselineFails) {
  std::filesystem::remove(baseline_file());
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("MISSING"), std::string::npos) << r.out;
  EXPECT_EQ(run_msfem("regress --quiet --baselines " + (tmp_ / "none").string()).exit_code, 2);
}

TEST_F(Regress, EditedCaseIsAStaleBaseline) {
  std::ofstream(case_file_, std::ios::app) << "subsection material\n  set density = 1000\nend\n";
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("stale baseline, run --update"), std::string::npos) << r.out;
}

// The same case file with --set another material is another problem: STALE, not a metric-by-metric
// verdict against numbers of a different reference.
TEST_F(Regress, AnotherProblemThroughSetIsAStaleBaseline) {
  const auto r = regress("--set 'material/poisson ratio=0.3'");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("reference_hash"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("STALE"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("WORSE"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" 0 improved"), std::string::npos) << r.out;
}

TEST_F(Regress, NonFiniteValueInTheBaselineFieldFails) {
  // Overwrite one stored displacement in the baseline's HDF5 file with a NaN: the datasets are
  // contiguous little-endian doubles, so the row's 24 bytes are found in the file as they are.
  const auto fields = tmp_ / "baselines" / "small_sphere.fields.h5";
  const Eigen::MatrixXd u = compare::read_h5_matrix(fields, "/variants/tet_edges/displacement");
  const double row[3] = {u(7, 0), u(7, 1), u(7, 2)};
  std::string bytes = read_text(fields);
  const auto at = bytes.find(std::string(reinterpret_cast<const char*>(row), sizeof row));
  ASSERT_NE(at, std::string::npos);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  bytes.replace(at, sizeof nan, reinterpret_cast<const char*>(&nan), sizeof nan);
  std::ofstream(fields, std::ios::binary) << bytes;
  ASSERT_FALSE(compare::read_h5_matrix(fields, "/variants/tet_edges/displacement").allFinite());
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("NON-FINITE"), std::string::npos) << r.out;
}

TEST_F(Regress, MissingFieldsFileFails) {
  std::filesystem::remove(tmp_ / "baselines" / "small_sphere.fields.h5");
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("MISSING"), std::string::npos) << r.out;
}

TEST_F(Regress, TruncatedFieldsFileIsCorruptNotMissing) {
  const auto fields = tmp_ / "baselines" / "small_sphere.fields.h5";
  std::filesystem::resize_file(fields, std::filesystem::file_size(fields) / 2);
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("CORRUPT"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("MISSING"), std::string::npos) << r.out;
}

TEST_F(Regress, VariantWithoutReferenceFails) {
  auto j = nlohmann::json::parse(read_text(baseline_file()));
  j["variants"].erase("skeleton");
  std::ofstream(baseline_file()) << j.dump();
  const auto r = regress();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("MISSING"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace msfem
