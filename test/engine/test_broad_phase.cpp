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

Pairs sorted(Pairs pairs) {
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

std::vector<std::size_t> sorted(std::vector<std::size_t> keys) {
  std::sort(keys.begin(), keys.end());
  return keys;
}

// The keys of the boxes that overlap `box`, by testing every one.
std::vector<std::size_t> allOverlapping(const std::vector<Box>& boxes, const Box& box) {
  std::vector<std::size_t> keys;
  for (std::size_t key = 0; key < boxes.size(); ++key)
    if (overlap(boxes[key], box)) keys.push_back(key);
  return keys;
}

// The pairs of boxes that overlap, by testing every pair.
Pairs allPairs(const std::vector<Box>& boxes) {
  Pairs pairs;
  for (std::size_t a = 0; a < boxes.size(); ++a)
    for (std::size_t b = a + 1; b < boxes.size(); ++b)
      if (overlap(boxes[a], boxes[b])) pairs.emplace_back(a, b);
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
    BoxGrid grid;
    grid.reset(boxes);
    ASSERT_EQ(sorted(grid.pairs()), allPairs(boxes)) << "trial " << trial;
  }
  BoxGrid none;
  none.reset({});
  EXPECT_TRUE(none.pairs().empty());
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
  // A ball's own box, made directly, is that square to the bit.
  const Box own = ballBox(Vec2(2.0, 3.0), r);
  EXPECT_EQ(own.min, still.min);
  EXPECT_EQ(own.max, still.max);
}

TEST(BroadPhase, SegmentBoxHoldsItsCapsule) {
  Segment thick = segment(Vec2(3.0, 1.0), Vec2(-1.0, 2.0));
  thick.thickness = 0.4;
  const Box box = segmentBox(thick, 1.0);
  const double grow = 0.2 + kBoxMargin;
  EXPECT_EQ(box.min, Vec2(-1.0 - grow, 1.0 - grow));
  EXPECT_EQ(box.max, Vec2(3.0 + grow, 2.0 + grow));
}

TEST(BroadPhase, GridFindsExactlyTheBoxesAndPairsTestingAllFindsAsBoxesMove) {
  // Small boxes, long thin ones (walls), one over the whole field, moved about and out of the
  // bounds the grid was laid out for, then asked about with boxes of every size.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> at(0.0, 30.0), size(0.0, 1.5), far(-100.0, 130.0);
  std::vector<Box> boxes;
  for (int i = 0; i < 400; ++i) {
    const Vec2 min(at(rng), at(rng));
    boxes.push_back({min, min + Vec2(size(rng), size(rng))});
  }
  boxes.push_back({Vec2(0.0, 0.0), Vec2(30.0, 0.1)});
  boxes.push_back({Vec2(0.0, 0.0), Vec2(0.1, 30.0)});
  boxes.push_back({Vec2(-1.0, -1.0), Vec2(31.0, 31.0)});
  BoxGrid grid;
  grid.reset(boxes);
  for (int round = 0; round < 200; ++round) {
    const std::size_t key = rng() % boxes.size();
    const Vec2 min = round % 5 == 0 ? Vec2(far(rng), far(rng)) : Vec2(at(rng), at(rng));
    boxes[key] = {min, min + Vec2(size(rng), 10.0 * size(rng))};
    // Moved alone, or with the others given again (unchanged but that one, or two); every 50
    // rounds, half of them changed, then one box more or less, laid out anew.
    if (round % 50 == 25) {
      for (std::size_t k = 0; k < boxes.size(); k += 2) boxes[k].max += Vec2(0.5, 0.0);
      grid.update(boxes);
    } else if (round % 50 == 49) {
      if (round % 100 == 49) boxes.push_back({min, min + Vec2(1.0, 1.0)});
      else boxes.pop_back();
      grid.update(boxes);
    } else if (round % 2 == 0) {
      // (Now and then another box grown at its top only: its max alone changed.)
      if (round % 4 == 0) boxes[(key + 1) % boxes.size()].max += Vec2(0.0, 0.25);
      grid.update(boxes);
    } else {
      grid.move(key, boxes[key]);
    }
    for (int query = 0; query < 5; ++query) {
      const Vec2 corner(far(rng), far(rng));
      const Box box = query == 0 ? boxes[rng() % boxes.size()]
                                 : Box{corner, corner + Vec2(size(rng), size(rng)) * query * query};
      ASSERT_EQ(sorted(grid.overlapping(box)), allOverlapping(boxes, box)) << "round " << round;
    }
    const Pairs all = allPairs(boxes);
    ASSERT_EQ(sorted(grid.pairs()), all) << "round " << round;
    // The pairs of a few keys, of many, and of none: those of every pair that hold one.
    for (const std::size_t asked : {std::size_t{0}, std::size_t{3}, boxes.size() / 2}) {
      std::vector<std::size_t> keys;
      for (std::size_t k = 0; k < asked; ++k) keys.push_back((7 * k + round) % boxes.size());
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
      Pairs expected;
      for (const auto& pair : all)
        if (std::binary_search(keys.begin(), keys.end(), pair.first) ||
            std::binary_search(keys.begin(), keys.end(), pair.second))
          expected.push_back(pair);
      Pairs found;
      grid.pairsOf(keys, found);
      ASSERT_EQ(sorted(found), sorted(expected)) << "round " << round << ", " << asked << " keys";
    }
  }
  grid.reset({});
  EXPECT_TRUE(grid.overlapping(boxes[0]).empty());
  const BoxGrid never_reset;  // a world with no segments asks its segments' grid
  EXPECT_TRUE(never_reset.overlapping(boxes[0]).empty());
}

