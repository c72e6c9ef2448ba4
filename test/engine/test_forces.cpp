#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/forces.h"
#include "ball_physics_sim/engine/invariants.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using namespace ball_physics_sim::engine::test;

namespace {

Wind wind(Vec2 min, Vec2 max, Vec2 acceleration) { return {{min, max}, acceleration}; }

// A ball of radius 0.5 settled on a floor reaching `half_width` either side of the origin.
BallId ballAtRestOnAFloor(World& world, double half_width) {
  world.addSegment(segment(Vec2(-half_width, 0.0), Vec2(half_width, 0.0), 0.5));
  const BallId id = world.addBall(ball(Vec2(0.0, 0.5), Vec2::Zero(), 0.5, 1.0, 0.5));
  run(world, 0.5);
  EXPECT_TRUE(world.findBall(id)->at_rest);
  return id;
}

}  // namespace

TEST(Blast, ImpulseFallsLinearlyFromTheCentreToZeroAtItsRadius) {
  const Blast blast{Vec2(1.0, 1.0), 8.0, 4.0};
  EXPECT_EQ(blastImpulse(blast, Vec2(2.0, 1.0)), Vec2(6.0, 0.0));   // 8 (1 - 1/4)
  EXPECT_EQ(blastImpulse(blast, Vec2(1.0, -1.0)), Vec2(0.0, -4.0));  // 8 (1 - 2/4)
  EXPECT_EQ(blastImpulse(blast, Vec2(5.0, 1.0)), Vec2::Zero());      // at the radius
  EXPECT_EQ(blastImpulse(blast, Vec2(9.0, 1.0)), Vec2::Zero());
  EXPECT_EQ(blastImpulse(blast, Vec2(1.0, 1.0)), Vec2::Zero());      // no way away
}

TEST(Blast, CheckNamesWhatIsWrong) {
  EXPECT_NE(refusal([] { checkBlast({Vec2(NAN, 0.0), 1.0, 1.0}); }).find("centre"), std::string::npos);
  EXPECT_NE(refusal([] { checkBlast({Vec2::Zero(), -1.0, 1.0}); }).find("impulse"), std::string::npos);
  EXPECT_NE(refusal([] { checkBlast({Vec2::Zero(), 1.0, 0.0}); }).find("radius"), std::string::npos);
  EXPECT_EQ(refusal([] { checkBlast({Vec2::Zero(), 0.0, 1.0}); }), "no error");
}

TEST(Push, PressesOnWhatLiesWithin60DegreesOfIt) {
  const Vec2 push(2.0, 0.0);
  EXPECT_TRUE(pushesToward(push, Vec2(3.0, 0.0)));
  EXPECT_TRUE(pushesToward(push, Vec2(1.0, 1.7)));   // 59.5 degrees
  EXPECT_TRUE(pushesToward(push, Vec2(std::cos(kPi / 3.0), std::sin(kPi / 3.0))));  // 60
  EXPECT_FALSE(pushesToward(push, Vec2(1.0, 1.8)));  // 60.9 degrees
  EXPECT_FALSE(pushesToward(push, Vec2(0.0, 1.0)));  // beside it
  EXPECT_FALSE(pushesToward(push, Vec2(-1.0, 0.0)));
}

TEST(Wind, CheckNamesWhatIsWrong) {
  EXPECT_NE(refusal([] { checkWind(wind(Vec2(1, 0), Vec2(0, 1), Vec2::Zero())); }).find("min corner"),
            std::string::npos);
  EXPECT_NE(refusal([] { checkWind(wind(Vec2(0, 0), Vec2(INFINITY, 1), Vec2::Zero())); })
                .find("max corner"),
            std::string::npos);
  EXPECT_NE(refusal([] { checkWind(wind(Vec2(0, 0), Vec2(1, 1), Vec2(0, 2e4))); }).find("acceleration"),
            std::string::npos);
}

