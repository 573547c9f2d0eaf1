#include <gtest/gtest.h>

#include <cmath>

#include "msfem/compare/pipeline/metrics.hpp"

namespace msfem::compare {
namespace {

std::vector<int> all_rows(Eigen::Index n) {
  std::vector<int> r(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i)
    r[i] = static_cast<int>(i);
  return r;
}

TEST(Metrics, IdenticalFieldsHaveZeroError) {
  const Eigen::MatrixX3d v = Eigen::MatrixX3d::Random(50, 3);
  const ErrorMetrics m = displacement_error(v, v, all_rows(50));
  EXPECT_EQ(m.rel_l2_error, 0.0);
  EXPECT_EQ(m.rms_error_m, 0.0);
  EXPECT_EQ(m.max_error_m, 0.0);
  EXPECT_EQ(m.mean_error_over_max_disp, 0.0);
  EXPECT_EQ(m.vertices, 50);
}

TEST(Metrics, HandComputedExample) {
  Eigen::MatrixX3d v(3, 3), u(3, 3);
  v << 3, 0, 0, 0, 4, 0, 0, 0, 0;  // |v| = 3, 4, 0
  u << 3, 0, 0, 0, 4, 3, 0, 0, 4;  // errors 0, 3, 4
  const ErrorMetrics m = displacement_error(u, v, {0, 1, 2});
  EXPECT_DOUBLE_EQ(m.rel_l2_error, 5.0 / 5.0);             // sqrt(9+16)/sqrt(9+16)
  EXPECT_DOUBLE_EQ(m.rms_error_m, std::sqrt(25.0 / 3.0));  // sqrt((0+9+16)/3)
  EXPECT_DOUBLE_EQ(m.max_error_m, 4.0);
  EXPECT_DOUBLE_EQ(m.mean_error_over_max_disp, (7.0 / 3.0) / 4.0);
  // Only the rows asked for count: vertex 2 (a prescribed one, say) left out.
  const ErrorMetrics free = displacement_error(u, v, {0, 1});
  EXPECT_DOUBLE_EQ(free.rel_l2_error, 3.0 / 5.0);
  EXPECT_DOUBLE_EQ(free.max_error_m, 3.0);
}

TEST(Metrics, UniformScalingGivesItsFactorAsRelativeError) {
  const Eigen::MatrixX3d v = Eigen::MatrixX3d::Random(200, 3);
  const ErrorMetrics m = displacement_error(0.8 * v, v, all_rows(200));
  EXPECT_NEAR(m.rel_l2_error, 0.2, 1e-14);
}

TEST(Metrics, ZonesSplitByDistanceFromTheTool) {
  Eigen::MatrixX3d rest(4, 3), v(4, 3), u(4, 3);
  rest << 0, 0, 1, 0, 0, 0.99, 0, 0, -1, 1, 0, 0;
  v << 0, 0, -1, 0, 0, -0.5, 0, 0, -0.01, 0, 0, -0.1;
  u = v;
  u(3, 2) = -0.2;  // only the far vertex is wrong
  const ZonedErrorMetrics z =
      zoned_displacement_error(u, v, rest, {0, 1, 2, 3}, Eigen::Vector3d(0, 0, 1), 0.05);
  EXPECT_EQ(z.contact_zone.vertices, 2);
  EXPECT_EQ(z.far_field.vertices, 2);
  EXPECT_EQ(z.contact_zone.max_error_m, 0.0);
  EXPECT_NEAR(z.far_field.max_error_m, 0.1, 1e-15);
  EXPECT_NEAR(z.all.max_error_m, 0.1, 1e-15);
}

TEST(Metrics, RefusesWhatWouldBeMeaningless) {
  const Eigen::MatrixX3d zero = Eigen::MatrixX3d::Zero(3, 3);
  EXPECT_THROW(displacement_error(zero, zero, {0, 1, 2}), std::invalid_argument);
  Eigen::MatrixX3d nan = Eigen::MatrixX3d::Ones(3, 3);
  nan(1, 1) = std::nan("");
  EXPECT_THROW(displacement_error(nan, Eigen::MatrixX3d::Ones(3, 3), {0, 1, 2}),
               std::invalid_argument);
  EXPECT_THROW(displacement_error(zero, Eigen::MatrixX3d::Ones(4, 3), {0}), std::invalid_argument);
  EXPECT_THROW(reaction_force_rel_error(Eigen::Vector3d::Ones(), Eigen::Vector3d::Zero()),
               std::invalid_argument);
  EXPECT_DOUBLE_EQ(reaction_force_rel_error(Eigen::Vector3d(0, 0, 1.5), Eigen::Vector3d(0, 0, 2)),
                   0.25);
}

}  // namespace
}  // namespace msfem::compare
