#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/world.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using namespace ball_physics_sim::engine::test;

namespace {

Segment moving(Segment s, Vec2 velocity) {
  s.velocity = velocity;
  return s;
}

// A flipper: a bar from its pivot `length` along the x axis, turning at `angular_velocity`
// up to `max_angle`.
Segment flipper(double length, double angular_velocity, double max_angle, double restitution) {
  Segment s = segment(Vec2::Zero(), Vec2(length, 0.0), restitution);
  s.angular_velocity = angular_velocity;
  s.max_angle = max_angle;
  s.min_angle = 0.0;
  return s;
}

// The first hit of a flipper turning at 10 rad/s on a still ball of restitution 1 and mass 1,
// placed to touch the bar where it is `distance` from the pivot once it has turned `angle`, on
// the side it turns toward.
Contact flipperHit(double distance, double angle, double restitution) {
  World world(Vec2::Zero());
  world.addSegment(flipper(1.0, 10.0, 1.5, restitution));
  const double r = 0.2;
  const Vec2 along(std::cos(angle), std::sin(angle)), ahead(-std::sin(angle), std::cos(angle));
  world.addBall(ball(distance * along + r * ahead, Vec2::Zero(), r));
  world.step(0.1);
  const std::vector<Contact> contacts = world.takeContacts();
  return contacts.empty() ? Contact{} : contacts[0];
}

const Vec2 kThrownFrom(100.0, 0.0), kThrown(1.0, 2.0);

// A bin of rough balls (mu 0.3, e 0.5), `n` of radius 0.5 in rows of five 1.1 m apart, on the
// floor of a bin 6 m wide whose walls (rough too) stand at x = -3 and 3, with a ball thrown
// 100 m away: the floor is `floor`, its ends on the walls.
World binOnFloor(const Segment& floor, int n) {
  World world(Vec2(0.0, -kG));
  for (const double x : {-3.0, 3.0}) {
    Segment wall = segment(Vec2(x, -10.0), Vec2(x, 40.0), 0.5);
    wall.friction = 0.3;
    world.addSegment(wall);
  }
  world.addSegment(floor);
  for (int i = 0; i < n; ++i) {
    Ball b = ball(Vec2(-2.2 + 1.1 * (i % 5), floor.start.y() + 0.6 + 1.1 * (i / 5)),
                  Vec2::Zero(), 0.5, 1.0, 0.5);
    b.friction = 0.3;
    world.addBall(b);
  }
  world.addBall(ball(kThrownFrom, kThrown, 0.1));
  return world;
}

// A rough floor for binOnFloor, its pivot at its start.
Segment binFloor() {
  Segment floor = segment(Vec2(-3.0, 0.0), Vec2(3.0, 0.0), 0.5);
  floor.friction = 0.3;
  floor.pivot = floor.start;
  return floor;
}

// Steps the bin, checking after each step that nothing overlaps past what a settle may leave
// (of the bin's balls) and that the thrown ball is on its exact parabola.
void stepTheBin(World& world, int steps, const std::function<void(int)>& after_each = {}) {
  for (int step = 1; step <= steps; ++step) {
    world.step(kFrameStep);
    const double t = world.time();
    ASSERT_NEAR((world.balls().back().position - (kThrownFrom + kThrown * t +
                                                   0.5 * world.gravity() * t * t)).norm(),
                0.0, 1e-9)
        << "step " << step;
    ASSERT_FALSE(brokenInvariant(world, kMostSettledOverlap * 0.5)) << "step " << step;
    if (after_each) after_each(step);
  }
}

// How far the lowest of the bin's balls is above the floor (negative: into it).
double lowestGap(const World& world) {
  const double floor = world.segments()[2].start.y();
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < world.balls().size(); ++i)
    lowest = std::min(lowest, world.balls()[i].position.y() - 0.5 - floor);
  return lowest;
}

}  // namespace

