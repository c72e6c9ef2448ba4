// aimLauncher, the one call behind the node's aim service: each mode's answer, and each refusal
// with its reason.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/aim_request.h"
#include "ball_physics_sim/engine/bank_shot.h"
#include "ball_physics_sim/engine/format.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using ball_physics_sim::engine::test::addBox;
using ball_physics_sim::engine::test::ball;
using ball_physics_sim::engine::test::kG;
using ball_physics_sim::engine::test::segment;

namespace {

constexpr double kStep = 1.0 / 60.0;
constexpr double kSpeed = 5.0;     // m/s, the launcher's own
constexpr double kSpeedLimit = 10.0;  // m/s, the caller's limit
constexpr double kHorizon = 3.0;   // s
constexpr double kRadius = 0.5;    // m, of every ball here
const Vec2 kGravity(0.0, -kG);

AimRequest request(AimMode mode) {
  AimRequest r;
  r.mode = mode;
  return r;
}

// Without gravity: the launcher `gun` at the origin, a wall across the x axis at x = 8 (a shot
// along +x strikes it at x = 7.5 after 7.5 / kSpeed = 1.5 s).
struct Range : ::testing::Test {
  World world{Vec2::Zero()};
  Launcher launcher = [] {
    Launcher l;
    l.name = "gun";
    l.speed = kSpeed;
    l.projectile = ball(Vec2::Zero(), Vec2::Zero(), kRadius);
    return l;
  }();
  AimLimits limits{kStep, kHorizon, kSpeedLimit, 0.0};
  SegmentId wall = world.addSegment(segment(Vec2(8.0, -5.0), Vec2(8.0, 5.0)));

  AimAnswer aim(const AimRequest& r) const { return aimLauncher(world, launcher, r, limits); }
  // The refusal's reason; fails the test if it was not refused.
  std::string refusal(const AimRequest& r) const {
    const AimAnswer answer = aim(r);
    EXPECT_FALSE(answer.solution) << answer.message;
    return answer.message;
  }
  // "segment N at (7.5, 0) after 1.5 s": what a shot along +x at kSpeed strikes.
  std::string wallStrike() const { return "segment " + format(wall) + " at (7.5, 0) after 1.5 s"; }
  BallId muzzleBlocked() { return world.addBall(ball(Vec2(0.5, 0.0), Vec2::Zero(), kRadius)); }
};

}  // namespace

TEST_F(Range, SpeedIsTheLaunchersOrOneWithinTheLimit) {
  EXPECT_EQ(aim(request(AimMode::kAngle)).speed, kSpeed);
  AimRequest faster = request(AimMode::kAngle);
  faster.speed = kSpeedLimit;
  EXPECT_EQ(aim(faster).speed, kSpeedLimit);
  const std::string allowed = "speed must be finite and > 0, at most 10 m/s (~max_speed; or 0 for "
                              "the launcher's 5 m/s), got ";
  for (double bad : {-1.0, 11.0, std::nan("")}) {
    faster.speed = bad;
    EXPECT_EQ(refusal(faster), allowed + format(bad));
  }
}

TEST_F(Range, RequestsThatNoModeCanAnswerAreRefused) {
  AimRequest unknown = request(static_cast<AimMode>(9));
  EXPECT_EQ(refusal(unknown), "unknown mode 9; use ANGLE (0), TARGET (1), TARGET_BALLISTIC (2), "
                              "LEAD_BALL (3), TIMED (4) or BANK (5)");
  for (AimMode mode : {AimMode::kAngle, AimMode::kTimed}) {
    AimRequest r = request(mode);
    r.angle = std::nan("");
    EXPECT_EQ(refusal(r), "angle must be finite");
  }
  AimRequest timed = request(AimMode::kTarget);
  timed.target = Vec2(4.0, 3.0);
  timed.time_of_flight = 1.0;
  EXPECT_EQ(refusal(timed), "time_of_flight is for TARGET_BALLISTIC only");
}

