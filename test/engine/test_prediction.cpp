#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/prediction.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using ball_physics_sim::engine::test::ball;
using ball_physics_sim::engine::test::segment;

namespace {

const Vec2 kNoGravity = Vec2::Zero();
constexpr double kStep = 1.0 / 60.0;

}  // namespace

TEST(Prediction, ThrownBallFollowsItsParabolaAndEndsWhereItFirstTouchesTheFloor) {
  // From (0, 1) at (3, 4) m/s over a floor at y = 0: the centre is one radius up when
  // 1 + 4 t - g t^2 / 2 = r.
  const double g = 9.81, r = 0.25;
  World world(Vec2(0.0, -g));
  const SegmentId floor = world.addSegment(segment(Vec2(-10.0, 0.0), Vec2(20.0, 0.0)));
  const Ball shot = ball(Vec2(0.0, 1.0), Vec2(3.0, 4.0), r);
  const ShotPrediction prediction = predictShot(world, shot, kStep, 5.0);

  const double t_hit = (4.0 + std::sqrt(16.0 + 2.0 * g * (1.0 - r))) / g;
  ASSERT_TRUE(prediction.final_impact);
  EXPECT_NEAR(prediction.final_impact->time, t_hit, 1e-12);
  EXPECT_NEAR((prediction.final_impact->position - Vec2(3.0 * t_hit, r)).norm(), 0.0, 1e-12);
  EXPECT_EQ(prediction.final_impact->other_kind, ContactKind::kSegment);
  EXPECT_EQ(prediction.final_impact->other_id, floor);

  const int samples_before_impact = static_cast<int>(std::floor(t_hit / kStep));
  ASSERT_EQ(prediction.path.size(), samples_before_impact + 2u);  // muzzle ... impact
  for (int k = 0; k <= samples_before_impact; ++k) {
    const double t = k * kStep;
    const Vec2 exact(3.0 * t, 1.0 + 4.0 * t - 0.5 * g * t * t);
    EXPECT_NEAR((prediction.path[k] - exact).norm(), 0.0, 1e-12) << "sample " << k;
  }
  EXPECT_EQ(prediction.path.back(), prediction.final_impact->position);
}

