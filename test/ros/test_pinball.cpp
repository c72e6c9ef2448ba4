// Through ROS: the `pinball` scene with fire, step and set_segment_motion, read on contacts,
// sensor_events, balls and markers.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/ContactArray.h"
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

// The scene: the corner above the plunger's lane is segment 5, the top bumper segment 15
// (kicking at 2.5 m/s), the left flipper segment 8 (lying at atan2(-0.45, 0.95), turning up
// to 0.75 rad from there).
constexpr std::uint32_t kCorner = 5, kTopBumper = 15, kLeftFlipper = 8;
constexpr double kKick = 2.5, kFlipperLimit = 0.75;

// The turn about z of a marker's pose, which turns about z only.
double yawOf(const visualization_msgs::Marker& m) {
  return 2.0 * std::atan2(m.pose.orientation.z, m.pose.orientation.w);
}

}  // namespace

TEST(Pinball, ThePlungersBallIsKickedByABumperAndDrainsAndTheFlipperSwingsToItsLimit) {
  ros::NodeHandle nh;
  std::vector<Contact> contacts;
  std::vector<SensorEvent> events;
  std::optional<BallStateArray> balls;
  std::optional<visualization_msgs::Marker> flipper;
  ros::Subscriber contacts_sub = nh.subscribe<ContactArray>("contacts", 100, [&](const auto& msg) {
    contacts.insert(contacts.end(), msg->contacts.begin(), msg->contacts.end());
  });
  ros::Subscriber events_sub = nh.subscribe<SensorEvent>(
      "sensor_events", 10, [&](const auto& msg) { events.push_back(*msg); });
  ros::Subscriber balls_sub =
      nh.subscribe<BallStateArray>("balls", 10, [&](const auto& msg) { balls = *msg; });
  ros::Subscriber markers_sub =
      nh.subscribe<visualization_msgs::MarkerArray>("markers", 10, [&](const auto& msg) {
        for (const auto& m : msg->markers)
          if (m.ns == "segments" && m.id == int(kLeftFlipper)) flipper = m;
      });
  ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  ASSERT_TRUE(spinUntil([&] {
    return contacts_sub.getNumPublishers() > 0 && events_sub.getNumPublishers() > 0 && flipper;
  }));
  const double lying = yawOf(*flipper);
  EXPECT_NEAR(lying, std::atan2(-0.45, 0.95), 1e-9);

  const std::uint32_t ball = callSucceeding("fire", Fire()).response.ball_id;
  const double end = stepBy(720);  // 6 s
  // Its contacts come on their own topic, after the states of the same moment.
  std::vector<const Contact*> own;
  ASSERT_TRUE(spinUntil([&] {
    own.clear();
    for (const Contact& c : contacts)
      if (c.ball_id == ball) own.push_back(&c);
    return own.size() >= 2 && !events.empty() && balls &&
           std::abs(balls->header.stamp.toSec() - end) < 1e-9;
  }));
  // Up the lane, off the corner, into the top bumper, which sends it off faster than its kick.
  ASSERT_GE(own.size(), 2u);
  EXPECT_EQ(own[0]->other_id, kCorner);
  EXPECT_EQ(own[1]->other_id, kTopBumper);
  EXPECT_EQ(own[1]->other_kind, Contact::CAP);
  // The ball's mass is 1 kg: the impulse is the change of its normal speed, (1 + e) v + kick.
  EXPECT_GT(own[1]->impulse - own[1]->approach_speed, kKick);
  // Then round the table and down between the flippers, which nobody flips: drained and taken
  // off the table.
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].sensor, "drain");
  EXPECT_EQ(events[0].ball_id, ball);
  EXPECT_TRUE(balls->balls.empty());

  // The left flipper, swung up, stops at its limit.
  SetSegmentMotion flip;
  flip.request.segment_id = kLeftFlipper;
  flip.request.angular_velocity = 15.0;
  callSucceeding("set_segment_motion", flip);
  stepBy(12);  // 0.1 s, more than the 0.05 s the swing takes
  ASSERT_TRUE(spinUntil([&] {
    return std::abs(yawOf(*flipper) - lying - kFlipperLimit) < 1e-9;
  })) << "the flipper is at " << yawOf(*flipper) - lying;
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_pinball");
}
