#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/forces.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/scene.h"
#include "ball_physics_sim/engine/settle.h"
#include "ball_physics_sim/engine/world.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using ball_physics_sim::engine::test::addBox;
using ball_physics_sim::engine::test::ball;
using ball_physics_sim::engine::test::kFrameStep;
using ball_physics_sim::engine::test::kG;
using ball_physics_sim::engine::test::refusal;
using ball_physics_sim::engine::test::run;
using ball_physics_sim::engine::test::segment;

namespace {

const Vec2 kNoGravity = Vec2::Zero();

}  // namespace

TEST(World, ThrownBallBouncesOnTheSameExactParabola) {
  // The throw scene: from the floor at (1, 9.81) m/s, elastic bounces every 2 s. At 9 s, after
  // four bounces, the ball is at the top of its fifth hop: 4.905 m up, 9 m on, moving level.
  Scene scene = loadScene(SCENES_DIR "/throw.yaml");
  run(scene.world, 9.0, 1.0 / 120.0);
  const Ball& ball = scene.world.balls().at(0);
  EXPECT_NEAR(ball.position.x(), 4.0, 1e-9);
  EXPECT_NEAR(ball.position.y(), 0.2 + 4.905, 1e-9);
  EXPECT_NEAR((ball.velocity - Vec2(1.0, 0.0)).norm(), 0.0, 1e-9);
}

TEST(World, ProjectileFollowsItsExactParabola) {
  World world(Vec2(0.0, -9.81));
  const Vec2 p0(0.0, 100.0), v0(3.0, 20.0);
  world.addBall(ball(p0, v0));
  run(world, 4.0, 1.0 / 60.0);
  const double t = world.time();
  const Vec2 exact = p0 + v0 * t + 0.5 * Vec2(0.0, -9.81) * t * t;
  EXPECT_NEAR((world.balls()[0].position - exact).norm(), 0.0, 1e-10);
  EXPECT_NEAR((world.balls()[0].velocity - (v0 + Vec2(0.0, -9.81) * t)).norm(), 0.0, 1e-11);
}

TEST(World, HeadOnElasticImpactOfEqualMassesSwapsVelocities) {
  World world(kNoGravity);
  world.addBall(ball({0.0, 0.0}, {1.0, 0.0}));
  world.addBall(ball({3.0, 0.0}, {-1.0, 0.0}));
  world.step(2.0);  // they touch at t = 1, inside the step
  EXPECT_NEAR(world.balls()[0].velocity.x(), -1.0, 1e-15);
  EXPECT_NEAR(world.balls()[1].velocity.x(), 1.0, 1e-15);
  // After the impact each moved back for 1 s: exact positions, not a frame-end guess.
  EXPECT_NEAR(world.balls()[0].position.x(), 0.0, 1e-15);
  EXPECT_NEAR(world.balls()[1].position.x(), 3.0, 1e-15);
  const auto contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].time, 1.0, 1e-15);
  EXPECT_NEAR(contacts[0].point.x(), 1.5, 1e-15);
  EXPECT_NEAR(contacts[0].normal.x(), -1.0, 1e-15);
  EXPECT_NEAR(contacts[0].approach_speed, 2.0, 1e-15);
}

TEST(World, HeadOnImpactOfUnequalMassesMatchesNewtonsLaw) {
  // v1' = ((m1 - e m2) v1 + (1 + e) m2 v2) / (m1 + m2), and symmetrically for v2'.
  const double m1 = 2.0, m2 = 5.0, v1 = 3.0, v2 = -1.0, e = 0.6;
  World world(kNoGravity);
  world.addBall(ball({0.0, 0.0}, {v1, 0.0}, 0.5, m1, e));
  world.addBall(ball({5.0, 0.0}, {v2, 0.0}, 0.5, m2, 1.0));
  world.step(2.0);
  const double v1_after = ((m1 - e * m2) * v1 + (1 + e) * m2 * v2) / (m1 + m2);
  const double v2_after = ((m2 - e * m1) * v2 + (1 + e) * m1 * v1) / (m1 + m2);
  EXPECT_NEAR(world.balls()[0].velocity.x(), v1_after, 1e-12 * std::abs(v1_after));
  EXPECT_NEAR(world.balls()[1].velocity.x(), v2_after, 1e-12 * std::abs(v2_after));
  const double momentum = m1 * world.balls()[0].velocity.x() + m2 * world.balls()[1].velocity.x();
  EXPECT_NEAR(momentum, m1 * v1 + m2 * v2, 1e-12);
}