TEST_F(Range, AngleAnswersTheFirstImpactAlongIt) {
  AimRequest r = request(AimMode::kAngle);
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution);
  EXPECT_EQ(answer.solution->angle, 0.0);
  EXPECT_NEAR(answer.solution->time_of_flight, 1.5, 1e-12);
  ASSERT_TRUE(answer.predicted_hit);
  EXPECT_NEAR((*answer.predicted_hit - Vec2(7.5, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(answer.message, "aimed along the given angle; the shot first hits " + wallStrike());
  r.angle = 2.0 * M_PI + 0.5;  // the same direction as 0.5
  EXPECT_EQ(aim(r).solution->angle, normalizedAngle(r.angle));
}

TEST_F(Range, AnAngleIsKeptWithoutAnImpactAPredictionOrAClearMuzzle) {
  AimRequest away = request(AimMode::kAngle);
  away.angle = M_PI;
  AimAnswer answer = aim(away);
  ASSERT_TRUE(answer.solution);
  EXPECT_EQ(answer.solution->time_of_flight, 0.0);
  EXPECT_FALSE(answer.predicted_hit);
  EXPECT_EQ(answer.message, "aimed along the given angle; the shot hits nothing within 3 s "
                            "(~prediction_horizon)");

  limits.prediction_horizon = 0.0;
  answer = aim(request(AimMode::kAngle));
  ASSERT_TRUE(answer.solution);
  EXPECT_EQ(answer.solution->time_of_flight, 0.0);
  EXPECT_EQ(answer.message, "aimed along the given angle");

  limits.prediction_horizon = kHorizon;
  const BallId blocker = muzzleBlocked();
  answer = aim(request(AimMode::kAngle));
  ASSERT_TRUE(answer.solution);
  EXPECT_EQ(answer.solution->time_of_flight, 0.0);
  EXPECT_EQ(answer.message, "aimed along the given angle; cannot predict the shot: ball would "
                            "overlap ball " + format(blocker));
}

TEST_F(Range, TargetWithoutGravityTakesDistanceOverSpeed) {
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(4.0, 3.0);
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution);
  EXPECT_DOUBLE_EQ(answer.solution->angle, std::atan2(3.0, 4.0));
  EXPECT_DOUBLE_EQ(answer.solution->time_of_flight, 1.0);
  EXPECT_EQ(answer.predicted_hit, Vec2(4.0, 3.0));
  EXPECT_EQ(answer.message, "aimed at (4, 3): the shot arrives after 1 s");
}

TEST_F(Range, TargetOnTheWallArrivesWhereTheShotStrikesIt) {
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(8.0, 0.0);
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution);
  EXPECT_NEAR(answer.solution->time_of_flight, 1.5, 1e-12);
  EXPECT_NEAR((*answer.predicted_hit - Vec2(7.5, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(answer.message, "aimed at (8, 0): the shot strikes " + wallStrike() + ", at the target");
}

TEST_F(Range, TargetBehindTheWallIsBlocked) {
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(9.0, 0.0);
  EXPECT_EQ(refusal(r), "target (9, 0) is blocked: the shot would first hit " + wallStrike());
  EXPECT_EQ(aim(r).predicted_hit, Vec2(9.0, 0.0));  // the target it checked
}

TEST_F(Range, TargetAtABallsCentreArrivesByStrikingItAndOneItHidesIsBlocked) {
  const BallId covering = world.addBall(ball(Vec2(6.0, 0.0), Vec2::Zero(), kRadius));
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(6.0, 0.0);
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution) << answer.message;
  EXPECT_NEAR(answer.solution->time_of_flight, 1.0, 1e-12);  // centres 1 m apart at x = 5
  EXPECT_NEAR((*answer.predicted_hit - Vec2(5.0, 0.0)).norm(), 0.0, 1e-12);
  const std::string strike = "ball " + format(covering) + " at (5, 0) after 1 s";
  EXPECT_EQ(answer.message, "aimed at (6, 0): the shot strikes " + strike + ", at the target");
  r.target = Vec2(6.6, 0.0);  // just past its surface
  EXPECT_EQ(refusal(r), "target (6.6, 0) is blocked: the shot would first hit " + strike);
}

TEST_F(Range, TargetWithinTheToleranceOfTheWallStruckIsOnIt) {
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(8.01, 0.0);  // 1 cm behind the wall's line
  EXPECT_EQ(refusal(r), "target (8.01, 0) is blocked: the shot would first hit " + wallStrike());
  limits.target_tolerance = 0.02;
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution) << answer.message;
  EXPECT_EQ(answer.message, "aimed at (8.01, 0): the shot strikes " + wallStrike() +
                                ", at the target");
}

TEST_F(Range, TargetIsUncheckedWithoutPredictionsOrPastTheLongestFlight) {
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(9.0, 0.0);  // behind the wall, but not looked for
  limits.prediction_horizon = 0.0;
  AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution);
  EXPECT_EQ(answer.message, "aimed at (9, 0): the shot arrives after 1.8 s, unchecked for "
                            "obstacles (~prediction_horizon is 0)");

  limits.prediction_horizon = kHorizon;
  r.target = Vec2(7.0, 0.0);
  r.speed = 0.1;  // 70 s
  answer = aim(r);
  ASSERT_TRUE(answer.solution);
  EXPECT_DOUBLE_EQ(answer.solution->time_of_flight, 70.0);
  EXPECT_EQ(answer.message, "aimed at (7, 0): the shot arrives after 70 s, unchecked for "
                            "obstacles (longer than 60 s)");
}

