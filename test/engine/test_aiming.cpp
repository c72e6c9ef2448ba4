#include <cmath>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/polynomial.h"

using namespace ball_physics_sim::engine;

namespace {

const Vec2 kGravity(0.0, -9.81);

// Where a ball launched from `from` at `speed` along `angle` is after t seconds.
Vec2 flight(const Vec2& from, double speed, double angle, double t) {
  return from + speed * t * Vec2(std::cos(angle), std::sin(angle)) + 0.5 * t * t * kGravity;
}

}  // namespace

TEST(AimStraight, PointsAtTheTargetAndTakesDistanceOverSpeed) {
  const auto aim = aimStraight({1.0, 1.0}, {4.0, 5.0}, 10.0);
  ASSERT_TRUE(aim);
  EXPECT_DOUBLE_EQ(aim->angle, std::atan2(4.0, 3.0));
  EXPECT_DOUBLE_EQ(aim->time_of_flight, 0.5);
}

TEST(AimStraight, TargetAtTheLauncherHasNoDirection) {
  EXPECT_FALSE(aimStraight({1.0, 1.0}, {1.0, 1.0}, 10.0));
}

TEST(AimBallistic, LowArcOnLevelGroundIsHalfTheArcsineOfGxOverVSquared) {
  const double v = 10.0, x = 6.0;
  const auto aim = aimBallistic({0.0, 0.0}, {x, 0.0}, v, kGravity, false);
  ASSERT_TRUE(aim);
  EXPECT_NEAR(aim->angle, 0.5 * std::asin(9.81 * x / (v * v)), 1e-14);
  EXPECT_NEAR(aim->time_of_flight, x / (v * std::cos(aim->angle)), 1e-14);
}

TEST(AimBallistic, BothArcsPassThroughTheTargetAtTheirTimeOfFlight) {
  const Vec2 from(1.0, 2.0), target(7.0, 4.0);
  for (bool high : {false, true}) {
    const auto aim = aimBallistic(from, target, 12.0, kGravity, high);
    ASSERT_TRUE(aim);
    EXPECT_NEAR((flight(from, 12.0, aim->angle, aim->time_of_flight) - target).norm(), 0.0, 1e-12);
  }
}

TEST(AimBallistic, HighArcTakesLonger) {
  const auto low = aimBallistic({0.0, 0.0}, {5.0, 1.0}, 10.0, kGravity, false);
  const auto high = aimBallistic({0.0, 0.0}, {5.0, 1.0}, 10.0, kGravity, true);
  ASSERT_TRUE(low && high);
  EXPECT_GT(high->angle, low->angle);
  EXPECT_GT(high->time_of_flight, low->time_of_flight);
}

TEST(AimBallistic, TargetBeyondReachHasNoSolutionAndTheMinimumSpeedJustReachesIt) {
  const Vec2 target(30.0, 5.0);
  EXPECT_FALSE(aimBallistic({0.0, 0.0}, target, 10.0, kGravity, false));
  const double v_min = minimumBallisticSpeed({0.0, 0.0}, target, kGravity);
  EXPECT_NEAR(v_min, std::sqrt(9.81 * (5.0 + std::hypot(30.0, 5.0))), 1e-12);
  const auto aim = aimBallistic({0.0, 0.0}, target, v_min * (1.0 + 1e-12), kGravity, false);
  ASSERT_TRUE(aim);
  EXPECT_NEAR((flight({0.0, 0.0}, v_min, aim->angle, aim->time_of_flight) - target).norm(), 0.0,
              1e-6);
}

TEST(AimBallistic, TargetStraightAboveIsReachedGoingUp) {
  // v = 10, h = 3: 3 = 10 t - 4.905 t^2, first at t = (10 - sqrt(100 - 58.86)) / 9.81.
  const auto aim = aimBallistic({0.0, 0.0}, {0.0, 3.0}, 10.0, kGravity, false);
  ASSERT_TRUE(aim);
  EXPECT_NEAR(aim->angle, M_PI / 2, 1e-12);
  EXPECT_NEAR(aim->time_of_flight, (10.0 - std::sqrt(100.0 - 2 * 9.81 * 3.0)) / 9.81, 1e-12);
}