TEST(World, BallDroppedOnAFloorBouncesAtTheExactTimeAndSpeed) {
  const double g = 9.81, h = 2.0, r = 0.25, m = 3.0, e = 0.5;
  World world(Vec2(0.0, -g));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  world.addBall(ball({0.0, h + r}, {0.0, 0.0}, r, m, e));
  run(world, 1.0, 0.01);
  const auto contacts = world.takeContacts();
  ASSERT_GE(contacts.size(), 1u);
  const Contact& c = contacts[0];
  const double speed = std::sqrt(2.0 * g * h);
  EXPECT_NEAR(c.time, std::sqrt(2.0 * h / g), 1e-12);
  EXPECT_EQ(c.other_kind, ContactKind::kSegment);
  EXPECT_NEAR((c.point - Vec2(0.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((c.normal - Vec2(0.0, 1.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(c.approach_speed, speed, 1e-12);
  EXPECT_NEAR(c.impulse, m * (1.0 + e) * speed, 1e-11);
}

TEST(World, EarliestImpactIsResolvedFirst) {
  // Walls at x = 3 and x = -2; the ball moving left at 10 m/s meets the left one first.
  World world(kNoGravity);
  world.addSegment(segment({3.0, -1.0}, {3.0, 1.0}));
  world.addSegment(segment({-2.0, -1.0}, {-2.0, 1.0}));
  world.addBall(ball({0.0, 0.0}, {-10.0, 0.0}));
  world.step(0.5);  // left wall at t = 0.15, right wall at 0.15 + 4 / 10 = 0.55: not yet
  const auto contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].other_id, 2u);
  EXPECT_NEAR(contacts[0].time, 0.15, 1e-15);
  EXPECT_NEAR(world.balls()[0].position.x(), -1.5 + 10.0 * 0.35, 1e-13);
}

TEST(World, FastBallDoesNotTunnelThroughAThinWall) {
  // 1000 m/s against a wall of zero thickness, a step 200 radii long.
  World world(kNoGravity);
  world.addSegment(segment({1.0, -1.0}, {1.0, 1.0}));
  world.addBall(ball({0.0, 0.0}, {1000.0, 0.0}, 0.05));
  world.step(0.01);
  EXPECT_LT(world.balls()[0].position.x(), 1.0);
  EXPECT_NEAR(world.balls()[0].velocity.x(), -1000.0, 1e-9);
}

TEST(World, BallHittingASegmentEndBouncesOffTheCap) {
  // Moving down at x = 1.3 onto the end (1, 0) of a floor: the centre meets the cap where
  // |(0.3, y)| = 0.5, y = 0.4, so the normal is (0.6, 0.8).
  World world(kNoGravity);
  world.addSegment(segment({-1.0, 0.0}, {1.0, 0.0}));
  world.addBall(ball({1.3, 2.0}, {0.0, -1.0}));
  world.step(2.0);
  const auto contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].other_kind, ContactKind::kCap);
  EXPECT_NEAR(contacts[0].time, 1.6, 1e-14);
  EXPECT_NEAR((contacts[0].normal - Vec2(0.6, 0.8)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((contacts[0].point - Vec2(1.0, 0.0)).norm(), 0.0, 1e-14);
  // Reflected: v - 2 (v . n) n = (0, -1) + 1.6 (0.6, 0.8).
  EXPECT_NEAR((world.balls()[0].velocity - Vec2(0.96, 0.28)).norm(), 0.0, 1e-14);
}

TEST(World, ABallOutsideABoxBouncesOffItsCornerAndOneInsideOffBothFacesThere) {
  // Seen from outside, a box's corner is a cap like any other: the ball, head on along the
  // diagonal, meets it where |c| = 0.5, at c = -(s, s), s = 0.5 / sqrt(2), and comes back.
  const double s = 0.5 / std::sqrt(2.0);
  World outside(kNoGravity);
  addBox(outside, 5.0, {5.0, 5.0});
  outside.addBall(ball({-3.0, -3.0}, {1.0, 1.0}));
  outside.step(4.0);
  auto contacts = outside.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].other_kind, ContactKind::kCap);
  EXPECT_NEAR(contacts[0].time, 3.0 - s, 1e-14);
  EXPECT_NEAR((outside.balls()[0].velocity - Vec2(-1.0, -1.0)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((outside.balls()[0].position - Vec2(-1.0 - 2.0 * s, -1.0 - 2.0 * s)).norm(), 0.0,
              1e-13);
  // From inside (a room, whose corners it does not look for) it meets the floor and the left
  // wall at once at (0.5, 0.5), 0.21 from the corner's reach, and leaves along the diagonal,
  // as it would if it looked.
  World inside(kNoGravity);
  addBox(inside, 5.0, {5.0, 5.0});
  inside.addBall(ball({3.0, 3.0}, {-1.0, -1.0}));
  inside.step(4.0);
  contacts = inside.takeContacts();
  ASSERT_EQ(contacts.size(), 2u);
  for (const Contact& contact : contacts) {
    EXPECT_EQ(contact.other_kind, ContactKind::kSegment);
    EXPECT_NEAR(contact.time, 2.5, 1e-14);
  }
  EXPECT_NEAR((inside.balls()[0].velocity - Vec2(1.0, 1.0)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((inside.balls()[0].position - Vec2(2.0, 2.0)).norm(), 0.0, 1e-13);
}

TEST(World, ABoxWhoseWallIsTakenAwayOrMovedOffIsNoRoomAndTheFloorsFreeEndIsMet) {
  // The ball moves down the line y = x + 0.6 and out where the left wall was. It is over the
  // floor's end at x = 0 (y = 0.6 > 0.5), then meets the end itself, a cap no more a corner:
  // x^2 + (x + 0.6)^2 = 0.25, x = (-1.2 + sqrt(0.56)) / 4.
  const double x = (-1.2 + std::sqrt(0.56)) / 4.0;
  for (const bool removed : {true, false}) {
    World world(kNoGravity);
    addBox(world, 5.0, {5.0, 5.0});
    world.addBall(ball({2.0, 2.6}, {-1.0, -1.0}));
    world.step(1.0);  // in the room
    const SegmentId left = world.segments()[3].id;
    ASSERT_TRUE(removed ? world.removeSegment(left)
                        : world.setSegmentMotion(left, {-10.0, 0.0}, 0.0));
    world.step(2.0);
    const auto contacts = world.takeContacts();
    ASSERT_EQ(contacts.size(), 1u) << (removed ? "removed" : "moved off");
    EXPECT_EQ(contacts[0].other_kind, ContactKind::kCap);
    EXPECT_NEAR(contacts[0].time, 1.0 + (1.0 - x), 1e-14);
    EXPECT_NEAR((contacts[0].normal - Vec2(x, x + 0.6) / 0.5).norm(), 0.0, 1e-13);
  }
}

TEST(World, BallOnAFloorComesToRestExactlyOnIt) {
  const double r = 0.25;
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  world.addBall(ball({0.0, 1.0}, {0.0, 0.0}, r, 1.0, 0.5));
  run(world, 5.0, 0.01);
  const Ball& b = world.balls()[0];
  EXPECT_TRUE(b.at_rest);
  EXPECT_EQ(b.velocity, Vec2::Zero());
  EXPECT_NEAR(b.position.y(), r, 1e-9);
  run(world, 10.0, 0.01);  // and stays there
  EXPECT_NEAR(world.balls()[0].position.y(), r, 1e-9);
}

TEST(World, StackOfBallsSettlesWithoutSinking) {
  const double r = 0.5;
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  for (int i = 0; i < 3; ++i) world.addBall(ball({0.0, r + 0.2 + 1.5 * i}, {0.0, 0.0}, r, 1.0, 0.5));
  run(world, 10.0, 0.01);
  for (int i = 0; i < 3; ++i) {
    const Ball& b = world.balls()[i];
    EXPECT_TRUE(b.at_rest) << "ball " << i;
    EXPECT_NEAR(b.position.y(), r + 2.0 * r * i, 1e-9) << "ball " << i;
    EXPECT_EQ(b.position.x(), 0.0);
  }
}

TEST(World, ABallFarFromALandingPileFallsOnItsExactParabolaEveryStep) {
  // While hundreds of balls land on each other, every step still finishes: a ball falling
  // alone far away is where its parabola has it after each one. (A stale prediction of the
  // pile's impacts would spend a step's budget on an impact already past and end it early.)
  const double g = 9.81, r = 0.5;
  World world(Vec2(0.0, -g));
  const int columns = 12, rows = 10;
  const double width = columns * 1.2 + 0.2;
  addBox(world, 0.5 * width + 10.0, Vec2(0.5 * width, 0.5 * width + 10.0), 0.5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int i = 0; i < columns * rows; ++i)
    world.addBall(
        ball({0.1 + 1.2 * (i % columns + 0.5) + jitter(rng), 0.2 + 1.2 * (i / columns + 0.5)},
             {0.0, 0.0}, r, 1.0, std::sqrt(0.5)));
  const Vec2 start(width + 100.0, 1000.0);
  const BallId alone = world.addBall(ball(start, {0.0, 0.0}, r));
  for (int step = 1; step <= 75; ++step) {
    world.step(kFrameStep);
    const double t = world.time();
    ASSERT_NEAR(world.findBall(alone)->position.y(), start.y() - 0.5 * g * t * t, 1e-9)
        << "step " << step;
  }
}

TEST(World, SteppingUntilAStrikeStopsTheWorldAtItsExactTime) {
  // Two balls of r 0.25 whose centres are 1 m apart close at 2 m/s: they strike after
  // (1 - 2 r) / 2 = 0.25 s, where the world stops; a third ball, alone, is where its line has it
  // then, and a step goes on from there. A strike of another pair does not stop it.
  World world(Vec2::Zero());
  const BallId a = world.addBall(ball({0.0, 0.0}, {1.0, 0.0}, 0.25));
  world.addBall(ball({1.0, 0.0}, {-1.0, 0.0}, 0.25));
  const BallId alone = world.addBall(ball({0.0, 10.0}, {3.0, 0.0}, 0.25));
  EXPECT_DOUBLE_EQ(world.stepUntilStrike(1.0, alone), 1.0);
  EXPECT_NEAR(world.findBall(a)->velocity.x(), -1.0, 1e-12);  // (elastic: they swapped)
  World again(Vec2::Zero());
  const BallId first = again.addBall(ball({0.0, 0.0}, {1.0, 0.0}, 0.25));
  again.addBall(ball({1.0, 0.0}, {-1.0, 0.0}, 0.25));
  const BallId lone = again.addBall(ball({0.0, 10.0}, {3.0, 0.0}, 0.25));
  EXPECT_NEAR(again.stepUntilStrike(1.0, first), 0.25, 1e-15);
  EXPECT_NEAR(again.time(), 0.25, 1e-15);
  const std::vector<Contact> contacts = again.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].time, 0.25, 1e-15);
  EXPECT_NEAR((again.findBall(lone)->position - Vec2(0.75, 10.0)).norm(), 0.0, 1e-15);
  again.step(0.1);
  EXPECT_NEAR((again.findBall(lone)->position - Vec2(1.05, 10.0)).norm(), 0.0, 1e-14);
}

TEST(World, RestingBallWakesWhenHit) {
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  world.addBall(ball({0.0, 0.5}, {0.0, 0.0}));
  world.step(0.01);
  ASSERT_TRUE(world.balls()[0].at_rest);
  world.addBall(ball({-2.0, 0.5}, {2.0, 0.0}));
  run(world, 1.0, 0.01);
  // Equal masses, e = 1: the moving ball stops and the resting one leaves at 2 m/s.
  EXPECT_FALSE(world.balls()[0].at_rest);
  EXPECT_NEAR(world.balls()[0].velocity.x(), 2.0, 1e-12);
  EXPECT_NEAR(world.balls()[1].velocity.x(), 0.0, 1e-12);
}

TEST(World, AHitPassesDownAColumnOfTouchingBallsAndBackUpAtOneInstant) {
  // Elastic equal balls stacked on a floor, one dropped on them: each hit stops the ball that
  // strikes and passes its speed on, down to the floor and back up, so that the dropped ball
  // leaves at the speed it came, at the instant it struck, and the column stays still. (Three,
  // held exactly: four or more would settle as a pile, and be struck as one.)
  const int column = 3;
  const double gap = 1.0, g = 9.81;
  World world(Vec2(0.0, -g));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  for (int i = 0; i < column; ++i) world.addBall(ball({0.0, 0.5 + i}, {0.0, 0.0}));
  const double struck_at = 0.5 + column;  // the dropped ball's height when it strikes
  world.addBall(ball({0.0, struck_at + gap}, {0.0, 0.0}));
  run(world, 0.5, 0.01);
  const double t_hit = std::sqrt(2.0 * gap / g), speed = g * t_hit, after = 0.5 - t_hit;
  const std::vector<Contact> contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 2u * column + 1);  // down the column, the floor, back up
  EXPECT_NEAR(contacts.front().time, t_hit, 1e-12);
  for (const Contact& c : contacts) EXPECT_EQ(c.time, contacts.front().time);
  const Ball& dropped = world.balls().back();
  EXPECT_NEAR(dropped.position.y(), struck_at + speed * after - 0.5 * g * after * after, 1e-9);
  EXPECT_NEAR(dropped.velocity.y(), speed - g * after, 1e-9);
  for (int i = 0; i < column; ++i) {
    EXPECT_NEAR(world.balls()[i].position.y(), 0.5 + i, 1e-12) << "ball " << i;
    EXPECT_EQ(world.balls()[i].velocity, Vec2::Zero()) << "ball " << i;
  }
}

Ball inGroup(Ball b, int group) {
  b.group = group;
  return b;
}

TEST(World, BallsOfOneGroupPassThroughEachOtherAndStrikeEveryOtherBall) {
  // Two balls of group 1 head-on pass through each other; the first then strikes a still ball
  // of group 2 once 1 m from its centre, at t = (5 - 1 + 2) / 2 = 3 s: equal masses, e = 1, so
  // it stops there and the other leaves at 2 m/s.
  World world(kNoGravity);
  world.addBall(inGroup(ball({-2.0, 0.0}, {2.0, 0.0}), 1));
  world.addBall(inGroup(ball({2.0, 0.0}, {-2.0, 0.0}), 1));
  world.addBall(inGroup(ball({5.0, 0.0}, {0.0, 0.0}), 2));
  run(world, 4.0, 0.01);
  const std::vector<Contact> contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].time, 3.0, 1e-12);
  EXPECT_EQ(contacts[0].ball_id, 1u);
  EXPECT_EQ(contacts[0].other_id, 3u);
  EXPECT_NEAR(world.balls()[0].position.x(), 4.0, 1e-12);
  EXPECT_NEAR(world.balls()[1].position.x(), -6.0, 1e-12);
  EXPECT_NEAR(world.balls()[2].position.x(), 7.0, 1e-12);
  EXPECT_NEAR(world.balls()[2].velocity.x(), 2.0, 1e-12);
  // One group's balls may even start inside each other; a ball of another may not.
  World crowded(kNoGravity);
  crowded.addBall(inGroup(ball({0.0, 0.0}, {1.0, 0.0}), 1));
  EXPECT_NO_THROW(crowded.addBall(inGroup(ball({0.3, 0.0}, {-1.0, 0.0}), 1)));
  EXPECT_THROW(crowded.addBall(ball({0.0, 0.6}, {0.0, 0.0})), std::invalid_argument);
  run(crowded, 1.0, 0.01);
  EXPECT_EQ(crowded.takeContacts().size(), 0u);
  EXPECT_EQ(brokenInvariant(crowded, 1e-9), std::nullopt);
}

TEST(World, AddBallRefusesBadInputAndKeepsTheWorld) {
  World world(kNoGravity);
  world.addBall(ball({0.0, 0.0}, {0.0, 0.0}));
  EXPECT_THROW(world.addBall(ball({5.0, 0.0}, {0.0, 0.0}, std::nan(""))), std::invalid_argument);
  EXPECT_THROW(world.addBall(ball({5.0, 0.0}, {0.0, 0.0}, 0.5, -1.0)), std::invalid_argument);
  EXPECT_THROW(world.addBall(inGroup(ball({5.0, 0.0}, {0.0, 0.0}), -1)), std::invalid_argument);
  EXPECT_THROW(world.addBall(ball({0.5, 0.0}, {0.0, 0.0})), std::invalid_argument);
  try {
    world.addBall(ball({5.0, 0.0}, {0.0, 0.0}, -0.1));
    FAIL() << "negative radius accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("radius must be > 0"), std::string::npos);
  }
  EXPECT_EQ(world.balls().size(), 1u);
}

TEST(World, ElasticBallsInABoxKeepTheirEnergyAndNeverLeaveOrOverlap) {
  // 40 balls at random speeds up to 20 m/s (a step is up to 16 radii long) in a 10 m box,
  // e = 1, no gravity: kinetic energy is conserved through every impact.
  World world(kNoGravity);
  const double half = 5.0, r = 0.1;
  addBox(world, half);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> speed(-14.0, 14.0);
  for (int i = 0; i < 40; ++i)
    world.addBall(ball({-4.5 + 1.0 * (i % 10), -3.0 + 2.0 * (i / 10)}, {speed(rng), speed(rng)}, r,
                       1.0 + 0.1 * (i % 3)));
  auto energy = [&] {
    double e = 0.0;
    for (const Ball& b : world.balls()) e += 0.5 * b.mass * b.velocity.squaredNorm();
    return e;
  };
  const double e0 = energy();
  std::size_t impacts = 0;
  for (int step = 0; step < 600; ++step) {
    world.step(1.0 / 60.0);
    impacts += world.takeContacts().size();
    const auto& balls = world.balls();
    for (std::size_t i = 0; i < balls.size(); ++i) {
      ASSERT_LE(std::abs(balls[i].position.x()), half - r + 1e-9) << "ball " << balls[i].id;
      ASSERT_LE(std::abs(balls[i].position.y()), half - r + 1e-9) << "ball " << balls[i].id;
      for (std::size_t j = i + 1; j < balls.size(); ++j)
        ASSERT_GE((balls[i].position - balls[j].position).norm(), 2 * r - 1e-9);
    }
  }
  EXPECT_GT(impacts, 500u);
  EXPECT_NEAR(energy() / e0, 1.0, 1e-9);
}

TEST(World, AThousandElasticBallsKeepTheirEnergyAndTheMomentumTheWallsLeaveFor10s) {
  // Billiards: 1000 balls at random speeds up to 3 m/s in a 50 m box, e = 1, no gravity.
  // Ball/ball impulses cancel in pairs, so the momentum changes by the walls' impulses alone.
  World world(kNoGravity);
  const double half = 25.0, r = 0.2;
  addBox(world, half);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> speed(-3.0 / std::sqrt(2.0), 3.0 / std::sqrt(2.0));
  for (int i = 0; i < 1000; ++i)
    world.addBall(ball({-19.5 + 1.0 * (i % 40), -12.0 + 1.0 * (i / 40)}, {speed(rng), speed(rng)},
                       r, 1.0 + 0.1 * (i % 3)));
  auto momentum = [&] {
    Vec2 p = Vec2::Zero();
    for (const Ball& b : world.balls()) p += b.mass * b.velocity;
    return p;
  };
  const double e0 = mechanicalEnergy(world);
  const Vec2 p0 = momentum();
  Vec2 from_walls = Vec2::Zero();
  std::size_t impacts = 0;
  for (int step = 0; step < 600; ++step) {
    world.step(1.0 / 60.0);
    for (const Contact& c : world.takeContacts()) {
      ++impacts;
      if (c.other_kind != ContactKind::kBall) from_walls += c.impulse * c.normal;
    }
    for (const Ball& b : world.balls())
      ASSERT_LE(b.position.cwiseAbs().maxCoeff(), half - r + 1e-9) << "ball " << b.id;
    if (step % 60 == 59) {
      ASSERT_FALSE(brokenInvariant(world, 1e-6 * r)) << step;
    }
  }
  EXPECT_GT(impacts, 5000u);
  EXPECT_NEAR(mechanicalEnergy(world) / e0, 1.0, 1e-9);
  EXPECT_NEAR((momentum() - p0 - from_walls).norm(), 0.0, 1e-9 * 3.0 * 1000);
}

TEST(World, ThousandsOfRandomScenesWithBulletsNeitherTunnelNorBreakAnInvariant) {
  // A 4 m box split by a wall of no thickness; each side holds 3 balls, some of them bullets
  // that cross 100 radii a step. None may cross the wall or leave the box, overlap by more
  // than 1e-6 of a radius, turn NaN, or gain energy (every e <= 1).
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (unsigned seed = 0; seed < 2000; ++seed) {
    std::mt19937 rng(seed);
    World world(seed % 2 ? Vec2(0.0, -9.81) : kNoGravity);
    addBox(world, 2.0, Vec2(2.0, 2.0));
    world.addSegment(segment({2.0, 0.0}, {2.0, 4.0}, 0.5 + 0.5 * unit(rng)));
    std::vector<bool> left;
    double smallest = 1.0;
    for (int n = 0; n < 6; ++n) {
      const double radius = 0.02 + 0.08 * unit(rng);
      const bool bullet = unit(rng) < 0.3;
      const double speed = bullet ? 100.0 * radius / kFrameStep : 3.0 * unit(rng);
      const double heading = 2.0 * M_PI * unit(rng);
      const double x = (n % 2 ? 2.2 : 0.2) + 1.6 * unit(rng);
      try {
        world.addBall(ball({x, 0.2 + 3.6 * unit(rng)},
                           speed * Vec2(std::cos(heading), std::sin(heading)), radius,
                           0.5 + unit(rng), 0.5 + 0.5 * unit(rng)));
        left.push_back(x < 2.0);
        smallest = std::min(smallest, radius);
      } catch (const std::invalid_argument&) {  // overlaps one already there
      }
    }
    const double e0 = mechanicalEnergy(world);
    for (int step = 0; step < 30; ++step) {
      world.step(kFrameStep);
      const auto& balls = world.balls();
      for (std::size_t i = 0; i < balls.size(); ++i) {
        const Ball& b = balls[i];
        const double wall_gap = left[i] ? 2.0 - b.position.x() : b.position.x() - 2.0;
        ASSERT_GE(wall_gap, b.radius * (1.0 - 1e-6)) << "seed " << seed << " ball " << b.id;
        ASSERT_LE((b.position - Vec2(2.0, 2.0)).cwiseAbs().maxCoeff(), 2.0 - b.radius * (1.0 - 1e-6))
            << "seed " << seed << " ball " << b.id;
      }
      ASSERT_FALSE(brokenInvariant(world, 1e-6 * smallest)) << "seed " << seed;
      ASSERT_LE(mechanicalEnergy(world), e0 + 1e-9 * std::abs(e0)) << "seed " << seed;
    }
  }
}

TEST(World, CrowdedRandomBoxesOfRoughAndSmoothBallsNeverOverlapNorGainEnergy) {
  // Up to 27 balls of radius 0.05 to 0.15 m, some rough and spinning, thrown about a 4 m box
  // with a slope in it under gravity: they bounce, pile up, roll and wedge. Among them are
  // touching pairs their hold gives no force, which the accelerations later press together,
  // and rough balls spinning on smooth ones.
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (unsigned seed = 0; seed < 40; ++seed) {
    std::mt19937 rng(seed);
    World world(Vec2(0.0, -9.81));
    // One draw per statement: the order in which arguments are evaluated is unspecified.
    auto wall = [&](Vec2 from, Vec2 to) {
      Segment s = segment(from, to, 0.3 + 0.7 * unit(rng));
      s.friction = unit(rng) < 0.4 ? unit(rng) : 0.0;
      s.thickness = 0.02;
      world.addSegment(s);
    };
    wall({-2.0, -2.0}, {2.0, -2.0});
    wall({-2.0, 2.0}, {2.0, 2.0});
    wall({-2.0, -2.0}, {-2.0, 2.0});
    wall({2.0, -2.0}, {2.0, 2.0});
    wall({-1.0, -0.5}, {0.5, -1.2});
    const int wanted = 3 + static_cast<int>(25.0 * unit(rng));
    for (int tries = 0, added = 0; tries < 5 * wanted && added < wanted; ++tries) {
      Ball b;
      b.radius = 0.05 + 0.1 * unit(rng);
      b.position.x() = 3.4 * unit(rng) - 1.7;
      b.position.y() = 3.4 * unit(rng) - 1.7;
      b.velocity.x() = 4.0 * unit(rng) - 2.0;
      b.velocity.y() = 4.0 * unit(rng) - 2.0;
      b.restitution = unit(rng) < 0.3 ? 1.0 : unit(rng);
      b.friction = unit(rng) < 0.3 ? unit(rng) : 0.0;
      b.angular_velocity = unit(rng) < 0.3 ? 10.0 * unit(rng) : 0.0;
      b.mass = 0.5 + unit(rng);
      try {
        world.addBall(b);
        ++added;
      } catch (const std::invalid_argument&) {  // overlaps one already there
      }
    }
    double energy = mechanicalEnergy(world);
    for (int step = 0; step < 120; ++step) {
      world.step(kFrameStep);
      ASSERT_FALSE(brokenInvariant(world, mostSettledOverlap(world)))
          << "seed " << seed << " step " << step;
      const double now = mechanicalEnergy(world);
      ASSERT_LE(now, energy + 1e-9 * std::abs(energy)) << "seed " << seed << " step " << step;
      energy = now;
    }
  }
}

namespace {

// The benchmark's pile: n rough balls (mu 0.3, e 0.5 with walls and each other) dropped from a
// grid 1.2 diameters apart, `columns` wide and shifted sideways at random, into a closed box,
// added to `world`; the box's lower left corner at `corner`, the grid `raised` above where the
// benchmark has it.
World benchmarksPile(int n, int columns, World world = World(Vec2(0.0, -kG)),
                     const Vec2& corner = Vec2::Zero(), double raised = 0.0) {
  const double r = 0.5, spacing = 1.2 * 2.0 * r;
  const int rows = (n + columns - 1) / columns;
  const double width = columns * spacing + 0.2, height = rows * spacing + 2.0 + raised;
  const Vec2 corners[] = {{0.0, 0.0}, {width, 0.0}, {width, height}, {0.0, height}};
  for (int k = 0; k < 4; ++k) {
    Segment wall = segment(corner + corners[k], corner + corners[(k + 1) % 4]);
    wall.restitution = std::sqrt(0.5);
    wall.friction = 0.3;
    world.addSegment(wall);
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int i = 0; i < n; ++i) {
    Ball b = ball(corner + Vec2(0.1 + spacing * (i % columns + 0.5) + jitter(rng),
                                0.2 + raised + spacing * (i / columns + 0.5)),
                  {0, 0}, r);
    b.restitution = std::sqrt(0.5);
    b.friction = 0.3;
    world.addBall(b);
  }
  return world;
}

bool allAtRest(const World& world) {
  return std::all_of(world.balls().begin(), world.balls().end(),
                     [](const Ball& b) { return b.at_rest && b.velocity == Vec2::Zero(); });
}

// No ball rests in the air: each touches the floor at y = 0 or a ball below its centre, within
// `within_share` of its radius.
void expectEachOnTheFloorOrABallBelow(const World& world, double within_share) {
  for (const Ball& b : world.balls()) {
    const double within = within_share * b.radius;
    bool held = b.position.y() - b.radius <= within;
    for (const Ball& other : world.balls())
      held = held || (other.position.y() < b.position.y() && surfaceGap(b, other) <= within);
    EXPECT_TRUE(held) << "ball " << b.id << " at " << b.position.transpose();
  }
}

// Steps `world` for 60 s of sim time: every ball stays where it rests, still, and apart.
void expectStillFor60Seconds(World& world, double overlap_tolerance) {
  const std::vector<Ball> rested = world.balls();
  for (int step = 0; step < 3600; ++step) {
    world.step(kFrameStep);
    if (step % 600 == 599) {
      ASSERT_FALSE(brokenInvariant(world, overlap_tolerance));
    }
  }
  EXPECT_TRUE(allAtRest(world));
  for (std::size_t i = 0; i < rested.size(); ++i)
    EXPECT_EQ(world.balls()[i].position, rested[i].position) << "ball " << i;
}

}  // namespace

TEST(World, ARoughPileThatRunsOutOfTheStepsBudgetSettlesToRestApartWithoutGainingEnergy) {
  // 64 balls: landing, they strike each other far more often than a step's budget allows, and
  // settle whole, step after step. Every step they stay apart (to 1e-3 r) and the pile's
  // energy never grows; within 10 s it rests, and stays so for 60 s.
  World world = benchmarksPile(64, 8);
  double energy = mechanicalEnergy(world);
  int step = 0;
  for (; step < 600 && !allAtRest(world); ++step) {
    world.step(kFrameStep);
    ASSERT_FALSE(brokenInvariant(world, kMostSettledOverlap * 0.5)) << "step " << step;
    const double now = mechanicalEnergy(world);
    ASSERT_LE(now, energy + 1e-9 * std::abs(energy)) << "step " << step;
    energy = now;
  }
  ASSERT_TRUE(allAtRest(world)) << "after " << step << " steps";
  expectStillFor60Seconds(world, kMostSettledOverlap * 0.5);
}

TEST(World, ABallDroppedOnASleepingPileBouncesOffItAsItsRestitutionSays) {
  // A pile of 16 smooth balls in four columns, snug between two walls, cannot give way: struck
  // from above, it takes the blow as the floor under it would. A ball dropped from h above it
  // meets its top at sqrt(2 g h) and leaves at e times that (e the pair's restitution, the
  // product of both), slowed by gravity since, up to about e^2 h above the point where they
  // met; the pile stays where it slept, and sleeps again.
  const double r = 0.5, e = 0.5, h = 1.0, width = 8.0 * r + 1e-9;
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({0.0, 0.0}, {width, 0.0}));
  world.addSegment(segment({0.0, 0.0}, {0.0, 10.0}));
  world.addSegment(segment({width, 0.0}, {width, 10.0}));
  for (int column = 0; column < 4; ++column)
    for (int row = 0; row < 4; ++row)
      world.addBall(ball({(2 * column + 1) * r, (2 * row + 1) * r + 0.01 * (row + 1)},
                         {0.0, 0.0}, r, 1.0, e));
  for (int step = 0; step < 600 && !allAtRest(world); ++step) world.step(kFrameStep);
  ASSERT_TRUE(allAtRest(world));
  const std::vector<Ball> slept = world.balls();
  const double top = slept[7].position.y() + 2.0 * r;  // where they meet: column 1's top
  const BallId dropped = world.addBall(ball({3.0 * r, top + h}, {0.0, 0.0}, r, 1.0, 1.0));
  const double meeting = std::sqrt(2.0 * kG * h), met = world.time() + std::sqrt(2.0 * h / kG);
  double highest = 0.0, leaving = 0.0;
  for (int step = 0; step < 120; ++step) {
    world.step(kFrameStep);
    const Ball& b = *world.findBall(dropped);
    if (leaving == 0.0 && b.velocity.y() > 0.0) {  // e times the speed it met at, slowed since
      leaving = b.velocity.y();
      EXPECT_NEAR(leaving, e * meeting - kG * (world.time() - met), 1e-2 * e * meeting);
    }
    if (leaving > 0.0) highest = std::max(highest, b.position.y() - top);
  }
  ASSERT_GT(leaving, 0.0);
  // No higher than e^2 h; short of it by what its first steps in straight lines with the pile
  // lose (half g dt^2 a step).
  EXPECT_LE(highest, e * e * h);
  EXPECT_GT(highest, 0.97 * e * e * h);
  for (int step = 0; step < 600 && !allAtRest(world); ++step) world.step(kFrameStep);
  EXPECT_TRUE(allAtRest(world));
  for (std::size_t i = 0; i < slept.size(); ++i)
    EXPECT_LT((world.balls()[i].position - slept[i].position).norm(), 1e-3 * r) << "ball " << i;
}