TEST(Kinematics, AWallMovingIntoAStillBallThrowsItAtOnePlusETimesItsSpeed) {
  for (const double e : {1.0, 0.5, 0.0}) {
    World world(Vec2::Zero());
    world.addSegment(moving(segment(Vec2(-3.0, -1.0), Vec2(-3.0, 1.0), e), Vec2(2.0, 0.0)));
    world.addBall(ball(Vec2::Zero(), Vec2::Zero()));
    run(world, 2.0);
    const std::vector<Contact> contacts = world.takeContacts();
    ASSERT_EQ(contacts.size(), 1u) << e;
    EXPECT_NEAR(contacts[0].time, 1.25, 1e-12);  // the face, 2.5 m away, closes at 2 m/s
    EXPECT_NEAR(contacts[0].approach_speed, 2.0, 1e-12);
    const Ball& b = world.balls()[0];
    EXPECT_NEAR(b.velocity.x(), (1.0 + e) * 2.0, 1e-12) << e;
    EXPECT_NEAR(b.position.x(), std::max((1.0 + e) * 2.0 * 0.75, 2.0 * 0.75), 1e-9) << e;
    EXPECT_NEAR((world.segments()[0].start - Vec2(1.0, -1.0)).norm(), 0.0, 1e-12);
  }
}

TEST(Kinematics, AWallPushingABallAtRestOnAFloorWakesItAndCarriesItAlong) {
  World world(Vec2(0.0, -kG));
  world.addSegment(segment(Vec2(-10.0, 0.0), Vec2(10.0, 0.0)));
  world.addBall(ball(Vec2(0.0, 0.5), Vec2::Zero(), 0.5, 1.0, 0.0));
  run(world, 0.5);
  ASSERT_TRUE(world.balls()[0].at_rest);
  world.addSegment(moving(segment(Vec2(-2.0, 0.2), Vec2(-2.0, 2.0), 0.0), Vec2(1.0, 0.0)));
  run(world, 3.0);
  const Ball& b = world.balls()[0];
  EXPECT_FALSE(b.at_rest);
  EXPECT_NEAR(b.velocity.x(), 1.0, 1e-9);
  EXPECT_NEAR(b.position.x(), -2.0 + 3.0 + 0.5, 1e-9);  // just ahead of the wall
  EXPECT_NEAR(b.position.y(), 0.5, 1e-9);
  EXPECT_FALSE(brokenInvariant(world, 1e-6 * b.radius));
}

TEST(Kinematics, AWallCreepingIntoABallAtRestPushesItAndTheRestOfTheWorldGoesOn) {
  // The wall meets the ball slower than any impact (1 mm/s): the touch alone wakes it, and
  // its resting contact carries it. A ball falling elsewhere lands on time meanwhile.
  World world(Vec2(0.0, -kG));
  world.addSegment(segment(Vec2(-10.0, 0.0), Vec2(10.0, 0.0), 0.0));
  world.addBall(ball(Vec2(0.0, 0.5), Vec2::Zero(), 0.5, 1.0, 0.0));
  run(world, 0.5);
  ASSERT_TRUE(world.balls()[0].at_rest);
  world.addSegment(moving(segment(Vec2(-0.5001, 0.2), Vec2(-0.5001, 2.0), 0.0), Vec2(1e-4, 0.0)));
  world.addBall(ball(Vec2(5.0, 20.0), Vec2::Zero(), 0.5, 1.0, 0.0));
  run(world, 3.0);  // the wall reaches the ball at 1 s
  EXPECT_NEAR(world.balls()[0].position.x(), 2e-4, 1e-9);
  EXPECT_NEAR(world.balls()[0].velocity.x(), 1e-4, 1e-12);
  EXPECT_NEAR(world.balls()[1].position.y(), 0.5, 1e-9);  // landed at 1.96 s, e = 0
}

TEST(Kinematics, ABallRidesAnElevatorAndFliesOnWhenItTurnsDown) {
  World world(Vec2(0.0, -kG));
  Segment platform = segment(Vec2(-2.0, 0.0), Vec2(2.0, 0.0));
  platform.pivot = platform.start;
  platform.waypoints = {Vec2(-2.0, 0.0), Vec2(-2.0, 3.0)};
  platform.speed = 1.0;
  world.addSegment(platform);
  world.addBall(ball(Vec2(0.0, 0.5), Vec2::Zero(), 0.5, 1.0, 0.0));
  run(world, 1.5);
  const Ball& b = world.balls()[0];
  EXPECT_NEAR(b.position.y(), 0.5 + 1.5, 1e-9);
  EXPECT_NEAR(b.velocity.y(), 1.0, 1e-9);
  world.takeContacts();
  // At 3 s the platform turns down at 1 m/s; the ball goes on up at 1 m/s, then falls.
  run(world, 1.7);
  const double flight = 0.2;
  EXPECT_NEAR(b.position.y(), 3.5 + flight - 0.5 * kG * flight * flight, 1e-9);
  EXPECT_NEAR(world.segments()[0].start.y(), 3.0 - flight, 1e-12);
  // It lands when 3.5 + s - g s^2 / 2 = 3.5 - s: s = 4 / g, at 2 m/s relative to the platform.
  run(world, 0.3);
  const std::vector<Contact> contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].time, 3.0 + 4.0 / kG, 1e-9);
  EXPECT_NEAR(contacts[0].approach_speed, 2.0, 1e-9);
  EXPECT_NEAR(b.velocity.y(), -1.0, 1e-9);  // e = 0: with the platform from then on
}