TEST(World, ABallCrossingWindIsPushedExactlyWhileItsCentreIsInside) {
  World world(Vec2::Zero());
  world.addWind(wind(Vec2(0.0, -10.0), Vec2(2.0, 10.0), Vec2(0.0, 1.0)));
  // Enters at t = 1.005 and leaves at 3.005, between the steps' ends.
  const BallId id = world.addBall(ball(Vec2(-1.005, 0.5), Vec2(1.0, 0.0), 0.1));
  run(world, 2.0);
  const double inside = 2.0 - 1.005;
  EXPECT_NEAR(world.findBall(id)->position.y(), 0.5 + 0.5 * inside * inside, 1e-12);
  EXPECT_NEAR(world.findBall(id)->velocity.y(), inside, 1e-12);
  run(world, 2.0);
  EXPECT_NEAR(world.findBall(id)->position.x(), 2.995, 1e-12);
  EXPECT_NEAR(world.findBall(id)->position.y(), 0.5 + 2.0 + 2.0 * (4.0 - 3.005), 1e-12);
  EXPECT_NEAR(world.findBall(id)->velocity.y(), 2.0, 1e-12);
}

TEST(World, AnUpdraftTwiceGravityLiftsARestingBallAlongItsAnalyticPath) {
  World world;
  const BallId id = ballAtRestOnAFloor(world, 5.0);
  // Up at g while the centre is below 2 m (until t1), then a parabola over 1.5 m (until 3 t1),
  // back into the draft at the speed it left with, which stops it where it started: on the
  // floor, at 4 t1. The crossings fall within steps.
  world.addWind(wind(Vec2(-5.0, 0.0), Vec2(5.0, 2.0), Vec2(0.0, 2.0 * kG)));
  EXPECT_FALSE(world.findBall(id)->at_rest);
  const double t1 = std::sqrt(2.0 * 1.5 / kG), v1 = kG * t1;
  run(world, 1.0);  // above the draft
  EXPECT_NEAR(world.findBall(id)->position.y(), 2.0 + v1 * (1.0 - t1) - 0.5 * kG * std::pow(1.0 - t1, 2), 1e-9);
  EXPECT_NEAR(world.findBall(id)->velocity.y(), v1 - kG * (1.0 - t1), 1e-9);
  run(world, 1.0);  // back in it, slowing down
  const double tau = 2.0 - 3.0 * t1;
  EXPECT_NEAR(world.findBall(id)->position.y(), 2.0 - v1 * tau + 0.5 * kG * tau * tau, 1e-9);
  EXPECT_NEAR(world.findBall(id)->velocity.y(), -v1 + kG * tau, 1e-9);
}