TEST(World, BallsRainedOnASleepingPileWakeOnlyTheBallsNearWhereTheyLandAndItSleepsWhereStill) {
  // The 64-ball rough pile asleep; 12 balls of its kind dropped on it from 2 m above its top, one
  // every 0.25 s, across its width. Each strike wakes the balls within two touches of the ball
  // it lands on; the others hold still, as the floor does, and slower approaches (balls
  // creeping after a strike) wake none. So the balls on the floor, rows down, never wake
  // and never move, not by a bit. While it rains, at least half the pile sleeps at each drop
  // (still balls that no moving one presses on rest whatever the others do), and within 10 s
  // of the last drop every ball rests, nothing overlapping past what a settle may leave.
  const double r = 0.5;
  World world = benchmarksPile(64, 8);
  for (int step = 0; step < 600 && !allAtRest(world); ++step) world.step(kFrameStep);
  ASSERT_TRUE(allAtRest(world));
  const std::vector<Ball> slept = world.balls();
  std::vector<std::size_t> on_floor;
  double top = 0.0;
  for (std::size_t i = 0; i < slept.size(); ++i) {
    if (slept[i].position.y() < r + 1e-6) on_floor.push_back(i);
    top = std::max(top, slept[i].position.y() + r);
  }
  ASSERT_GE(on_floor.size(), 7u);
  auto expectFloorUnmoved = [&](int step) {
    for (const std::size_t i : on_floor) {
      ASSERT_TRUE(world.balls()[i].at_rest) << "ball " << i << ", step " << step;
      ASSERT_EQ(world.balls()[i].position, slept[i].position) << "ball " << i << ", step " << step;
    }
  };
  int step = 0;
  for (int drop = 0; drop < 12; ++drop) {
    const auto resting = std::count_if(slept.begin(), slept.end(), [&](const Ball& b) {
      return world.findBall(b.id)->at_rest;
    });
    EXPECT_GE(resting, 32) << "drop " << drop;
    Ball b = ball({1.0 + 1.1 * (drop % 8), top + 2.0}, {0.0, 0.0}, r);
    b.restitution = std::sqrt(0.5);
    b.friction = 0.3;
    world.addBall(b);
    for (int k = 0; k < 15; ++k, ++step) {
      world.step(kFrameStep);
      expectFloorUnmoved(step);
    }
  }
  for (int k = 0; k < 600 && !allAtRest(world); ++k, ++step) {
    world.step(kFrameStep);
    expectFloorUnmoved(step);
  }
  EXPECT_TRUE(allAtRest(world));
  EXPECT_FALSE(brokenInvariant(world, kMostSettledOverlap * 0.5));
  // None rests in the air, though the strikes woke only the balls near them: within what a
  // settle may leave (a resting ball whose support a settle moves farther wakes:
  // World::recordUnheld).
  expectEachOnTheFloorOrABallBelow(world, kMostSettledOverlap);
}