TEST(Prediction, ShotStrikingAnotherBallEndsOneDiameterShortOfIt) {
  World world(kNoGravity);
  const BallId target = world.addBall(ball(Vec2(5.0, 0.0), Vec2::Zero()));
  const ShotPrediction prediction =
      predictShot(world, ball(Vec2::Zero(), Vec2(2.0, 0.0)), kStep, 5.0);
  ASSERT_TRUE(prediction.final_impact);
  EXPECT_NEAR(prediction.final_impact->time, 2.0, 1e-12);  // 4 m apart at 2 m/s
  EXPECT_NEAR((prediction.final_impact->position - Vec2(4.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(prediction.final_impact->other_kind, ContactKind::kBall);
  EXPECT_EQ(prediction.final_impact->other_id, target);
}

TEST(Prediction, AnImpactCoversTheShotsDiscAndTheBodyItStrikesWhereItIsThen) {
  // A shot of radius 0.2 at 2 m/s meets a ball of radius 0.5 coming at 1 m/s from x = 5 when
  // 3 t = 5 - 0.7: the shot's centre is then at 2 t, the ball's at 5 - t.
  World world(kNoGravity);
  world.addBall(ball(Vec2(5.0, 0.0), Vec2(-1.0, 0.0)));
  const PredictedImpact on_ball =
      *predictShot(world, ball(Vec2::Zero(), Vec2(2.0, 0.0), 0.2), kStep, 5.0).final_impact;
  const double t = 4.3 / 3.0, shot = 2.0 * t, struck = 5.0 - t;
  EXPECT_NEAR((on_ball.position - Vec2(shot, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((on_ball.point - Vec2(shot + 0.2, 0.0)).norm(), 0.0, 1e-12);
  for (const Vec2& covered : {Vec2(struck + 0.45, 0.0), Vec2(struck, 0.45),
                              Vec2(shot - 0.15, 0.1)})
    EXPECT_TRUE(impactCovers(world, on_ball, 0.2, covered, 0.0)) << covered.transpose();
  for (const Vec2& outside : {Vec2(struck + 0.55, 0.0), Vec2(5.0, 0.0), Vec2(shot, 0.25),
                              Vec2(shot - 0.25, 0.0)})
    EXPECT_FALSE(impactCovers(world, on_ball, 0.2, outside, 0.0)) << outside.transpose();
  EXPECT_TRUE(impactCovers(world, on_ball, 0.2, Vec2(struck + 0.55, 0.0), 0.06));

  // A wall 0.2 m thick at x = 3 covers its capsule, from x = 2.9 to 3.1.
  World walled(kNoGravity);
  Segment wall = segment(Vec2(3.0, -2.0), Vec2(3.0, 2.0));
  wall.thickness = 0.2;
  walled.addSegment(wall);
  const PredictedImpact on_wall =
      *predictShot(walled, ball(Vec2::Zero(), Vec2(2.0, 0.0)), kStep, 5.0).final_impact;
  EXPECT_NEAR(on_wall.position.x(), 2.4, 1e-12);
  EXPECT_TRUE(impactCovers(walled, on_wall, 0.5, Vec2(3.05, 1.0), 0.0));
  EXPECT_TRUE(impactCovers(walled, on_wall, 0.5, Vec2(3.0, 2.05), 0.0));
  EXPECT_FALSE(impactCovers(walled, on_wall, 0.5, Vec2(3.15, 0.0), 0.0));
  EXPECT_TRUE(impactCovers(walled, on_wall, 0.5, Vec2(3.15, 0.0), 0.06));
  EXPECT_FALSE(impactCovers(world, on_wall, 0.5, Vec2(3.05, 1.0), 0.0));  // no such segment
}

TEST(Prediction, OtherBallsMoveInThePredictionAsTheyWill) {
  // The target rolls into the shot's line: a ghost in a frozen world would miss it.
  World world(kNoGravity);
  world.addBall(ball(Vec2(4.0, -3.0), Vec2(0.0, 1.0)));
  const ShotPrediction prediction =
      predictShot(world, ball(Vec2::Zero(), Vec2(1.0, 0.0)), kStep, 5.0);
  ASSERT_TRUE(prediction.final_impact);
  // Both at (t, 0) and (4, t - 3): they touch when (4 - t)^2 + (t - 3)^2 = 1, first at t = 3.
  EXPECT_NEAR(prediction.final_impact->time, 3.0, 1e-12);
}

TEST(Prediction, WithoutAnImpactThePathEndsAtTheHorizon) {
  World world(kNoGravity);
  const ShotPrediction prediction =
      predictShot(world, ball(Vec2::Zero(), Vec2(1.0, 2.0)), 0.1, 0.95);
  EXPECT_FALSE(prediction.final_impact);
  ASSERT_EQ(prediction.path.size(), 11u);  // the muzzle, 9 whole steps, the horizon
  EXPECT_NEAR((prediction.path.back() - Vec2(0.95, 1.9)).norm(), 0.0, 1e-12);
}

TEST(Prediction, EndsOneHorizonAfterTheShotWhateverTheWorldsClockReads) {
  // After 259 steps of 1/120 s the world's clock is not a whole number of steps in binary: the
  // horizon must still be 360 steps, then stop (it used to loop on a remainder too small to
  // advance the clock, or add a step of 4e-16 s).
  const double step = 1.0 / 120.0;
  const Ball shot = ball(Vec2::Zero(), Vec2(1.0, 0.0));
  World world(kNoGravity);
  EXPECT_EQ(predictShot(world, shot, step, 3.0).path.size(), 361u);  // muzzle and 360 steps
  for (int i = 0; i < 259; ++i) world.step(step);
  const ShotPrediction prediction = predictShot(world, shot, step, 3.0);
  ASSERT_EQ(prediction.path.size(), 361u);
  EXPECT_NEAR(prediction.path.back().x(), 3.0, 1e-12);
}

TEST(Prediction, AgreesWithTheWorldOnceTheShotIsFired) {
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment(Vec2(-10.0, 0.0), Vec2(10.0, 0.0)));
  world.addSegment(segment(Vec2(6.0, 0.0), Vec2(6.0, 8.0)));
  world.addBall(ball(Vec2(3.0, 0.5), Vec2(-1.0, 0.0)));
  const Ball shot = ball(Vec2(0.0, 2.0), Vec2(7.0, 3.0), 0.2);
  const ShotPrediction prediction = predictShot(world, shot, kStep, 3.0);
  ASSERT_TRUE(prediction.final_impact);

  const BallId fired = world.addBall(shot);
  for (int i = 0; i < 180; ++i) world.step(kStep);
  const std::vector<Contact> contacts = world.takeContacts();
  const auto first = std::find_if(contacts.begin(), contacts.end(), [&](const Contact& c) {
    return c.ball_id == fired || (c.other_kind == ContactKind::kBall && c.other_id == fired);
  });
  ASSERT_NE(first, contacts.end());
  EXPECT_EQ(first->time, prediction.final_impact->time);  // fired at time 0: bit for bit
}

TEST(Prediction, WithBouncesAllowedTheShotGoesOnThroughThemToTheNextImpact) {
  // Between walls at x = +-3 at 2 m/s: the centre touches x = 2.5 after 1.25 s, x = -2.5 after
  // 3.75 s, x = 2.5 again after 6.25 s.
  World world(kNoGravity);
  const SegmentId right = world.addSegment(segment(Vec2(3.0, -5.0), Vec2(3.0, 5.0)));
  const SegmentId left = world.addSegment(segment(Vec2(-3.0, -5.0), Vec2(-3.0, 5.0)));
  const Ball shot = ball(Vec2::Zero(), Vec2(2.0, 0.0));
  const ShotPrediction prediction = predictShot(world, shot, kStep, 10.0, 1);
  ASSERT_EQ(prediction.bounces.size(), 1u);
  EXPECT_EQ(prediction.bounces[0].other_id, right);
  EXPECT_NEAR(prediction.bounces[0].time, 1.25, 1e-12);
  ASSERT_TRUE(prediction.final_impact);
  EXPECT_EQ(prediction.final_impact->other_id, left);
  EXPECT_NEAR(prediction.final_impact->time, 3.75, 1e-12);
  EXPECT_NEAR((prediction.final_impact->position - Vec2(-2.5, 0.0)).norm(), 0.0, 1e-12);
  // The path turns exactly at the bounce.
  EXPECT_NE(std::find(prediction.path.begin(), prediction.path.end(), prediction.bounces[0].position),
            prediction.path.end());
  EXPECT_NEAR(std::max_element(prediction.path.begin(), prediction.path.end(),
                               [](const Vec2& a, const Vec2& b) { return a.x() < b.x(); })->x(),
              2.5, 1e-12);

  EXPECT_THROW(predictShot(world, shot, kStep, 10.0, -1), std::invalid_argument);
}

TEST(Prediction, ShotThatCannotBePlacedIsRefusedAndTheWorldIsUntouched) {
  World world(kNoGravity);
  world.addBall(ball(Vec2::Zero(), Vec2::Zero()));
  EXPECT_THROW(predictShot(world, ball(Vec2(0.5, 0.0), Vec2(1.0, 0.0)), kStep, 1.0),
               std::invalid_argument);
  EXPECT_THROW(predictShot(world, ball(Vec2(5.0, 0.0), Vec2(1.0, 0.0)), 0.0, 1.0),
               std::invalid_argument);
  EXPECT_THROW(predictShot(world, ball(Vec2(5.0, 0.0), Vec2(1.0, 0.0)), kStep, -1.0),
               std::invalid_argument);
  EXPECT_THROW(predictShot(world, ball(Vec2(5.0, 0.0), Vec2(1.0, 0.0)), kStep, std::nan("")),
               std::invalid_argument);
  EXPECT_EQ(world.balls().size(), 1u);
}
