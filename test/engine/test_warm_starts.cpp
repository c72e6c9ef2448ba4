#include <gtest/gtest.h>

#include "ball_physics_sim/engine/warm_starts.h"

using namespace ball_physics_sim::engine;

namespace {

using Impulses = WarmStarts::Impulses;
constexpr auto ball = WarmStarts::ballName;
constexpr auto segment = WarmStarts::segmentName;

}  // namespace

TEST(WarmStarts, ABallAndASegmentOfTheSameIdHaveNamesApart) {
  EXPECT_NE(ball(3), segment(3));
  EXPECT_NE(ball(4), segment(3));
  EXPECT_NE(ball(3), ball(4));
}

TEST(WarmStarts, APairStartsFromItsLatestSettleAndOneNeverSettledFromNone) {
  WarmStarts starts;
  EXPECT_EQ(starts.latest({ball(0), ball(1)}), (Impulses{0.0, 0.0}));
  starts.record({ball(0), ball(1)}, {2.0, -0.5});
  EXPECT_EQ(starts.latest({ball(0), ball(1)}), (Impulses{2.0, -0.5}));
  // (A pair is ordered: a ball, then what it touches.)
  EXPECT_EQ(starts.latest({ball(1), ball(0)}), (Impulses{0.0, 0.0}));
  EXPECT_EQ(starts.latest({ball(0), segment(1)}), (Impulses{0.0, 0.0}));
  starts.record({ball(0), ball(1)}, {3.0, 0.25});
  EXPECT_EQ(starts.latest({ball(0), ball(1)}), (Impulses{3.0, 0.25}));
  starts.clear();
  EXPECT_EQ(starts.latest({ball(0), ball(1)}), (Impulses{0.0, 0.0}));
}

TEST(WarmStarts, ABodyForgottenTakesItsPairsAlongAndLeavesTheOthers) {
  WarmStarts starts;
  starts.record({ball(0), segment(1)}, {1.0, 0.0});
  starts.record({ball(1), ball(0)}, {2.0, 0.0});
  starts.record({ball(1), segment(1)}, {3.0, 0.5});
  starts.record({ball(2), ball(1)}, {4.0, 0.0});
  starts.forget(ball(1));
  EXPECT_EQ(starts.latest({ball(1), ball(0)}), (Impulses{0.0, 0.0}));
  EXPECT_EQ(starts.latest({ball(1), segment(1)}), (Impulses{0.0, 0.0}));
  EXPECT_EQ(starts.latest({ball(2), ball(1)}), (Impulses{0.0, 0.0}));
  EXPECT_EQ(starts.latest({ball(0), segment(1)}), (Impulses{1.0, 0.0}));
  starts.forget(segment(1));
  EXPECT_EQ(starts.latest({ball(0), segment(1)}), (Impulses{0.0, 0.0}));
}

TEST(WarmStarts, APairOfTwoBallsIsTheSameWhicheverComesFirstAndABallComesBeforeASegment) {
  EXPECT_EQ(WarmStarts::pairOf(ball(3), ball(1)), WarmStarts::pairOf(ball(1), ball(3)));
  EXPECT_EQ(WarmStarts::pairOf(ball(3), ball(1)), (WarmStarts::Pair{ball(1), ball(3)}));
  EXPECT_EQ(WarmStarts::pairOf(ball(3), segment(1)), (WarmStarts::Pair{ball(3), segment(1)}));
  EXPECT_TRUE(WarmStarts::isSegment(segment(0)));
  EXPECT_FALSE(WarmStarts::isSegment(ball(0)));
}

TEST(WarmStarts, PairsUnrecordedForTheirStepsAreForgottenButThoseOfRestingBodies) {
  // Balls 0 and 3 rest, 1 and 2 do not; a segment is still.
  WarmStarts starts;
  starts.record({ball(0), segment(1)}, {1.0, 0.0});  // step 0
  starts.record({ball(0), ball(3)}, {1.5, 0.0});
  starts.record({ball(0), ball(1)}, {2.0, 0.5});
  starts.record({ball(1), ball(2)}, {2.5, 0.0});
  starts.record({ball(1), segment(1)}, {0.5, 0.0});
  for (std::uint64_t step = 1; step < WarmStarts::kStepsKept; ++step) {
    EXPECT_FALSE(starts.startStep()) << step;
    if (step == 1) starts.record({ball(1), ball(2)}, {3.0, 0.0});  // again: its count restarts
  }
  ASSERT_TRUE(starts.startStep());  // step kStepsKept
  starts.forgetStale({ball(1), ball(2)});
  EXPECT_EQ(starts.latest({ball(0), segment(1)}), (Impulses{1.0, 0.0}));
  EXPECT_EQ(starts.latest({ball(0), ball(3)}), (Impulses{1.5, 0.0}));
  EXPECT_EQ(starts.latest({ball(0), ball(1)}), (Impulses{0.0, 0.0}));
  EXPECT_EQ(starts.latest({ball(1), ball(2)}), (Impulses{3.0, 0.0}));
  EXPECT_EQ(starts.latest({ball(1), segment(1)}), (Impulses{0.0, 0.0}));  // (1 is awake)
}