TEST(World, ABallRestingOnOneThatAStrikeWakesAndMovesAwayFallsInsteadOfHanging) {
  // A sleeping row of 16 rough balls on a floor, the last free on its right, and a 17th asleep
  // on the crown of the last. A ball dropped just right of the notch after the 13th strikes
  // the 14th: the strike wakes the balls within two touches of it (the last two), which roll
  // right, and the ball on top, three touches away, is not among them. It wakes when its
  // support rolls off: a resting ball is never apart from every ball below it and the floor
  // by more than a settle's allowance.
  const double r = 0.5;
  World world(Vec2(0.0, -kG));
  Segment floor = segment({-1.0, 0.0}, {40.0, 0.0});
  Segment wall = segment({0.0, 0.0}, {0.0, 5.0});
  floor.friction = wall.friction = 0.3;
  world.addSegment(floor);
  world.addSegment(wall);
  auto rough = [&](Vec2 position, Vec2 velocity) {
    Ball b = ball(position, velocity, r);
    b.friction = 0.3;
    return world.addBall(b);
  };
  for (int i = 0; i < 16; ++i) rough({r + i, r}, {0.0, 0.0});
  const BallId top = rough({15.5, 1.5}, {0.0, 0.0});
  for (int step = 0; step < 60 && !allAtRest(world); ++step) world.step(kFrameStep);
  ASSERT_TRUE(allAtRest(world));
  rough({14.05, 3.0}, {0.0, -5.0});
  bool top_woke = false;
  for (int step = 0; step < 60; ++step) {
    world.step(kFrameStep);
    top_woke = top_woke || !world.findBall(top)->at_rest;
    for (const Ball& b : world.balls()) {
      if (!b.at_rest) continue;
      bool held = b.position.y() - r <= kMostSettledOverlap * r;
      for (const Ball& other : world.balls())
        held = held || (other.position.y() < b.position.y() &&
                        surfaceGap(b, other) <= kMostSettledOverlap * r);
      ASSERT_TRUE(held) << "ball " << b.id << " at " << b.position.transpose() << ", step "
                        << step;
    }
  }
  EXPECT_TRUE(top_woke);
}

TEST(World, ABodyAddedRemovedOrMovedFarFromASettlingPileChangesNothingInIt) {
  // One second into the 64-ball pile's landing, with a ball falling and a segment 90 m away,
  // the world is copied and each copy changed there. The pile's settles go on from their
  // impulses as they were (their pairs go by the bodies' ids), so for the next 30 steps its
  // balls are where the unchanged world's are, to the bit. (The far segment comes before the
  // pile's box, and the far ball after its balls, so that removing either moves the indices of
  // the box's walls.)
  World far(Vec2(0.0, -kG));
  const SegmentId far_segment = far.addSegment(segment({95.0, 0.0}, {105.0, 0.0}));
  World kept = benchmarksPile(64, 8, far);
  const BallId far_ball = kept.addBall(ball({100.0, 50.0}, {0.0, 0.0}));
  for (int step = 0; step < 60; ++step) kept.step(kFrameStep);
  const std::vector<std::pair<std::string, std::function<void(World&)>>> changes = {
      {"a ball added", [](World& w) { w.addBall(ball({110.0, 50.0}, {0.0, 0.0})); }},
      {"the ball removed", [&](World& w) { ASSERT_TRUE(w.removeBall(far_ball)); }},
      {"the ball moved",
       [&](World& w) { ASSERT_TRUE(w.setBallState(far_ball, {100.0, 40.0}, {1.0, 0.0}, 0.0)); }},
      {"a segment added", [](World& w) { w.addSegment(segment({110.0, 0.0}, {120.0, 0.0})); }},
      {"the segment removed", [&](World& w) { ASSERT_TRUE(w.removeSegment(far_segment)); }}};
  std::vector<World> changed(changes.size(), kept);
  for (std::size_t k = 0; k < changes.size(); ++k) changes[k].second(changed[k]);
  for (int step = 0; step < 30; ++step) {
    kept.step(kFrameStep);
    for (std::size_t k = 0; k < changes.size(); ++k) {
      changed[k].step(kFrameStep);
      for (std::size_t i = 0; i < 64; ++i)
        ASSERT_EQ(kept.balls()[i].position, changed[k].balls()[i].position)
            << changes[k].first << ", ball " << i << ", step " << step;
    }
  }
  EXPECT_FALSE(allAtRest(kept));  // (still settling all along)
}

TEST(World, TheBenchmarksPileOfAThousandBallsComesToRestAndStaysSoFor60Seconds) {
  // Within 15 s of sim time, every ball at rest, none overlapping by 1e-3 r on the way (checked
  // every 0.5 s: the check is O(N^2)) nor after, energy never above the start's.
  World world = benchmarksPile(1000, 32);
  const double start = mechanicalEnergy(world);
  int step = 0;
  for (; step < 900 && !allAtRest(world); ++step) {
    world.step(kFrameStep);
    world.takeContacts();
    if (step % 30 == 29) {
      ASSERT_FALSE(brokenInvariant(world, kMostSettledOverlap * 0.5)) << "step " << step;
      ASSERT_LE(mechanicalEnergy(world), start) << "step " << step;
    }
  }
  ASSERT_TRUE(allAtRest(world)) << "after " << step << " steps";
  expectStillFor60Seconds(world, kMostSettledOverlap * 0.5);
}

TEST(World, BallsRainingIntoTheDefaultBoxNeverHangStillWhileAwake) {
  // 150 balls of radius 0.1 dropped at random near the default box's ceiling, 10 a second, at
  // the node's 1/120 s steps: they land on each other, the ramps and the pyramid and settle.
  // Slowing a settle's balls where a gap closed past touching by rounding once froze whole
  // piles awake, still in mid-fall, step after step. Every second, no awake ball is where it
  // was a second before with no velocity at all, and no two bodies overlap by more than the
  // tests accept of a settle (kMostSettledOverlap).
  Scene scene = loadScene(SCENES_DIR "/default.yaml");
  World& world = scene.world;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-5.8, 5.8), y(7.0, 7.8);
  const double dt = 1.0 / 120.0;
  std::vector<Ball> second_ago = world.balls();
  for (int step = 1; step <= 120 * 17; ++step) {
    if (step % 12 == 1 && world.balls().size() < 156)
      for (int tries = 0; tries < 50; ++tries) {
        Ball b = ball({x(rng), y(rng)}, {0.0, 0.0}, 0.1, 1.0, 0.8);
        try {
          world.addBall(b);
          break;
        } catch (const std::invalid_argument&) {  // a place taken: another one
        }
      }
    world.step(dt);
    world.takeContacts();
    if (step % 120 != 0) continue;
    ASSERT_FALSE(brokenInvariant(world, kMostSettledOverlap * 0.1)) << "t = " << world.time();
    for (const Ball& b : world.balls()) {
      const auto before = std::find_if(second_ago.begin(), second_ago.end(),
                                       [&](const Ball& a) { return a.id == b.id; });
      ASSERT_FALSE(!b.at_rest && b.velocity == Vec2::Zero() && before != second_ago.end() &&
                   before->position == b.position)
          << "ball " << b.id << " hangs still, awake, at t = " << world.time();
    }
    second_ago = world.balls();
  }
  EXPECT_EQ(world.balls().size(), 156u);  // the scene's 6 and all 150 dropped
}

TEST(World, AnElasticBallBouncingFarFromASettlingPileKeepsItsExactBounce) {
  // The pile runs out of its steps' budgets and settles, step after step; the settle is the
  // pile's own. A ball bouncing elastically on its own floor 60 m away keeps its energy and
  // bounces exactly: up to h from the floor, back every 2 sqrt(2 h / g).
  World world = benchmarksPile(200, 16);
  const double r = 0.5, h = 1.0;
  world.addSegment(segment({80.0, 0.0}, {90.0, 0.0}));
  const BallId far = world.addBall(ball({85.0, r + h}, {0.0, 0.0}, r));
  const double period = 2.0 * std::sqrt(2.0 * h / kG);
  for (int step = 1; step <= 300; ++step) {
    world.step(kFrameStep);
    world.takeContacts();
    // Time since it was last at the top of its bounce: it falls from there.
    const double since_top = std::fmod(world.time() + 0.5 * period, period) - 0.5 * period;
    const Ball& b = *world.findBall(far);
    ASSERT_NEAR(b.position.y(), r + h - 0.5 * kG * since_top * since_top, 1e-9)
        << "step " << step;
    ASSERT_NEAR(b.velocity.y(), -kG * since_top, 1e-9) << "step " << step;
  }
}

TEST(World, ABallThatLeftASettlingPileMeetsAWallInTheStepItLeavesTheSettleBehind) {
  // Four smooth balls lying in a row on a floor are a pile, settled from the first step, and a
  // fifth touching its end, sliding away at 30 m/s, settles with them (it may meet them). In
  // the second step it is 0.5 m away, alone, and no settle takes it: it meets the wall 0.2 m
  // on, 1/150 s into the step, and bounces back elastically at 30 m/s.
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-10.0, 0.0}, {10.0, 0.0}));
  world.addSegment(segment({1.6, 0.0}, {1.6, 1.0}));
  const double r = 0.1, speed = 30.0;
  for (int k = 0; k < 4; ++k) world.addBall(ball({2.0 * r * k, r}, {0.0, 0.0}, r));
  const BallId away = world.addBall(ball({0.8, r}, {speed, 0.0}, r));
  world.step(kFrameStep);
  ASSERT_NEAR(world.findBall(away)->position.x(), 0.8 + speed * kFrameStep, 1e-9);
  world.step(kFrameStep);
  const Ball& b = *world.findBall(away);
  const double met = (1.6 - r - 1.3) / speed;
  EXPECT_NEAR(b.position.x(), 1.6 - r - speed * (kFrameStep - met), 1e-9);
  EXPECT_NEAR(b.velocity.x(), -speed, 1e-9);
}

TEST(World, ABallThatLeftASettlingPileInFlightFollowsItsParabolaOnceAlone) {
  // A ball flying away from a settling pile (four balls lying in a row on a floor), 2 mm
  // above the floor, settles with it in the first step: in a straight line, at its velocity at
  // the step's end, level. In the second it is alone but for the floor, which it does not
  // reach in the step, and no settle takes it: it follows its parabola exactly.
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-10.0, 0.0}, {10.0, 0.0}));
  const double r = 0.1;
  for (int k = 0; k < 4; ++k) world.addBall(ball({2.0 * r * k, r}, {0.0, 0.0}, r));
  const Vec2 p0(0.8, r + 0.002), v0(6.0, kG * kFrameStep), g(0.0, -kG);
  const BallId away = world.addBall(ball(p0, v0, r));
  world.step(kFrameStep);
  const Ball first = *world.findBall(away);
  const Vec2 v1 = v0 + g * kFrameStep;
  ASSERT_NEAR((first.position - (p0 + v1 * kFrameStep)).norm(), 0.0, 1e-12);  // settled
  ASSERT_NEAR((first.velocity - v1).norm(), 0.0, 1e-12);
  world.step(kFrameStep);
  const Ball& b = *world.findBall(away);
  const Vec2 p2 = first.position + v1 * kFrameStep + 0.5 * g * kFrameStep * kFrameStep;
  EXPECT_NEAR((b.position - p2).norm(), 0.0, 1e-12);
  EXPECT_NEAR((b.velocity - (v1 + g * kFrameStep)).norm(), 0.0, 1e-12);
}

TEST(World, ARowOfBallsCreepingAlongAFloorSlowerThanTheSleepSpeedRestsAfterTheTimeToSleep) {
  // 16 smooth balls touching in a row on a floor, all sliding at 5 mm/s: a pile, settled from
  // the first step. Exact, they would slide on for ever; slower than 1e-2 m/s for 0.5 s, they
  // rest (Box2D's rule), after sliding 2.5 mm.
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-10.0, 0.0}, {30.0, 0.0}));
  const double r = 0.5, speed = 0.005;
  for (int k = 0; k < 16; ++k) world.addBall(ball({2.0 * r * k, r}, {speed, 0.0}, r));
  const double time_to_sleep = 0.5;
  for (int step = 1; step <= 40; ++step) {
    world.step(kFrameStep);
    if (step * kFrameStep < time_to_sleep - 1e-9) {
      for (const Ball& b : world.balls()) {
        ASSERT_FALSE(b.at_rest) << "step " << step;
        ASSERT_NEAR(b.velocity.x(), speed, 1e-9) << "step " << step;
      }
    }
  }
  ASSERT_TRUE(allAtRest(world));
  for (int k = 0; k < 16; ++k)
    EXPECT_NEAR(world.balls()[k].position.x(), 2.0 * r * k + speed * time_to_sleep, 1e-9);
}

