// How independent work is dealt out to MPI ranks (ranks::deal): the split's makespan against the
// best split, on the shapes the pipeline deals (a sweep resolution's variants, the brain's
// variants x tools).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "msfem/compare/pipeline/ranks.hpp"

namespace msfem::compare {
namespace {

// The most work any rank is given.
double makespan(const std::vector<double>& cost, const std::vector<int>& owner, int ranks) {
  std::vector<double> work(static_cast<std::size_t>(ranks), 0.0);
  for (std::size_t j = 0; j < cost.size(); ++j) {
    EXPECT_GE(owner[j], 0);
    EXPECT_LT(owner[j], ranks);
    work[static_cast<std::size_t>(owner[j])] += cost[j];
  }
  return *std::max_element(work.begin(), work.end());
}

// The best makespan over every assignment (small lists only).
double best_makespan(const std::vector<double>& cost, int ranks) {
  double best = std::accumulate(cost.begin(), cost.end(), 0.0);
  std::vector<int> owner(cost.size(), 0);
  for (;;) {
    best = std::min(best, makespan(cost, owner, ranks));
    std::size_t j = 0;
    while (j < owner.size() && ++owner[j] == ranks)
      owner[j++] = 0;
    if (j == owner.size()) return best;
  }
}

TEST(Dealing, ASweepResolutionsThreeVariantsGoOneCostlyAgainstTwoCheap) {
  // three_tier (3 n nodes), single_layer (n), skeleton (1.1 n) at one load, cost nodes^1.5: the
  // round-robin the pipeline had put three_tier and skeleton on one rank (6.35 against 1).
  const std::vector<double> cost = {std::pow(3.0, 1.5), 1.0, std::pow(1.1, 1.5)};
  const std::vector<int> owner = ranks::deal(cost, 2);
  EXPECT_NE(owner[0], owner[1]);
  EXPECT_EQ(owner[1], owner[2]);
  EXPECT_DOUBLE_EQ(makespan(cost, owner, 2), best_makespan(cost, 2));
}

TEST(Dealing, WithinFourThirdsOfTheBestSplitOnMixedLists) {
  const std::vector<std::vector<double>> lists = {
      {5.2, 5.2, 5.2, 5.2, 1, 1, 1, 1, 1.15, 1.15, 1.15, 1.15},  // brain: 3 variants x 4 tools
      {6, 6, 1, 1, 6, 6, 1, 1},  // sweep items: implicit and RK4 at 6, explicit at 1
      {3, 3, 2, 2, 2},           // the classic case where the greedy split is 7 against 6
      {7, 1, 1, 1, 1, 1, 1, 1}};
  for (const auto& cost : lists)
    for (const int ranks : {2, 3}) {
      const double dealt = makespan(cost, ranks::deal(cost, ranks), ranks);
      EXPECT_LE(dealt, 4.0 / 3.0 * best_makespan(cost, ranks) + 1e-12) << cost.size() << " items";
      EXPECT_GE(dealt, best_makespan(cost, ranks) - 1e-12);
    }
}

TEST(Dealing, EveryRankDealsAlikeAndOneRankTakesAll) {
  const std::vector<double> cost = {2, 2, 2, 2, 1, 1};  // ties broken the same way every time
  EXPECT_EQ(ranks::deal(cost, 2), ranks::deal(cost, 2));
  EXPECT_EQ(ranks::deal(cost, 2), (std::vector<int>{0, 1, 0, 1, 0, 1}));
  for (const int owner : ranks::deal(cost, 1))
    EXPECT_EQ(owner, 0);
  EXPECT_TRUE(ranks::deal({}, 2).empty());
}

}  // namespace
}  // namespace msfem::compare
