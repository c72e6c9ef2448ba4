// Through ROS: the `bricks` scene played with aim, fire, set_segment_motion and step, read on
// brick_hits, sensor_events and markers.
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/BrickHit.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/SensorEvent.h"
#include "ball_physics_sim/SetSegmentMotion.h"
#include "ball_physics_sim/Step.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::callSucceeding;
using ball_physics_sim::test::spinUntil;
using ball_physics_sim::test::stepBy;

namespace {

// The scene: the serve at (0, 1.2), 8 m/s, balls of radius 0.2; the paddle (segment 4) on
// y = 0.5 from x = -1 to 1; the bottom row's middle brick (segment 9, one hit) on y = 6, 0.4
// thick; the out sensor below y = -0.5. No gravity.
constexpr double kServeY = 1.2, kSpeed = 8.0, kRadius = 0.2;
constexpr std::uint32_t kPaddle = 4, kMiddleBrick = 9;
constexpr double kBrickFace = 6.0 - 0.2, kOutTop = -0.5;

void movePaddle(double velocity) {
  SetSegmentMotion motion;
  motion.request.segment_id = kPaddle;
  motion.request.velocity.x = velocity;
  callSucceeding("set_segment_motion", motion);
}

}  // namespace

TEST(Bricks, AServeStraightUpBreaksTheBrickAboveAndFallsPastThePaddleIntoTheOutSensor) {
  ros::NodeHandle nh;
  std::vector<BrickHit> hits;
  std::vector<SensorEvent> events;
  std::optional<visualization_msgs::Marker> brick_marker;
  ros::Subscriber hits_sub =
      nh.subscribe<BrickHit>("brick_hits", 10, [&](const auto& msg) { hits.push_back(*msg); });
  ros::Subscriber events_sub = nh.subscribe<SensorEvent>(
      "sensor_events", 10, [&](const auto& msg) { events.push_back(*msg); });
  ros::Subscriber markers_sub =
      nh.subscribe<visualization_msgs::MarkerArray>("markers", 10, [&](const auto& msg) {
        for (const auto& m : msg->markers)
          if (m.ns == "segments" && m.id == int(kMiddleBrick)) brick_marker = m;
      });
  ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  ASSERT_TRUE(spinUntil([&] { return hits_sub.getNumPublishers() > 0 &&
                                     events_sub.getNumPublishers() > 0 && brick_marker; }));
  EXPECT_EQ(brick_marker->action, visualization_msgs::Marker::ADD);

  Aim aim;
  aim.request.mode = Aim::Request::ANGLE;
  aim.request.angle = M_PI / 2.0;
  callSucceeding("aim", aim);
  const Fire fired = callSucceeding("fire", Fire());
  // The paddle slides out of the way (2 m in 0.5 s) before the ball comes back.
  movePaddle(4.0);
  stepBy(60);
  movePaddle(0.0);
  stepBy(120);  // to 1.5 s

  const double hit_time = (kBrickFace - kRadius - kServeY) / kSpeed;  // 0.55 s
  ASSERT_TRUE(spinUntil([&] { return !hits.empty() && !events.empty(); }));
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_NEAR(hits[0].time, hit_time, 1e-12);
  EXPECT_EQ(hits[0].segment_id, kMiddleBrick);
  EXPECT_EQ(hits[0].ball_id, fired.response.ball_id);
  EXPECT_EQ(hits[0].hits_left, 0u);
  // Back down at 8 m/s, its centre crossing into the out zone.
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].sensor, "out");
  EXPECT_EQ(events[0].ball_id, fired.response.ball_id);
  EXPECT_TRUE(events[0].entered);
  EXPECT_NEAR(events[0].time, hit_time + (kBrickFace - kRadius - kOutTop) / kSpeed, 1e-12);
  // The broken brick's marker is deleted.
  EXPECT_TRUE(spinUntil(
      [&] { return brick_marker->action == visualization_msgs::Marker::DELETE; }));
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_bricks");
}
