#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

const std::string small_case = std::string(MSFEM_TEST_DATA_DIR) + "/small_sphere.prm";

TEST(CliSweep, AResolutionThatCannotBeRunIsReportedAndTheOthersAreStillSwept) {
  // Icosphere level 10 is out of range: as a surface that self-intersects once simplified (the
  // brain below ~2,500 vertices) it is bad input at that resolution only.
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto r =
      run_msfem("sweep " + small_case +
                " --quiet --resolutions 1,10 --integrators symplectic_euler --out " + out.string());
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
  EXPECT_NE(read_text(out / "report.md").find("resolution 10 failed"), std::string::npos);
}

TEST(CliSweep, WhenNoResolutionCanBeRunItIsAnErrorAndNothingIsWritten) {
  TemporaryDirectory tmp;
  const auto out = tmp / "sweep";
  const auto r =
      run_msfem("sweep " + small_case + " --quiet --resolutions 10 --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("level '10'"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace msfem