TEST_F(Range, TargetsNoAimReachesAreRefused) {
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(INFINITY, 0.0);
  EXPECT_EQ(refusal(r), "target must be finite");
  r.target = Vec2::Zero();
  EXPECT_EQ(refusal(r), "target (0, 0) is where launcher 'gun' is");
  const BallId blocker = muzzleBlocked();
  r.target = Vec2(4.0, 3.0);
  EXPECT_EQ(refusal(r), "cannot predict the shot: ball would overlap ball " + format(blocker));
}

TEST_F(Range, TargetUnderGravityOnlyPointsAndSaysWhereTheShotLands) {
  world = World(kGravity);  // open space
  AimRequest r = request(AimMode::kTarget);
  r.target = Vec2(4.0, 3.0);
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution);
  EXPECT_DOUBLE_EQ(answer.solution->angle, std::atan2(3.0, 4.0));
  EXPECT_EQ(answer.message.rfind("pointed straight at the target; gravity bends the path, so use "
                                 "TARGET_BALLISTIC to hit it; the shot hits nothing within 3 s",
                                 0),
            0u)
      << answer.message;
}

TEST_F(Range, BallisticAimIsTheArcThroughTheTarget) {
  world = World(kGravity);  // open space
  AimRequest r = request(AimMode::kTargetBallistic);
  r.target = Vec2(4.0, 0.0);
  r.speed = kSpeedLimit;
  for (bool high : {false, true}) {
    r.high_arc = high;
    const AimAnswer answer = aim(r);
    ASSERT_TRUE(answer.solution) << answer.message;
    // Level ground: sin(2 theta) = g x / v^2, the high arc at the complement.
    const double low = 0.5 * std::asin(kG * 4.0 / (kSpeedLimit * kSpeedLimit));
    const double theta = high ? 0.5 * M_PI - low : low;
    EXPECT_NEAR(answer.solution->angle, theta, 1e-14);
    EXPECT_NEAR(answer.solution->time_of_flight, 4.0 / (kSpeedLimit * std::cos(theta)), 1e-13);
    EXPECT_EQ(answer.predicted_hit, Vec2(4.0, 0.0));
    EXPECT_EQ(answer.message, "aimed at (4, 0): the shot arrives after " +
                                  format(answer.solution->time_of_flight) + " s");
  }
  r.target = Vec2(50.0, 0.0);
  r.speed = 0.0;
  EXPECT_EQ(refusal(r), "target (50, 0) is out of reach at 5 m/s; it needs at least " +
                            format(std::sqrt(kG * 50.0)) + " m/s");
}

TEST_F(Range, BallisticAimGivenATimeOfFlightTakesTheSpeedThatArrivesThen) {
  world = World(kGravity);  // open space
  AimRequest r = request(AimMode::kTargetBallistic);
  r.target = Vec2(4.0, 0.0);
  r.time_of_flight = 0.8;
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution) << answer.message;
  // v = (target - from) / t - g t / 2 = (5, 9.81 * 0.4)
  EXPECT_NEAR(answer.speed, std::hypot(5.0, kG * 0.4), 1e-14);
  EXPECT_NEAR(answer.solution->angle, std::atan2(kG * 0.4, 5.0), 1e-15);
  EXPECT_EQ(answer.solution->time_of_flight, 0.8);
  EXPECT_EQ(answer.message, "aimed at (4, 0): the shot arrives after 0.8 s");
}

