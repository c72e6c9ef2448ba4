// Through ROS: a turn of the `artillery` scene with aim, fire, step and explode, read on
// contacts.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/ContactArray.h"
#include "ball_physics_sim/Explode.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/Step.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::callSucceeding;
using ball_physics_sim::test::spinUntil;
using ball_physics_sim::test::stepBy;

namespace {

// The scene: crates 1-3 in the left valley, 4-6 in the right one (radius 0.3, centres on
// y = 0.8 at x = 5.1, 5.7, 6.3); shells of radius 0.15.
constexpr std::uint32_t kTargetCrate = 6;
constexpr double kShellRadius = 0.15, kTimeStep = 1.0 / 120.0;

}  // namespace

TEST(Artillery, TheShotStrikesTheCrateAimSaidWhereAndWhenItSaidAndTheBlastThrowsItsNeighbours) {
  ros::NodeHandle nh;
  std::vector<Contact> contacts;
  ros::Subscriber sub = nh.subscribe<ContactArray>("contacts", 100, [&](const auto& msg) {
    contacts.insert(contacts.end(), msg->contacts.begin(), msg->contacts.end());
  });
  ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  ASSERT_TRUE(spinUntil([&] { return sub.getNumPublishers() > 0; }));

  // The left launcher's turn: the high arc over the mountain onto the far crate.
  Aim aim;
  aim.request.launcher = "left";
  aim.request.mode = Aim::Request::TARGET_BALLISTIC;
  aim.request.target.x = 6.3;
  aim.request.target.y = 0.8;
  aim.request.speed = 16.0;
  aim.request.high_arc = true;
  const Aim aimed = callSucceeding("aim", aim);
  ASSERT_GT(aimed.response.time_of_flight, 0.0);
  Fire fire;
  fire.request.launcher = "left";
  const std::uint32_t shell = callSucceeding("fire", fire).response.ball_id;
  stepBy(static_cast<std::uint32_t>(aimed.response.time_of_flight / kTimeStep) + 2);

  auto first_strike = [&]() -> const Contact* {
    for (const Contact& c : contacts)
      if (c.ball_id == shell || (c.other_kind == Contact::BALL && c.other_id == shell)) return &c;
    return nullptr;
  };
  ASSERT_TRUE(spinUntil([&] { return first_strike() != nullptr; }));
  const Contact& strike = *first_strike();
  const bool shell_first = strike.ball_id == shell;
  ASSERT_EQ(strike.other_kind, Contact::BALL);
  EXPECT_EQ(shell_first ? strike.other_id : strike.ball_id, kTargetCrate);
  const double sign = shell_first ? 1.0 : -1.0;  // the normal points toward `ball_id`
  EXPECT_NEAR(strike.point.x + sign * kShellRadius * strike.normal.x, aimed.response.predicted_hit.x, 1e-9);
  EXPECT_NEAR(strike.point.y + sign * kShellRadius * strike.normal.y, aimed.response.predicted_hit.y, 1e-9);
  EXPECT_NEAR(strike.time, aimed.response.time_of_flight, 1e-9);

  // The blast where it struck reaches the three crates there and none of the others.
  Explode blast;
  blast.request.centre = strike.point;
  blast.request.impulse = 4.0;
  blast.request.radius = 2.5;
  std::vector<std::uint32_t> pushed = callSucceeding("explode", blast).response.ball_ids;
  pushed.erase(std::remove(pushed.begin(), pushed.end(), shell), pushed.end());
  std::sort(pushed.begin(), pushed.end());
  EXPECT_EQ(pushed, std::vector<std::uint32_t>({4, 5, 6}));
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_artillery");
}