TEST(Kinematics, AStillBallOnARoughPlatformSlidingUnderItRollsAtTwoSeventhsOfItsSpeed) {
  const double u = 2.0, mu = 0.3;
  World world(Vec2(0.0, -kG));
  Segment platform = moving(segment(Vec2(-10.0, 0.0), Vec2(40.0, 0.0)), Vec2(u, 0.0));
  platform.friction = mu;
  world.addSegment(platform);
  Ball b = ball(Vec2(0.0, 0.5), Vec2::Zero());
  b.friction = mu;
  world.addBall(b);
  // In the platform's frame it slides back at u until friction leaves it rolling at 5/7 of
  // that: 2u/7 forward, from t* = 2u / (7 mu g) on.
  const double t_star = 2.0 * u / (7.0 * mu * kG);
  run(world, 1.0);
  const Ball& rolling = world.balls()[0];
  EXPECT_NEAR(rolling.velocity.x(), 2.0 * u / 7.0, 1e-9);
  EXPECT_NEAR(rolling.angular_velocity, (u - rolling.velocity.x()) / 0.5, 1e-9);  // no slip
  const double x_star = 0.5 * mu * kG * t_star * t_star;
  EXPECT_NEAR(rolling.position.x(), x_star + 2.0 * u / 7.0 * (1.0 - t_star), 1e-9);
  EXPECT_FALSE(rolling.at_rest);
}

TEST(Kinematics, ABallMovingWithARoughPlatformRidesItStill) {
  World world(Vec2(0.0, -kG));
  Segment platform = moving(segment(Vec2(-1.0, 0.0), Vec2(1.0, 0.0)), Vec2(1.5, 0.0));
  platform.friction = 0.5;
  world.addSegment(platform);
  Ball b = ball(Vec2(0.3, 0.5), Vec2(1.5, 0.0));
  b.friction = 0.5;
  world.addBall(b);
  run(world, 2.0);
  const Ball& riding = world.balls()[0];
  EXPECT_NEAR(riding.position.x() - world.segments()[0].start.x(), 1.3, 1e-9);
  EXPECT_NEAR(riding.position.y(), 0.5, 1e-9);
  EXPECT_NEAR(riding.velocity.x(), 1.5, 1e-12);
  EXPECT_EQ(riding.angular_velocity, 0.0);
}

TEST(Kinematics, AFlipperThrowsAStillBallWithTheSpeedOfThePointThatHitsIt) {
  // Where the bar meets the ball its velocity is w d along the contact normal: an elastic hit
  // gives the ball 2 w d, an inelastic one w d, along the normal, when the bar has turned
  // `angle` at w.
  const double angle = 0.6;
  for (const double e : {1.0, 0.0}) {
    for (const double d : {0.5, 1.0}) {  // on the face, and at the tip
      const Contact hit = flipperHit(d, angle, e);
      EXPECT_NEAR(hit.time, angle / 10.0, 1e-12) << e << " " << d;
      EXPECT_NEAR(hit.approach_speed, 10.0 * d, 1e-9) << e << " " << d;
      EXPECT_NEAR(hit.impulse, (1.0 + e) * 10.0 * d, 1e-9) << e << " " << d;
      EXPECT_NEAR(std::atan2(hit.normal.y(), hit.normal.x()), angle + 0.5 * M_PI, 1e-9);
      if (d < 1.0) {
        EXPECT_EQ(hit.other_kind, ContactKind::kSegment);
      }
    }
  }
}

