// Through ROS: the `contraption` scene (an incredible machine) with add_segment, fire, pause,
// reset and step, read on sensor_events.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>

#include "ball_physics_sim/AddSegment.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/SensorEvent.h"
#include "ball_physics_sim/Step.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::callSucceeding;
using ball_physics_sim::test::spinUntil;
using ball_physics_sim::test::stepBy;

namespace {

void setPaused(bool paused) {
  std_srvs::SetBool pause;
  pause.request.data = paused;
  callSucceeding("pause", pause);
}

}  // namespace

TEST(Contraption, APlacedRampDeliversTheDroppedBallToTheGoalAndWithoutItTheBallMisses) {
  ros::NodeHandle nh;
  std::vector<SensorEvent> events;
  ros::Subscriber sub = nh.subscribe<SensorEvent>(
      "sensor_events", 10, [&](const auto& msg) { events.push_back(*msg); });
  ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  ASSERT_TRUE(spinUntil([&] { return sub.getNumPublishers() > 0; }));

  // The ramp the scene file suggests, placed while paused; then the drop, and time runs.
  AddSegment ramp = test::segmentRequest(-5.0, 4.5, 3.5, 2.0);
  ramp.request.thickness = 0.1;
  ramp.request.restitution = 0.2;
  callSucceeding("add_segment", ramp);
  const std::uint32_t ball = callSucceeding("fire", Fire()).response.ball_id;
  setPaused(false);
  ASSERT_TRUE(spinUntil([&] { return !events.empty(); }, 20.0)) << "the ball never reached the goal";
  setPaused(true);
  EXPECT_EQ(events[0].sensor, "goal");
  EXPECT_EQ(events[0].ball_id, ball);
  EXPECT_TRUE(events[0].entered);

  // Without the ramp (reset takes it away) the same drop rolls to a stop short of the cup.
  std_srvs::Trigger reset;
  ASSERT_TRUE(ros::service::call("reset", reset));
  events.clear();
  callSucceeding("fire", Fire());
  stepBy(120 * 20);
  spinUntil([] { return false; }, 0.5);  // anything on its way arrives
  EXPECT_TRUE(events.empty());
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_contraption");
}
