// Through ROS: the `racing` scene's car pushed with cmd_vel and stepped, read on sensor_events.
#include <cmath>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/SensorEvent.h"
#include "ball_physics_sim/Step.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::spinUntil;

TEST(Racing, TheCarPushedAlongTheStraightCrossesTheStartLineWhenConstantAccelerationSays) {
  ros::NodeHandle nh;
  std::vector<SensorEvent> events;
  ros::Subscriber sub = nh.subscribe<SensorEvent>(
      "sensor_events", 10, [&](const auto& msg) { events.push_back(*msg); });
  ros::Publisher cmd_vel = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  ASSERT_TRUE(spinUntil([&] {
    return sub.getNumPublishers() > 0 && cmd_vel.getNumSubscribers() > 0;
  }));
  geometry_msgs::Twist twist;
  twist.linear.x = 4.0;  // m/s^2, from rest at x = -3 toward the line, 0.2 m wide at x = 0
  cmd_vel.publish(twist);
  spinUntil([] { return false; }, 0.5);  // the node takes it while paused (no answer says so)
  Step step;
  step.request.steps = 180;  // 1.5 s
  ASSERT_TRUE(ros::service::call("step", step));
  ASSERT_TRUE(spinUntil([&] { return events.size() >= 2; }));
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].sensor, "start");
  EXPECT_TRUE(events[0].entered);
  EXPECT_NEAR(events[0].time, std::sqrt(2.0 * 2.9 / 4.0), 1e-12);  // x = -3 + 2 t^2 = -0.1
  EXPECT_EQ(events[1].sensor, "start");
  EXPECT_FALSE(events[1].entered);
  EXPECT_NEAR(events[1].time, std::sqrt(2.0 * 3.1 / 4.0), 1e-12);  // and 0.1
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_racing");
}
