#include <cmath>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/region.h"
#include "ball_physics_sim/engine/scene.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using namespace ball_physics_sim::engine::test;

TEST(Region, CheckNamesWhatIsWrong) {
  EXPECT_EQ(refusal([] { checkRegion({Vec2(1, 0), Vec2(0, 1)}, "goal"); }),
            "goal's min corner must be below and left of its max corner");
  EXPECT_NE(refusal([] { checkRegion({Vec2(0, 0), Vec2(INFINITY, 1)}, "goal"); })
                .find("goal's max corner must be finite"),
            std::string::npos);
  EXPECT_EQ(refusal([] { checkRegion({Vec2(0, 0), Vec2(1, 1)}, "goal"); }), "no error");
}

TEST(Region, HoldsACentreInsideOrOnASideMovingIn) {
  const Region r{Vec2(0, 0), Vec2(2, 1)};
  EXPECT_TRUE(centreInside(r, {Vec2(1.0, 0.5)}));
  EXPECT_FALSE(centreInside(r, {Vec2(3.0, 0.5)}));
  EXPECT_TRUE(centreInside(r, {Vec2(2.0, 0.5)}));  // still on the side
  // A hair outside the side it is crossing, as rounding leaves a centre at a crossing's time.
  EXPECT_TRUE(centreInside(r, {Vec2(-1e-15, 0.5), Vec2(1.0, 0.0)}));
  EXPECT_FALSE(centreInside(r, {Vec2(1e-15, 0.5), Vec2(-1.0, 0.0)}));
  EXPECT_FALSE(centreInside(r, {Vec2(1.0, 1.0), Vec2::Zero(), Vec2(0.0, 1.0)}));  // lifted out
}

TEST(Region, CrossingIsTheFirstRootOfASidesQuadraticThatLiesOnTheSide) {
  const Region r{Vec2(0, 0), Vec2(1, 1)};
  EXPECT_EQ(timeToCrossRegion(r, {Vec2(-1.0, 0.5), Vec2(4.0, 0.0)}, 10.0), 0.25);
  EXPECT_EQ(timeToCrossRegion(r, {Vec2(0.5, 0.5), Vec2(0.0, 1.0)}, 10.0), 0.5);  // leaving
  // Falling in from above: 2 - t^2 = 1.
  EXPECT_EQ(timeToCrossRegion(r, {Vec2(0.5, 2.0), Vec2::Zero(), Vec2(0.0, -2.0)}, 10.0), 1.0);
  // Thrown up inside, it leaves through the top only if it gets there: 0.5 + t - t^2 / 2 = 1.
  EXPECT_EQ(timeToCrossRegion(r, {Vec2(0.5, 0.5), Vec2(0.0, 1.0), Vec2(0.0, -1.0)}, 10.0), 1.0);
  EXPECT_EQ(timeToCrossRegion(r, {Vec2(0.5, 0.5), Vec2(0.0, 0.9), Vec2(0.0, -1.0)}, 10.0),
            0.9 + std::sqrt(0.81 + 1.0));  // back out through the bottom
  EXPECT_EQ(timeToCrossRegion(r, {Vec2(-1.0, 5.0), Vec2(1.0, 0.0)}, 10.0), std::nullopt);  // passes above
  EXPECT_EQ(timeToCrossRegion(r, {Vec2(-1.0, 0.5), Vec2(1.0, 0.0)}, 0.5), std::nullopt);  // too late
}

TEST(World, ASensorReportsABallGoingInAndOutAtTheExactTimes) {
  World world(Vec2::Zero());
  world.addSensor({"goal", {Vec2(0.0, 0.0), Vec2(2.0, 1.0)}});
  // In at t = 1.005 and out at 3.005, between the steps' ends.
  const BallId id = world.addBall(ball(Vec2(-1.005, 0.5), Vec2(1.0, 0.0), 0.1));
  run(world, 4.0);
  const std::vector<SensorEvent> events = world.takeSensorEvents();
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].sensor, "goal");
  EXPECT_EQ(events[0].ball, id);
  EXPECT_TRUE(events[0].entered);
  EXPECT_NEAR(events[0].time, 1.005, 1e-12);
  EXPECT_FALSE(events[1].entered);
  EXPECT_NEAR(events[1].time, 3.005, 1e-12);
  EXPECT_TRUE(world.takeSensorEvents().empty());
}

TEST(World, ABallDroppedIntoAGoalIsReportedOnceAtTheTimeItsCentreFallsIn) {
  World world;
  world.addSegment(segment(Vec2(-5.0, 0.0), Vec2(5.0, 0.0), 0.0));
  world.addSensor({"cup", {Vec2(-1.0, 0.0), Vec2(1.0, 2.0)}});
  const BallId id = world.addBall(ball(Vec2(0.0, 5.0), Vec2::Zero(), 0.5, 1.0, 0.0));
  run(world, 3.0);
  const std::vector<SensorEvent> events = world.takeSensorEvents();
  ASSERT_EQ(events.size(), 1u);  // it stays there, at rest
  EXPECT_EQ(events[0].ball, id);
  EXPECT_NEAR(events[0].time, std::sqrt(2.0 * 3.0 / kG), 1e-12);
  EXPECT_TRUE(world.findBall(id)->at_rest);
}

TEST(World, ABallAddedInASensorGoesInAtTheNextStepAndOneRemovedLeavesNoEvent) {
  World world(Vec2::Zero());
  world.addSensor({"zone", {Vec2(-1.0, -1.0), Vec2(1.0, 1.0)}});
  world.step(0.5);
  const BallId id = world.addBall(ball(Vec2(0.0, 0.0), Vec2::Zero(), 0.1));
  world.step(0.5);
  const std::vector<SensorEvent> events = world.takeSensorEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].ball, id);
  EXPECT_EQ(events[0].time, 0.5);
  world.removeBall(id);
  world.step(0.5);
  EXPECT_TRUE(world.takeSensorEvents().empty());
}

TEST(World, ASensorNeedsAName) {
  World world;
  EXPECT_EQ(refusal([&] { world.addSensor({"", {Vec2(0, 0), Vec2(1, 1)}}); }),
            "a sensor needs a name");
  world.addSensor({"goal", {Vec2(0, 0), Vec2(1, 1)}});
  EXPECT_EQ(refusal([&] { world.addSensor({"goal", {Vec2(2, 0), Vec2(3, 1)}}); }),
            "there is a sensor named 'goal' already");
  EXPECT_EQ(world.sensors().size(), 1u);
}

TEST(World, SensorsOnlyWatch) {
  // Elastic billiards is chaotic: a motion cut at a sensor's crossing, however exactly, would
  // part the two runs within seconds.
  Scene watched = loadScene(SCENES_DIR "/billiards.yaml");
  Scene plain = watched;
  for (int k = 0; k < 9; ++k) {  // a grid of three by three over the box
    const Vec2 corner(-6.0 + 4.0 * (k % 3), 8.0 / 3.0 * (k / 3));
    watched.world.addSensor({"cell" + std::to_string(k), {corner, corner + Vec2(4.0, 8.0 / 3.0)}});
  }
  run(watched.world, 10.0);
  run(plain.world, 10.0);
  EXPECT_FALSE(watched.world.takeSensorEvents().empty());
  ASSERT_EQ(watched.world.balls().size(), plain.world.balls().size());
  for (std::size_t i = 0; i < plain.world.balls().size(); ++i) {
    EXPECT_EQ(watched.world.balls()[i].position, plain.world.balls()[i].position);
    EXPECT_EQ(watched.world.balls()[i].velocity, plain.world.balls()[i].velocity);
  }
}