TEST(AimBallistic, WithoutGravityItAimsStraight) {
  const auto aim = aimBallistic({0.0, 0.0}, {3.0, 4.0}, 5.0, Vec2::Zero(), true);
  ASSERT_TRUE(aim);
  EXPECT_DOUBLE_EQ(aim->angle, std::atan2(4.0, 3.0));
  EXPECT_DOUBLE_EQ(aim->time_of_flight, 1.0);
}

TEST(NormalizedAngle, WrapsIntoMinusPiToPi) {
  const double pi = std::acos(-1.0);
  EXPECT_NEAR(normalizedAngle(0.3 + 2.0 * pi), 0.3, 1e-15);
  EXPECT_NEAR(normalizedAngle(-0.3 - 4.0 * pi), -0.3, 1e-14);
  EXPECT_NEAR(normalizedAngle(1.5 * pi), -0.5 * pi, 1e-15);
  EXPECT_NEAR(normalizedAngle(pi), pi, 1e-15);
}

TEST(LaunchVelocityFor, ReachesTheTargetAtTheGivenTime) {
  // 10 m away on level ground in 2 s: 5 m/s across, and up g t / 2 to come down there.
  const Vec2 gravity(0.0, -9.81);
  EXPECT_NEAR((launchVelocityFor(Vec2(1.0, 2.0), Vec2(11.0, 2.0), 2.0, gravity) - Vec2(5.0, 9.81))
                  .norm(),
              0.0, 1e-15);
  // Any time works, the parabola changes: a shorter flight is faster and flatter.
  const Vec2 from(-3.0, 1.0), target(4.0, 6.0);
  for (const double t : {0.25, 1.0, 3.0}) {
    const Vec2 v = launchVelocityFor(from, target, t, gravity);
    EXPECT_NEAR((from + v * t + 0.5 * gravity * t * t - target).norm(), 0.0, 1e-12) << t;
  }
  EXPECT_EQ(launchVelocityFor(from, target, 0.5, Vec2::Zero()), (target - from) / 0.5);
}

TEST(AimLeading, WithoutGravityItSolvesTheInterceptTriangle) {
  // Target 10 m ahead crossing at 3 m/s, shot at 5 m/s: (5 t)^2 = 10^2 + (3 t)^2, t = 2.5 s,
  // met at (10, 7.5).
  const Motion target{Vec2(10.0, 0.0), Vec2(0.0, 3.0), Vec2::Zero()};
  const auto aim = aimLeading(Vec2::Zero(), 5.0, target, Vec2::Zero());
  ASSERT_TRUE(aim);
  EXPECT_NEAR(aim->time_of_flight, 2.5, 1e-12);
  EXPECT_NEAR(aim->angle, std::atan2(7.5, 10.0), 1e-12);
}

TEST(AimLeading, FallingTargetIsHitAsIfNeitherFell) {
  // Both fall alike, so the intercept is the one without gravity; only the meeting point drops.
  const Motion target{Vec2(10.0, 5.0), Vec2(0.0, 3.0), kGravity};
  const auto aim = aimLeading(Vec2(0.0, 5.0), 5.0, target, kGravity);
  ASSERT_TRUE(aim);
  EXPECT_NEAR(aim->time_of_flight, 2.5, 1e-12);
  const double t = aim->time_of_flight;
  EXPECT_NEAR((flight(Vec2(0.0, 5.0), 5.0, aim->angle, t) - target.positionAt(t)).norm(), 0.0,
              1e-9);
}

