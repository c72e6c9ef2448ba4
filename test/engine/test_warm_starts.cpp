#include <optional>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/warm_starts.h"

using namespace ball_physics_sim::engine;

namespace {

using Impulses = WarmStarts::Impulses;
using Pair = WarmStarts::Pair;

}  // namespace

TEST(WarmStarts, APairStartsFromItsLatestSettleAndOneNeverSettledFromNone) {
  WarmStarts starts;
  EXPECT_EQ(starts.latest({0, 1}), (Impulses{0.0, 0.0}));
  starts.record({0, 1}, {2.0, -0.5});
  EXPECT_EQ(starts.latest({0, 1}), (Impulses{2.0, -0.5}));
  EXPECT_EQ(starts.latest({1, 0}), (Impulses{0.0, 0.0}));  // (a pair is ordered: ball, key)
  starts.record({0, 1}, {3.0, 0.25});
  EXPECT_EQ(starts.latest({0, 1}), (Impulses{3.0, 0.25}));
  starts.clear();
  EXPECT_EQ(starts.latest({0, 1}), (Impulses{0.0, 0.0}));
}

TEST(WarmStarts, RenamingMovesEachPairsImpulsesToItsNewNameOrForgetsThem) {
  WarmStarts starts;
  starts.record({0, 5}, {1.0, 0.0});
  starts.record({2, 5}, {2.0, 0.0});
  starts.record({1, 5}, {9.0, 0.0});
  // Body 1 removed: the names past it move down one, and its own go.
  starts.rename([](const Pair& pair) -> std::optional<Pair> {
    if (pair.first == 1 || pair.second == 1) return std::nullopt;
    return Pair(pair.first - (pair.first > 1), pair.second - (pair.second > 1));
  });
  EXPECT_EQ(starts.latest({0, 4}), (Impulses{1.0, 0.0}));
  EXPECT_EQ(starts.latest({1, 4}), (Impulses{2.0, 0.0}));
  EXPECT_EQ(starts.latest({0, 5}), (Impulses{0.0, 0.0}));
  EXPECT_EQ(starts.latest({2, 5}), (Impulses{0.0, 0.0}));
}