TEST(Kinematics, AFlipperStopsExactlyAtItsLimit) {
  World world(Vec2::Zero());
  const SegmentId id = world.addSegment(flipper(1.0, 4.0, 1.0, 1.0));
  world.step(0.2);
  EXPECT_NEAR(world.segments()[0].angle, 0.8, 1e-15);
  world.step(0.1);  // reaches 1 rad at 0.25 s
  const Segment& s = world.segments()[0];
  EXPECT_EQ(s.angle, 1.0);
  EXPECT_EQ(s.angular_velocity, 0.0);
  EXPECT_NEAR((s.end - Vec2(std::cos(1.0), std::sin(1.0))).norm(), 0.0, 1e-15);
  EXPECT_TRUE(world.setSegmentMotion(id, Vec2::Zero(), -2.0));  // back down to 0
  world.step(1.0);
  EXPECT_EQ(world.segments()[0].angle, 0.0);
  EXPECT_NEAR((world.segments()[0].end - Vec2(1.0, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_FALSE(world.setSegmentMotion(id + 1, Vec2::Zero(), 1.0));
}

TEST(Kinematics, ABallRestingOnAFlipperIsThrownUpWithoutSinkingIntoIt) {
  World world(Vec2(0.0, -kG));
  const SegmentId id = world.addSegment(flipper(1.0, 0.0, 0.6, 0.0));
  world.addBall(ball(Vec2(0.8, 0.1), Vec2::Zero(), 0.1, 0.1, 0.0));
  run(world, 0.5);
  ASSERT_TRUE(world.balls()[0].at_rest);
  ASSERT_TRUE(world.setSegmentMotion(id, Vec2::Zero(), 15.0));  // up to 0.6 rad in 0.04 s
  for (int i = 0; i < 30; ++i) {
    world.step(1.0 / 600.0);
    ASSERT_FALSE(brokenInvariant(world, 1e-7)) << i;
  }
  // It leaves at least as fast as the bar's point under it was when it stopped.
  const Ball& b = world.balls()[0];
  EXPECT_EQ(world.segments()[0].angle, 0.6);
  EXPECT_GT(b.velocity.norm(), 15.0 * 0.8);
  EXPECT_GT(surfaceGap(b, world.segments()[0]), 0.0);
  EXPECT_GT(b.velocity.y(), 0.0);
}

TEST(Kinematics, SpinnersAndPlatformsNeverLetABallInsideThem) {
  for (int seed = 0; seed < 6; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    World world(seed % 2 ? Vec2(0.0, -kG) : Vec2::Zero());
    addBox(world, 6.0, Vec2(6.0, 6.0), 0.8);
    Segment spinner = segment(Vec2(2.0, 6.0), Vec2(5.0, 6.0));
    spinner.pivot = Vec2(3.5, 6.0);
    spinner.thickness = 0.1;
    spinner.angular_velocity = 2.0 + 6.0 * u(rng);
    world.addSegment(spinner);
    Segment platform = segment(Vec2(7.0, 2.0), Vec2(10.0, 2.0), 0.5);
    platform.pivot = platform.start;
    platform.waypoints = {Vec2(7.0, 2.0), Vec2(7.0, 9.0), Vec2(8.5, 9.0)};
    platform.speed = 1.0 + 3.0 * u(rng);
    world.addSegment(platform);
    for (int n = 0; n < 30; ++n) {
      const double fast = n < 4 ? 12.0 : 1.0;  // up to 48 m/s: 5 radii a step
      Ball b = ball(Vec2(0.5 + 11.0 * u(rng), 0.5 + 11.0 * u(rng)),
                    fast * Vec2(8.0 * (u(rng) - 0.5), 8.0 * (u(rng) - 0.5)), 0.15 + 0.2 * u(rng),
                    0.5 + u(rng), 0.5 + 0.5 * u(rng));
      try {
        world.addBall(b);
      } catch (const std::invalid_argument&) {
      }
    }
    for (int i = 0; i < 180; ++i) {
      world.step(kFrameStep);
      ASSERT_FALSE(brokenInvariant(world, 1e-6 * 0.15)) << seed << " step " << i;
      for (const Ball& b : world.balls())
        ASSERT_TRUE(b.position.x() > 0.0 && b.position.x() < 12.0 && b.position.y() > 0.0 &&
                    b.position.y() < 12.0)
            << seed << " ball " << b.id << " step " << i;
    }
  }
}

TEST(Kinematics, MovingALoadedSegmentWakesWhatRestsOnIt) {
  World world(Vec2(0.0, -kG));
  const SegmentId floor = world.addSegment(segment(Vec2(-5.0, 0.0), Vec2(5.0, 0.0), 0.0));
  world.addBall(ball(Vec2(0.0, 0.5), Vec2::Zero(), 0.5, 1.0, 0.0));
  run(world, 0.5);
  ASSERT_TRUE(world.balls()[0].at_rest);
  ASSERT_TRUE(world.setSegmentMotion(floor, Vec2(0.0, 0.5), 0.0));
  run(world, 1.0);
  EXPECT_FALSE(world.balls()[0].at_rest);
  EXPECT_NEAR(world.balls()[0].position.y(), 1.0, 1e-9);
  EXPECT_NEAR(world.balls()[0].velocity.y(), 0.5, 1e-9);
}

TEST(Kinematics, SegmentsRefuseMotionsTheyCannotHave) {
  World world;
  auto refuses = [&](Segment s, const char* what) {
    try {
      world.addSegment(s);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  const Segment bar = segment(Vec2::Zero(), Vec2(1.0, 0.0));
  Segment s = bar;
  s.angular_velocity = NAN;
  refuses(s, "angular velocity");
  s = bar;
  s.velocity = Vec2(2e5, 0.0);
  refuses(s, "faster than");
  s = bar;
  s.min_angle = 0.5;
  refuses(s, "within [min_angle, max_angle]");
  s = bar;
  s.waypoints = {Vec2(1.0, 1.0)};
  refuses(s, "at least two");
  s.waypoints = {Vec2(1.0, 1.0), Vec2(1.0, 1.0)};
  s.speed = 1.0;
  refuses(s, "repeats");
  s.waypoints = {Vec2(1.0, 1.0), Vec2(2.0, 1.0)};
  s.speed = 0.0;
  refuses(s, "speed along waypoints");
  s = bar;
  s.pivot = Vec2(NAN, 0.0);
  refuses(s, "pivot");
  EXPECT_TRUE(world.segments().empty());
  const SegmentId id = world.addSegment(bar);
  EXPECT_THROW(world.setSegmentMotion(id, Vec2(INFINITY, 0.0), 0.0), std::invalid_argument);
  EXPECT_EQ(world.segments()[0].velocity, Vec2::Zero());
}

TEST(Kinematics, APileOnALiftRidesItUpAndTheLiftKeepsItsPace) {
  // 30 balls land in a bin whose floor rises at 0.2 m/s: they settle on it and go up with it,
  // and the lift goes on as it was told, never stopped. The pile stays awake while it rides.
  const double u = 0.2;
  World world = binOnFloor(moving(binFloor(), Vec2(0.0, u)), 30);
  stepTheBin(world, 300, [&](int step) {
    ASSERT_NEAR(world.segments()[2].start.y(), u * world.time(), 1e-12) << "step " << step;
    if (step < 120) return;  // (landed by 2 s)
    ASSERT_NEAR(lowestGap(world), 0.0, kMostSettledOverlap * 0.5) << "step " << step;
    ASSERT_TRUE(std::none_of(world.balls().begin(), world.balls().end(),
                             [](const Ball& b) { return b.at_rest; }))
        << "step " << step;
  });
}

TEST(Kinematics, APileOnALiftSlowerThanTheSleepSpeedRidesItAwake) {
  // At 5 mm/s (slower than a settled ball must be to sleep) the pile still rides the lift,
  // awake: resting, the lift would push into it.
  const double u = 0.005;
  World world = binOnFloor(moving(binFloor(), Vec2(0.0, u)), 30);
  stepTheBin(world, 360, [&](int step) {
    ASSERT_NEAR(world.segments()[2].start.y(), u * world.time(), 1e-12) << "step " << step;
    if (step < 120) return;
    ASSERT_NEAR(lowestGap(world), 0.0, kMostSettledOverlap * 0.5) << "step " << step;
    ASSERT_TRUE(std::none_of(world.balls().begin(), world.balls().end(),
                             [](const Ball& b) { return b.at_rest; }))
        << "step " << step;
  });
}

TEST(Kinematics, APileOnALiftThatTurnsDownFliesOnAndLandsOnItAgain) {
  // The lift goes between y = 0 and y = 2 at 1 m/s: at each turn down the pile goes on up, as
  // a ball does, and lands on the lift again; at each turn up the lift meets it settled. The
  // lift never stops, and nothing sinks into it.
  Segment floor = binFloor();
  floor.waypoints = {Vec2(-3.0, 0.0), Vec2(-3.0, 2.0)};
  floor.speed = 1.0;
  World world = binOnFloor(floor, 20);
  stepTheBin(world, 600, [&](int step) {
    const double t = world.time(), leg = std::fmod(t, 4.0);
    ASSERT_NEAR(world.segments()[2].start.y(), leg < 2.0 ? leg : 4.0 - leg, 1e-9)
        << "step " << step;
    ASSERT_GE(lowestGap(world), -kMostSettledOverlap * 0.5) << "step " << step;
  });
}

TEST(Kinematics, ARowPushedAgainstAWallStopsThePusherAndTheOthersGoOn) {
  // A wall closing at 0.5 m/s on 12 balls in a bin (rows of five, a tenth of a diameter apart)
  // pushes the bottom row together against the other wall, then cannot go on without crushing
  // it: it stops there, step after step, 5 diameters from that wall, and nothing overlaps. A
  // ball thrown 100 m away stays on its parabola throughout.
  World world(Vec2(0.0, -kG));
  Segment floor = segment(Vec2(-10.0, 0.0), Vec2(10.0, 0.0), 0.5);
  floor.friction = 0.3;
  world.addSegment(floor);
  Segment wall = floor;
  wall.end = Vec2(-10.0, 20.0);
  world.addSegment(wall);
  Segment pusher = moving(segment(Vec2(-4.0, 0.0), Vec2(-4.0, 20.0), 0.5), Vec2(-0.5, 0.0));
  pusher.friction = 0.3;
  pusher.pivot = pusher.start;
  world.addSegment(pusher);
  for (int i = 0; i < 12; ++i) {
    Ball b = ball(Vec2(-9.4 + 1.1 * (i % 5), 0.6 + 1.1 * (i / 5)), Vec2::Zero(), 0.5, 1.0, 0.5);
    b.friction = 0.3;
    world.addBall(b);
  }
  world.addBall(ball(kThrownFrom, kThrown, 0.1));
  stepTheBin(world, 600, [&](int step) {
    const double x = world.segments()[2].start.x();
    if (step < 180) return;  // (the row is closed up by 2 s)
    ASSERT_NEAR(x, -10.0 + 5.0, 5.0 * kMostSettledOverlap * 0.5) << "step " << step;
  });
}

TEST(Kinematics, ASleepingRowThatAPusherReachesWakesAndIsPushedAlong) {
  // Six balls asleep in a row on a rough floor, each touching the next; a wall creeping at
  // 5 cm/s reaches them: however slow, it wakes them where it touches, and pushes the row on,
  // without stopping.
  World world(Vec2(0.0, -kG));
  Segment floor = segment(Vec2(-10.0, 0.0), Vec2(30.0, 0.0), 0.5);
  floor.friction = 0.3;
  world.addSegment(floor);
  for (int i = 0; i < 6; ++i) {
    Ball b = ball(Vec2(1.0 * i, 0.5), Vec2::Zero(), 0.5, 1.0, 0.5);
    b.friction = 0.3;
    world.addBall(b);
  }
  world.addBall(ball(kThrownFrom, kThrown, 0.1));
  const auto rowRests = [&] {
    return std::all_of(world.balls().begin(), world.balls().begin() + 6,
                       [](const Ball& b) { return b.at_rest; });
  };
  for (int step = 0; step < 120 && !rowRests(); ++step) world.step(kFrameStep);
  ASSERT_TRUE(rowRests());
  const double u = 0.05;
  Segment pusher = moving(segment(Vec2(-0.6, 0.0), Vec2(-0.6, 3.0), 0.5), Vec2(u, 0.0));
  pusher.pivot = pusher.start;
  world.addSegment(pusher);
  const double added = world.time();
  stepTheBin(world, 600, [&](int step) {
    ASSERT_NEAR(world.segments()[1].start.x(), -0.6 + u * (world.time() - added), 1e-12)
        << "step " << step;
  });
  // Pushed 10 s at 5 cm/s from 0.1 m away: the row's nearest ball went 0.4 m.
  const double nearest = std::min_element(world.balls().begin(), world.balls().begin() + 6,
                                          [](const Ball& a, const Ball& b) {
                                            return a.position.x() < b.position.x();
                                          })->position.x();
  EXPECT_NEAR(nearest, -0.6 + u * 10.0 + 0.5, kMostSettledOverlap * 0.5);
}

TEST(Kinematics, ARowOnALeverTurningUpRollsDownItWithinWhatASettleMayLeave) {
  // A settle meets a turning segment where the stretch leaves it: along the normal then, the
  // gap is linear in a ball's straight path. Along the normal now, a row of smooth balls (a
  // pile: it settles) rolling down a lever turning up at 0.5 rad/s would end steps 3e-3 r into
  // it, and rough ones 7e-4 r.
  for (const double mu : {0.0, 0.3}) {
    World world(Vec2(0.0, -kG));
    Segment wall = segment(Vec2(0.0, -1.0), Vec2(0.0, 10.0), 0.5);
    Segment lever = segment(Vec2(0.0, 0.0), Vec2(6.0, 0.0), 0.5);
    wall.friction = lever.friction = mu;
    lever.pivot = lever.start;
    lever.max_angle = 0.6;
    world.addSegment(wall);
    const SegmentId id = world.addSegment(lever);
    for (int i = 0; i < 5; ++i) {
      Ball b = ball(Vec2(0.5 + 1.001 * i, 0.5), Vec2::Zero(), 0.5, 1.0, 0.5);
      b.friction = mu;
      world.addBall(b);
    }
    world.addBall(ball(kThrownFrom, kThrown, 0.1));
    stepTheBin(world, 60);
    ASSERT_TRUE(world.setSegmentMotion(id, Vec2::Zero(), 0.5));
    const double started = world.time();
    stepTheBin(world, 90, [&](int step) {  // never stopped: at its limit at 1.2 s
      ASSERT_NEAR(world.segments()[1].angle, std::min(0.6, 0.5 * (world.time() - started)), 1e-12)
          << mu << ", step " << step;
    });
  }
}

TEST(Kinematics, ASpinnerDiggingIntoAPileSettlesWithItAndTheRestOfTheWorldGoesOn) {
  // Turning at 1 rad/s inside a bin of 30 balls, it pushes them up and aside until it would
  // crush them against the floor or a wall: it stops there, as a lift does. Left to events (before
  // settles took turning segments), every ball waited while its budgets ran out, and the ball
  // thrown 100 m away fell 3.5 cm behind its parabola in 2 s.
  Segment spinner = segment(Vec2(-1.0, 1.15), Vec2(1.0, 1.15), 0.5);
  spinner.friction = 0.3;
  spinner.pivot = Vec2(0.0, 1.15);
  spinner.angular_velocity = 1.0;
  World world = binOnFloor(binFloor(), 30);
  world.addSegment(spinner);
  stepTheBin(world, 60);
  EXPECT_NEAR(world.segments()[3].angle, 1.0, 1e-12);  // its pace kept
  stepTheBin(world, 540);
  EXPECT_GT(world.segments()[3].angle, kPi / 2.0 - 0.05);  // through the pile to upright, at least
}

namespace {

// Random bins of 5 to 64 balls (rough or smooth, any restitution), for each of `seeds`: for
// 5 s nothing overlaps past what a settle may leave, and a ball thrown 200 m away keeps its
// parabola. A bin sits on a lift, a lift on waypoints, a sliding floor, or between a wall and a
// pusher closing on it, at up to 1 m/s (or 1 cm/s); or, `turning`, it holds a spinner (at up
// to 3 rad/s, or 0.03; thin or thick) or its floor is a lever rocking up and down.
void expectRandomBinsKeepWithinWhatASettleMayLeave(const std::vector<unsigned>& seeds,
                                                   bool turning) {
  for (const unsigned seed : seeds) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    World world(Vec2(0.0, -kG));
    const double mu = unit(rng) < 0.3 ? 0.0 : 0.6 * unit(rng), e = unit(rng);
    const double width = 3.0 + 4.0 * unit(rng);
    Segment left = segment(Vec2(0.0, -5.0), Vec2(0.0, 30.0), e);
    left.friction = mu;
    Segment right = left, floor = left;
    right.start.x() = right.end.x() = width;
    floor.start = Vec2(0.0, 0.0);
    floor.end = Vec2(width, 0.0);
    floor.pivot = floor.start;
    const unsigned kind = turning ? 4 + rng() % 2 : rng() % 4;
    const double u = (unit(rng) < 0.2 ? 0.01 : 1.0) * (2.0 * unit(rng) - 1.0);
    if (kind == 0) {
      floor.velocity = Vec2(0.0, u);
    } else if (kind == 1) {
      floor.waypoints = {Vec2(0.0, 0.0), Vec2(0.0, 2.0)};
      floor.speed = std::abs(u) + 0.1;
    } else if (kind == 2) {
      right.velocity = Vec2(-std::abs(u), 0.0);
      right.pivot = right.start;
    } else if (kind == 3) {
      floor.velocity = Vec2(u, 0.0);
      floor.start.x() -= 20.0;
      floor.end.x() += 20.0;
      floor.pivot = floor.start;
    } else if (kind == 5) {
      floor.min_angle = 0.0;
      floor.max_angle = 0.4;
      floor.angular_velocity = 3.0 * std::abs(u);
    }
    for (const Segment& s : {left, right, floor}) world.addSegment(s);
    if (kind == 4) {
      const Vec2 middle(width / 2.0 + unit(rng) - 0.5, 0.5 + 2.0 * unit(rng));
      const Vec2 half(0.15 * width * (1.0 + unit(rng)), 0.0);
      Segment spinner = segment(middle - half, middle + half, e);
      spinner.friction = mu;
      spinner.pivot = middle;
      spinner.thickness = unit(rng) < 0.5 ? 0.0 : 0.2;
      spinner.angular_velocity = 3.0 * u;
      world.addSegment(spinner);
    }
    const int n = 5 + static_cast<int>(rng() % 60);
    const double r = 0.2 + 0.3 * unit(rng);
    const int columns = std::max(1, static_cast<int>((width - 0.2) / (2.2 * r)));
    double smallest = r;
    for (int i = 0; i < n; ++i) {
      Ball b = ball(Vec2(0.1 + 1.1 * r + (i % columns) * 2.2 * r + 0.02 * unit(rng),
                         0.1 + 1.1 * r + (i / columns) * 2.2 * r),
                    Vec2::Zero(), r * (0.8 + 0.2 * unit(rng)), 1.0, e);
      b.mass = b.radius * b.radius;
      b.friction = mu;
      if (kind == 4 && surfaceGap(b, world.segments()[3]) < 0.1) continue;  // (off the spinner)
      smallest = std::min(smallest, b.radius);
      world.addBall(b);
    }
    const Vec2 from(200.0, 0.0);
    world.addBall(ball(from, kThrown, 0.1));
    for (int step = 1; step <= 300; ++step) {
      // (The lever turns back at each limit.)
      if (const Segment& lever = world.segments()[2]; kind == 5 && lever.angular_velocity == 0.0)
        ASSERT_TRUE(world.setSegmentMotion(lever.id, Vec2::Zero(),
                                           (lever.angle > 0.2 ? -3.0 : 3.0) * std::abs(u)));
      world.step(kFrameStep);
      const double t = world.time();
      ASSERT_NEAR(
          (world.balls().back().position - (from + kThrown * t + 0.5 * world.gravity() * t * t))
              .norm(),
          0.0, 1e-9)
          << "seed " << seed << ", step " << step;
      const auto broken = brokenInvariant(world, kMostSettledOverlap * smallest);
      ASSERT_FALSE(broken)
          << *broken << ", seed " << seed << ", kind " << kind << ", step " << step;
    }
  }
}

}  // namespace

TEST(Kinematics, RandomBinsOnMovingSegmentsKeepWithinWhatASettleMayLeave) {
  // Seeds 0 to 39, and two where a pusher reaches a ball resting in a settling pile (it must
  // wake). (Of seeds 0 to 299, 12 end a step past it, by up to a few times: pushers squeezing
  // balls out of a row.)
  std::vector<unsigned> seeds(40);
  std::iota(seeds.begin(), seeds.end(), 0u);
  seeds.insert(seeds.end(), {92u, 118u});
  expectRandomBinsKeepWithinWhatASettleMayLeave(seeds, false);
}

TEST(Kinematics, RandomBinsWithATurningSegmentKeepWithinWhatASettleMayLeave) {
  // Seeds 0 to 39. (Of seeds 0 to 99, 2 end a step past it, by 2.2e-3 r and 6.6e-3 r: a
  // spinner pressing a ball into the pile, opened again at 1 cm/s.)
  std::vector<unsigned> seeds(40);
  std::iota(seeds.begin(), seeds.end(), 0u);
  expectRandomBinsKeepWithinWhatASettleMayLeave(seeds, true);
}