TEST(AimLeading, RollingTargetUnderGravityIsMetOnTheQuartic) {
  // The target rolls along the floor (no vertical acceleration), the shot arcs: the meeting
  // time is a root of a quartic. Both centres must coincide then.
  const Motion target{Vec2(8.0, 0.3), Vec2(-1.5, 0.0), Vec2::Zero()};
  const Vec2 from(-4.0, 1.0);
  const auto aim = aimLeading(from, 12.0, target, kGravity);
  ASSERT_TRUE(aim);
  const double t = aim->time_of_flight;
  EXPECT_GT(t, 0.0);
  EXPECT_NEAR((flight(from, 12.0, aim->angle, t) - target.positionAt(t)).norm(), 0.0, 1e-9);
  // It is the earliest: a moment before, no direction at this speed reaches the target.
  const Vec2 d = target.positionAt(0.99 * t) - from - 0.5 * 0.99 * t * 0.99 * t * kGravity;
  EXPECT_GT(d.norm(), 12.0 * 0.99 * t);
}

TEST(AimLeading, TargetRunningAwayFasterThanTheShotCannotBeHit) {
  const Motion target{Vec2(5.0, 0.0), Vec2(6.0, 0.0), Vec2::Zero()};
  EXPECT_FALSE(aimLeading(Vec2::Zero(), 5.0, target, Vec2::Zero()));
  // ...but one running toward the launcher can.
  const Motion coming{Vec2(5.0, 0.0), Vec2(-6.0, 0.0), Vec2::Zero()};
  const auto aim = aimLeading(Vec2::Zero(), 5.0, coming, Vec2::Zero());
  ASSERT_TRUE(aim);
  EXPECT_NEAR(aim->time_of_flight, 5.0 / 11.0, 1e-12);
  EXPECT_NEAR(aim->angle, 0.0, 1e-12);
}

TEST(AimLeading, TargetAtTheLauncherHasNoDirection) {
  EXPECT_FALSE(aimLeading(Vec2(1.0, 1.0), 5.0, Motion{Vec2(1.0, 1.0)}, kGravity));
}

TEST(TimeShot, WithoutGravityTheTargetMustReachTheLineWhenTheShotDoes) {
  // Shot along +x at 5 m/s; target at (10, -6) moving up at 2 m/s crosses the x axis at
  // s = 3 s, where the shot takes 2 s: fire after 1 s.
  const Motion target{Vec2(10.0, -6.0), Vec2(0.0, 2.0), Vec2::Zero()};
  const auto shot = timeShot(Vec2::Zero(), 0.0, 5.0, target, Vec2::Zero());
  ASSERT_TRUE(shot);
  EXPECT_NEAR(shot->delay, 1.0, 1e-12);
  EXPECT_NEAR(shot->time_of_flight, 2.0, 1e-12);
}

TEST(TimeShot, UnderGravityTheEarliestOfTheArcsCrossingsIsChosen) {
  // 45 degrees at v: the path is y = x - g x^2 / v^2. A target rolling left at height h from
  // x0 meets it where x - g x^2 / v^2 = h; at x it is at s = x0 - x, the shot at
  // t = x / (v cos 45). Of the rising and the falling crossing, the shorter delay wins.
  const double v = 10.0, g = 9.81, h = 1.5, x0 = 20.0;
  const Motion target{Vec2(x0, h), Vec2(-1.0, 0.0), Vec2::Zero()};
  const auto shot = timeShot(Vec2::Zero(), M_PI / 4.0, v, target, kGravity);
  ASSERT_TRUE(shot);
  const Roots x = quadraticRoots(g / (v * v), -1.0, h);
  ASSERT_EQ(x.count, 2);
  double delay = INFINITY, flight_time = 0.0;
  for (int i = 0; i < 2; ++i) {
    const double t = x.t[i] / (v * std::cos(M_PI / 4.0)), d = (x0 - x.t[i]) - t;
    if (d >= 0.0 && d < delay) delay = d, flight_time = t;
  }
  EXPECT_NEAR(shot->delay, delay, 1e-9);
  EXPECT_NEAR(shot->time_of_flight, flight_time, 1e-9);
}

TEST(TimeShot, FallingTargetAndShotMeet) {
  const Vec2 from(-5.0, 1.0);
  const Motion target{Vec2(6.0, 9.0), Vec2(-2.0, 1.0), kGravity};
  const auto shot = timeShot(from, 0.8, 9.0, target, kGravity);
  ASSERT_TRUE(shot);
  const double t = shot->time_of_flight;
  EXPECT_NEAR((flight(from, 9.0, 0.8, t) - target.positionAt(shot->delay + t)).norm(), 0.0,
              1e-9);
}