TEST_F(Range, TimesOfFlightNoShotKeepsAreRefused) {
  world = World(kGravity);  // open space
  AimRequest r = request(AimMode::kTargetBallistic);
  r.target = Vec2(4.0, 0.0);
  for (double bad : {-1.0, std::nan("")}) {
    r.time_of_flight = bad;
    EXPECT_EQ(refusal(r), "time_of_flight must be finite and > 0 (or 0 to aim at `speed`), got " +
                              format(bad));
  }
  r.time_of_flight = 1.0;
  r.speed = kSpeed;
  EXPECT_EQ(refusal(r), "give speed or time_of_flight, not both: the time fixes the speed");
  r.speed = 0.0;
  r.time_of_flight = 0.01;
  const double needed = std::hypot(400.0, kG * 0.005);
  EXPECT_EQ(refusal(r), "reaching (4, 0) in 0.01 s needs " + format(needed) +
                            " m/s; shots go > 0 and at most 10 m/s (~max_speed)");
}

TEST_F(Range, LeadBallStrikesABallAtRestWhenTheGapIsClosed) {
  const BallId target = world.addBall(ball(Vec2(6.0, 0.0), Vec2::Zero(), kRadius));
  AimRequest r = request(AimMode::kLeadBall);
  r.target_ball = target;
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution) << answer.message;
  // Centres 6 m apart touch 2 radii short: (6 - 1) / 5 s.
  EXPECT_NEAR(answer.solution->angle, 0.0, 1e-15);
  EXPECT_NEAR(answer.solution->time_of_flight, 1.0, 1e-12);
  EXPECT_NEAR((*answer.predicted_hit - Vec2(5.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(answer.message, "leading ball " + format(target) + ": it is struck after 1 s");
}

TEST_F(Range, LeadBallIsRefusedForABallItCannotStrike) {
  AimRequest r = request(AimMode::kLeadBall);
  r.target_ball = 99;
  EXPECT_EQ(refusal(r), "there is no ball 99");
  r.target_ball = world.addBall(ball(Vec2(3.0, 3.0), Vec2(kSpeedLimit, 0.0), kRadius));
  EXPECT_EQ(refusal(r), "ball " + format(r.target_ball) + " cannot be caught at 5 m/s from "
                        "launcher 'gun'");
  r.target_ball = world.addBall(ball(Vec2(10.0, 0.0), Vec2::Zero(), kRadius));
  EXPECT_EQ(refusal(r), "the shot at ball " + format(r.target_ball) + " would first hit " +
                            wallStrike());
}

TEST_F(Range, LeadBallIsRefusedWhenTheTargetIsKnockedAwayFirst) {
  // A lighter ball dropping onto the target at t = 0.2 s sends it down at 20/3 m/s and bounces
  // back up: the shot along y = 0 finds nothing.
  const BallId target = world.addBall(ball(Vec2(6.0, 0.0), Vec2::Zero(), kRadius));
  world.addBall(ball(Vec2(6.0, 3.0), Vec2(0.0, -10.0), kRadius, 0.5));
  AimRequest r = request(AimMode::kLeadBall);
  r.target_ball = target;
  EXPECT_EQ(refusal(r), "ball " + format(target) + " changes course (it hits something) before "
                        "the shot reaches it");
}

TEST_F(Range, TimedShotWaitsWholeStepsForTheTargetToCrossThePath) {
  // Up x = 5 at 5 m/s from y = -5: it crosses the x axis at 1 s, where a shot at 10 m/s takes
  // 0.5 s, so the shot waits 0.5 s (30 steps). Then the centres close along (1, -1/2) * (5 - 10 t)
  // and touch 1 m apart: t = (5 - 1 / sqrt(1.25)) / 10.
  const BallId target = world.addBall(ball(Vec2(5.0, -5.0), Vec2(0.0, 5.0), kRadius));
  AimRequest r = request(AimMode::kTimed);
  r.target_ball = target;
  r.speed = kSpeedLimit;
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution) << answer.message;
  EXPECT_EQ(answer.solution->angle, 0.0);
  EXPECT_EQ(answer.fire_after, 30 * kStep);
  const double strike = (5.0 - 1.0 / std::sqrt(1.25)) / 10.0;
  EXPECT_NEAR(answer.solution->time_of_flight, strike, 1e-9);
  EXPECT_NEAR((*answer.predicted_hit - Vec2(10.0 * strike, 0.0)).norm(), 0.0, 1e-8);
  EXPECT_EQ(answer.message.rfind("fire after 30 steps (0.5 s; exactly 0.5 s): ball " +
                                     format(target) + " is struck " + format(strike) + " s later",
                                 0),
            0u)
      << answer.message;
}

TEST_F(Range, TimedShotIsRefusedForABallThatNeverCrossesWithinTheLongestPrediction) {
  AimRequest r = request(AimMode::kTimed);
  r.target_ball = 99;
  EXPECT_EQ(refusal(r), "there is no ball 99");
  r.target_ball = world.addBall(ball(Vec2(5.0, 2.0), Vec2(1.0, 0.0), kRadius));
  EXPECT_EQ(refusal(r), "ball " + format(r.target_ball) + " never crosses the path of launcher "
                        "'gun' at 0 rad and 5 m/s");
  // Struck 60.5 s from now (fired after 59.5 s, 1 s of flight): past kMaxPredictionHorizon.
  const BallId late_ball = world.addBall(ball(Vec2(5.0, -30.25), Vec2(0.0, 0.5), kRadius));
  r.target_ball = late_ball;
  EXPECT_EQ(refusal(r), "ball " + format(late_ball) + " is struck only 60.5 s from now, too far "
                        "ahead to predict (more than 60 s)");
  // Struck 58 s from now: within it, and confirmed.
  world.removeBall(late_ball);
  r.target_ball = world.addBall(ball(Vec2(5.0, -29.0), Vec2(0.0, 0.5), kRadius));
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution) << answer.message;
  EXPECT_NEAR(answer.fire_after, 57.0, kStep);
}