TEST(BroadPhase, GridOfOneCellFindsTheWallsOfABoxInTheirOrderAsTestingAllDoes) {
  // A 10 m box's four walls make a grid of one cell (two median boxes wide), asked without
  // finding cells: the walls a query meets come in key order, as the order of hits needs.
  const std::vector<Segment> walls = {segment(Vec2(0.0, 0.0), Vec2(10.0, 0.0)),
                                      segment(Vec2(10.0, 0.0), Vec2(10.0, 10.0)),
                                      segment(Vec2(10.0, 10.0), Vec2(0.0, 10.0)),
                                      segment(Vec2(0.0, 10.0), Vec2(0.0, 0.0))};
  std::vector<Box> boxes;
  for (const Segment& wall : walls) boxes.push_back(segmentBox(wall, 1.0));
  BoxGrid grid;
  grid.reset(boxes);
  const double r = 0.1;
  // A ball in a corner, one by a wall, one in the middle, a bullet's sweep over the box.
  EXPECT_EQ(grid.overlapping(ballBox(Vec2(0.05, 0.05), r)), (std::vector<std::size_t>{0, 3}));
  EXPECT_EQ(grid.overlapping(ballBox(Vec2(5.0, 9.95), r)), (std::vector<std::size_t>{2}));
  EXPECT_TRUE(grid.overlapping(ballBox(Vec2(5.0, 5.0), r)).empty());
  const Box sweep = sweptBox(Motion{Vec2(5.0, 5.0), Vec2(400.0, 400.0)}, r, 1.0 / 60.0);
  EXPECT_EQ(grid.overlapping(sweep), allOverlapping(boxes, sweep));
  EXPECT_EQ(grid.overlapping(sweep), (std::vector<std::size_t>{1, 2}));
  // A wall moved within the cell, and one moved out of the bounds it was laid out for.
  boxes[0] = segmentBox(segment(Vec2(0.0, 5.0), Vec2(10.0, 5.0)), 1.0);
  grid.move(0, boxes[0]);
  boxes[2] = segmentBox(segment(Vec2(30.0, 30.0), Vec2(40.0, 30.0)), 1.0);
  grid.move(2, boxes[2]);
  for (const Box& box : {ballBox(Vec2(5.0, 5.05), r), ballBox(Vec2(35.0, 30.0), r), sweep})
    EXPECT_EQ(grid.overlapping(box), allOverlapping(boxes, box));
}
