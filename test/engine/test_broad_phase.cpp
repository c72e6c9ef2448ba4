#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/broad_phase.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using ball_physics_sim::engine::test::segment;

namespace {

using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

bool overlap(const Box& a, const Box& b) {
  return a.min.x() <= b.max.x() && b.min.x() <= a.max.x() && a.min.y() <= b.max.y() &&
         b.min.y() <= a.max.y();
}

Pairs sorted(Pairs pairs) {
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace

TEST(BroadPhase, FindsExactlyThePairsThatTestingAllPairsFinds) {
  // Boxes of mixed sizes, some sharing edges exactly (touching counts), some identical.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(0.0, 20.0), size(0.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Box> boxes;
    for (int i = 0; i < 300; ++i) {
      const Vec2 min(at(rng), at(rng));
      boxes.push_back({min, min + Vec2(size(rng), size(rng))});
    }
    boxes.push_back({boxes[0].max, boxes[0].max + Vec2(1.0, 1.0)});  // corner to corner
    boxes.push_back(boxes[1]);
    Pairs all;
    for (std::size_t a = 0; a < boxes.size(); ++a)
      for (std::size_t b = a + 1; b < boxes.size(); ++b)
        if (overlap(boxes[a], boxes[b])) all.emplace_back(a, b);
    ASSERT_EQ(sorted(overlappingPairs(boxes)), all) << "trial " << trial;
  }
  EXPECT_TRUE(overlappingPairs({}).empty());
}

TEST(BroadPhase, SweptBoxHoldsTheWholeArcOfAThrownBall) {
  // From the origin at (1, 4) m/s under g = 10: the top, y = 0.8, comes at t = 0.4, and after
  // 1 s the ball is at (1, -1).
  const Motion thrown{Vec2::Zero(), Vec2(1.0, 4.0), Vec2(0.0, -10.0)};
  const double r = 0.5, grow = r + kBoxMargin;
  const Box box = sweptBox(thrown, r, 1.0);
  EXPECT_NEAR(box.min.x(), -grow, 1e-15);
  EXPECT_NEAR(box.max.x(), 1.0 + grow, 1e-15);
  EXPECT_NEAR(box.min.y(), -1.0 - grow, 1e-15);
  EXPECT_NEAR(box.max.y(), 0.8 + grow, 1e-15);
  // Before the top, the box ends where the ball is then.
  EXPECT_NEAR(sweptBox(thrown, r, 0.2).max.y(), 0.6 + grow, 1e-15);
  // At rest, or over no time: the ball's own square.
  const Box still = sweptBox(Motion{Vec2(2.0, 3.0)}, r, 5.0);
  EXPECT_EQ(still.min, Vec2(2.0 - grow, 3.0 - grow));
  EXPECT_EQ(still.max, Vec2(2.0 + grow, 3.0 + grow));
}

TEST(BroadPhase, SegmentBoxHoldsItsCapsule) {
  Segment thick = segment(Vec2(3.0, 1.0), Vec2(-1.0, 2.0));
  thick.thickness = 0.4;
  const Box box = segmentBox(thick, 1.0);
  const double grow = 0.2 + kBoxMargin;
  EXPECT_EQ(box.min, Vec2(-1.0 - grow, 1.0 - grow));
  EXPECT_EQ(box.max, Vec2(3.0 + grow, 2.0 + grow));
}