TEST(World, ABallInFlightFollowsTheParabolaOfTheGravitySetMidFlight) {
  World world;
  const BallId id = world.addBall(ball(Vec2(0.0, 100.0), Vec2(1.0, 2.0)));
  run(world, 0.5);
  const Vec2 p = world.findBall(id)->position, v = world.findBall(id)->velocity;
  const Vec2 g(0.5, -2.0);
  world.setGravity(g);
  EXPECT_EQ(world.gravity(), g);
  EXPECT_EQ(world.motionOfBall(id)->acceleration, g);
  run(world, 1.0);
  EXPECT_NEAR((world.findBall(id)->position - (p + v + 0.5 * g)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((world.findBall(id)->velocity - (v + g)).norm(), 0.0, 1e-12);
}

TEST(World, GravityTurnedUpWakesARestingBallWhichRisesFromTheFloor) {
  World world;
  const BallId id = ballAtRestOnAFloor(world, 5.0);
  world.setGravity(Vec2(0.0, 2.0));
  EXPECT_FALSE(world.findBall(id)->at_rest);
  run(world, 1.0);
  EXPECT_NEAR(world.findBall(id)->position.y(), 0.5 + 0.5 * 2.0, 1e-12);  // g t^2 / 2
  EXPECT_NEAR(world.findBall(id)->velocity.y(), 2.0, 1e-12);
}

TEST(World, GravityTheConstructorWouldRefuseIsRefusedAndChangesNothing) {
  World world;
  const BallId id = ballAtRestOnAFloor(world, 5.0);
  EXPECT_NE(refusal([&] { world.setGravity(Vec2(NAN, 0.0)); }).find("gravity must be finite"),
            std::string::npos);
  EXPECT_NE(refusal([&] { world.setGravity(Vec2(0.0, -2e4)); }).find("at most"),
            std::string::npos);
  EXPECT_EQ(world.gravity(), Vec2(0.0, -kG));
  EXPECT_TRUE(world.findBall(id)->at_rest);
  world.addWater({{Vec2(-5.0, -3.0), Vec2(5.0, 0.0)}, 1000.0, 0.0});
  EXPECT_NE(refusal([&] { world.setGravity(Vec2(1.0, -kG)); }).find("water"), std::string::npos);
  EXPECT_EQ(world.gravity(), Vec2(0.0, -kG));
  world.setGravity(Vec2(0.0, -1.0));  // still down: the water stays level
  EXPECT_EQ(world.gravity(), Vec2(0.0, -1.0));
}

TEST(World, ADrivenBallWakesAndAcceleratesExactlyUntilTheDriveStops) {
  World world;
  const BallId id = ballAtRestOnAFloor(world, 50.0);
  ASSERT_TRUE(world.drive(id, Vec2(2.0, 0.0)));
  EXPECT_FALSE(world.findBall(id)->at_rest);
  EXPECT_EQ(world.motionOfBall(id)->acceleration, Vec2(2.0, -kG));
  run(world, 1.5);
  EXPECT_NEAR(world.findBall(id)->position.x(), 2.25, 1e-12);  // a t^2 / 2
  EXPECT_NEAR(world.findBall(id)->velocity.x(), 3.0, 1e-12);
  EXPECT_NEAR(world.findBall(id)->position.y(), 0.5, 1e-12);   // on the floor all along
  ASSERT_TRUE(world.drive(id, Vec2::Zero()));
  run(world, 1.0);
  EXPECT_NEAR(world.findBall(id)->position.x(), 5.25, 1e-12);
  EXPECT_NEAR(world.findBall(id)->velocity.x(), 3.0, 1e-12);
}

TEST(World, ADrivenBallPushesARestingBallItTouchesAlongAFrictionlessFloor) {
  World world;
  const BallId resting = ballAtRestOnAFloor(world, 50.0);
  Ball pusher = ball(Vec2(-1.0, 0.5), Vec2::Zero(), 0.5, 3.0, 0.5);
  const BallId driven = world.addBall(pusher);
  ASSERT_TRUE(world.drive(driven, Vec2(2.0, 0.0)));
  run(world, 1.0);
  // Both at 3 kg x 2 m/s^2 / 4 kg: not held still as if the resting ball were a wall.
  EXPECT_NEAR(world.findBall(driven)->position.x(), -1.0 + 0.75, 1e-9);
  EXPECT_NEAR(world.findBall(resting)->position.x(), 0.75, 1e-9);
  EXPECT_NEAR(world.findBall(resting)->velocity.x(), 1.5, 1e-9);
  EXPECT_FALSE(world.findBall(driven)->at_rest);
}

TEST(World, ADriveOfNoBallOrOfNoFiniteAccelerationIsRefused) {
  World world;
  const BallId id = world.addBall(ball(Vec2(0.0, 0.5), Vec2::Zero()));
  EXPECT_FALSE(world.drive(id + 1, Vec2(1.0, 0.0)));
  EXPECT_NE(refusal([&] { world.drive(id, Vec2(NAN, 0.0)); }).find("drive"), std::string::npos);
  EXPECT_NE(refusal([&] { world.drive(id, Vec2(0.0, 2e4)); }).find("drive"), std::string::npos);
  world.step(0.5);
  EXPECT_NEAR(world.findBall(id)->velocity.y(), -0.5 * kG, 1e-12);  // undriven
}

TEST(World, ABlastThrowsTheBallsItReachesAwayWithTheImpulseOfTheirDistance) {
  World world;
  world.addSegment(segment(Vec2(-10.0, 0.0), Vec2(10.0, 0.0), 0.0));
  const BallId near = world.addBall(ball(Vec2(1.0, 0.5), Vec2::Zero(), 0.5, 2.0, 0.0));
  const BallId on_top = world.addBall(ball(Vec2(1.0, 1.5), Vec2::Zero(), 0.5, 1.0, 0.0));
  const BallId far = world.addBall(ball(Vec2(-5.0, 0.5), Vec2::Zero(), 0.5, 1.0, 0.0));
  run(world, 0.5);
  ASSERT_TRUE(world.findBall(near)->at_rest && world.findBall(on_top)->at_rest);
  const std::vector<BallId> pushed = world.explode({Vec2(0.0, 0.5), 6.0, 4.0});
  EXPECT_EQ(pushed, std::vector<BallId>({near, on_top}));
  EXPECT_FALSE(world.findBall(near)->at_rest);
  EXPECT_EQ(world.motionOfBall(near)->acceleration, world.gravity());  // until it is held
  EXPECT_EQ(world.findBall(near)->velocity, Vec2(6.0 * 0.75 / 2.0, 0.0));
  const double d = std::sqrt(2.0);  // the top ball's distance from the blast
  EXPECT_NEAR((world.findBall(on_top)->velocity - 6.0 * (1.0 - d / 4.0) / d * Vec2(1.0, 1.0)).norm(),
              0.0, 1e-15);
  EXPECT_TRUE(world.findBall(far)->at_rest);
}

TEST(World, ABlastThatWouldThrowABallTooFastIsRefusedAndChangesNothing) {
  World world(Vec2::Zero());
  const BallId heavy = world.addBall(ball(Vec2(-1.0, 0.0), Vec2::Zero(), 0.5, 1.0));
  const BallId light = world.addBall(ball(Vec2(1.0, 0.0), Vec2(1.0, 0.0), 0.5, kMinMass));
  EXPECT_NE(refusal([&] { world.explode({Vec2::Zero(), 1.0, 4.0}); }).find("faster than"),
            std::string::npos);
  EXPECT_NE(refusal([&] { world.explode({Vec2::Zero(), 1.0, -4.0}); }).find("radius"),
            std::string::npos);
  EXPECT_EQ(world.findBall(heavy)->velocity, Vec2::Zero());  // reached first, left alone too
  EXPECT_EQ(world.findBall(light)->velocity, Vec2(1.0, 0.0));
}

TEST(Attractor, PullsWithTheInverseSquareOfTheDistanceSoftenedWithinItsCore) {
  const Attractor point{Vec2(1.0, 1.0), 8.0, 0.0};
  EXPECT_EQ(attraction(point, Vec2(3.0, 1.0)), Vec2(-2.0, 0.0));  // 8 / 2^2, toward the centre
  EXPECT_EQ(attraction(point, Vec2(1.0, 1.0)), Vec2::Zero());     // at a point's centre: none
  const Attractor soft{Vec2::Zero(), 8.0, 2.0};
  EXPECT_NEAR((attraction(soft, Vec2(2.0, 0.0)) - Vec2(-8.0 * 2.0 / std::pow(8.0, 1.5), 0.0)).norm(),
              0.0, 1e-15);
  // Its rate of change along a path, against a difference quotient.
  const Vec2 p(0.7, -1.3), v(2.0, 0.5);
  const double dt = 1e-6;
  const Vec2 quotient = (attraction(soft, p + dt * v) - attraction(soft, p - dt * v)) / (2.0 * dt);
  EXPECT_NEAR((attractionRate(soft, p, v) - quotient).norm(), 0.0, 1e-8);
  EXPECT_NE(refusal([] { checkAttractor({Vec2::Zero(), -1.0, 0.0}); }).find("strength"),
            std::string::npos);
  EXPECT_NE(refusal([] { checkAttractor({Vec2::Zero(), 1.0, NAN}); }).find("core"),
            std::string::npos);
}

TEST(World, ABallCirclesAnAttractorOnItsKeplerOrbit) {
  // Strength 1 at radius 1 and speed 1: a circle, once round in 2 pi s, energy -1/2.
  World world(Vec2::Zero());
  world.addAttractor({Vec2::Zero(), 1.0, 0.0});
  const BallId id = world.addBall(ball(Vec2(1.0, 0.0), Vec2(0.0, 1.0), 0.01));
  for (int orbit = 1; orbit <= 3; ++orbit) {
    run(world, 2.0 * M_PI * orbit - world.time());
    const Ball& b = *world.findBall(id);
    const double t = world.time();
    // The midpoint rule over stretches that drift by at most 1e-9 m: the radius and the energy
    // hold to 1e-8 an orbit, the phase to a few 1e-6.
    EXPECT_NEAR(b.position.norm(), 1.0, 1e-8 * orbit);
    EXPECT_NEAR(0.5 * b.velocity.squaredNorm() - 1.0 / b.position.norm(), -0.5, 1e-8 * orbit);
    EXPECT_NEAR((b.position - Vec2(std::cos(t), std::sin(t))).norm(), 0.0, 5e-6 * orbit);
  }
}

TEST(Water, TheSunkVolumeOfASphereAndTheRateOfItsPush) {
  const double r = 0.1;
  EXPECT_EQ(sunkVolume(r, 0.0), 0.0);
  EXPECT_NEAR(sunkVolume(r, r), 2.0 / 3.0 * kPi * r * r * r, 1e-17);  // half
  EXPECT_NEAR(sunkVolume(r, 2.0 * r), 4.0 / 3.0 * kPi * r * r * r, 1e-17);
  EXPECT_NEAR(sunkVolume(r, 5.0), 4.0 / 3.0 * kPi * r * r * r, 1e-17);  // no deeper than whole
  const Water water{{Vec2(-5.0, -3.0), Vec2(5.0, 0.0)}, 1000.0, 4.0};
  Ball b = ball(Vec2::Zero(), Vec2::Zero(), r, 2.0);
  const Vec2 p(0.3, 0.02), v(0.5, -0.7), a(0.0, -3.0);
  const double dt = 1e-7;
  const Vec2 quotient =
      (waterAcceleration(water, b, p + dt * v, v + dt * a, kG) -
       waterAcceleration(water, b, p - dt * v, v - dt * a, kG)) / (2.0 * dt);
  EXPECT_NEAR((waterAccelerationRate(water, b, p, v, a, kG) - quotient).norm(), 0.0, 1e-6);
}

TEST(Water, ItsStiffnessIsHowFastItsPushFallsWithTheBallsSpeedAndRise) {
  const double r = 0.1, mass = 2.0, density = 1000.0, drag = 4.0;
  const Water water{{Vec2(-5.0, -3.0), Vec2(5.0, 0.0)}, density, drag};
  const Ball b = ball(Vec2::Zero(), Vec2::Zero(), r, mass);
  // Half sunk: half the drag, and the cross-section at the surface is the sphere's widest.
  const WaterStiffness half = waterStiffness(water, b, Vec2(0.3, 0.0), kG);
  EXPECT_NEAR(half.drag, 0.5 * drag, 1e-12);
  EXPECT_NEAR(half.buoyancy, density * kG * kPi * r * r / mass, 1e-12);
  // Anywhere: the push's derivatives, by central differences.
  const Vec2 p(0.3, 0.02), v(0.5, -0.7);
  const double h = 1e-7;
  const WaterStiffness at = waterStiffness(water, b, p, kG);
  const Vec2 faster = (waterAcceleration(water, b, p, v + h * Vec2(1.0, 0.0), kG) -
                       waterAcceleration(water, b, p, v - h * Vec2(1.0, 0.0), kG)) / (2.0 * h);
  const Vec2 higher = (waterAcceleration(water, b, p + h * Vec2(0.0, 1.0), Vec2::Zero(), kG) -
                       waterAcceleration(water, b, p - h * Vec2(0.0, 1.0), Vec2::Zero(), kG)) /
                      (2.0 * h);
  EXPECT_NEAR(at.drag, -faster.x(), 1e-6);
  EXPECT_NEAR(at.buoyancy, -higher.y(), 1e-3 * at.buoyancy);
  const WaterStiffness dry = waterStiffness(water, b, Vec2(0.3, 0.5), kG);
  EXPECT_EQ(dry.drag, 0.0);
  EXPECT_EQ(dry.buoyancy, 0.0);
}

TEST(World, AFloatingBallSettlesAtTheDepthArchimedesGives) {
  const double r = 0.1, density = 1000.0;
  for (const double sunk_fraction : {0.5, 0.3}) {
    // The depth d at which the water displaced weighs what the ball does.
    const double depth = 2.0 * r * sunk_fraction;
    const double mass = density * sunkVolume(r, depth);
    World world;
    world.addWater({{Vec2(-5.0, -3.0), Vec2(5.0, 0.0)}, density, 5.0});
    const BallId id = world.addBall(ball(Vec2(0.0, 0.5), Vec2::Zero(), r, mass));
    run(world, 40.0);  // dropped in, bobbing, damped by the drag
    EXPECT_NEAR(world.findBall(id)->position.y(), r - depth, 1e-9) << sunk_fraction;
    EXPECT_NEAR(world.findBall(id)->velocity.norm(), 0.0, 1e-9) << sunk_fraction;
  }
}

TEST(World, APileSinkingInWaterThatStopsItWithinAStepNeverOutrunsItsTerminalSpeed) {
  // 16 heavy rough balls let go under water whose drag (200/s) would stop them within a 1/60 s
  // step (its time is 0.3 of one): they sink, pile up and settle, never faster than a ball
  // alone sinks, g (1 - displaced / m) / drag. Taken at the start of a settle's stretch, the drag would
  // more than reverse their velocities each step.
  const double r = 0.1, mass = 10.0, drag = 200.0;
  World world(Vec2(0.0, -kG));
  addBox(world, 1.0, {0.0, 1.0}, 0.5);
  world.addWater({{Vec2(-1.0, 0.0), Vec2(1.0, 2.0)}, 1000.0, drag});
  for (int k = 0; k < 16; ++k) {
    Ball b = ball({-0.45 + 0.23 * (k % 4) + 0.01 * (k % 3), 0.1 + 0.23 * (k / 4)}, Vec2::Zero(),
                  r, mass, 0.5);
    b.friction = 0.3;
    world.addBall(b);
  }
  const double terminal = kG * (1.0 - 1000.0 * sunkVolume(r, 2.0 * r) / mass) / drag;
  for (int step = 1; step <= 600; ++step) {
    world.step(kFrameStep);
    ASSERT_EQ(brokenInvariant(world, mostSettledOverlap(world)), std::nullopt) << "step " << step;
    for (const Ball& b : world.balls())
      ASSERT_LE(b.velocity.norm(), terminal * (1.0 + 1e-9)) << "step " << step << " ball " << b.id;
  }
}

TEST(World, ARowOfFloatsTooStiffForItsStepsComesToArchimedesDepth) {
  // Eight balls of 0.1 g and radius 0.1 m touching in a row across a pond, let go 0.2 mm deeper
  // than the depth where the water they displace weighs what they do: they come up to it, and
  // float still there. The water holds each as a spring of omega = 185 rad/s, which steps of
  // 1/60 s taken from their start would throw wider at each step.
  const double r = 0.1, mass = 1e-4, density = 1000.0, surface = 1.0;
  double shallow = 0.0, deep = r;  // Archimedes' depth, by bisection
  for (int k = 0; k < 100; ++k)
    (density * sunkVolume(r, 0.5 * (shallow + deep)) < mass ? shallow : deep) =
        0.5 * (shallow + deep);
  const double afloat = surface + r - shallow;
  World world(Vec2(0.0, -kG));
  addBox(world, 0.8 + 1e-6, {0.0, 0.8}, 0.5);
  world.addWater({{Vec2(-0.8, 0.0), Vec2(0.8, surface)}, density, 3.0});
  for (int k = 0; k < 8; ++k)
    world.addBall(ball({-0.7 + 0.2 * k, afloat - 2e-4}, Vec2::Zero(), r, mass, 0.5));
  for (int step = 1; step <= 300; ++step) {
    world.step(kFrameStep);
    for (const Ball& b : world.balls())
      ASSERT_NEAR(b.position.y(), afloat, step < 60 ? 2e-4 : 1e-6)
          << "step " << step << " ball " << b.id;
  }
}

TEST(World, ABallFallingFromRestIntoAnAttractorKeepsToTheRadialInfallWhateverTheStep) {
  // From rest at r0 under strength S: t = sqrt(r0^3 / 2S) (sqrt(x (1 - x)) + acos(sqrt(x))),
  // x = r / r0. At rest the pull's rate is zero: the stretches must still be short.
  auto fallen_to = [](double t) {  // r at time t, for r0 = S = 1, by bisection
    double lo = 1e-9, hi = 1.0;
    for (int k = 0; k < 200; ++k) {
      const double x = 0.5 * (lo + hi);
      const double at = std::sqrt(0.5) * (std::sqrt(x * (1.0 - x)) + std::acos(std::sqrt(x)));
      (at > t ? lo : hi) = x;
    }
    return 0.5 * (lo + hi);
  };
  for (const double dt : {1.0 / 60.0, 0.3}) {
    World world(Vec2::Zero());
    world.addAttractor({Vec2::Zero(), 1.0, 0.0});
    const BallId id = world.addBall(ball(Vec2(1.0, 0.0), Vec2::Zero(), 0.01));
    run(world, 0.3, dt);
    // The midpoint rule's error over some 60 stretches (not exact: 1.6e-8 m in one 0.3 s step).
    EXPECT_NEAR(world.findBall(id)->position.x(), fallen_to(0.3), 1e-7) << "steps of " << dt;
  }
}

TEST(World, ABallDroppedIntoWaterFeelsItOnlyOnceItTouchesItWhateverTheStep) {
  std::vector<Vec2> after;
  for (const double dt : {1.0 / 600.0, 1.0 / 60.0, 0.1}) {
    World world;
    world.addWater({{Vec2(-5.0, -3.0), Vec2(5.0, 0.0)}, 1000.0, 2.0});
    const BallId id = world.addBall(ball(Vec2(0.0, 0.3), Vec2::Zero(), 0.1, 2.0));
    run(world, 0.1, dt);  // in the air until sqrt(2 0.2 / g) = 0.2019 s: free fall
    EXPECT_NEAR(world.findBall(id)->position.y(), 0.3 - 0.5 * kG * 0.01, 1e-12) << dt;
    run(world, 0.4, dt);  // in the water
    after.push_back(world.findBall(id)->position);
  }
  // Stretches sized by the push's rate, whatever the step: the runs part by the midpoint rule's
  // error only (1.5e-7 m here; before the stretches also ended at the water's surface and
  // looked at the rate at their middle, 1e-2 m with steps of 0.1 s).
  EXPECT_NEAR((after[1] - after[0]).norm(), 0.0, 1e-6);
  EXPECT_NEAR((after[2] - after[0]).norm(), 0.0, 1e-6);
}
