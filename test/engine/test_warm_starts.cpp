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
  starts.prefetch({ball(0), ball(1)});  // (nothing held: nothing to fetch)
  starts.forgetStale({});
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

TEST(WarmStarts, ThousandsOfPairsAreKeptAsTheTableGrowsAndAForgottenBodyTakesOnlyItsOwn) {
  // The table grows and is laid out anew many times over; a body forgotten, or pairs gone stale,
  // lay it out anew with the others as they were.
  WarmStarts starts;
  const std::uint64_t n = 5000;
  for (std::uint64_t i = 0; i < n; ++i) {
    starts.record({ball(i), ball(i + 1)}, {1.0 * i, -1.0 * i});
    starts.record({ball(i), segment(i % 7)}, {0.5 * i, 0.0});
  }
  starts.forget(ball(2500));
  for (std::uint64_t i = 0; i < n; ++i) {
    const Impulses none{0.0, 0.0};
    const bool gone = i == 2499 || i == 2500;
    EXPECT_EQ(starts.latest({ball(i), ball(i + 1)}), (gone ? none : Impulses{1.0 * i, -1.0 * i}))
        << i;
    EXPECT_EQ(starts.latest({ball(i), segment(i % 7)}), (i == 2500 ? none : Impulses{0.5 * i, 0.0}))
        << i;
  }
  // Stale, every pair of a ball awake goes (the even ones), but those recorded again lately;
  // those of resting balls stay.
  for (std::uint64_t step = 0; step < 2 * WarmStarts::kStepsKept; ++step) starts.startStep();
  for (std::uint64_t i = 0; i < n; i += 100) starts.record({ball(i), ball(i + 1)}, {7.0, 0.0});
  std::vector<std::uint64_t> awake;
  for (std::uint64_t i = 0; i <= n; i += 2) awake.push_back(ball(i));
  starts.forgetStale(awake);
  for (std::uint64_t i = 0; i < n; ++i) {
    EXPECT_EQ(starts.latest({ball(i), ball(i + 1)}),
              (i % 100 == 0 ? Impulses{7.0, 0.0} : Impulses{0.0, 0.0}))
        << i;
    const Impulses kept = i % 2 == 1 ? Impulses{0.5 * i, 0.0} : Impulses{0.0, 0.0};
    EXPECT_EQ(starts.latest({ball(i), segment(i % 7)}), kept) << i;
  }
}
