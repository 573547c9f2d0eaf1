// Every case msfem ships runs as a user runs it (msfem run), its reference moves, and its summary
// carries the reference's own error bar. Reduced where CI's time needs it: no timing, no
// force-depth curve, and the brain's FEM at degree 1 on a coarser mesh (said below).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

std::vector<std::string> shipped_cases() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(MSFEM_CASES_DIR))
    if (entry.path().extension() == ".prm") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

// What CI changes of a case to fit its time, beyond --no-timing and --no-curve.
std::string reduced(const std::string& name) {
  // The brain at the paper's 9,177 vertices with its P2 reference takes minutes per load; P1 on
  // 6 mm cells keeps every stage (four tools, loading path, all variants) in about a minute.
  if (name == "brain_indent")
    return " --set \"fem/degree=1\" --set \"fem/cell size=0.006\" --set \"fem/tool cell "
           "size=0.003\"";
  // The MRI brain: as the brain above, on 8 mm cells.
  if (name == "brain_mri_indent")
    return " --set \"fem/degree=1\" --set \"fem/cell size=0.008\" --set \"fem/tool cell "
           "size=0.004\" --set \"fem/error estimate=refine\"";
  // The liver's P2 reference with its refined twin takes minutes; P1 keeps both under 30 s.
  if (name == "liver_ct_indent")
    return " --set \"fem/degree=1\" --set \"fem/error estimate=refine\"";
  return "";
}

class ShippedCase : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedCase, RunsWithItsReferencesOwnErrorBar) {
  const std::string name = GetParam();
  TemporaryDirectory dir;
  const auto out = dir / "run";
  const auto r = run_msfem("run " + std::string(MSFEM_CASES_DIR) + "/" + name +
                           ".prm --quiet --no-timing --no-curve --no-cache --out " + out.string() +
                           reduced(name));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // No variant gives way under the sphere cases' tool (a buckling warning is on stderr); on the
  // brain's folded cortex some do, and say so.
  if (name.rfind("sphere", 0) == 0) {
    EXPECT_EQ(r.err.find("buckles under the tool"), std::string::npos) << r.err;
  }
  const nlohmann::json s = nlohmann::json::parse(read_text(out / "summary.json"));
  const auto& fem = s.at("fem");
  ASSERT_TRUE(fem.at("estimated_rel_l2_error").is_number()) << fem.at("error_estimate").dump();
  const double estimate = fem.at("estimated_rel_l2_error");
  EXPECT_GT(estimate, 0.0);
  EXPECT_LT(estimate, 0.5);  // a reference this far off would not be a reference
  const bool tool = !s.at("tools").empty();
  const bool patch = !fem.at("patch_mean_displacement_m").is_null();
  // A force is measured with a tool or a patch force; gravity alone measures none.
  EXPECT_EQ(fem.at("estimated_force_rel_error").is_number(), tool || patch);
  const std::string report = read_text(out / "report.md");
  EXPECT_NE(report.find("FEM reference's own error"), std::string::npos);
  for (const auto& v : s.at("variants")) {
    EXPECT_EQ(v.at("reaction_force_rel_error").is_number(), tool) << v.at("name");
    EXPECT_TRUE(v.at("not_resolved_by_reference").is_array());
    // A variant with no force where the FEM pushes back is marked and warned about, never a
    // plain force error (the skeleton's surface gives way on the CT pancreas).
    if (v.at("lost_tool").get<bool>()) {
      const std::string name = v.at("name");
      EXPECT_NE(r.err.find(name + ": loses the tool"), std::string::npos) << r.err;
      const auto row = r.out.find("| " + name + " ");
      ASSERT_NE(row, std::string::npos) << r.out;
      EXPECT_NE(r.out.substr(row, r.out.find('\n', row) - row).find("lost"), std::string::npos)
          << r.out;
    }
    if (patch) {
      // The pulled patch moves in the spring model as in the FEM.
      const auto& u = v.at("patch_mean_displacement_m");
      EXPECT_GT(std::hypot(u[0].get<double>(), u[1].get<double>(), u[2].get<double>()), 1e-5)
          << v.at("name");
    }
  }
  if (!tool) {
    // No tool: the table's force columns are dashes, not a zero that reads as a perfect force.
    EXPECT_EQ(r.out.find("force err 0.0000"), std::string::npos);
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, ShippedCase, ::testing::ValuesIn(shipped_cases()),
                         [](const auto& info) { return info.param; });

TEST(ShippedCaseInput, APatchForceOnTheFixedRegionIsRefusedNamingTheFileAndKey) {
  TemporaryDirectory dir;
  // The pancreas tail's tip lies in the fixed posterior half.
  const auto r = run_msfem("run " + std::string(MSFEM_CASES_DIR) +
                           "/pancreas_drag.prm --quiet --no-cache --out " + (dir / "run").string() +
                           " --set \"loads/patch force/direction=1,0,0\"");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("pancreas_drag.prm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("loads/patch force/direction"), std::string::npos) << r.err;
  EXPECT_EQ(testing::count_lines(r.err), 1u) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "run"));
}

}  // namespace
}  // namespace msfem