namespace {

// Whether the first `count` balls of the two worlds are where the other's are, to the bit, and
// rest alike.
::testing::AssertionResult sameBalls(const World& a, const World& b, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i)
    if (a.balls()[i].position != b.balls()[i].position ||
        a.balls()[i].at_rest != b.balls()[i].at_rest)
      return ::testing::AssertionFailure() << "ball " << i << " differs";
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(World, APileLandingBesideAnotherOneFarAwayLandsAndSleepsAsItWouldAlone) {
  // The 64-ball pile, and in the other world the same pile beside another one 100 m away whose
  // balls start 10 m higher, so that it lands while the first settles. Each island settles on
  // its own, and each group of balls that may meet spends its own budgets of events, so the
  // first pile's balls are where they are alone, to the bit, through its landing, its settling
  // and its sleep (all 64 asleep by 5 s).
  World alone = benchmarksPile(64, 8);
  World beside = benchmarksPile(64, 8, alone, {100.0, 0.0}, 10.0);
  int both_settling = 0;  // steps with the first pile awake and the other one landed
  for (int step = 1; step <= 300; ++step) {
    alone.step(kFrameStep);
    beside.step(kFrameStep);
    ASSERT_TRUE(sameBalls(alone, beside, 64)) << "step " << step;
    const bool other_landed =
        std::any_of(beside.balls().begin() + 64, beside.balls().end(),
                    [](const Ball& b) { return b.position.y() < 0.5 + 1e-3; });
    both_settling += other_landed && !allAtRest(alone);
  }
  EXPECT_TRUE(allAtRest(alone));
  EXPECT_GT(both_settling, 30);
}

namespace {

// Heaps of eight rough balls, two columns of four laid out as the benchmark's heaps are, but
// 20 m apart along one open floor 1.4 km long.
World heapsOnOneFloor(int heaps) {
  World world(Vec2(0.0, -kG));
  Segment floor = segment({-50.0, 0.0}, {1350.0, 0.0});
  floor.restitution = std::sqrt(0.5);
  floor.friction = 0.3;
  world.addSegment(floor);
  const double r = 0.5, spacing = 1.2 * 2.0 * r;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int heap = 0; heap < heaps; ++heap)
    for (int k = 0; k < 8; ++k) {
      Ball b = ball({heap * 20.0 + spacing * (k % 2) + jitter(rng), 0.2 + spacing * (k / 2 + 0.5)},
                    {0, 0}, r);
      b.restitution = std::sqrt(0.5);
      b.friction = 0.3;
      world.addBall(b);
    }
  return world;
}

}  // namespace

TEST(World, HeapsLandingFarApartOnOneFloorEachLandAsItWouldAlone) {
  // A floor passes nothing from one ball to another, so heaps far apart on it spend their own
  // budgets of events: the first heap lands, to the bit, as it does with the floor to itself,
  // beside 63 others landing at once, whose events would otherwise spend its budget.
  World alone = heapsOnOneFloor(1);
  World beside = heapsOnOneFloor(64);
  for (int step = 1; step <= 300; ++step) {
    alone.step(kFrameStep);
    beside.step(kFrameStep);
    ASSERT_TRUE(sameBalls(alone, beside, 8)) << "step " << step;
  }
  // (The comparison ran through the whole landing: the heap has come apart, every ball on the
  // floor.)
  for (const Ball& b : alone.balls()) EXPECT_NEAR(b.position.y(), 0.5, 1e-3);
}

TEST(World, APileStruckAsleepBouncesAsItWouldAloneWhileARowSlidesFarAway) {
  // The 64-ball pile sleeps, and a ball dropped on it strikes it. In the other world, 100 m
  // below, 16 smooth balls touching in a row slide along a floor at 1 m/s: a pile that settles
  // at every step. A pile's settles start from its own last impulses, kept for a few steps
  // after each and while it sleeps: what settles elsewhere has no say. The struck pile and the
  // dropped ball go as they would alone, to the bit.
  World alone = benchmarksPile(64, 8);
  World beside = benchmarksPile(64, 8);
  beside.addSegment(segment({-100.0, -100.0}, {900.0, -100.0}));
  const double r = 0.5;
  for (int k = 0; k < 16; ++k) beside.addBall(ball({2.0 * r * k, r - 100.0}, {1.0, 0.0}, r));
  const auto asleep = [](const World& world) {
    return std::all_of(world.balls().begin(), world.balls().begin() + 64,
                       [](const Ball& b) { return b.at_rest; });
  };
  for (int step = 1; step <= 300 && !asleep(alone); ++step) {
    alone.step(kFrameStep);
    beside.step(kFrameStep);
  }
  ASSERT_TRUE(asleep(alone));
  const auto top = std::max_element(
      alone.balls().begin(), alone.balls().end(),
      [](const Ball& a, const Ball& b) { return a.position.y() < b.position.y(); });
  const Vec2 above = top->position + Vec2(0.1, 1.5);
  const BallId dropped_alone = alone.addBall(ball(above, {0.0, 0.0}, r));
  const BallId dropped_beside = beside.addBall(ball(above, {0.0, 0.0}, r));
  bool woke = false;
  for (int step = 1; step <= 60; ++step) {
    alone.step(kFrameStep);
    beside.step(kFrameStep);
    ASSERT_TRUE(sameBalls(alone, beside, 64)) << "step " << step;
    ASSERT_EQ(alone.findBall(dropped_alone)->position, beside.findBall(dropped_beside)->position)
        << "step " << step;
    woke = woke || !asleep(alone);
    ASSERT_TRUE(std::none_of(beside.balls().begin() + 64, beside.balls().end() - 1,
                             [](const Ball& b) { return b.at_rest; }));
  }
  EXPECT_TRUE(woke);
}

TEST(World, APileLandingWhileAPlatformMovesAndAPendulumSwingsFarAwayLandsAndSleepsAsAlone) {
  // The 64-ball pile and a pendulum 100 m below, its rope held exactly, and in the other world
  // the same with a platform going to and fro (its events at 1 s, 2 s, ...) and a second
  // pendulum 100 m away. Neither can settle (a settle knows no rope, and the platform carries
  // nothing), but that is theirs alone: no settle mode is world-wide, a platform's event ends
  // the holds near it only, and a pendulum's events do not hold the pile anew. The pile and the
  // first pendulum go as they would alone, to the bit, and the pile sleeps.
  World alone = benchmarksPile(64, 8);
  World beside = benchmarksPile(64, 8);
  for (World* world : {&alone, &beside}) {
    Rope rope;
    rope.ball = world->addBall(ball({1.0, -100.0}, {0.0, 0.0}, 0.1));
    rope.anchor = Vec2(0.0, -100.0);
    world->addRope(rope);
  }
  Segment platform = segment({-101.0, 0.0}, {-99.0, 0.0});
  platform.pivot = Vec2(-100.0, 0.0);
  platform.waypoints = {Vec2(-100.0, 0.0), Vec2(-100.0, 1.0)};
  platform.speed = 1.0;
  beside.addSegment(platform);
  Rope rope;
  rope.ball = beside.addBall(ball({-99.0, 5.0}, {0.0, 0.0}, 0.1));
  rope.anchor = Vec2(-100.0, 5.0);
  beside.addRope(rope);
  for (int step = 1; step <= 300; ++step) {
    alone.step(kFrameStep);
    beside.step(kFrameStep);
    ASSERT_TRUE(sameBalls(alone, beside, 65)) << "step " << step;
  }
  EXPECT_TRUE(std::all_of(alone.balls().begin(), alone.balls().begin() + 64,
                          [](const Ball& b) { return b.at_rest; }));
  EXPECT_FALSE(beside.balls().back().at_rest);  // (the pendulums swing on)
}

namespace {

// Adds a ball thrown from 100 m along x, and steps the world while it is on its exact parabola
// after every step, nothing in the world overlapping by more than `overlap_tolerance` m.
void stepBesideABallThrown100mAway(World& world, int steps, double overlap_tolerance = 1e-9) {
  const Vec2 from(100.0, 0.0), thrown(1.0, 2.0);
  const BallId free = world.addBall(ball(from, thrown, 0.1));
  for (int step = 1; step <= steps; ++step) {
    world.step(kFrameStep);
    const double t = step * kFrameStep;
    ASSERT_NEAR((world.findBall(free)->position -
                 (from + thrown * t + 0.5 * world.gravity() * t * t)).norm(),
                0.0, 1e-9)
        << "step " << step;
    ASSERT_EQ(brokenInvariant(world, overlap_tolerance), std::nullopt) << "step " << step;
  }
}

}  // namespace

TEST(World, AStruggleThatRunsOutOfTheStepsBudgetWaitsWhileTheOtherBallsGoOn) {
  // A ball whirled at 20 m/s on a 2 cm rope needs a hold renewed every few microseconds, more
  // than a step's budget allows: it waits for the rest of each step, and keeps its speed for
  // the next. A ball thrown 100 m away is on its exact parabola after every step all the same.
  World world(Vec2(0.0, -9.81));
  const BallId whirled = world.addBall(ball({0.02, 0.0}, {0.0, 20.0}, 0.005));
  Rope rope;
  rope.ball = whirled;
  rope.length = 0.02;
  world.addRope(rope);
  stepBesideABallThrown100mAway(world, 30);
  const Ball& b = *world.findBall(whirled);
  EXPECT_FALSE(b.at_rest);
  EXPECT_NEAR(b.velocity.norm(), 20.0, 0.1);
}

namespace {

// Where the segment `id` starts along x.
double segmentStartX(const World& world, SegmentId id) {
  return std::find_if(world.segments().begin(), world.segments().end(),
                      [&](const Segment& s) { return s.id == id; })
      ->start.x();
}

// A pusher closing at 0.5 m/s on a row of six balls (r 0.25, e 0) on a smooth floor, pressing
// it against a wall from 0.2 s: at 1 s it stands jammed 12 r from the wall.
struct JammedPusher {
  static constexpr double kRadius = 0.25;
  World world{Vec2(0.0, -kG)};
  SegmentId wall, pusher;
  JammedPusher() {
    world.addSegment(segment({-10.0, 0.0}, {5.0, 0.0}, 0.5));
    wall = world.addSegment(segment({0.0, 0.0}, {0.0, 2.0}, 0.5));
    Segment closing = segment({3.1, 0.0}, {3.1, 2.0}, 0.5);
    closing.velocity = Vec2(-0.5, 0.0);
    pusher = world.addSegment(closing);
    for (int k = 0; k < 6; ++k)
      world.addBall(ball({kRadius * (1.0 + 2.0 * k), kRadius}, {0.0, 0.0}, kRadius, 1.0, 0.0));
    run(world, 1.0);
  }
  double pusherX() const { return segmentStartX(world, pusher); }
};

}  // namespace

TEST(World, ABallCrushedBetweenAMovingSegmentAndAWallStopsTheSegmentWhileTheOthersGoOn) {
  // A pusher closing on a wall at 0.5 m/s meets a ball on the floor between them. The ball
  // cannot give way: the pusher stops against it, the ball stays whole between them, and a
  // ball thrown 100 m away is on its exact parabola after every step.
  const double r = 0.5;
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-1.0, 0.0}, {3.0, 0.0}, 0.5));
  world.addSegment(segment({0.0, 0.0}, {0.0, 2.0}, 0.5));
  Segment pusher = segment({1.2, 0.0}, {1.2, 2.0}, 0.5);
  pusher.velocity = Vec2(-0.5, 0.0);
  const SegmentId pusher_id = world.addSegment(pusher);
  const BallId crushed = world.addBall(ball({0.6, r}, {0.0, 0.0}, r, 1.0, 0.5));
  stepBesideABallThrown100mAway(world, 120);
  const Ball& b = *world.findBall(crushed);
  EXPECT_NEAR(b.position.x(), r, 1e-9);
  EXPECT_NEAR(segmentStartX(world, pusher_id), 2.0 * r, 1e-9);
}

TEST(World, APusherJammedOnARowAgainstAWallGoesOnAtOnceWhenTheWallIsTakenAway) {
  // Taken away, the wall holds nothing: the pusher goes on at once, pushing the row along the
  // smooth floor, every step.
  JammedPusher jam;
  const double jammed_at = 12.0 * JammedPusher::kRadius;
  ASSERT_NEAR(jam.pusherX(), jammed_at, 1e-9);
  jam.world.removeSegment(jam.wall);
  for (int step = 1; step <= 60; ++step) {
    jam.world.step(kFrameStep);
    ASSERT_NEAR(jam.pusherX(), jammed_at - 0.5 * step * kFrameStep, 1e-9) << "step " << step;
  }
}

TEST(World, APusherJammedOnARowAndSentBackGoesBackAtOnce) {
  // A jammed segment stands still between its tries, a tenth of a second apart. Sent back (its
  // motion set anew), it goes back at once, every step.
  JammedPusher jam;
  const double jammed_at = 12.0 * JammedPusher::kRadius;
  ASSERT_NEAR(jam.pusherX(), jammed_at, 1e-9);
  ASSERT_TRUE(jam.world.setSegmentMotion(jam.pusher, Vec2(0.5, 0.0), 0.0));
  for (int step = 1; step <= 30; ++step) {
    jam.world.step(kFrameStep);
    ASSERT_NEAR(jam.pusherX(), jammed_at + 0.5 * step * kFrameStep, 1e-9) << "step " << step;
  }
}

