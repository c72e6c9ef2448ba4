// Through ROS: the `platformer` scene played with cmd_vel and step, read on sensor_events and
// balls.
#include <optional>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/SensorEvent.h"
#include "ball_physics_sim/Step.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::spinUntil;

TEST(Platformer, ARouteOfCmdVelCommandsTakesTheBallToTheFlag) {
  ros::NodeHandle nh;
  std::vector<SensorEvent> events;
  std::optional<BallStateArray> last;
  ros::Subscriber events_sub = nh.subscribe<SensorEvent>(
      "sensor_events", 10, [&](const auto& msg) { events.push_back(*msg); });
  ros::Subscriber balls_sub =
      nh.subscribe<BallStateArray>("balls", 10, [&](const auto& msg) { last = *msg; });
  ros::Publisher cmd_vel = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  ASSERT_TRUE(spinUntil([&] {
    return events_sub.getNumPublishers() > 0 && cmd_vel.getNumSubscribers() > 0;
  }));
  // A run, a jump over the wall, a glide, a jump onto the upper step; then hands off.
  struct Command {
    double x, y;
    std::uint32_t steps;  // of the node's 1/120 s
  };
  const Command route[] = {{3.0, 0.0, 150}, {3.0, 22.0, 50}, {0.0, 0.0, 60},
                           {1.0, 26.0, 50}, {0.0, 0.0, 240}};
  double time = 0.0;
  for (const Command& command : route) {
    geometry_msgs::Twist twist;
    twist.linear.x = command.x;
    twist.linear.y = command.y;
    cmd_vel.publish(twist);
    spinUntil([] { return false; }, 0.5);  // the node takes it while paused (no answer says so)
    Step step;
    step.request.steps = command.steps;
    ASSERT_TRUE(ros::service::call("step", step));
    ASSERT_TRUE(step.response.success) << step.response.message;
    time = step.response.time;
  }
  ASSERT_TRUE(spinUntil([&] {
    return !events.empty() && last && std::abs(last->header.stamp.toSec() - time) < 1e-9;
  }));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].sensor, "flag");
  EXPECT_TRUE(events[0].entered);
  ASSERT_EQ(last->balls.size(), 1u);
  const BallState& ball = last->balls[0];
  EXPECT_NEAR(ball.position.y, 2.1 + ball.radius, 1e-9);  // on the flag's step
  EXPECT_GT(ball.position.x, 5.5);
  EXPECT_LT(ball.position.x, 7.5);
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_platformer");
}
