// Through ROS: the `pool` scene's break, fired with `fire` and run with `step`, read on
// sensor_events and balls.
#include <cmath>
#include <optional>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/SensorEvent.h"
#include "ball_physics_sim/Step.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::spinUntil;

namespace {

// The table's cushion lines: x = 0 and 2.54 m, y = 0 and 1.27 m; 15 balls racked.
constexpr double kLength = 2.54, kWidth = 1.27;
constexpr std::size_t kRack = 15;
constexpr std::uint32_t kMinute = 7200;  // steps of the node's 1/120 s

}  // namespace

TEST(Pool, TheBreakPocketsBallsOnlyThroughThePockets) {
  ros::NodeHandle nh;
  std::set<std::uint32_t> pocketed;
  std::optional<BallStateArray> after;
  double end_time = -1.0;
  ros::Subscriber events = nh.subscribe<SensorEvent>("sensor_events", 100, [&](const auto& msg) {
    EXPECT_TRUE(msg->entered) << "ball " << msg->ball_id << " left " << msg->sensor;
    EXPECT_EQ(msg->sensor.find("corner_") == 0 || msg->sensor.find("side_") == 0, true)
        << msg->sensor;
    pocketed.insert(msg->ball_id);
  });
  ros::Subscriber balls = nh.subscribe<BallStateArray>("balls", 10, [&](const auto& msg) {
    if (std::abs(msg->header.stamp.toSec() - end_time) < 1e-9) after = *msg;
  });
  ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  ASSERT_TRUE(spinUntil([&] { return events.getNumPublishers() > 0; }));
  Fire fire;
  ASSERT_TRUE(ros::service::call("fire", fire));
  ASSERT_TRUE(fire.response.success) << fire.response.message;
  Step step;
  step.request.steps = kMinute;
  ASSERT_TRUE(ros::service::call("step", step));
  ASSERT_TRUE(step.response.success) << step.response.message;
  end_time = step.response.time;
  // The events come on their own topic: wait for them all (or time out and fail below).
  spinUntil([&] { return after && after->balls.size() + pocketed.size() == kRack + 1; });
  ASSERT_TRUE(after.has_value());

  // Every ball is on the table, its centre within the cushions, or was taken by a pocket.
  std::set<std::uint32_t> on_table;
  for (const BallState& b : after->balls) {
    on_table.insert(b.id);
    EXPECT_TRUE(b.position.x >= 0.0 && b.position.x <= kLength && b.position.y >= 0.0 &&
                b.position.y <= kWidth)
        << "ball " << b.id << " off the table at (" << b.position.x << ", " << b.position.y << ")";
    EXPECT_EQ(pocketed.count(b.id), 0u) << "ball " << b.id << " pocketed but still there";
  }
  EXPECT_EQ(on_table.size() + pocketed.size(), kRack + 1);  // and the cue ball
  EXPECT_FALSE(pocketed.empty());
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_pool");
}