TEST(World, APileSunkInWaterAndBlownAgainstAWallSleepsThereWhileABallFarAwayGoesOn) {
  // 64 rough balls, too heavy to float, dropped into a pond in a box that a wind blows along
  // +x: they sink and pile up in the corner it blows them into. The pile settles as one under
  // gravity, buoyancy, drag and wind, and sleeps there: the ball in the corner touches the
  // floor and the wall. A ball thrown 100 m away, outside the pond and the wind, is on its
  // exact parabola after every step.
  const double r = 0.1, half = 3.0;
  World world(Vec2(0.0, -kG));
  addBox(world, half, {0.0, half}, 0.5);
  Water pond;
  pond.region = {{-half, 0.0}, {half, 1.0}};
  pond.drag = 3.0;
  world.addWater(pond);
  Wind wind;
  wind.region = {{-half, 0.0}, {half, 2.0 * half}};
  wind.acceleration = Vec2(4.0, 0.0);
  world.addWind(wind);
  std::vector<BallId> pile;
  for (int k = 0; k < 64; ++k) {
    Ball b = ball({-1.0 + 0.25 * (k % 8) + 0.01 * (k % 3), 1.5 + 0.25 * (k / 8)}, {0.0, 0.0}, r,
                  10.0, 0.5);
    b.friction = 0.3;
    pile.push_back(world.addBall(b));
  }
  stepBesideABallThrown100mAway(world, 300, mostSettledOverlap(world));
  const Vec2 corner(half - r, r);
  double nearest = std::numeric_limits<double>::infinity();
  for (const BallId id : pile) {
    const Ball& b = *world.findBall(id);
    EXPECT_TRUE(b.at_rest) << "ball " << id;
    nearest = std::min(nearest, (b.position - corner).norm());
  }
  EXPECT_LT(nearest, kMostSettledOverlap * r);
}

TEST(World, ABallDrivenIntoASleepingRowPushesItAlongAsOne) {
  // Four smooth balls asleep in a row on a smooth floor, and a heavier fifth 5 mm from its end
  // driven along it at 2 m/s^2: it meets the row at 0.14 m/s, slower than lasting contact
  // comes together (0.16 m/s in a step), and pushes it on. Nothing else pushes along the
  // floor, so the five go on together with the momentum the drive gave: M a t / (M + 4 m).
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-10.0, 0.0}, {20.0, 0.0}, 0.0));
  for (int k = 0; k < 4; ++k) world.addBall(ball({1.0 * k, 0.5}, {0.0, 0.0}, 0.5, 1.0, 0.0));
  run(world, 1.0);
  ASSERT_TRUE(allAtRest(world));
  const double start = world.time(), mass = 2.0, drive = 2.0;
  const BallId driven = world.addBall(ball({-1.005, 0.5}, {0.0, 0.0}, 0.5, mass, 0.0));
  world.drive(driven, Vec2(drive, 0.0));
  run(world, 2.0);
  const double together = mass * drive * (world.time() - start) / (mass + 4.0);
  for (const Ball& b : world.balls()) {
    EXPECT_FALSE(b.at_rest) << "ball " << b.id;
    EXPECT_NEAR(b.velocity.x(), together, 1e-3 * together) << "ball " << b.id;
  }
}

TEST(World, RemovingTheFloorLetsTheBallsRestingOnItFall) {
  World world(Vec2(0.0, -9.81));
  const SegmentId floor = world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  world.addBall(ball({0.0, 0.5}, {0.0, 0.0}));
  world.addBall(ball({0.0, 1.5}, {0.0, 0.0}));
  world.step(0.01);
  ASSERT_TRUE(world.balls()[0].at_rest && world.balls()[1].at_rest);
  ASSERT_TRUE(world.removeSegment(floor));
  EXPECT_FALSE(world.removeSegment(floor));
  world.step(0.1);
  // Both fall freely together: y = y0 - g t^2 / 2.
  EXPECT_NEAR(world.balls()[0].position.y(), 0.5 - 0.5 * 9.81 * 0.01, 1e-12);
  EXPECT_NEAR(world.balls()[1].position.y(), 1.5 - 0.5 * 9.81 * 0.01, 1e-12);
}

TEST(World, RemovingABallLetsTheOneOnItFallAndKeepsTheOthers) {
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  const BallId bottom = world.addBall(ball({0.0, 0.5}, {0.0, 0.0}));
  world.addBall(ball({0.0, 1.5}, {0.0, 0.0}));
  world.addBall(ball({3.0, 0.5}, {0.0, 0.0}));
  world.step(0.01);
  ASSERT_TRUE(world.removeBall(bottom));
  EXPECT_FALSE(world.removeBall(bottom));
  ASSERT_EQ(world.balls().size(), 2u);
  world.step(0.1);
  EXPECT_NEAR(world.balls()[0].position.y(), 1.5 - 0.5 * 9.81 * 0.01, 1e-12);
  EXPECT_TRUE(world.balls()[1].at_rest);
  EXPECT_EQ(world.balls()[1].position, Vec2(3.0, 0.5));
}

TEST(World, RemovingABallFromASleepingPyramidWakesOnlyTheBallsItHoldsUp) {
  // Rough balls in a pyramid, 4, 3, 2 and 1, on a rough floor between two walls, asleep. The
  // bottom left ball goes: the ball on it wakes, and what rests on that, up to the apex; the
  // others sleep on, until struck. All come to rest again, each on a ball or the floor below.
  const double r = 0.5;
  World world(Vec2(0.0, -kG));
  Segment floor = segment({-5.0 * r, 0.0}, {5.0 * r, 0.0}, 0.5);
  floor.friction = 0.5;
  world.addSegment(floor);
  world.addSegment(segment({-5.0 * r, 0.0}, {-5.0 * r, 12.0 * r}, 0.5));
  world.addSegment(segment({5.0 * r, 0.0}, {5.0 * r, 12.0 * r}, 0.5));
  // Balls side by side 1 cm apart, each on the two below: a pile of four or more settles, and
  // balls touching side by side would be left pressing on each other.
  const double apart = 2.0 * r + 0.01;
  const double row = std::sqrt(4.0 * r * r - 0.25 * apart * apart);  // height between rows
  std::vector<BallId> ids;
  for (int level = 0; level < 4; ++level)
    for (int k = 0; k < 4 - level; ++k) {
      Ball b = ball({(2 * k - 3 + level) * 0.5 * apart, r + level * row}, {0.0, 0.0}, r, 1.0, 0.5);
      b.friction = 0.5;
      ids.push_back(world.addBall(b));
    }
  for (int step = 0; step < 600 && !allAtRest(world); ++step) world.step(kFrameStep);
  ASSERT_TRUE(allAtRest(world));
  const std::vector<Ball> asleep = world.balls();
  ASSERT_TRUE(world.removeBall(ids[0]));
  const auto at = [&](std::size_t k) { return *world.findBall(ids[k]); };
  // ids: the floor 0-3, the next row 4-6, then 7-8, the apex 9.
  ASSERT_GT(surfaceGap(asleep[0], asleep[1]), kRestingGap);
  for (const std::size_t k : {4, 7, 9}) EXPECT_FALSE(at(k).at_rest) << "ball " << k;
  for (const std::size_t k : {1, 2, 3, 5, 6, 8}) EXPECT_TRUE(at(k).at_rest) << "ball " << k;
  world.step(kFrameStep);
  for (const std::size_t k : {1, 2, 3})  // struck by nothing yet
    EXPECT_EQ(at(k).position, asleep[k].position) << "ball " << k;
  for (int step = 0; step < 900 && !allAtRest(world); ++step) world.step(kFrameStep);
  ASSERT_TRUE(allAtRest(world));
  ASSERT_FALSE(brokenInvariant(world, kMostSettledOverlap * r));
  expectEachOnTheFloorOrABallBelow(world, kRestingGap / r);
}

TEST(World, RemovingOneOfTwoBallsInAVeeLetsTheOtherSlideDown) {
  // Two smooth balls asleep in a 90 degree vee, each on its slope and pushing the other level.
  // One goes: the other, which leaned on it without resting on it, slides down to the bottom.
  const double r = 0.5, side = r * std::sqrt(2.0);
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-2.0, 2.0}, {0.0, 0.0}, 0.0));
  world.addSegment(segment({0.0, 0.0}, {2.0, 2.0}, 0.0));
  const BallId left = world.addBall(ball({-r, r + side}, {0.0, 0.0}, r, 1.0, 0.0));
  const BallId right = world.addBall(ball({r, r + side}, {0.0, 0.0}, r, 1.0, 0.0));
  for (int step = 0; step < 600 && !allAtRest(world); ++step) world.step(kFrameStep);
  ASSERT_TRUE(allAtRest(world));
  ASSERT_TRUE(world.removeBall(left));
  EXPECT_FALSE(world.findBall(right)->at_rest);
  for (int step = 0; step < 600 && !allAtRest(world); ++step) world.step(kFrameStep);
  ASSERT_TRUE(allAtRest(world));
  EXPECT_NEAR((world.findBall(right)->position - Vec2(0.0, side)).norm(), 0.0, 1e-6);
}

TEST(World, ABallSetMovingFollowsTheExactParabolaFromItsNewState) {
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  const BallId id = world.addBall(ball({0.0, 0.5}, {0.0, 0.0}));
  world.step(0.01);
  ASSERT_TRUE(world.findBall(id)->at_rest);
  const Vec2 p0(20.0, 10.0), v0(1.0, 3.0);
  ASSERT_TRUE(world.setBallState(id, p0, v0, 4.0));
  EXPECT_FALSE(world.findBall(id)->at_rest);
  const double t0 = world.time();
  run(world, 1.0);
  const double t = world.time() - t0;
  const Ball& b = *world.findBall(id);
  EXPECT_NEAR((b.position - (p0 + v0 * t + 0.5 * Vec2(0.0, -kG) * t * t)).norm(), 0.0, 1e-10);
  EXPECT_NEAR((b.velocity - (v0 + Vec2(0.0, -kG) * t)).norm(), 0.0, 1e-11);
  EXPECT_EQ(b.angular_velocity, 4.0);  // nothing touched it to change its spin
}

TEST(World, ABallRestingOnOneSetElsewhereFallsAndTheOthersStay) {
  // A stack of two at rest and a ball beside it: the bottom ball is set down elsewhere on the
  // floor, and the top one, woken, falls freely; the ball beside it stays at rest.
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  const BallId bottom = world.addBall(ball({0.0, 0.5}, {0.0, 0.0}));
  const BallId top = world.addBall(ball({0.0, 1.5}, {0.0, 0.0}));
  const BallId beside = world.addBall(ball({3.0, 0.5}, {0.0, 0.0}));
  world.step(0.01);
  ASSERT_TRUE(world.findBall(top)->at_rest);
  ASSERT_TRUE(world.setBallState(bottom, Vec2(-3.0, 0.5), Vec2::Zero(), 0.0));
  EXPECT_FALSE(world.findBall(top)->at_rest);
  world.step(0.1);
  EXPECT_NEAR(world.findBall(top)->position.y(), 1.5 - 0.5 * kG * 0.01, 1e-12);
  EXPECT_EQ(world.findBall(top)->position.x(), 0.0);
  EXPECT_NEAR((world.findBall(bottom)->position - Vec2(-3.0, 0.5)).norm(), 0.0, 1e-12);
  EXPECT_TRUE(world.findBall(beside)->at_rest);
  EXPECT_EQ(world.findBall(beside)->position, Vec2(3.0, 0.5));
}

TEST(World, ABallSetDownOnARestingOneWakesItAndBothComeToRestStacked) {
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  const BallId under = world.addBall(ball({0.0, 0.5}, {0.0, 0.0}, 0.5, 1.0, 0.5));
  const BallId moved = world.addBall(ball({3.0, 0.5}, {0.0, 0.0}, 0.5, 1.0, 0.5));
  world.step(0.01);
  ASSERT_TRUE(world.findBall(under)->at_rest && world.findBall(moved)->at_rest);
  ASSERT_TRUE(world.setBallState(moved, Vec2(0.0, 1.5), Vec2::Zero(), 0.0));
  EXPECT_FALSE(world.findBall(under)->at_rest);
  run(world, 2.0, 0.01);
  for (const auto& [id, height] : {std::pair{under, 0.5}, std::pair{moved, 1.5}}) {
    const Ball& b = *world.findBall(id);
    EXPECT_TRUE(b.at_rest) << "ball " << id;
    EXPECT_NEAR((b.position - Vec2(0.0, height)).norm(), 0.0, 1e-9) << "ball " << id;
  }
}

