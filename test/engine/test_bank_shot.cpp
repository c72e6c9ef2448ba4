#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/bank_shot.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using ball_physics_sim::engine::test::ball;
using ball_physics_sim::engine::test::segment;

namespace {

constexpr double kStep = 1.0 / 60.0;
constexpr double kSpeed = 5.0;
constexpr double kHorizon = 3.0;

Launcher launcherAt(const Vec2& position) {
  Launcher launcher;
  launcher.position = position;
  launcher.projectile = ball(Vec2::Zero(), Vec2::Zero(), 0.5);
  return launcher;
}

// No gravity, e = 1: a floor, a ceiling, and a wall hanging between the launcher at (0, 3) and
// a ball at rest at (6, 3), so only a shot off the floor or the ceiling reaches it.
struct WallBetween : ::testing::Test {
  World world{Vec2::Zero()};
  Launcher launcher = launcherAt(Vec2(0.0, 3.0));
  SegmentId floor = world.addSegment(segment(Vec2(-2.0, 0.0), Vec2(10.0, 0.0)));
  SegmentId ceiling = world.addSegment(segment(Vec2(-2.0, 7.0), Vec2(10.0, 7.0)));
  SegmentId wall = world.addSegment(segment(Vec2(3.0, 2.4), Vec2(3.0, 5.0)));
  BallId target = world.addBall(ball(Vec2(6.0, 3.0), Vec2::Zero()));
};

}  // namespace

TEST_F(WallBetween, BanksOffTheFloorAimingAtTheTargetsMirrorImage) {
  // The shot's centre bounces where it is one radius above the floor, at y = 0.5: it flies at
  // the target's image in that line, (6, -2), the middle of the aims that strike it.
  const std::optional<BankShot> shot = aimBank(world, launcher, kSpeed, target, kStep, kHorizon);
  ASSERT_TRUE(shot);
  EXPECT_NEAR(shot->angle, std::atan2(-5.0, 6.0), 1e-9);
  ASSERT_EQ(shot->prediction.bounces.size(), 1u);
  EXPECT_EQ(shot->prediction.bounces[0].other_kind, ContactKind::kSegment);
  EXPECT_EQ(shot->prediction.bounces[0].other_id, floor);
  EXPECT_NEAR((shot->prediction.bounces[0].position - Vec2(3.0, 0.5)).norm(), 0.0, 1e-8);

  // Centre on centre: the strike comes one diameter short of the target along the path, which
  // is as long as the straight line to the image.
  const Vec2 rising = Vec2(6.0, 5.0).normalized();
  const std::optional<PredictedImpact>& strike = shot->prediction.final_impact;
  ASSERT_TRUE(strike);
  EXPECT_EQ(strike->other_id, target);
  EXPECT_NEAR((strike->position - (Vec2(6.0, 3.0) - rising)).norm(), 0.0, 1e-8);
  EXPECT_NEAR(strike->time, (std::sqrt(61.0) - 1.0) / kSpeed, 1e-9);
}

TEST_F(WallBetween, TheWorldThenStrikesTheTargetWhenThePredictionSaid) {
  const std::optional<BankShot> shot = aimBank(world, launcher, kSpeed, target, kStep, kHorizon);
  ASSERT_TRUE(shot);
  launcher.angle = shot->angle;
  const BallId fired = world.addBall(launcher.launch(kSpeed));
  for (int i = 0; i < 120; ++i) world.step(kStep);
  const std::vector<Contact> contacts = world.takeContacts();
  const auto strike = std::find_if(contacts.begin(), contacts.end(), [&](const Contact& c) {
    return c.other_kind == ContactKind::kBall &&
           std::minmax(c.ball_id, c.other_id) == std::minmax(fired, target);
  });
  ASSERT_NE(strike, contacts.end());
  EXPECT_EQ(strike->time, shot->prediction.final_impact->time);  // fired at time 0
}

TEST_F(WallBetween, ABallInTheWayOfTheFloorBankSendsTheShotOffTheCeiling) {
  // The scan runs without other balls; the whole world's prediction then refuses the floor
  // bank (it would strike the ball on its rising leg) and confirms the next, off the ceiling.
  world.addBall(ball(Vec2(4.5, 1.75), Vec2::Zero(), 0.3));
  const std::optional<BankShot> shot = aimBank(world, launcher, kSpeed, target, kStep, kHorizon);
  ASSERT_TRUE(shot);
  ASSERT_EQ(shot->prediction.bounces.size(), 1u);
  EXPECT_EQ(shot->prediction.bounces[0].other_id, ceiling);
  ASSERT_TRUE(shot->prediction.final_impact);
  EXPECT_EQ(shot->prediction.final_impact->other_id, target);
}

TEST(BankShot, NoneIntoAClosedBox) {
  World world(Vec2::Zero());
  const Vec2 corners[] = {Vec2(4, -2), Vec2(8, -2), Vec2(8, 2), Vec2(4, 2)};
  for (int i = 0; i < 4; ++i) world.addSegment(segment(corners[i], corners[(i + 1) % 4]));
  world.addSegment(segment(Vec2(-5.0, -5.0), Vec2(-5.0, 5.0)));  // something to bank off
  const BallId target = world.addBall(ball(Vec2(6.0, 0.0), Vec2::Zero()));
  EXPECT_FALSE(aimBank(world, launcherAt(Vec2::Zero()), kSpeed, target, kStep, kHorizon));
}

TEST(BankShot, NoneAtABallThatIsNotThere) {
  World world(Vec2::Zero());
  world.addSegment(segment(Vec2(-5.0, -5.0), Vec2(-5.0, 5.0)));
  EXPECT_FALSE(aimBank(world, launcherAt(Vec2::Zero()), kSpeed, 7, kStep, kHorizon));
}

TEST(BankShot, TargetAtopAStackIsSoughtWhereItRests) {
  // The scan drops the balls the target does not lean on; the two under it stay, so it does
  // not fall in the scan (it did once: every shot found then struck the stack's bottom ball).
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment(Vec2(-2.0, 0.0), Vec2(12.0, 0.0)));
  world.addSegment(segment(Vec2(9.0, 0.0), Vec2(9.0, 8.0)));
  world.addSegment(segment(Vec2(3.0, 1.2), Vec2(3.0, 8.0)));
  world.addBall(ball(Vec2(6.0, 0.5), Vec2::Zero()));
  world.addBall(ball(Vec2(6.0, 1.5), Vec2::Zero()));
  const BallId top = world.addBall(ball(Vec2(6.0, 2.5), Vec2::Zero()));
  world.addBall(ball(Vec2(-1.0, 0.5), Vec2::Zero()));  // elsewhere, dropped by the scan
  for (int i = 0; i < 30; ++i) world.step(kStep);
  ASSERT_TRUE(world.motionOfBall(top)->velocity.isZero());

  Launcher launcher = launcherAt(Vec2(0.0, 3.0));
  launcher.projectile.radius = 0.2;
  const std::optional<BankShot> shot = aimBank(world, launcher, 8.0, top, kStep, kHorizon);
  ASSERT_TRUE(shot);
  EXPECT_GE(shot->prediction.bounces.size(), 1u);
  ASSERT_TRUE(shot->prediction.final_impact);
  EXPECT_EQ(shot->prediction.final_impact->other_id, top);
}
