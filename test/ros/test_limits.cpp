// Through ROS: what sim_node refuses beyond its limits (limits.test sets them low), saying which
// parameter limits it, while valid calls keep working.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/AddSegment.h"
#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::expectRefused;

namespace {

constexpr double kMaxSpawnRate = 4.0;  // balls per second, as limits.test sets it

SpawnBall spawnAt(double x) { return test::spawnRequest(x, 7.5, 0.1, 1.0); }

}  // namespace

TEST(Limits, SpeedsAndSizesBeyondTheParametersAreRefused) {
  ASSERT_TRUE(ros::service::waitForService("spawn_ball", ros::Duration(30.0)));
  expectRefused<SpawnBall>("spawn_ball", spawnAt(0.0), {
      {"too big", [](SpawnBall& s) { s.request.radius = 1.5; },
       "radius must be at most 1 m (~max_radius), got 1.5"},
      {"too fast", [](SpawnBall& s) { s.request.velocity.x = 60.0; },
       "speed must be at most 50 m/s (~max_speed), got 60"},
      {"too light", [](SpawnBall& s) { s.request.mass = 1e-9; }, "mass must be within [1e-06, 1e+06] kg"},
  });
  expectRefused<Fire>("fire", Fire(), {
      {"too fast", [](Fire& f) { f.request.speed = 51.0; }, "at most 50 m/s (~max_speed"},
  });
  Aim aim;
  aim.request.mode = Aim::Request::ANGLE;
  expectRefused<Aim>("aim", aim, {
      {"too fast", [](Aim& a) { a.request.speed = 51.0; }, "at most 50 m/s (~max_speed"},
  });
}

TEST(Limits, SegmentsBeyondMaxSegmentsAreRefused) {
  // The default scene has 7 segments; ~max_segments is 8.
  AddSegment add = test::segmentRequest(-1.0, 6.5, 1.0, 6.5);
  ASSERT_TRUE(ros::service::call("add_segment", add));
  EXPECT_TRUE(add.response.success) << add.response.message;
  add.request.start.y = add.request.end.y = 6.0;
  expectRefused<AddSegment>("add_segment", add, {
      {"one too many", [](AddSegment&) {}, "the world has its most segments, 8 (~max_segments)"},
  });
}

TEST(Limits, SpawnsBeyondTheRateAreRefusedUntilTheAllowanceRefills) {
  // A second's worth at once, then only what the time the burst takes refills (the bound is
  // measured, so that a slow machine, such as the sanitizer build's, does not fail it).
  constexpr int kBurst = 20;
  int spawned = 0;
  SpawnBall refused;
  const ros::WallTime start = ros::WallTime::now();
  for (int i = 0; i < kBurst; ++i) {
    SpawnBall s = spawnAt(-5.0 + 0.3 * i);
    ASSERT_TRUE(ros::service::call("spawn_ball", s));
    if (s.response.success)
      ++spawned;
    else
      refused = s;
  }
  const double elapsed = (ros::WallTime::now() - start).toSec();
  EXPECT_GE(spawned, int(kMaxSpawnRate));
  EXPECT_LE(spawned, int(kMaxSpawnRate * (1.0 + elapsed)));
  ASSERT_LT(spawned, kBurst) << "the burst took " << elapsed << " s";
  EXPECT_NE(refused.response.message.find("too many new balls: at most 4 per second (~max_spawn_rate)"),
            std::string::npos)
      << refused.response.message;
  ros::WallDuration(1.0 / kMaxSpawnRate + 0.05).sleep();
  SpawnBall later = spawnAt(3.0);
  ASSERT_TRUE(ros::service::call("spawn_ball", later));
  EXPECT_TRUE(later.response.success) << later.response.message;
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_limits");
}