TEST(World, SetBallStateRefusesBadInputAndKeepsTheWorld) {
  // Two like worlds, one refused every bad call: they go on bit for bit alike.
  auto makeWorld = [] {
    World world(Vec2(0.0, -kG));
    world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
    world.addBall(ball({0.0, 0.5}, {0.0, 0.0}));
    world.addBall(ball({0.0, 1.5}, {0.0, 0.0}));
    world.addBall(ball({3.0, 2.0}, {1.0, 0.0}));
    Rope rope;
    rope.ball = 3;
    rope.anchor = Vec2(3.0, 3.0);
    rope.length = 1.5;
    world.addRope(rope);
    world.step(0.01);
    return world;
  };
  World world = makeWorld(), untouched = makeWorld();
  ASSERT_TRUE(world.findBall(1)->at_rest && world.findBall(2)->at_rest);
  const Vec2 free_place(-3.0, 3.0), still = Vec2::Zero();
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  auto set = [&](BallId id, const Vec2& p, const Vec2& v, double w) {
    return refusal([&] { world.setBallState(id, p, v, w); });
  };
  EXPECT_EQ(set(1, Vec2(0.0, 2.0), still, 0.0), "ball would overlap ball 2");
  EXPECT_EQ(set(2, Vec2(1.0, 0.2), still, 0.0), "ball would overlap segment 1");
  EXPECT_EQ(set(1, Vec2(nan, 3.0), still, 0.0), "position must be finite");
  EXPECT_EQ(set(1, free_place, Vec2(inf, 0.0), 0.0), "velocity must be finite");
  EXPECT_EQ(set(1, free_place, still, nan), "angular velocity must be finite");
  EXPECT_NE(set(1, free_place, Vec2(2e5, 0.0), 0.0).find("speed must be at most"),
            std::string::npos);
  EXPECT_NE(set(3, Vec2(3.0, 0.5), still, 0.0).find("rope's length 1.5"), std::string::npos);
  EXPECT_FALSE(world.setBallState(99, free_place, still, 0.0));
  EXPECT_TRUE(world.findBall(1)->at_rest && world.findBall(2)->at_rest);
  run(world, 1.0);
  run(untouched, 1.0);
  ASSERT_EQ(world.balls().size(), untouched.balls().size());
  for (std::size_t i = 0; i < world.balls().size(); ++i) {
    const Ball &a = world.balls()[i], &b = untouched.balls()[i];
    EXPECT_EQ(a.position, b.position) << "ball " << a.id;
    EXPECT_EQ(a.velocity, b.velocity) << "ball " << a.id;
    EXPECT_EQ(a.angular_velocity, b.angular_velocity) << "ball " << a.id;
    EXPECT_EQ(a.at_rest, b.at_rest) << "ball " << a.id;
  }
}

TEST(World, ABallWhoseSupportCameToRestIsStillStoppedByItWhenStruckFromAbove) {
  // A ball settles at rest in a V while the one on it still creeps sideways; a third, dropped
  // at 5 m/s, strikes the creeping one. Held anew after that impact, the creeping ball's
  // contact with the resting one must be taken up again, not left as it was: nothing sinks.
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment({-0.8, 0.8}, {0.0, 0.0}, 0.0));
  world.addSegment(segment({0.0, 0.0}, {0.8, 0.8}, 0.0));
  const double h = 0.5 * std::sqrt(2.0);
  world.addBall(ball({0.0, h + 1e-12}, {0.0, 0.0}, 0.5, 1.0, 0.0));
  world.addBall(ball({0.0, h + 1.0 + 2e-12}, {0.002, 0.0}));
  world.addBall(ball({0.0, h + 2.01}, {0.0, -5.0}));
  for (int step = 0; step < 12; ++step) {
    world.step(1.0 / 120.0);
    const auto broken = brokenInvariant(world, 1e-9);
    ASSERT_FALSE(broken) << "at t = " << world.time() << ": " << *broken;
  }
  EXPECT_TRUE(world.balls()[0].at_rest);
}

TEST(World, BallsLookedAtBeforeAnotherIsRemovedStillStrikeEachOther) {
  // Within a step balls are moved when looked at, by index: a removal moves the indices, and
  // what was looked at before it must not hide a ball from the next step's bookkeeping.
  World world(kNoGravity);
  const BallId gone = world.addBall(ball({-5.0, 5.0}, {0.0, 0.0}, 0.1));
  const BallId striker = world.addBall(ball({0.0, 0.0}, {10.0, 0.0}, 0.1));
  const BallId struck = world.addBall(ball({0.215, 0.0}, {0.0, 0.0}, 0.1));
  world.motionOfBall(struck);
  world.removeBall(gone);
  world.step(0.01);
  // Equal masses, elastic, head on: they swap velocities when the 0.015 m gap closes, at 1.5 ms.
  EXPECT_NEAR(world.findBall(striker)->velocity.x(), 0.0, 1e-12);
  EXPECT_NEAR(world.findBall(struck)->velocity.x(), 10.0, 1e-12);
  EXPECT_NEAR(world.findBall(struck)->position.x(), 0.215 + 10.0 * (0.01 - 0.0015), 1e-12);
}

TEST(World, RestingClusterIsTheBallAndTheRestingBallsItTouchesTransitively) {
  // A stack of three at rest, a ball at rest beside it (not touching), one falling far away.
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}));
  const BallId bottom = world.addBall(ball({0.0, 0.5}, {0.0, 0.0}));
  const BallId middle = world.addBall(ball({0.0, 1.5}, {0.0, 0.0}));
  const BallId top = world.addBall(ball({0.0, 2.5}, {0.0, 0.0}));
  const BallId beside = world.addBall(ball({3.0, 0.5}, {0.0, 0.0}));
  world.step(0.01);
  const BallId falling = world.addBall(ball({-3.0, 4.0}, {0.0, 0.0}));
  ASSERT_NE(world.findBall(top), nullptr);
  ASSERT_TRUE(world.findBall(top)->at_rest);
  EXPECT_EQ(world.findBall(beside)->position, Vec2(3.0, 0.5));
  EXPECT_EQ(world.findBall(99), nullptr);

  std::vector<BallId> cluster = world.restingClusterOf(top);
  std::sort(cluster.begin(), cluster.end());
  EXPECT_EQ(cluster, (std::vector<BallId>{bottom, middle, top}));
  EXPECT_EQ(world.restingClusterOf(beside), std::vector<BallId>{beside});
  EXPECT_EQ(world.restingClusterOf(falling), std::vector<BallId>{falling});
  EXPECT_TRUE(world.restingClusterOf(99).empty());
}

TEST(World, ABallRollingOffACapWithLongStepsNeverSinksIntoIt) {
  // Found by fuzzing: held contacts on a cap follow constant accelerations, which leave the
  // circle; they are held anew before they drift by more than kHeldDrift.
  World world(Vec2(0.0, -9.81));
  world.addSegment(segment({-1.0154879072251468, -9.452811474784466},
                           {0.00015259021896696368, -8.999923704890517}, 0.2382696269169146));
  world.addBall(ball({-6.093690394445716, 9.844052796215763}, {2.705882352941174, 2.705882352941174},
                     0.5450217441062027, 9.990386816205081, 0.013839932860303654));
  for (int step = 0; step < 24; ++step) {
    world.step(0.1);
    EXPECT_GE(surfaceGap(world.balls()[0], world.segments()[0]), -1e-9) << "t = " << world.time();
  }
}

TEST(World, ABulletStoppedOnALongSegmentSlidesAlongItWithoutSinking) {
  // Found by fuzzing: sliding at 1100 m/s, a normal taken from the offset to the nearest point
  // (rounded over 26 m) made the contact look separating, so it was not held and fell in.
  World world(Vec2(0.0, -9.81));
  Segment long_one = segment({-8.999923704890517, -8.999923704890517}, {8.999923704890517, 10.0},
                             0.00392156862745098);
  long_one.thickness = 9.155413138017853e-05;
  world.addSegment(long_one);
  world.addBall(ball({6.015869382772564, 9.062485694666972}, {-601.9531548027771, -998.4740978103304},
                     0.0007629510948348211, 10.0, 0.006836041809719997));
  world.step(1.0 / 60.0);
  EXPECT_GE(surfaceGap(world.balls()[0], world.segments()[0]), -1e-9);
  EXPECT_GT(world.balls()[0].velocity.norm(), 1000.0);  // it slides on
}

TEST(World, ABrickCountsItsHitsAndIsGoneAfterTheLast) {
  World world(Vec2::Zero());
  world.addSegment(segment(Vec2(-2.0, -2.0), Vec2(-2.0, 2.0)));
  Segment brick = segment(Vec2(2.0, -2.0), Vec2(2.0, 2.0));
  brick.hits_to_break = 2;
  const SegmentId brick_id = world.addSegment(brick);
  // Elastic, to and fro at 1 m/s: the brick at 1.5 s and 7.5 s, the wall at 4.5 s.
  const BallId id = world.addBall(ball(Vec2::Zero(), Vec2(1.0, 0.0)));
  run(world, 9.0);
  const std::vector<BrickHit> hits = world.takeBrickHits();
  ASSERT_EQ(hits.size(), 2u);
  EXPECT_NEAR(hits[0].time, 1.5, 1e-12);
  EXPECT_EQ(hits[0].segment, brick_id);
  EXPECT_EQ(hits[0].ball, id);
  EXPECT_EQ(hits[0].hits_left, 1);
  EXPECT_NEAR(hits[1].time, 7.5, 1e-12);
  EXPECT_EQ(hits[1].hits_left, 0);
  ASSERT_EQ(world.segments().size(), 1u);  // the wall
  EXPECT_NE(world.segments()[0].id, brick_id);
  // Back from the wall at 10.5 s, through where the brick was.
  run(world, 6.0);
  EXPECT_NEAR(world.findBall(id)->position.x(), 3.0, 1e-12);
}

TEST(World, TheBrickBreakerSceneIsPlayedForAMinuteWithoutBreakingAnInvariant) {
  Scene scene = loadScene(SCENES_DIR "/bricks.yaml");
  World& world = scene.world;
  const Launcher& serve = scene.launchers.at(0);
  BallId id = world.addBall(serve.launch(serve.speed));
  const std::size_t fixed_parts = 5;  // walls, top, paddle, the out zone's floor
  const std::size_t bricks = world.segments().size() - fixed_parts;
  std::size_t broken = 0;
  for (int frame = 0; frame < 60 * 60; ++frame) {
    // A player: the paddle (its centre kept off the walls) chases the ball.
    const Segment& paddle = world.segments().at(3);
    const double centre = 0.5 * (paddle.start.x() + paddle.end.x());
    const double target = std::clamp(world.findBall(id)->position.x(), -4.8, 4.8);
    ASSERT_TRUE(world.setSegmentMotion(
        paddle.id, Vec2(std::clamp(8.0 * (target - centre), -6.0, 6.0), 0.0), 0.0));
    world.step(kFrameStep);
    ASSERT_EQ(brokenInvariant(world, 1e-9), std::nullopt) << "at " << world.time() << " s";
    const Ball& ball = *world.findBall(id);
    ASSERT_LT(std::abs(ball.position.x()), 6.0);
    ASSERT_GT(ball.position.y(), -2.0);
    ASSERT_LT(ball.position.y(), 10.0);
    for (const BrickHit& hit : world.takeBrickHits()) {
      EXPECT_EQ(hit.ball, id);
      broken += hit.hits_left == 0;
    }
    // A brick is gone by the end of the step it broke in.
    ASSERT_EQ(world.segments().size(), fixed_parts + bricks - broken);
    // A ball lost past the paddle is reported as it falls into the out zone: serve another.
    for (const SensorEvent& event : world.takeSensorEvents()) {
      ASSERT_EQ(event.sensor, "out");
      ASSERT_EQ(event.ball, id);
      ASSERT_TRUE(event.entered);
      EXPECT_LT(ball.position.y(), -0.5);
      world.removeBall(id);
      id = world.addBall(serve.launch(serve.speed));
    }
  }
  EXPECT_GT(broken, 0u);
}

TEST(World, ThePoolBreakPocketsBallsOnlyThroughPocketsForAMinute) {
  Scene scene = loadScene(SCENES_DIR "/pool.yaml");
  World& world = scene.world;
  world.addBall(scene.launchers.at(0).launch(scene.launchers.at(0).speed));
  const std::size_t on_table = world.balls().size();
  std::size_t pocketed = 0;
  double energy = mechanicalEnergy(world);
  for (int frame = 0; frame < 60 * 60; ++frame) {
    world.step(kFrameStep);
    ASSERT_EQ(brokenInvariant(world, 1e-9), std::nullopt) << "at " << world.time() << " s";
    // A centre past a cushion's line went through a pocket's gap, and the pocket took it.
    for (const Ball& ball : world.balls()) {
      ASSERT_TRUE(ball.position.x() >= 0.0 && ball.position.x() <= 2.54 &&
                  ball.position.y() >= 0.0 && ball.position.y() <= 1.27)
          << "ball " << ball.id << " off the table at " << world.time() << " s";
    }
    for (const SensorEvent& event : world.takeSensorEvents()) {
      ASSERT_TRUE(event.entered);
      EXPECT_EQ(world.findBall(event.ball), nullptr);  // gone at the end of its step
      ++pocketed;
    }
    ASSERT_EQ(world.balls().size(), on_table - pocketed);
    const double now = mechanicalEnergy(world);
    ASSERT_LE(now, energy * (1.0 + 1e-12));  // impacts with e < 1 and pockets only take
    energy = now;
  }
  EXPECT_GT(pocketed, 0u);
}

