#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/settle.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using namespace ball_physics_sim::engine::test;

namespace {

constexpr double kH = kFrameStep;

// A contact of ball 0 with a floor below it, whose gap may close at `bias` over the settle.
RestingContact floorContact(double bias = 0.0) { return {0, std::nullopt, Vec2(0, 1), bias, 0}; }

// The rates at which the contacts' gaps may close at most: their biases, nothing past touching.
std::vector<double> biasesOf(const std::vector<RestingContact>& contacts) {
  std::vector<double> biases;
  for (const RestingContact& c : contacts) biases.push_back(c.bias);
  return biases;
}

}  // namespace

TEST(Settle, ABallOnTheFloorIsHeldUpWithTheImpulseOfItsWeightOverTheStretch) {
  std::vector<std::array<double, 2>> impulses;
  const Settled s = settleTogether({ball({0, 0.5}, {0, -kG * kH}, 0.5, 2.0)}, {0.5},
                                   {floorContact()}, {0.3}, {0.0}, &impulses);
  EXPECT_NEAR(s.velocities[0].norm(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(s.spins[0], 0.0);
  EXPECT_NEAR(impulses[0][0], 2.0 * kG * kH, 1e-14);
  EXPECT_DOUBLE_EQ(impulses[0][1], 0.0);
}

TEST(Settle, AFallingBallClosesItsGapToTheFloorNoMore) {
  // 0.1 m above the floor at 3 m/s: over the stretch it may close 0.1 m, at 0.1 / h m/s.
  const double bias = 0.1 / kH;
  const Settled s =
      settleTogether({ball({0, 0.6}, {0, -3.0})}, {1.0}, {floorContact(bias)}, {0.0}, {bias});
  EXPECT_NEAR(s.velocities[0].y(), -std::min(3.0, bias), 1e-12);
  const Settled slow =
      settleTogether({ball({0, 0.6}, {0, -1.0})}, {1.0}, {floorContact(bias)}, {0.0}, {bias});
  EXPECT_DOUBLE_EQ(slow.velocities[0].y(), -1.0);  // its gap closes less: untouched
}

TEST(Settle, ASlidingBallIsSlowedAndSpunByFrictionAtTheConesEdge) {
  // Pressed by its weight over h, friction takes mu m g h of momentum from a ball sliding at
  // 1 m/s, and turns it by mu g h / (k r) (a solid ball, k = 2/5).
  const double mu = 0.3, r = 0.5;
  const Settled s =
      settleTogether({ball({0, r}, {1.0, -kG * kH}, r)}, {1.0}, {floorContact()}, {mu}, {0.0});
  EXPECT_NEAR(s.velocities[0].x(), 1.0 - mu * kG * kH, 1e-14);
  EXPECT_NEAR(s.velocities[0].y(), 0.0, 1e-15);
  EXPECT_NEAR(s.spins[0], -mu * kG * kH / (0.4 * r), 1e-13);
}

TEST(Settle, ASlowlySlidingBallIsGrippedIntoRolling) {
  // Within the cone, friction stops the slip: v (1 - k / (1 + k)) = v / (1 + k) rolling, spin
  // -v / ((1 + k) r).
  const double v = 1e-3, r = 0.5;
  const Settled s =
      settleTogether({ball({0, r}, {v, -kG * kH}, r)}, {1.0}, {floorContact()}, {0.3}, {0.0});
  EXPECT_NEAR(s.velocities[0].x(), v / 1.4, 1e-16);
  EXPECT_NEAR(s.spins[0], -v / (1.4 * r), 1e-16);
  EXPECT_NEAR(s.velocities[0].x() + r * s.spins[0], 0.0, 1e-17);  // rolling: no slip
}

TEST(Settle, TwoBallsMeetingHeadOnMoveOnTogetherWithTheirMomentum) {
  // Perfectly inelastic: (m1 v1 + m2 v2) / (m1 + m2) = (1 * 2 + 3 * -1) / 4.
  const Settled s = settleTogether({ball({0, 0}, {2, 0}), ball({1, 0}, {-1, 0}, 0.5, 3.0)},
                                   {1.0, 1.0 / 3.0}, {{0, 1, Vec2(-1, 0), 0.0, 1}}, {0.0}, {0.0});
  EXPECT_NEAR(s.velocities[0].x(), -0.25, 1e-15);
  EXPECT_NEAR(s.velocities[1].x(), -0.25, 1e-15);
}

TEST(Settle, AResolvedPileStartedFromItsImpulsesIsLeftStill) {
  // Three balls stacked on a floor: the floor holds up 3 m g h, the middle contact 2 m g h,
  // the top one m g h. Started from those impulses, the settle changes nothing.
  std::vector<Ball> balls;
  for (int i = 0; i < 3; ++i) balls.push_back(ball({0, 0.5 + i}, {0, -kG * kH}));
  const std::vector<RestingContact> contacts{
      floorContact(), {1, 0, Vec2(0, 1), 0.0, 1}, {2, 1, Vec2(0, 1), 0.0, 2}};
  std::vector<std::array<double, 2>> impulses{
      {3 * kG * kH, 0.0}, {2 * kG * kH, 0.0}, {kG * kH, 0.0}};
  const Settled s = settleTogether(balls, {1.0, 1.0, 1.0}, contacts, {0.3, 0.3, 0.3}, biasesOf(contacts),
                                   &impulses);
  for (const Vec2& v : s.velocities) EXPECT_NEAR(v.norm(), 0.0, 1e-15);
  EXPECT_NEAR(impulses[0][0], 3 * kG * kH, 1e-14);
  EXPECT_NEAR(impulses[2][0], kG * kH, 1e-14);
}

TEST(Settle, BallsThatWouldCloseAGapTooFastSlowDownByTheShareThatClosesItJustInTime) {
  // Falling at 3 m/s onto a floor whose gap may close at 1 m/s: a third of their velocities.
  // The other ball, moving off at 5 m/s, would close nothing, but slows down with them.
  const std::vector<Vec2> velocities{{0, -3}, {5, 0}};
  auto share = [](const std::vector<RestingContact>& contacts, const std::vector<Vec2>& v,
                  double rounding = 0.0) {
    return shareClosingNoGapTooFast(contacts, v, biasesOf(contacts), rounding);
  };
  EXPECT_DOUBLE_EQ(share({floorContact(1.0)}, velocities), 1.0 / 3.0);
  // Head on at 1 m/s each, their gap closing at 2 m/s where it may at 0.5: a quarter.
  const RestingContact head_on{0, 1, Vec2(-1, 0), 0.5, 1};
  EXPECT_DOUBLE_EQ(share({head_on}, {{1, 0}, {-1, 0}}), 0.25);
  // Both at once, the first falling at 3 m/s onto the floor (a third would do) and meeting the
  // second head on at 2 m/s: the smaller share holds both.
  EXPECT_DOUBLE_EQ(share({floorContact(1.0), head_on}, {{1, -3}, {-1, 0}}), 0.25);
  // Touching, with no gap to close: they stand still.
  EXPECT_DOUBLE_EQ(share({floorContact()}, velocities), 0.0);
  // Closing as fast as they may, or faster by rounding only: untouched; past rounding, slowed.
  EXPECT_DOUBLE_EQ(share({floorContact(3.0)}, velocities), 1.0);
  const double bias = 3.0 - 1e-13;
  EXPECT_DOUBLE_EQ(share({floorContact(bias)}, velocities, 1e-12), 1.0);
  EXPECT_DOUBLE_EQ(share({floorContact(bias)}, velocities), bias / 3.0);
  // Allowed past its bias (to kSettleOverlap past touching, over a 1/60 s settle): a touching
  // contact closing within that is untouched, and one closing faster slows to it.
  const double allowed = kSettleOverlap / kH;
  EXPECT_DOUBLE_EQ(
      shareClosingNoGapTooFast({floorContact()}, {{0, -0.5 * allowed}}, {allowed}, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(
      shareClosingNoGapTooFast({floorContact()}, {{0, -4.0 * allowed}}, {allowed}, 0.0), 0.25);
}
