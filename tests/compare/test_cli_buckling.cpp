// A spring network whose equilibrium gives way under the tool is reported, not hidden: the seed's
// three tiers on the level-5 icosphere (10,242 vertices per tier), pressed 5 mm by the bonded 5 mm
// tool, stop resisting at the full depth (the level-3 default does not: test_shipped_cases.cpp).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

TEST(CliBuckling, TheLevelFiveSeedSphereWarnsWhereItBuckles) {
  TemporaryDirectory tmp;
  const auto out = tmp / "run";
  // A coarse P1 reference: the warning comes from the spring model's own loading path.
  const auto r = run_msfem("run " + std::string(MSFEM_CASES_DIR) +
                           "/sphere_indent_bonded.prm --quiet --no-timing --no-cache "
                           "--set geometry/source=icosphere:5:0.05 --set \"mass spring/variants="
                           "three_tier\" --set fem/degree=1 --set \"fem/cell size=0.008\" --set "
                           "\"fem/refine at tool=false\" --set \"fem/error estimate=none\" --out " +
                           out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string warning = "three_tier: buckles under the tool: from 5 mm of 5 mm";
  EXPECT_NE(r.err.find("warning: " + warning), std::string::npos) << r.err;
  EXPECT_NE(read_text(out / "report.md").find(warning), std::string::npos);
  const auto summary = nlohmann::json::parse(read_text(out / "summary.json"));
  bool in_summary = false;
  for (const auto& w : summary["variants"][0]["warnings"])
    in_summary = in_summary || w.get<std::string>().find("buckles under the tool: from 5 mm") !=
                                   std::string::npos;
  EXPECT_TRUE(in_summary) << summary["variants"][0]["warnings"].dump();
}

}  // namespace
}  // namespace msfem