TEST(World, TheArtillerySceneIsPlayedForAMinuteOfTurnsWithoutBreakingAnInvariant) {
  Scene scene = loadScene(SCENES_DIR "/artillery.yaml");
  World& world = scene.world;
  // Turns of 10 s: each launcher in turn lobs a shell onto the far crate of the other side
  // and sets off a blast where the shell first strikes.
  const Vec2 targets[] = {Vec2(6.3, 0.8), Vec2(-3.5, 0.8)};
  std::size_t blasts = 0;
  for (int turn = 0; turn < 6; ++turn) {
    Launcher& launcher = scene.launchers.at(turn % 2);
    const std::optional<AimSolution> aim =
        aimBallistic(launcher.position, targets[turn % 2], 16.0, world.gravity(), true);
    ASSERT_TRUE(aim.has_value());
    launcher.angle = aim->angle;
    const BallId shell = world.addBall(launcher.launch(16.0));
    bool blasted = false;
    for (int frame = 0; frame < 600; ++frame) {
      world.step(kFrameStep);
      // (A blast's struggle among the crates settles.)
      ASSERT_EQ(brokenInvariant(world, mostSettledOverlap(world)), std::nullopt)
          << "at " << world.time() << " s";
      for (const Ball& ball : world.balls())
        ASSERT_TRUE(std::abs(ball.position.x()) < 14.0 && ball.position.y() < 16.0)
            << "ball " << ball.id << " out at " << world.time() << " s";
      for (const Contact& c : world.takeContacts()) {
        if (blasted || c.ball_id != shell) continue;
        EXPECT_FALSE(world.explode({c.point, 4.0, 2.5}).empty());
        blasted = true;
        ++blasts;
      }
    }
  }
  EXPECT_EQ(blasts, 6u);
}

TEST(World, ALightBallWedgedUnderAHeavyOneOnAFloorMovesWithItInsteadOfStoppingTime) {
  // Recorded from the artillery scene after a blast: a crate sliding down a slope into the
  // corner with the floor pushes a second crate, under whose side a light shell is wedged on
  // the floor. The inelastic push left the second crate rising from the floor at a few 1e-9
  // m/s; let go, it fell back at once, and zero-time impacts used up every step, so that no
  // ball moved although all had speed.
  World world;
  auto add_segment = [&](Vec2 a, Vec2 b) { world.addSegment(segment(a, b, 0.3)); };
  add_segment({1.0, 4.0}, {3.0, 0.5});
  add_segment({3.0, 0.5}, {8.0, 0.5});
  world.addBall(ball({3.170613122063751, 0.80609636751082736},
                     {0.11651916257247953, -0.20390853450183918}, 0.3, 2.0, 0.3));
  world.addBall(ball({3.7705821505217822, 0.8}, {0.11859339953965874, 0.0}, 0.3, 2.0, 0.3));
  world.addBall(ball({4.1949660621821252, 0.65}, {0.12489870805275569, 0.0}, 0.15, 1.0, 0.3));
  world.step(kFrameStep);  // the crate reaches the corner; the three move on together
  for (int frame = 0; frame < 5; ++frame) {
    const std::vector<Ball> before = world.balls();
    world.step(kFrameStep);
    // Each goes about as far as its speed says (still pushed by the slope: a little further);
    // held still, they went 1e-6 m a frame.
    for (std::size_t i = 0; i < before.size(); ++i)
      EXPECT_GT(world.balls()[i].position.x() - before[i].position.x(),
                0.5 * before[i].velocity.x() * kFrameStep)
          << "ball " << before[i].id << " in frame " << frame;
  }
}

TEST(World, TheContraptionsRampDeliversTheBallToTheGoalAndWithoutItTheBallMisses) {
  for (const bool ramp : {true, false}) {
    Scene scene = loadScene(SCENES_DIR "/contraption.yaml");
    World& world = scene.world;
    if (ramp) {  // the part the scene file's comment suggests
      Segment part = segment(Vec2(-5.0, 4.5), Vec2(3.5, 2.0), 0.2);
      part.thickness = 0.1;
      world.addSegment(part);
    }
    const BallId id = world.addBall(scene.launchers.at(0).launch(scene.launchers.at(0).speed));
    std::vector<SensorEvent> events;
    for (int frame = 0; frame < 60 * 60; ++frame) {
      world.step(kFrameStep);
      ASSERT_EQ(brokenInvariant(world, 1e-9), std::nullopt) << "at " << world.time() << " s";
      for (const SensorEvent& event : world.takeSensorEvents()) events.push_back(event);
    }
    if (ramp) {
      ASSERT_EQ(events.size(), 1u);  // in, and it stays in the cup
      EXPECT_EQ(events[0].sensor, "goal");
      EXPECT_EQ(events[0].ball, id);
      EXPECT_TRUE(events[0].entered);
      EXPECT_TRUE(world.findBall(id)->at_rest);
    } else {
      EXPECT_TRUE(events.empty());  // it rolls to a stop short of the cup
    }
  }
}

TEST(World, ThePlatformerIsPlayedToItsFlagByADrivenBall) {
  Scene scene = loadScene(SCENES_DIR "/platformer.yaml");
  World& world = scene.world;
  const BallId id = world.balls().back().id;
  // A run, a jump over the wall, a glide, a jump onto the upper step; then hands off.
  struct Command {
    Vec2 acceleration;
    int steps;  // of 1/120 s
  };
  const Command route[] = {{{3.0, 0.0}, 150}, {{3.0, 22.0}, 50}, {{0.0, 0.0}, 60},
                           {{1.0, 26.0}, 50}, {{0.0, 0.0}, 240}};
  std::vector<SensorEvent> events;
  for (const Command& command : route) {
    ASSERT_TRUE(world.drive(id, command.acceleration));
    for (int k = 0; k < command.steps; ++k) {
      world.step(1.0 / 120.0);
      ASSERT_EQ(brokenInvariant(world, 1e-9), std::nullopt) << "at " << world.time() << " s";
      for (const SensorEvent& event : world.takeSensorEvents()) events.push_back(event);
    }
  }
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].sensor, "flag");
  EXPECT_TRUE(events[0].entered);
  const Ball& ball = *world.findBall(id);
  EXPECT_NEAR(ball.position.y(), 2.1 + ball.radius, 1e-9);  // on the flag's step
  EXPECT_GT(ball.position.x(), 5.5);
  EXPECT_LT(ball.position.x(), 7.5);
  run(world, 50.0);  // and the lift beyond goes up and down meanwhile, breaking nothing
  EXPECT_EQ(brokenInvariant(world, 1e-9), std::nullopt);
}

TEST(World, ALapOfTheRacingTrackDrivenByACarPassesItsCheckpointsInOrder) {
  Scene scene = loadScene(SCENES_DIR "/racing.yaml");
  World& world = scene.world;
  const BallId car = world.balls().back().id;
  // A driver steering for the middle of the track at each corner in turn: a push toward the
  // next corner, less what the car's speed across that way would overshoot.
  const Vec2 corners[] = {{7.5, -3.75}, {7.5, 3.75}, {-7.5, 3.75}, {-7.5, -3.75}};
  std::size_t next = 0;
  std::vector<std::string> passed;
  for (int frame = 0; frame < 60 * 60 && passed.size() < 5; ++frame) {
    const Ball& ball = *world.findBall(car);
    if ((corners[next % 4] - ball.position).norm() < 1.5) ++next;
    Vec2 push = 2.0 * (corners[next % 4] - ball.position) - 2.0 * ball.velocity;
    if (push.norm() > 6.0) push *= 6.0 / push.norm();
    ASSERT_TRUE(world.drive(car, push));
    world.step(kFrameStep);
    ASSERT_EQ(brokenInvariant(world, 1e-9), std::nullopt) << "at " << world.time() << " s";
    for (const SensorEvent& event : world.takeSensorEvents())
      if (event.entered) passed.push_back(event.sensor);
  }
  EXPECT_EQ(passed, std::vector<std::string>({"start", "east", "north", "west", "start"}));
}

TEST(World, ABumperAddsItsKickToTheBounce) {
  World world(Vec2::Zero());
  Segment bumper = segment(Vec2(0.0, -1.0), Vec2(0.0, 1.0), 0.5);
  bumper.kick = 3.0;
  const SegmentId bumper_id = world.addSegment(bumper);
  const BallId id = world.addBall(ball(Vec2(-2.0, 0.0), Vec2(2.0, 0.0), 0.5, 2.0, 1.0));
  run(world, 1.0);  // the hit at 0.75 s
  // Back at e v + kick = 0.5 x 2 + 3 m/s; the impulse, m (4 + 2).
  EXPECT_NEAR(world.findBall(id)->velocity.x(), -4.0, 1e-12);
  EXPECT_NEAR(world.findBall(id)->position.x(), -0.5 - 4.0 * 0.25, 1e-12);
  const std::vector<Contact> contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].other_id, bumper_id);
  EXPECT_NEAR(contacts[0].impulse, 12.0, 1e-12);
}

TEST(World, PinballIsPlayedForAMinuteWithoutBreakingAnInvariant) {
  Scene scene = loadScene(SCENES_DIR "/pinball.yaml");
  World& world = scene.world;
  const Launcher& plunger = scene.launchers.at(0);
  const SegmentId flippers[] = {8, 9};
  const double up[] = {15.0, -15.0};  // each flipper's angular velocity up; down is the opposite
  double down_at[] = {-1.0, -1.0};    // when a raised flipper goes down again
  std::size_t served = 1, drained = 0, kicks = 0, flips = 0;
  world.addBall(plunger.launch(plunger.speed));
  for (int frame = 0; frame < 60 * 60; ++frame) {
    // A player: a flipper goes up for 0.15 s when a ball comes down near it.
    for (int f = 0; f < 2; ++f) {
      const Segment* flipper = nullptr;
      for (const Segment& s : world.segments())
        if (s.id == flippers[f]) flipper = &s;
      ASSERT_NE(flipper, nullptr);
      const Vec2 middle = 0.5 * (flipper->start + flipper->end);
      const bool coming = std::any_of(world.balls().begin(), world.balls().end(), [&](const Ball& b) {
        return (b.position - middle).norm() < 0.7 && b.velocity.y() < 0.0;
      });
      if (down_at[f] < 0.0 && coming) {
        ASSERT_TRUE(world.setSegmentMotion(flippers[f], Vec2::Zero(), up[f]));
        down_at[f] = world.time() + 0.15;
        ++flips;
      } else if (down_at[f] >= 0.0 && world.time() >= down_at[f]) {
        ASSERT_TRUE(world.setSegmentMotion(flippers[f], Vec2::Zero(), -up[f]));
        down_at[f] = -1.0;
      }
    }
    world.step(kFrameStep);
    // (A ball riding a flipper up is in lasting contact with it: it settles, and may end a
    // step as far as a settle lets it past touching.)
    const double settled_overlap = 2.0 * kSettleOverlap * plunger.projectile.radius;
    ASSERT_EQ(brokenInvariant(world, settled_overlap), std::nullopt)
        << "at " << world.time() << " s";
    for (const Ball& ball : world.balls())
      ASSERT_TRUE(ball.position.x() > 0.0 && ball.position.x() < 6.0 && ball.position.y() > -1.0 &&
                  ball.position.y() < 10.0)
          << "ball " << ball.id << " off the table at " << world.time() << " s";
    // A bumper's hit on a ball of 1 kg: the impulse is (1 + e) v + kick, e = 0.5 x 0.5.
    for (const Contact& c : world.takeContacts())
      kicks += c.other_id >= 13 && c.other_id <= 15 && c.impulse > 1.25 * c.approach_speed + 2.5 - 1e-9;
    for (const SensorEvent& event : world.takeSensorEvents()) {
      ASSERT_EQ(event.sensor, "drain");
      ++drained;
      world.addBall(plunger.launch(plunger.speed));  // the next ball
      ++served;
    }
    ASSERT_EQ(world.balls().size(), served - drained);
  }
  EXPECT_GT(kicks, 0u);
  EXPECT_GT(flips, 0u);
}

TEST(World, TheFieldsSceneFloatsSinksAndLiftsItsBallsWithoutBreakingAnInvariant) {
  Scene scene = loadScene(SCENES_DIR "/fields.yaml");
  World& world = scene.world;
  for (int frame = 1; frame <= 20 * 60; ++frame) {
    if (frame % 300 == 1) world.addBall(scene.launchers.at(0).launch(scene.launchers.at(0).speed));
    world.step(kFrameStep);
    ASSERT_EQ(brokenInvariant(world, 1e-9), std::nullopt) << "at " << world.time() << " s";
  }
  // The pond's light balls float, partly sunk (the magnet pulls them a little, and they
  // jostle: Archimedes' depth itself is tested alone), the heavy one lies on its floor.
  const double r = 0.25, surface = 1.5;
  for (const std::size_t light : {0, 1}) {
    EXPECT_GT(world.balls()[light].position.y(), surface - r);
    EXPECT_LT(world.balls()[light].position.y(), surface + r);
  }
  EXPECT_NEAR(world.balls()[2].position.y(), r, 1e-9);  // 80 kg
}