TEST(TimeShot, VerticalShotMeetsATargetCrossingAbove) {
  // Straight up at 10 m/s; a target flying level at 3 m above crosses x = 0 at s = 2 s; the
  // shot is at 3 m going up and again coming down, t = (10 -+ sqrt(100 - 2 g 3)) / g: met
  // coming down, it is fired sooner.
  const Motion target{Vec2(4.0, 3.0), Vec2(-2.0, 0.0), Vec2::Zero()};
  const auto shot = timeShot(Vec2::Zero(), M_PI / 2.0, 10.0, target, kGravity);
  ASSERT_TRUE(shot);
  const double t = (10.0 + std::sqrt(100.0 - 2.0 * 9.81 * 3.0)) / 9.81;
  EXPECT_NEAR(shot->time_of_flight, t, 1e-9);
  EXPECT_NEAR(shot->delay, 2.0 - t, 1e-9);
}

TEST(TimeShot, TargetThatNeverCrossesThePathHasNoTime) {
  // A ball at rest off the path, and one moving away from it.
  EXPECT_FALSE(timeShot(Vec2::Zero(), 0.0, 5.0, Motion{Vec2(3.0, 1.0)}, Vec2::Zero()));
  const Motion away{Vec2(3.0, 1.0), Vec2(0.0, 1.0), Vec2::Zero()};
  EXPECT_FALSE(timeShot(Vec2::Zero(), 0.0, 5.0, away, Vec2::Zero()));
}

TEST(TimeShot, AimedAsLeadingAdvisesFiringNow) {
  // At the angle aimLeading gives, firing at once hits: the delay is zero, not rounding below.
  const Motion target{Vec2(8.0, 0.3), Vec2(-1.5, 0.0), Vec2::Zero()};
  const Vec2 from(-4.0, 1.0);
  const auto lead = aimLeading(from, 12.0, target, kGravity);
  ASSERT_TRUE(lead);
  const auto shot = timeShot(from, lead->angle, 12.0, target, kGravity);
  ASSERT_TRUE(shot);
  EXPECT_NEAR(shot->delay, 0.0, 1e-12);
  EXPECT_NEAR(shot->time_of_flight, lead->time_of_flight, 1e-9);
}

TEST(TimeShot, NearlyVerticalShotsStillMeetTheirTarget) {
  const Motion target{Vec2(4.0, 3.0), Vec2(-2.0, 0.0), Vec2::Zero()};
  for (const double angle : {M_PI / 2.0 - 1e-9, M_PI / 2.0 - 1e-8, 1.5707963, 1.57079633}) {
    const auto shot = timeShot(Vec2::Zero(), angle, 10.0, target, kGravity);
    ASSERT_TRUE(shot) << angle;
    EXPECT_NEAR((flight(Vec2::Zero(), 10.0, angle, shot->time_of_flight) -
                 target.positionAt(shot->delay + shot->time_of_flight)).norm(),
                0.0, 1e-9)
        << angle;
  }
}

TEST(TimeShot, TargetOnThePathItselfIsShotAtOnce) {
  // At rest on the line of a shot without gravity: 5 m at 5 m/s.
  const auto level = timeShot(Vec2::Zero(), 0.0, 5.0, Motion{Vec2(5.0, 0.0)}, Vec2::Zero());
  ASSERT_TRUE(level);
  EXPECT_EQ(level->delay, 0.0);
  EXPECT_NEAR(level->time_of_flight, 1.0, 1e-12);
  // Dropped from 10 m straight above a shot fired up at 10 m/s: both fall alike, met at 1 s.
  const Motion dropped{Vec2(0.0, 10.0), Vec2::Zero(), kGravity};
  const auto up = timeShot(Vec2::Zero(), M_PI / 2.0, 10.0, dropped, kGravity);
  ASSERT_TRUE(up);
  EXPECT_EQ(up->delay, 0.0);
  EXPECT_NEAR(up->time_of_flight, 1.0, 1e-12);
}
