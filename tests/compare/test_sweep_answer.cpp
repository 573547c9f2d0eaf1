// The sweep's answer: which configuration keeps a 60 Hz or a 1 kHz loop in real time, and the
// least-error one among those.
#include <gtest/gtest.h>

#include <cmath>

#include "msfem/compare/pipeline/sweep.hpp"
#include "msfem/compare/writers/sweep_report.hpp"

namespace msfem::compare {
namespace {

SweepPoint point(const std::string& variant, double dt, double steps_per_second, double error) {
  SweepPoint p;
  p.variant = variant;
  p.integrator = "symplectic_euler";
  p.resolution = 3;
  p.nodes = 100;
  p.dt_s = dt;
  p.steps_per_second = steps_per_second;
  p.realtime_factor = 2 * dt * steps_per_second;  // at the stable step, twice the timed one
  p.rel_l2_error = error;
  p.reaction_force_rel_error = error / 2;
  return p;
}

// A tick of 1/f s takes ceil(1 / (f dt)) steps: at dt = 0.1 ms a 60 Hz frame is 167 steps
// (10,020 steps/s), a 1 kHz tick 10 (10,000 steps/s); at dt = 1 ms a tick is one step.
TEST(SweepAnswer, ALoopKeepsRealTimeWhenATicksStepsFitInTheTick) {
  EXPECT_TRUE(keeps_real_time(point("a", 1e-4, 10020, 0.1), 60));
  EXPECT_FALSE(keeps_real_time(point("a", 1e-4, 10019, 0.1), 60));
  EXPECT_TRUE(keeps_real_time(point("a", 1e-4, 10000, 0.1), 1000));
  EXPECT_FALSE(keeps_real_time(point("a", 1e-4, 9999, 0.1), 1000));
  EXPECT_TRUE(keeps_real_time(point("a", 1e-3, 1000, 0.1), 1000));
  EXPECT_FALSE(keeps_real_time(point("a", 1e-3, 999, 0.1), 1000));
  EXPECT_TRUE(keeps_real_time(point("a", 1e-3, 1020, 0.1), 60));  // 17 steps per frame
  EXPECT_FALSE(keeps_real_time(point("a", 1e-3, 1019, 0.1), 60));
  EXPECT_FALSE(keeps_real_time(point("a", 0, 1e6, 0.1), 60));  // not timed
}

TEST(SweepAnswer, TheLeastErrorWithinEachBudgetAndTheCheapestWithinAnError) {
  const std::vector<SweepPoint> points = {
      point("fast", 1e-4, 50000, 0.40),      // keeps both loops
      point("visual", 2e-3, 600, 0.20),      // keeps 60 Hz (9 steps a frame) only
      point("accurate", 1e-4, 2000, 0.05)};  // keeps neither
  const std::string answer = sweep_answer(points, 0.3);
  auto row = [&](const std::string& budget) {
    const auto at = answer.find("| " + budget);
    EXPECT_NE(at, std::string::npos) << budget << "\n" << answer;
    return at == std::string::npos ? "" : answer.substr(at, answer.find('\n', at) - at);
  };
  EXPECT_NE(row("least error, 60 Hz").find("| visual, "), std::string::npos) << answer;
  EXPECT_NE(row("least error, 1 kHz").find("| fast, "), std::string::npos) << answer;
  EXPECT_NE(row("cheapest with rel L2 <= 0.3").find("| visual, "), std::string::npos) << answer;
  EXPECT_NE(row("least error, 60 Hz").find("0.2000"), std::string::npos) << answer;
  // Nothing keeps 1 kHz once the fast one is gone, and no error bound: no cheapest row.
  const std::string without = sweep_answer({points[1], points[2]}, std::nullopt);
  EXPECT_NE(without.find("1 kHz haptic loop in real time | none"), std::string::npos) << without;
  EXPECT_EQ(without.find("| cheapest"), std::string::npos) << without;
}

// e ∝ h^p with h ∝ N^(-1/2): the error halving while the vertices quadruple is order 1; an error
// that grows is a negative order, and the report says the variant does not converge.
TEST(SweepAnswer, ObservedOrderPerVariantAndTheVariantsThatDoNotConverge) {
  auto at = [](const std::string& variant, int vertices, double error, const char* integrator) {
    SweepPoint p = point(variant, 1e-4, 1e4, error);
    p.surface_vertices = vertices;
    p.integrator = integrator;
    return p;
  };
  const auto convergence = convergence_by_variant(
      {at("good", 642, 0.2, "rk4"), at("bad", 162, 0.3, "rk4"), at("good", 162, 0.4, "rk4"),
       at("good", 162, 0.4, "implicit_euler"), at("bad", 2562, 0.9, "rk4")});
  ASSERT_EQ(convergence.size(), 2u);
  EXPECT_EQ(convergence[0].variant, "good");
  ASSERT_EQ(convergence[0].error_at_vertices.size(), 2u);  // one entry per resolution
  EXPECT_EQ(convergence[0].error_at_vertices[0].first, 162);
  EXPECT_NEAR(*convergence[0].observed_order, 2 * std::log(2.0) / std::log(642.0 / 162), 1e-12);
  EXPECT_LT(*convergence[1].observed_order, 0);
  const std::string section = convergence_section(convergence);
  EXPECT_NE(section.find("**Not converging: bad**"), std::string::npos) << section;
}

// A configuration the reference does not resolve (its error within 3x of the FEM's own) is named
// only where no resolved one meets the budget, and then its row says so in words.
TEST(SweepAnswer, AResolvedConfigurationIsPreferredAndAnUnresolvedOneIsSaidToBe) {
  SweepPoint unresolved = point("coarse", 1e-4, 50000, 0.35);
  unresolved.not_resolved_by_reference = {Metric::rel_l2_error};
  const SweepPoint resolved = point("fine", 1e-4, 50000, 0.50);
  const std::string answer = sweep_answer({unresolved, resolved}, std::nullopt);
  const auto at = answer.find("| least error, 1 kHz");
  ASSERT_NE(at, std::string::npos) << answer;
  const std::string row = answer.substr(at, answer.find('\n', at) - at);
  EXPECT_NE(row.find("| fine, "), std::string::npos) << row;
  EXPECT_EQ(row.find("not resolved"), std::string::npos) << row;
  const std::string alone = sweep_answer({unresolved}, std::nullopt);
  const auto only = alone.find("| least error, 1 kHz");
  ASSERT_NE(only, std::string::npos) << alone;
  const std::string named = alone.substr(only, alone.find('\n', only) - only);
  EXPECT_NE(named.find("| coarse, "), std::string::npos) << named;
  EXPECT_NE(named.find("**not resolved by this reference**"), std::string::npos) << named;
  // ‡ on the metric the reference does not resolve, not on the other.
  EXPECT_NE(named.find("0.3500 ‡"), std::string::npos) << named;
  EXPECT_EQ(named.find("0.1750 ‡"), std::string::npos) << named;
}

}  // namespace
}  // namespace msfem::compare