// No gravity, e = 1: a floor, a ceiling, and a wall hanging between the launcher at (0, 3) and
// a ball at rest at (6, 3), so only a shot off the floor or the ceiling reaches it.
struct Banked : Range {
  Banked() {
    launcher.position = Vec2(0.0, 3.0);
    world = World(Vec2::Zero());
    world.addSegment(segment(Vec2(-2.0, 0.0), Vec2(10.0, 0.0)));
    world.addSegment(segment(Vec2(-2.0, 7.0), Vec2(10.0, 7.0)));
    world.addSegment(segment(Vec2(3.0, 2.4), Vec2(3.0, 5.0)));
    target = world.addBall(ball(Vec2(6.0, 3.0), Vec2::Zero(), kRadius));
  }
  BallId target = 0;
};

TEST_F(Banked, BankAnswersTheShotAimBankFinds) {
  AimRequest r = request(AimMode::kBank);
  r.target_ball = target;
  const AimAnswer answer = aim(r);
  ASSERT_TRUE(answer.solution) << answer.message;
  const auto shot = aimBank(world, launcher, kSpeed, target, kStep, kHorizon);
  ASSERT_TRUE(shot);
  const PredictedImpact& strike = *shot->prediction.final_impact;
  EXPECT_EQ(answer.solution->angle, shot->angle);
  EXPECT_EQ(answer.solution->time_of_flight, strike.time);
  EXPECT_EQ(answer.predicted_hit, strike.position);
  std::string said = "bank shot:";
  for (const PredictedImpact& bounce : shot->prediction.bounces)
    said += " off segment " + format(bounce.other_id) + " at " + format(bounce.position) +
            " after " + format(bounce.time) + " s, then";
  EXPECT_EQ(answer.message, said + " strikes ball " + format(target) + " at " +
                                format(strike.position) + " after " + format(strike.time) + " s");
}

TEST_F(Banked, BankIsRefusedWithoutATargetAPredictionOrAShot) {
  AimRequest r = request(AimMode::kBank);
  r.target_ball = 99;
  EXPECT_EQ(refusal(r), "there is no ball 99");
  r.target_ball = target;
  limits.prediction_horizon = 0.0;
  EXPECT_EQ(refusal(r), "BANK searches shots with the prediction: it needs ~prediction_horizon > 0");
  limits.prediction_horizon = kHorizon;
  const BallId blocker = world.addBall(ball(Vec2(0.5, 3.0), Vec2::Zero(), kRadius));
  EXPECT_EQ(refusal(r), "cannot predict the shot: ball would overlap ball " + format(blocker));
}

TEST_F(Range, BankIsRefusedWhenNoBounceReachesTheTarget) {
  // The target sits in a closed box of its own.
  addBox(world, 1.0, Vec2(5.0, 0.0));
  AimRequest r = request(AimMode::kBank);
  r.target_ball = world.addBall(ball(Vec2(5.0, 0.0), Vec2::Zero(), kRadius));
  EXPECT_EQ(refusal(r), "found no shot at 5 m/s from launcher 'gun' that strikes ball " +
                            format(r.target_ball) + " after 1 to 3 bounces within 3 s "
                            "(~prediction_horizon)");
}
