// Through ROS: the `resting` scene's balls fall on a floor and on each other. At every
// published state nothing overlaps beyond rounding; in the end every ball rests where the
// geometry says and stays there.
#include <cmath>
#include <map>
#include <optional>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/engine/scene.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;

namespace {

// Touching bodies sit exactly at contact up to rounding.
constexpr double kOverlapTolerance = 1e-9;  // m
// The scene's first ball lands at t = 0.67 s; watching must start before.
constexpr double kFirstLanding = 0.67;  // s of sim time
constexpr double kSettledBy = 6.0;      // s of sim time
constexpr double kStillUntil = 8.0;     // s of sim time

struct Observation {
  double first_stamp = -1.0;
  double largest_overlap = 0.0;
  std::string worst;
  std::optional<BallStateArray> settled, later;
};

void check(const BallStateArray& msg, const engine::Scene& scene, Observation& seen) {
  auto note = [&](double overlap, const std::string& what) {
    if (overlap > seen.largest_overlap) {
      seen.largest_overlap = overlap;
      seen.worst = what + " at t = " + std::to_string(msg.header.stamp.toSec());
    }
  };
  for (std::size_t i = 0; i < msg.balls.size(); ++i) {
    const BallState& a = msg.balls[i];
    const engine::Vec2 p(a.position.x, a.position.y);
    for (const engine::Segment& s : scene.world.segments())
      note(a.radius - (p - s.closestPoint(p)).norm(),
           "ball " + std::to_string(a.id) + " in segment " + std::to_string(s.id));
    for (std::size_t j = i + 1; j < msg.balls.size(); ++j) {
      const BallState& b = msg.balls[j];
      note(a.radius + b.radius - std::hypot(a.position.x - b.position.x, a.position.y - b.position.y),
           "ball " + std::to_string(a.id) + " in ball " + std::to_string(b.id));
    }
  }
  const double t = msg.header.stamp.toSec();
  if (seen.first_stamp < 0.0) seen.first_stamp = t;
  if (!seen.settled && t >= kSettledBy) seen.settled = msg;
  if (!seen.later && t >= kStillUntil) seen.later = msg;
}

}  // namespace

TEST(RestingBalls, DroppedBallsComeToRestWithoutPassingThroughAnything) {
  ros::NodeHandle private_nh("~");
  std::string scene_file;
  ASSERT_TRUE(private_nh.getParam("scene_file", scene_file));
  const engine::Scene scene = engine::loadScene(scene_file);
  Observation seen;
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<BallStateArray>(
      "balls", 10000, [&](const BallStateArray::ConstPtr& msg) { check(*msg, scene, seen); });
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(90.0);
  while (ros::ok() && !seen.later && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    ros::WallDuration(0.001).sleep();
  }
  ASSERT_TRUE(seen.later) << "no state past t = " << kStillUntil << " s arrived";
  ASSERT_LT(seen.first_stamp, kFirstLanding) << "started watching too late to see the landings";
  EXPECT_LE(seen.largest_overlap, kOverlapTolerance) << seen.worst;

  // Where they rest: the well's two bottom balls against its walls, the third on them at
  // 0.5 + sqrt(1 - 0.55^2); the column stacked at 0.5, 1.5, 2.5; the lone ball on the floor.
  const std::map<unsigned, std::pair<double, double>> expected = {
      {1, {0.5, 0.5}}, {2, {1.6, 0.5}}, {3, {1.05, 0.5 + std::sqrt(1.0 - 0.55 * 0.55)}},
      {4, {4.0, 0.5}}, {5, {4.0, 1.5}}, {6, {4.0, 2.5}}, {7, {7.0, 0.3}}};
  ASSERT_EQ(seen.settled->balls.size(), expected.size());
  for (std::size_t i = 0; i < seen.settled->balls.size(); ++i) {
    const BallState& b = seen.settled->balls[i];
    const BallState& later = seen.later->balls[i];
    EXPECT_TRUE(b.at_rest) << "ball " << b.id;
    EXPECT_NEAR(b.position.x, expected.at(b.id).first, 1e-6) << "ball " << b.id;
    EXPECT_NEAR(b.position.y, expected.at(b.id).second, 1e-6) << "ball " << b.id;
    EXPECT_EQ(std::hypot(b.velocity.x, b.velocity.y), 0.0) << "ball " << b.id;
    // Still: not a bit moved in the seconds after.
    EXPECT_EQ(later.position.x, b.position.x) << "ball " << b.id;
    EXPECT_EQ(later.position.y, b.position.y) << "ball " << b.id;
    EXPECT_TRUE(later.at_rest) << "ball " << b.id;
  }
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_resting_balls");
}
