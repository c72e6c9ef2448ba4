// Through ROS: fire at the wall of the `wall` scene and read `contacts` and `balls`.
#include <cmath>
#include <optional>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/ContactArray.h"
#include "ball_physics_sim/Fire.h"
#include "ros_test_support.h"
#include "std_srvs/Trigger.h"
#include "visualization_msgs/MarkerArray.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::spinUntil;

namespace {

// The wall scene: cannon at the origin aiming along +x at 10 m/s, balls of radius 0.25 and
// mass 2 with restitution 0.8, a wall (segment 1, restitution 1) on x = 5.
constexpr double kSpeed = 10.0, kRadius = 0.25, kMass = 2.0, kRestitution = 0.8, kWallX = 5.0;
constexpr double kStampResolution = 1e-9;  // s, of a ros::Time

}  // namespace

TEST(Contacts, FiredBallHitsTheWallAtTheExactPointAndComesBackReflected) {
  ros::NodeHandle nh;
  std::optional<Contact> contact;
  std::optional<BallState> later_state;
  double later_stamp = 0.0;
  std::optional<visualization_msgs::Marker> drawn;
  Fire fire;
  ros::Subscriber markers =
      nh.subscribe<visualization_msgs::MarkerArray>("markers", 10, [&](const auto& msg) {
        for (const auto& m : msg->markers)
          if (fire.response.success && m.ns == "balls" && m.id == int(fire.response.ball_id))
            drawn = m;
      });
  ros::Subscriber contacts = nh.subscribe<ContactArray>("contacts", 100, [&](const auto& msg) {
    for (const Contact& c : msg->contacts)
      if (c.ball_id == fire.response.ball_id && !contact) contact = c;
  });
  ros::Subscriber balls = nh.subscribe<BallStateArray>("balls", 100, [&](const auto& msg) {
    if (!contact || msg->header.stamp.toSec() < contact->time + 0.1) return;
    for (const BallState& b : msg->balls)
      if (b.id == fire.response.ball_id) {
        later_state = b;
        later_stamp = msg->header.stamp.toSec();
      }
  });
  ASSERT_TRUE(ros::service::waitForService("fire", ros::Duration(30.0)));
  ASSERT_TRUE(ros::service::call("fire", fire));
  ASSERT_TRUE(fire.response.success) << fire.response.message;
  ASSERT_TRUE(spinUntil([&] { return later_state.has_value() && drawn.has_value(); }, 20.0));

  // Drawn as a sphere of its diameter.
  EXPECT_EQ(drawn->type, visualization_msgs::Marker::SPHERE);
  EXPECT_DOUBLE_EQ(drawn->scale.x, 2.0 * kRadius);

  EXPECT_EQ(contact->other_kind, Contact::SEGMENT);
  EXPECT_EQ(contact->other_id, 1u);
  EXPECT_NEAR(contact->point.x, kWallX, 1e-12);
  EXPECT_NEAR(contact->point.y, 0.0, 1e-12);
  EXPECT_NEAR(contact->normal.x, -1.0, 1e-15);
  EXPECT_NEAR(contact->normal.y, 0.0, 1e-15);
  EXPECT_NEAR(contact->approach_speed, kSpeed, 1e-12);
  EXPECT_NEAR(contact->impulse, kMass * (1.0 + kRestitution) * kSpeed, 1e-10);

  // Reflected with e = 0.8, and where exact motion from the reported impact time puts it.
  EXPECT_NEAR(later_state->velocity.x, -kRestitution * kSpeed, 1e-12);
  EXPECT_NEAR(later_state->velocity.y, 0.0, 1e-15);
  // header.stamp holds the sim time to the nanosecond: the position is known to that.
  const double since_impact = later_stamp - contact->time;
  EXPECT_NEAR(later_state->position.x, kWallX - kRadius - kRestitution * kSpeed * since_impact,
              kRestitution * kSpeed * kStampResolution);
  EXPECT_NEAR(later_state->position.y, 0.0, 1e-15);
}

TEST(Contacts, BadFireRequestsAreRefusedWithAReason) {
  ASSERT_TRUE(ros::service::waitForService("fire", ros::Duration(30.0)));
  test::expectRefused<Fire>(
      "fire", Fire(),
      {{"unknown launcher", [](Fire& f) { f.request.launcher = "catapult"; },
        "no launcher named 'catapult'"},
       {"NaN speed", [](Fire& f) { f.request.speed = std::nan(""); }, "speed must be finite and > 0"},
       {"negative speed", [](Fire& f) { f.request.speed = -1.0; }, "speed must be finite and > 0"},
       {"infinite speed", [](Fire& f) { f.request.speed = INFINITY; }, "speed must be finite and > 0"}});
}

TEST(Contacts, TargetAimAtAPointOnTheWallStrikesItWhereAimPredicted) {
  // Straight at (5, 1) on the wall (no gravity): the wall covers the target, so the shot
  // arrives as its centre reaches x = 5 - r on the line to the target, at (4.75, 0.95).
  ros::NodeHandle nh;
  Fire fire;
  std::optional<Contact> contact;
  ros::Subscriber contacts = nh.subscribe<ContactArray>("contacts", 100, [&](const auto& msg) {
    for (const Contact& c : msg->contacts)
      if (fire.response.success && c.ball_id == fire.response.ball_id && !contact) contact = c;
  });
  // The balls fired before fly back through the line of fire: start from the empty scene.
  std_srvs::Trigger reset;
  ASSERT_TRUE(ros::service::waitForService("reset", ros::Duration(30.0)));
  ASSERT_TRUE(ros::service::call("reset", reset));
  ASSERT_TRUE(reset.response.success);
  Aim aim;
  aim.request.mode = Aim::Request::TARGET;
  aim.request.target.x = kWallX;
  aim.request.target.y = 1.0;
  ASSERT_TRUE(ros::service::call("aim", aim));
  ASSERT_TRUE(aim.response.success) << aim.response.message;
  const double hit_x = kWallX - kRadius, hit_y = hit_x / kWallX;
  EXPECT_NEAR(aim.response.angle, std::atan2(1.0, kWallX), 1e-15);
  EXPECT_NEAR(aim.response.predicted_hit.x, hit_x, 1e-12);
  EXPECT_NEAR(aim.response.predicted_hit.y, hit_y, 1e-12);
  EXPECT_NEAR(aim.response.time_of_flight, std::hypot(hit_x, hit_y) / kSpeed, 1e-12);

  ASSERT_TRUE(ros::service::call("fire", fire));
  ASSERT_TRUE(fire.response.success) << fire.response.message;
  ASSERT_TRUE(spinUntil([&] { return contact.has_value(); }, 20.0));
  EXPECT_EQ(contact->other_kind, Contact::SEGMENT);
  EXPECT_EQ(contact->other_id, 1u);
  // The centre then: one radius from the point of impact along the normal.
  EXPECT_NEAR(contact->point.x + kRadius * contact->normal.x, hit_x, 1e-9);
  EXPECT_NEAR(contact->point.y + kRadius * contact->normal.y, hit_y, 1e-9);
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_contacts");
}
