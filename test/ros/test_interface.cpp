// Through ROS: each service of sim_node with valid calls and a table of bad ones, pause/step
// determinism, reset, clicked_point, tf frames, marker deletion and /clock. The node runs the
// default scene (6 balls, 7 segments, launcher `cannon` at (-5, 1) aiming at 0.8 rad, 9 m/s)
// with ~max_balls 12, ~fire_on_click true, ~cmd_vel_timeout 0.29 s, starting paused, under
// /use_sim_time.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/AddSegment.h"
#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/Explode.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/RemoveBall.h"
#include "ball_physics_sim/RemoveSegment.h"
#include "ball_physics_sim/SetBallState.h"
#include "ball_physics_sim/SetSegmentMotion.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ball_physics_sim/Step.h"
#include "ball_physics_sim/ContactArray.h"
#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/scene.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::BadRequest;
using ball_physics_sim::test::expectRefused;
using ball_physics_sim::test::kInTransit;
using ball_physics_sim::test::kTimeStep;
using ball_physics_sim::test::spinUntil;
using ball_physics_sim::test::stepBy;

namespace {

constexpr std::size_t kSceneBalls = 6;
const double kNaN = std::nan("");
const double kInf = INFINITY;

// Watches the node's topics for the whole test run.
class Interface : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    nh_ = new ros::NodeHandle;
    tf_buffer_ = new tf2_ros::Buffer;
    tf_listener_ = new tf2_ros::TransformListener(*tf_buffer_);
    balls_sub_ = nh_->subscribe("balls", 10, &Interface::onBalls);
    markers_sub_ = nh_->subscribe("markers", 100, &Interface::onMarkers);
    clock_sub_ = nh_->subscribe("/clock", 100, &Interface::onClock);
    contacts_sub_ = nh_->subscribe("contacts", 1000, &Interface::onContacts);
    ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
  }

  static void onBalls(const BallStateArray::ConstPtr& msg) { balls_ = *msg; }
  static void onMarkers(const visualization_msgs::MarkerArray::ConstPtr& msg) {
    for (const auto& m : msg->markers) markers_[{m.ns, m.id}] = m;
  }
  static void onClock(const rosgraph_msgs::Clock::ConstPtr& msg) { clock_ = msg->clock; }
  static void onContacts(const ContactArray::ConstPtr& msg) {
    contacts_.insert(contacts_.end(), msg->contacts.begin(), msg->contacts.end());
  }

  void SetUp() override {
    // Each test starts from the scene's initial state, paused.
    setPaused(true);
    std_srvs::Trigger reset;
    ASSERT_TRUE(ros::service::call("reset", reset));
    ASSERT_TRUE(reset.response.success);
    waitForBalls([](const BallStateArray& b) { return b.header.stamp.toSec() == 0.0; });
  }

  template <typename Service>
  static Service call(const std::string& name, Service service) {
    EXPECT_TRUE(ros::service::call(name, service)) << name;
    return service;
  }

  static void setPaused(bool paused) {
    std_srvs::SetBool pause;
    pause.request.data = paused;
    EXPECT_TRUE(call("pause", pause).response.success);
  }

  // The next `balls` message that satisfies `ready`, published after this call.
  static BallStateArray waitForBalls(const std::function<bool(const BallStateArray&)>& ready) {
    return test::nextMessage(balls_, ready);
  }

  // The state at sim time `time`.
  static BallStateArray ballsAt(double time) { return test::ballsAt(balls_, time); }

  static const BallState* find(const BallStateArray& balls, std::uint32_t id) {
    for (const BallState& b : balls.balls)
      if (b.id == id) return &b;
    return nullptr;
  }
  // The answer points into `balls`: a temporary array would leave it dangling.
  static const BallState* find(BallStateArray&& balls, std::uint32_t id) = delete;

  static std::optional<visualization_msgs::Marker> marker(const std::string& ns, int id) {
    const auto it = markers_.find({ns, id});
    if (it == markers_.end()) return std::nullopt;
    return it->second;
  }

  // Fires the first launcher as aimed, steps past the aimed time of flight, and expects the
  // fired ball's first contact with a ball to be with ball `target`, after at least one bounce
  // off segments if `banked` and none otherwise, its centre then at aim's predicted hit within
  // 1e-9 m, aim's time of flight after `fired_at`.
  static void fireAndExpectStrike(const Aim::Response& aimed, std::uint32_t target,
                                  double fired_at, bool banked = false) {
    Fire fire;
    fire = call("fire", fire);
    ASSERT_TRUE(fire.response.success);
    const std::uint32_t fired = fire.response.ball_id;
    contacts_.clear();
    ballsAt(stepBy(static_cast<std::uint32_t>(aimed.time_of_flight / kTimeStep) + 2));
    spinUntil([] { return false; }, kInTransit);
    std::size_t bounces = 0;
    const Contact* first = nullptr;
    for (const Contact& c : contacts_) {
      if (c.ball_id != fired && !(c.other_kind == Contact::BALL && c.other_id == fired)) continue;
      if (c.other_kind == Contact::BALL) {
        first = &c;
        break;
      }
      ++bounces;
    }
    ASSERT_NE(first, nullptr);
    if (banked)
      EXPECT_GE(bounces, 1u);
    else
      EXPECT_EQ(bounces, 0u);
    const bool fired_is_ball = first->ball_id == fired;
    EXPECT_EQ(fired_is_ball ? first->other_id : first->ball_id, target);
    const double radius = 0.2, sign = fired_is_ball ? 1.0 : -1.0;  // the cannon's balls
    EXPECT_NEAR(first->point.x + sign * radius * first->normal.x, aimed.predicted_hit.x, 1e-9);
    EXPECT_NEAR(first->point.y + sign * radius * first->normal.y, aimed.predicted_hit.y, 1e-9);
    EXPECT_NEAR(first->time - fired_at, aimed.time_of_flight, 1e-9);
  }

  // Whether the marker was last added (markers of earlier tests linger as DELETE).
  static bool drawn(const std::string& ns, int id) {
    const auto m = marker(ns, id);
    return m && m->action == visualization_msgs::Marker::ADD;
  }

  // The aim the launcher's marker shows.
  static double launcherYaw() {
    const auto arrow = marker("launchers", 0);
    return arrow ? 2.0 * std::atan2(arrow->pose.orientation.z, arrow->pose.orientation.w) : kNaN;
  }

  static ros::NodeHandle* nh_;
  static tf2_ros::Buffer* tf_buffer_;
  static tf2_ros::TransformListener* tf_listener_;
  static ros::Subscriber balls_sub_, markers_sub_, clock_sub_, contacts_sub_;
  static std::vector<Contact> contacts_;
  static std::optional<BallStateArray> balls_;
  static std::map<std::pair<std::string, int>, visualization_msgs::Marker> markers_;
  static ros::Time clock_;
};

ros::NodeHandle* Interface::nh_;
tf2_ros::Buffer* Interface::tf_buffer_;
tf2_ros::TransformListener* Interface::tf_listener_;
ros::Subscriber Interface::balls_sub_, Interface::markers_sub_, Interface::clock_sub_,
    Interface::contacts_sub_;
std::vector<Contact> Interface::contacts_;
std::optional<BallStateArray> Interface::balls_;
std::map<std::pair<std::string, int>, visualization_msgs::Marker> Interface::markers_;
ros::Time Interface::clock_;

SpawnBall spawnRequest(double x, double y) { return test::spawnRequest(x, y, 0.2, 2.0, 1.0); }

}  // namespace

TEST_F(Interface, SpawnedBallAppearsOnBallsTfAndMarkers) {
  const SpawnBall spawned = call("spawn_ball", spawnRequest(0.0, 5.0));
  ASSERT_TRUE(spawned.response.success) << spawned.response.message;
  EXPECT_EQ(spawned.response.ball_id, kSceneBalls + 1);
  const std::uint32_t id = spawned.response.ball_id;
  const BallStateArray spawned_states = ballsAt(0.0);
  const BallState* b = find(spawned_states, id);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->position.x, 0.0);
  EXPECT_EQ(b->position.y, 5.0);
  EXPECT_EQ(b->velocity.x, 1.0);
  EXPECT_EQ(b->radius, 0.2);
  EXPECT_EQ(b->mass, 2.0);
  ASSERT_TRUE(spinUntil([&] { return marker("balls", int(id)).has_value(); }));
  EXPECT_EQ(marker("balls", int(id))->pose.position.y, 5.0);
  EXPECT_EQ(marker("balls", int(id))->scale.x, 0.4);
  // tf follows sim time: one step on, its frame is where `balls` says at that stamp.
  const BallStateArray later = ballsAt(stepBy(1));
  const BallState* moved = find(later, id);
  ASSERT_NE(moved, nullptr);
  EXPECT_NEAR(moved->position.y, 5.0 - 0.5 * 9.81 * kTimeStep * kTimeStep, 1e-15);
  const std::string frame = "ball_" + std::to_string(id);
  ASSERT_TRUE(spinUntil([&] { return tf_buffer_->canTransform("world", frame, later.header.stamp); }));
  const auto t = tf_buffer_->lookupTransform("world", frame, later.header.stamp);
  EXPECT_EQ(t.transform.translation.x, moved->position.x);
  EXPECT_EQ(t.transform.translation.y, moved->position.y);
}

TEST_F(Interface, ARoughBallPushedAlongARoughSegmentSlidesThenRollsAndItsFrameTurns) {
  // Friction through both services: pushed at v0 without spin, it slides until friction has
  // spun it up to rolling, at t* = 2 v0 / (7 mu g), and rolls on at 5/7 v0; its tf frame
  // turns with it. Up by the ceiling, where no ball of the scene passes in this time.
  AddSegment floor = test::segmentRequest(-2.5, 7.2, -0.5, 7.2);
  floor.request.friction = 0.5;
  ASSERT_TRUE(call("add_segment", floor).response.success);
  SpawnBall spawn = test::spawnRequest(-2.0, 7.4, 0.2, 1.0, 2.0);
  spawn.request.friction = 0.5;
  const SpawnBall spawned = call("spawn_ball", spawn);
  ASSERT_TRUE(spawned.response.success) << spawned.response.message;
  const double mu = 0.5, g = 9.81, v0 = 2.0, r = 0.2;
  const double t = 24 * kTimeStep, rolling_at = 2.0 * v0 / (7.0 * mu * g);
  const double spin_up = -mu * g / (0.4 * r);  // angular acceleration while it slides
  const BallStateArray states = ballsAt(stepBy(24));
  const BallState* b = find(states, spawned.response.ball_id);
  ASSERT_NE(b, nullptr);
  const double x = -2.0 + v0 * rolling_at - 0.5 * mu * g * rolling_at * rolling_at +
                   5.0 / 7.0 * v0 * (t - rolling_at);
  EXPECT_NEAR(b->position.x, x, 1e-9);
  EXPECT_NEAR(b->position.y, 7.4, 1e-12);
  EXPECT_NEAR(b->velocity.x, 5.0 / 7.0 * v0, 1e-12);
  EXPECT_NEAR(b->angular_velocity, -5.0 / 7.0 * v0 / r, 1e-12);
  const double angle = 0.5 * spin_up * rolling_at * rolling_at + b->angular_velocity * (t - rolling_at);
  const std::string frame = "ball_" + std::to_string(spawned.response.ball_id);
  ASSERT_TRUE(spinUntil([&] { return tf_buffer_->canTransform("world", frame, states.header.stamp); }));
  const auto pose = tf_buffer_->lookupTransform("world", frame, states.header.stamp);
  // q and -q are the same turn: compare the angles they give, a whole turn either way.
  const double yaw = 2.0 * std::atan2(pose.transform.rotation.z, pose.transform.rotation.w);
  EXPECT_NEAR(std::remainder(yaw - angle, 2.0 * M_PI), 0.0, 1e-9);
}

TEST_F(Interface, AWallSetMovingPushesABallAlongAndRefusesMotionsItCannotHave) {
  // A wall 0.3 m behind a ball on a floor, set moving at 1 m/s: it meets the ball at 0.3 s,
  // stops its restitution (e = 0) and carries it along at its own speed. Up by the ceiling,
  // where no ball of the scene passes in this time.
  ASSERT_TRUE(call("add_segment", test::segmentRequest(-2.5, 7.2, -0.5, 7.2)).response.success);
  const AddSegment wall = call("add_segment", test::segmentRequest(-2.2, 7.25, -2.2, 7.8));
  ASSERT_TRUE(wall.response.success) << wall.response.message;
  const SpawnBall spawned = call("spawn_ball", test::spawnRequest(-1.7, 7.4, 0.2, 1.0));
  ASSERT_TRUE(spawned.response.success) << spawned.response.message;
  SetSegmentMotion move;
  move.request.segment_id = wall.response.segment_id;
  move.request.velocity.x = 1.0;
  move = call("set_segment_motion", move);
  ASSERT_TRUE(move.response.success) << move.response.message;
  const BallStateArray states = ballsAt(stepBy(96));  // 0.8 s
  const BallState* b = find(states, spawned.response.ball_id);
  ASSERT_NE(b, nullptr);
  EXPECT_NEAR(b->position.x, -2.2 + 0.8 + 0.2, 1e-9);
  EXPECT_NEAR(b->position.y, 7.4, 1e-9);
  EXPECT_NEAR(b->velocity.x, 1.0, 1e-9);
  EXPECT_FALSE(b->at_rest);

  expectRefused<SetSegmentMotion>("set_segment_motion", move, {
      {"NaN angular velocity", [](SetSegmentMotion& m) { m.request.angular_velocity = kNaN; },
       "cannot move the segment: segment velocity and angular velocity must be finite"},
      {"too fast", [](SetSegmentMotion& m) { m.request.velocity.y = 2e5; }, "faster than"},
      {"no such segment", [](SetSegmentMotion& m) { m.request.segment_id = 999; },
       "there is no segment 999"},
  });
}

TEST_F(Interface, SpawnBallRefusesBadInputAndKeepsTheWorld) {
  expectRefused<SpawnBall>("spawn_ball", spawnRequest(0.0, 5.0), {
      {"NaN position", [](SpawnBall& s) { s.request.position.x = kNaN; }, "position must be finite"},
      {"infinite velocity", [](SpawnBall& s) { s.request.velocity.y = kInf; }, "velocity must be finite"},
      {"NaN spin", [](SpawnBall& s) { s.request.angular_velocity = kNaN; }, "angular velocity"},
      {"zero radius", [](SpawnBall& s) { s.request.radius = 0.0; }, "radius must be > 0"},
      {"negative radius", [](SpawnBall& s) { s.request.radius = -1.0; }, "radius must be > 0"},
      {"zero mass", [](SpawnBall& s) { s.request.mass = 0.0; }, "mass must be > 0"},
      {"too heavy", [](SpawnBall& s) { s.request.mass = 1e7; }, "mass must be within [1e-06, 1e+06] kg"},
      {"too big", [](SpawnBall& s) { s.request.radius = 101.0; }, "radius must be at most 100 m (~max_radius)"},
      {"restitution above 1", [](SpawnBall& s) { s.request.restitution = 1.5; }, "restitution"},
      {"negative friction", [](SpawnBall& s) { s.request.friction = -0.1; }, "friction must be finite and >= 0"},
      {"NaN rolling resistance", [](SpawnBall& s) { s.request.rolling_resistance = kNaN; }, "rolling resistance must be finite"},
      {"inertia above a ring's", [](SpawnBall& s) { s.request.inertia_factor = 1.5; }, "inertia factor must be within (0, 1]"},
      {"too fast", [](SpawnBall& s) { s.request.velocity.x = 1e160; }, "speed must be at most"},
      {"too far", [](SpawnBall& s) { s.request.position.y = 1e7; }, "position must be within"},
      {"inside a wall", [](SpawnBall& s) { s.request.position.x = 5.9; }, "would overlap segment"},
      {"inside a ball", [](SpawnBall& s) { s.request.position.x = 3.0; s.request.position.y = 0.3; },
       "would overlap ball 1"},
  });
  // The world is full at ~max_balls = 12.
  for (std::size_t i = kSceneBalls; i < 12; ++i)
    ASSERT_TRUE(call("spawn_ball", spawnRequest(-4.0 + i * 0.5, 5.0)).response.success);
  const SpawnBall full = call("spawn_ball", spawnRequest(0.0, 7.0));
  EXPECT_FALSE(full.response.success);
  EXPECT_NE(full.response.message.find("the world is full: 12 balls"), std::string::npos)
      << full.response.message;
  Fire fire;
  fire = call("fire", fire);
  EXPECT_FALSE(fire.response.success);
  EXPECT_NE(fire.response.message.find("the world is full"), std::string::npos);
  EXPECT_EQ(ballsAt(0.0).balls.size(), 12u);
}

TEST_F(Interface, RemovedBallLeavesBallsAndItsMarkerIsDeleted) {
  const std::uint32_t id = call("spawn_ball", spawnRequest(0.0, 5.0)).response.ball_id;
  ASSERT_TRUE(spinUntil([&] { return drawn("balls", int(id)) && drawn("ball_labels", int(id)); }));
  EXPECT_EQ(marker("ball_labels", int(id))->text, std::to_string(id));
  RemoveBall remove;
  remove.request.ball_id = id;
  EXPECT_TRUE(call("remove_ball", remove).response.success);
  const BallStateArray after_removal = ballsAt(0.0);
  EXPECT_EQ(find(after_removal, id), nullptr);
  ASSERT_TRUE(spinUntil([&] {
    return marker("balls", int(id))->action == visualization_msgs::Marker::DELETE &&
           marker("ball_labels", int(id))->action == visualization_msgs::Marker::DELETE;
  }));
  // Bad input: an id that is not (or no longer) there.
  remove = call("remove_ball", remove);
  EXPECT_FALSE(remove.response.success);
  EXPECT_EQ(remove.response.message, "there is no ball " + std::to_string(id));
  EXPECT_EQ(ballsAt(0.0).balls.size(), kSceneBalls);
}

TEST_F(Interface, ABallSetOutOfARestingColumnLetsTheOneOnItFallAndBadStatesAreRefused) {
  // The scene's falling balls go, so that nothing else comes near: a column of three balls of
  // radius 0.3 rests on the floor at x = -3, and its middle ball is set down at x = -4.5.
  for (std::uint32_t id : {4u, 5u, 6u}) {
    RemoveBall remove;
    remove.request.ball_id = id;
    ASSERT_TRUE(call("remove_ball", remove).response.success);
  }
  std::vector<std::uint32_t> column;
  for (double y : {0.3, 0.9, 1.5})
    column.push_back(call("spawn_ball", test::spawnRequest(-3.0, y, 0.3, 1.0)).response.ball_id);
  const double rested = stepBy(1);
  const BallStateArray at_rest = ballsAt(rested);
  for (std::uint32_t id : column) {
    ASSERT_NE(find(at_rest, id), nullptr);
    ASSERT_TRUE(find(at_rest, id)->at_rest) << "ball " << id;
  }
  const std::uint32_t bottom = column[0], middle = column[1], top = column[2];

  SetBallState set;
  set.request.ball_id = middle;
  set.request.position.x = -4.5;
  set.request.position.y = 0.3;
  expectRefused<SetBallState>("set_ball_state", set, {
      {"unknown ball", [](SetBallState& s) { s.request.ball_id = 99; }, "there is no ball 99"},
      {"NaN position", [](SetBallState& s) { s.request.position.y = kNaN; }, "position must be finite"},
      {"infinite velocity", [](SetBallState& s) { s.request.velocity.x = kInf; }, "velocity must be finite"},
      {"NaN spin", [](SetBallState& s) { s.request.angular_velocity = kNaN; }, "angular velocity must be finite"},
      {"too fast", [](SetBallState& s) { s.request.velocity.x = 1001.0; }, "speed must be at most 1000 m/s (~max_speed)"},
      {"inside a ball", [=](SetBallState& s) { s.request.position.y = 1.5; s.request.position.x = -3.0; },
       "cannot set the state of ball " + std::to_string(middle) + ": ball would overlap ball " + std::to_string(top)},
      {"inside the floor", [](SetBallState& s) { s.request.position.y = 0.1; }, "would overlap segment 1"},
  });
  const BallStateArray refused = ballsAt(rested);
  for (std::uint32_t id : column) {
    EXPECT_TRUE(find(refused, id)->at_rest) << "ball " << id;
    EXPECT_EQ(find(refused, id)->position.y, find(at_rest, id)->position.y) << "ball " << id;
  }

  set = call("set_ball_state", set);
  ASSERT_TRUE(set.response.success) << set.response.message;
  EXPECT_EQ(set.response.message, "ball " + std::to_string(middle) + " is at (-4.5, 0.3) moving at (0, 0) m/s, 0 rad/s");
  // The top ball falls freely (y = 1.5 - g t^2 / 2) until it meets the bottom one, 0.6 m down,
  // at 0.35 s; the bottom ball and the one set down stay on the floor.
  const std::uint32_t falling_steps = 12;
  const BallStateArray falling = ballsAt(stepBy(falling_steps));
  const double t = falling_steps * kTimeStep;
  EXPECT_FALSE(find(falling, top)->at_rest);
  EXPECT_NEAR(find(falling, top)->position.y, 1.5 - 0.5 * 9.81 * t * t, 1e-9);
  EXPECT_EQ(find(falling, top)->position.x, -3.0);
  for (const auto& [id, x] : {std::pair{bottom, -3.0}, std::pair{middle, -4.5}}) {
    EXPECT_NEAR(find(falling, id)->position.x, x, 1e-12) << "ball " << id;
    EXPECT_NEAR(find(falling, id)->position.y, 0.3, 1e-12) << "ball " << id;
  }
  // Having bounced (restitution 0.5), it rests on the bottom ball.
  const BallStateArray landed = ballsAt(stepBy(240));
  EXPECT_TRUE(find(landed, top)->at_rest);
  EXPECT_NEAR(find(landed, top)->position.x, -3.0, 1e-9);
  EXPECT_NEAR(find(landed, top)->position.y, 0.9, 1e-9);
}

TEST_F(Interface, SegmentsAreAddedAndRemovedWithTheirMarkers) {
  AddSegment add = test::segmentRequest(-1.0, 6.5, 1.0, 6.0);
  add.request.thickness = 0.1;
  add.request.restitution = 0.9;
  add = call("add_segment", add);
  ASSERT_TRUE(add.response.success) << add.response.message;
  const int id = int(add.response.segment_id);
  EXPECT_EQ(id, 8);  // after the scene's seven
  ASSERT_TRUE(spinUntil([&] { return drawn("segments", id) && drawn("segment_labels", id); }));
  EXPECT_EQ(marker("segments", id)->scale.x, std::hypot(2.0, 0.5));
  EXPECT_EQ(marker("segment_labels", id)->text, std::to_string(id));

  expectRefused<AddSegment>("add_segment", add, {
      {"NaN end", [](AddSegment& a) { a.request.end.x = kNaN; }, "segment ends must be finite"},
      {"zero length", [](AddSegment& a) { a.request.end = a.request.start; }, "must differ"},
      {"negative thickness", [](AddSegment& a) { a.request.thickness = -0.1; }, "thickness must be within [0, "},
      {"too far", [](AddSegment& a) { a.request.end.y = 2e6; }, "segment ends must be within"},
      {"restitution below 0", [](AddSegment& a) { a.request.restitution = -0.1; }, "restitution"},
      {"negative friction", [](AddSegment& a) { a.request.friction = -1.0; }, "friction must be finite and >= 0"},
      {"through a ball", [](AddSegment& a) { a.request.start.y = a.request.end.y = 0.3; a.request.start.x = 2.5; a.request.end.x = 4.0; },
       "would overlap ball"},
  });

  RemoveSegment remove;
  remove.request.segment_id = id;
  EXPECT_TRUE(call("remove_segment", remove).response.success);
  ASSERT_TRUE(spinUntil([&] {
    return marker("segments", id)->action == visualization_msgs::Marker::DELETE &&
           marker("caps", 2 * id)->action == visualization_msgs::Marker::DELETE &&
           marker("segment_labels", id)->action == visualization_msgs::Marker::DELETE;
  }));
  remove = call("remove_segment", remove);
  EXPECT_FALSE(remove.response.success);
  EXPECT_EQ(remove.response.message, "there is no segment " + std::to_string(id));
}

TEST_F(Interface, PausedTimeStandsStillAndStepAdvancesItByWholeSteps) {
  const BallStateArray before = ballsAt(0.0);
  ros::WallDuration(0.3).sleep();
  EXPECT_EQ(ballsAt(0.0).balls.size(), before.balls.size());  // still at t = 0
  EXPECT_DOUBLE_EQ(stepBy(12), 12 * kTimeStep);
  EXPECT_DOUBLE_EQ(stepBy(1), 13 * kTimeStep);
  ballsAt(stepBy(2));

  Step bad;
  bad.request.steps = 0;
  bad = call("step", bad);
  EXPECT_FALSE(bad.response.success);
  EXPECT_NE(bad.response.message.find("steps must be within [1, 100000], got 0"), std::string::npos);
  bad.request.steps = 100001;
  EXPECT_FALSE(call("step", bad).response.success);
  setPaused(false);
  bad.request.steps = 1;
  bad = call("step", bad);
  EXPECT_FALSE(bad.response.success);
  EXPECT_NE(bad.response.message.find("pause it first"), std::string::npos);
}

TEST_F(Interface, SameCallsAtTheSameSimTimesGiveBitIdenticalStates) {
  auto play = [&] {
    std_srvs::Trigger reset;
    call("reset", reset);
    stepBy(30);
    Fire fire;
    EXPECT_TRUE(call("fire", fire).response.success);
    stepBy(20);
    EXPECT_TRUE(call("spawn_ball", spawnRequest(1.5, 7.5)).response.success);
    return ballsAt(stepBy(300));
  };
  const BallStateArray first = play();
  const BallStateArray second = play();
  ASSERT_EQ(first.balls.size(), kSceneBalls + 2);
  ASSERT_EQ(second.balls.size(), first.balls.size());
  for (std::size_t i = 0; i < first.balls.size(); ++i) {
    EXPECT_EQ(first.balls[i], second.balls[i]) << "ball " << first.balls[i].id;
  }
}

TEST_F(Interface, EveryContactArrivesAsTheEngineComputesIt) {
  // The same scene and calls run here on the engine itself: `contacts` must carry every impact,
  // none dropped, with the same exact values.
  engine::Scene scene = engine::loadScene(
      ros::package::getPath("ball_physics_sim") + "/config/scenes/default.yaml");
  auto run = [&](std::uint32_t steps) {
    for (std::uint32_t i = 0; i < steps; ++i) scene.world.step(kTimeStep);
  };
  spinUntil([] { return false; }, kInTransit);
  contacts_.clear();
  stepBy(90);
  run(90);
  Fire fire;
  ASSERT_TRUE(call("fire", fire).response.success);
  scene.world.addBall(scene.launchers[0].launch(scene.launchers[0].speed));
  const double t = stepBy(240);
  run(240);
  ballsAt(t);
  spinUntil([] { return false; }, kInTransit);
  const std::vector<engine::Contact> expected = scene.world.takeContacts();
  ASSERT_GT(expected.size(), 10u);
  ASSERT_EQ(contacts_.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(contacts_[i].time, expected[i].time) << i;
    EXPECT_EQ(contacts_[i].ball_id, expected[i].ball_id) << i;
    EXPECT_EQ(contacts_[i].other_id, expected[i].other_id) << i;
    EXPECT_EQ(contacts_[i].point.x, expected[i].point.x()) << i;
    EXPECT_EQ(contacts_[i].point.y, expected[i].point.y()) << i;
    EXPECT_EQ(contacts_[i].impulse, expected[i].impulse) << i;
  }
}

TEST_F(Interface, ResetRestoresTheSceneAndTime) {
  call("spawn_ball", spawnRequest(0.0, 5.0));
  const BallStateArray initial = ballsAt(0.0);
  stepBy(100);
  std_srvs::Trigger reset;
  reset = call("reset", reset);
  EXPECT_TRUE(reset.response.success);
  const BallStateArray after = ballsAt(0.0);
  ASSERT_EQ(after.balls.size(), kSceneBalls);
  for (std::size_t i = 0; i < kSceneBalls; ++i) EXPECT_EQ(after.balls[i], initial.balls[i]);
}

TEST_F(Interface, AimRefusesBadInputAndLeavesTheLauncherAsItWas) {
  Aim angle;
  angle.request.mode = Aim::Request::ANGLE;
  angle.request.angle = 0.3;
  angle = call("aim", angle);
  ASSERT_TRUE(angle.response.success);
  EXPECT_DOUBLE_EQ(angle.response.angle, 0.3);
  ASSERT_TRUE(spinUntil([&] { return std::abs(launcherYaw() - 0.3) < 1e-12; }));

  // Malformed requests; the refusals that weigh the world (out of reach, blocked, no shot)
  // are engine tests, in test/engine/test_aim_request.cpp.
  Aim valid;
  valid.request.mode = Aim::Request::ANGLE;
  valid.request.angle = 1.0;
  expectRefused<Aim>("aim", valid, {
      {"unknown launcher", [](Aim& a) { a.request.launcher = "catapult"; }, "no launcher named 'catapult'; the scene has: 'cannon'"},
      {"unknown mode", [](Aim& a) { a.request.mode = 9; }, "unknown mode 9"},
      {"NaN angle", [](Aim& a) { a.request.angle = kNaN; }, "angle must be finite"},
      {"infinite target", [](Aim& a) { a.request.mode = Aim::Request::TARGET; a.request.target.x = kInf; }, "target must be finite"},
      {"speed and time of flight", [](Aim& a) { a.request.mode = Aim::Request::TARGET_BALLISTIC; a.request.time_of_flight = 1.0; a.request.speed = 5.0; },
       "give speed or time_of_flight, not both"},
      {"negative time of flight", [](Aim& a) { a.request.mode = Aim::Request::TARGET_BALLISTIC; a.request.time_of_flight = -1.0; },
       "time_of_flight must be finite and > 0"},
      {"NaN time of flight", [](Aim& a) { a.request.mode = Aim::Request::TARGET_BALLISTIC; a.request.time_of_flight = kNaN; },
       "time_of_flight must be finite and > 0"},
      {"negative speed", [](Aim& a) { a.request.speed = -1.0; }, "speed must be finite and > 0"},
      {"NaN speed", [](Aim& a) { a.request.speed = kNaN; }, "speed must be finite and > 0"},
      {"LEAD_BALL at no ball", [](Aim& a) { a.request.mode = Aim::Request::LEAD_BALL; a.request.target_ball_id = 99; }, "there is no ball 99"},
      {"time of flight outside TARGET_BALLISTIC", [](Aim& a) { a.request.mode = Aim::Request::TARGET; a.request.target.y = 2.0; a.request.time_of_flight = 1.0; },
       "time_of_flight is for TARGET_BALLISTIC only"},
  });
  Aim check;
  check.request.mode = Aim::Request::ANGLE;
  check.request.angle = 0.3;
  EXPECT_DOUBLE_EQ(call("aim", check).response.angle, 0.3);  // untouched by the bad calls
}

namespace {

// A thread of a process, as /proc shows it.
struct Task {
  std::string name;
  int niceness;
  bool main;  // the process's own
};

// The field of a thread's /proc stat line, numbered from 1 as proc(5) does (its name, field 2,
// in parentheses, may hold spaces); none if the thread is gone.
std::optional<std::string> statField(const std::filesystem::path& task, int number) {
  std::ifstream stat(task / "stat");
  std::string line;
  if (!std::getline(stat, line) || line.rfind(") ") == std::string::npos) return std::nullopt;
  std::istringstream fields(line.substr(line.rfind(") ") + 2));
  std::string field;
  for (int k = 3; k <= number; ++k)
    if (!(fields >> field)) return std::nullopt;
  return field;
}

// The threads of each process named `name` that has a thread named `thread`, by process.
std::map<std::string, std::vector<Task>> tasksOfProcessesWith(const std::string& name,
                                                              const std::string& thread) {
  std::map<std::string, std::vector<Task>> found;
  std::error_code error;
  for (const auto& process : std::filesystem::directory_iterator("/proc", error)) {
    std::ifstream comm(process.path() / "comm");
    std::string command;
    if (!std::getline(comm, command) || command != name) continue;
    std::vector<Task> tasks;
    std::error_code gone;
    for (const auto& task : std::filesystem::directory_iterator(process.path() / "task", gone)) {
      std::ifstream task_comm(task.path() / "comm");
      std::string task_name;
      const std::optional<std::string> niceness = statField(task.path(), 19);
      if (!std::getline(task_comm, task_name) || !niceness) continue;  // (it ended)
      tasks.push_back({task_name, std::stoi(*niceness),
                       task.path().filename() == process.path().filename()});
    }
    if (std::any_of(tasks.begin(), tasks.end(), [&](const Task& t) { return t.name == thread; }))
      found[process.path().filename()] = tasks;
  }
  return found;
}

}  // namespace

TEST_F(Interface, AimIsWorkedOutBelowTheLoopsPriority) {
  // An aim may run for a minute in a big world: its thread, named sim_aim, is 10 nicer than
  // the node's own.
  Aim aim;
  aim.request.mode = Aim::Request::ANGLE;
  aim.request.angle = 0.5;
  ASSERT_TRUE(call("aim", aim).response.success);
  const auto processes = tasksOfProcessesWith("sim_node", "sim_aim");
  ASSERT_FALSE(processes.empty());
  for (const auto& [pid, tasks] : processes) {
    const auto main = std::find_if(tasks.begin(), tasks.end(), [](const Task& t) { return t.main; });
    const auto aimer =
        std::find_if(tasks.begin(), tasks.end(), [](const Task& t) { return t.name == "sim_aim"; });
    ASSERT_NE(main, tasks.end()) << pid;
    EXPECT_EQ(aimer->niceness, std::min(main->niceness + 10, 19)) << pid;
  }
}

TEST_F(Interface, BallisticAimGivenATimeOfFlightArrivesThenAtTheSpeedItAnswered) {
  // (-5, 1) to (0, 2) in 0.8 s: v = (d - g t^2 / 2) / t = (6.25, 1.25 + 9.81 * 0.4).
  Aim aim;
  aim.request.mode = Aim::Request::TARGET_BALLISTIC;
  aim.request.target.x = 0.0;
  aim.request.target.y = 2.0;
  aim.request.time_of_flight = 0.8;
  aim = call("aim", aim);
  ASSERT_TRUE(aim.response.success) << aim.response.message;
  const double vx = 6.25, vy = 1.25 + 9.81 * 0.4;
  EXPECT_NEAR(aim.response.speed, std::hypot(vx, vy), 1e-12);
  EXPECT_NEAR(aim.response.angle, std::atan2(vy, vx), 1e-12);
  EXPECT_EQ(aim.response.time_of_flight, 0.8);
  EXPECT_EQ(aim.response.predicted_hit.x, 0.0);
  EXPECT_EQ(aim.response.predicted_hit.y, 2.0);
  Fire fire;  // at the launcher's speed, which aim set
  fire = call("fire", fire);
  ASSERT_TRUE(fire.response.success);
  const double t = stepBy(96);  // 0.8 s
  const BallStateArray states = ballsAt(t);
  const BallState* b = find(states, fire.response.ball_id);
  ASSERT_NE(b, nullptr);
  EXPECT_NEAR(b->position.x, 0.0, 1e-9);
  EXPECT_NEAR(b->position.y, 2.0, 1e-9);
}

TEST_F(Interface, BankShotStrikesItsTargetAfterBouncingWhereAimPredicted) {
  // The top of the pyramid (the frictionless pyramid collapses at once), by way of walls or
  // ceiling: the search finds the aim with the engine's own prediction, so the fired ball does
  // exactly what aim answered.
  const std::uint32_t top = 3;
  Aim aim;
  aim.request.mode = Aim::Request::BANK;
  aim.request.target_ball_id = top;
  aim = call("aim", aim);
  ASSERT_TRUE(aim.response.success) << aim.response.message;
  EXPECT_NE(aim.response.message.find("bank shot: off "), std::string::npos) << aim.response.message;
  // The launcher's predicted path follows the bounces to the strike.
  EXPECT_TRUE(spinUntil([&] {
    const auto path = marker("predicted_paths", 0);
    return drawn("predicted_paths", 0) && path->points.back() == aim.response.predicted_hit;
  }));
  fireAndExpectStrike(aim.response, top, 0.0, true);
}

TEST_F(Interface, LeadBallStrikesAFallingBallWhereAimPredicted) {
  // A ball thrown level at (-1, 7): the cannon leads it, and the fired ball's first contact is
  // with it, at the predicted hit and time (bit for bit: the prediction is the engine's own).
  const std::uint32_t target = call("spawn_ball", test::spawnRequest(-1.0, 7.0, 0.2, 1.0, 1.0)).response.ball_id;
  ASSERT_NE(target, 0u);
  Aim aim;
  aim.request.mode = Aim::Request::LEAD_BALL;
  aim.request.target_ball_id = target;
  aim = call("aim", aim);
  ASSERT_TRUE(aim.response.success) << aim.response.message;
  EXPECT_GT(aim.response.time_of_flight, 0.0);

  fireAndExpectStrike(aim.response, target, 0.0);  // paused at 0 since the reset
}

TEST_F(Interface, TimedShotFiredAfterTheAnsweredDelayStrikesItsTarget) {
  // The cannon stays at 1 rad; a ball thrown left from (-1, 7) crosses its path. Step the
  // answered delay, fire, and the shot strikes the ball where aim predicted.
  const std::uint32_t target = call("spawn_ball", test::spawnRequest(-1.0, 7.0, 0.2, 1.0, -1.0)).response.ball_id;
  ASSERT_NE(target, 0u);
  Aim aim;
  aim.request.mode = Aim::Request::TIMED;
  aim.request.angle = 1.0;
  aim.request.target_ball_id = target;
  aim = call("aim", aim);
  ASSERT_TRUE(aim.response.success) << aim.response.message;
  EXPECT_EQ(aim.response.angle, 1.0);
  const auto steps = static_cast<std::uint32_t>(std::lround(aim.response.fire_after / kTimeStep));
  EXPECT_NEAR(steps * kTimeStep, aim.response.fire_after, 1e-12);  // whole steps

  fireAndExpectStrike(aim.response, target, steps > 0 ? stepBy(steps) : 0.0);
}

TEST_F(Interface, PredictedPathEndsWhereTheFiredBallFirstHits) {
  // Paused, the world does not change between the marker and the shot: the ball's first
  // contact must be the predicted hit, bit for bit.
  Aim aim;
  aim.request.angle = 0.5;
  aim = call("aim", aim);
  ASSERT_TRUE(aim.response.success);
  // One step out of the muzzle (-5, 1) at 9 m/s along 0.5 rad, under gravity.
  const double vx = 9.0 * std::cos(0.5), vy = 9.0 * std::sin(0.5);
  const double x1 = -5.0 + vx * kTimeStep;
  const double y1 = 1.0 + vy * kTimeStep - 0.5 * 9.81 * kTimeStep * kTimeStep;
  auto path_from_muzzle = [&] {
    const auto path = marker("predicted_paths", 0);
    return path && path->points.size() >= 2 && path->points[0].x == -5.0 &&
           path->points[0].y == 1.0 && std::abs(path->points[1].x - x1) < 1e-12 &&
           std::abs(path->points[1].y - y1) < 1e-12;
  };
  ASSERT_TRUE(spinUntil(path_from_muzzle));
  ASSERT_TRUE(drawn("predicted_hits", 0));  // sent with the path
  const geometry_msgs::Point hit = marker("predicted_hits", 0)->pose.position;
  EXPECT_EQ(marker("predicted_paths", 0)->points.back(), hit);
  EXPECT_EQ(aim.response.predicted_hit, hit);  // aim answers what the marker shows
  EXPECT_GT(aim.response.time_of_flight, 0.0);

  Fire fire;
  fire = call("fire", fire);
  ASSERT_TRUE(fire.response.success);
  contacts_.clear();
  ballsAt(stepBy(360));
  spinUntil([] { return false; }, kInTransit);
  const auto first = std::find_if(contacts_.begin(), contacts_.end(), [&](const Contact& c) {
    return c.ball_id == fire.response.ball_id ||
           (c.other_kind == Contact::BALL && c.other_id == fire.response.ball_id);
  });
  ASSERT_NE(first, contacts_.end());
  const double radius = 0.2;  // the cannon's balls
  const double sign = first->ball_id == fire.response.ball_id ? 1.0 : -1.0;
  EXPECT_NEAR(first->point.x + sign * radius * first->normal.x, hit.x, 1e-12);
  EXPECT_NEAR(first->point.y + sign * radius * first->normal.y, hit.y, 1e-12);
}

TEST_F(Interface, FireRefusesBadInput) {
  expectRefused<Fire>("fire", Fire(), {
      {"unknown launcher", [](Fire& f) { f.request.launcher = "x"; }, "no launcher named 'x'"},
      {"NaN speed", [](Fire& f) { f.request.speed = kNaN; }, "speed must be finite and > 0"},
      {"negative speed", [](Fire& f) { f.request.speed = -3.0; }, "speed must be finite and > 0"},
      {"infinite speed", [](Fire& f) { f.request.speed = kInf; }, "speed must be finite and > 0"},
      {"speed beyond the limit", [](Fire& f) { f.request.speed = 2e5; }, "at most 1000 m/s (~max_speed"},
  });
  // A ball still in the muzzle blocks the next shot.
  Fire first;
  ASSERT_TRUE(call("fire", first).response.success);
  Fire blocked;
  blocked = call("fire", blocked);
  EXPECT_FALSE(blocked.response.success);
  EXPECT_NE(blocked.response.message.find("cannot fire: ball would overlap ball 7"),
            std::string::npos)
      << blocked.response.message;
  EXPECT_EQ(ballsAt(0.0).balls.size(), kSceneBalls + 1);
}

TEST_F(Interface, ClickedPointAimsBallisticallyAndFires) {
  geometry_msgs::PointStamped click;
  click.header.frame_id = "world";
  click.point.x = 1.0;
  click.point.y = 1.5;
  ros::Publisher pub = nh_->advertise<geometry_msgs::PointStamped>("clicked_point", 1, true);
  pub.publish(click);
  const auto expected = engine::aimBallistic({-5.0, 1.0}, {1.0, 1.5}, 9.0, {0.0, -9.81}, false);
  ASSERT_TRUE(expected);
  EXPECT_TRUE(spinUntil([&] { return std::abs(launcherYaw() - expected->angle) < 1e-9; }));
  // ~fire_on_click: a ball left the launcher.
  EXPECT_EQ(ballsAt(0.0).balls.size(), kSceneBalls + 1);
}

TEST_F(Interface, ClockAdvancesWhileRunning) {
  setPaused(false);
  ASSERT_TRUE(spinUntil([&] { return clock_.toSec() > 0.0; }));
  const ros::Time first = clock_;
  EXPECT_TRUE(spinUntil([&] { return clock_ > first; }));
  // And `balls` is stamped with that sim time.
  const BallStateArray later = waitForBalls([&](const BallStateArray& b) { return b.header.stamp > first; });
  EXPECT_GT(later.header.stamp, first);
  setPaused(true);
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_interface");
}

TEST_F(Interface, ExplodeThrowsTheBallsWithinItsRadiusAwayAndRefusesABadBlast) {
  const SpawnBall spawned = call("spawn_ball", test::spawnRequest(0.0, 5.0, 0.2, 2.0));
  ASSERT_TRUE(spawned.response.success) << spawned.response.message;
  Explode blast;
  blast.request.centre.x = -0.5;
  blast.request.centre.y = 5.0;
  blast.request.impulse = 8.0;
  blast.request.radius = 2.0;
  const Explode exploded = call("explode", blast);
  ASSERT_TRUE(exploded.response.success) << exploded.response.message;
  EXPECT_EQ(exploded.response.ball_ids, std::vector<std::uint32_t>({spawned.response.ball_id}));
  // 8 N s (1 - 0.5 / 2) on 2 kg, away from the blast: along +x.
  const BallStateArray after = waitForBalls([&](const BallStateArray& b) {
    const BallState* ball = find(b, spawned.response.ball_id);
    return ball && ball->velocity.x != 0.0;
  });
  const BallState* b = find(after, spawned.response.ball_id);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->velocity.x, 3.0);
  EXPECT_EQ(b->velocity.y, 0.0);
  expectRefused<Explode>("explode", blast,
                         {{"no radius", [](Explode& e) { e.request.radius = 0.0; }, "radius"},
                          {"NaN impulse", [](Explode& e) { e.request.impulse = kNaN; }, "impulse"},
                          {"infinite centre", [](Explode& e) { e.request.centre.y = kInf; }, "centre"},
                          {"past ~max_speed", [](Explode& e) { e.request.impulse = 1e5; },
                           "faster than 1000"}});
}

TEST_F(Interface, CmdVelPushesTheNewestBallUntilItsCommandTimesOut) {
  const SpawnBall spawned = call("spawn_ball", test::spawnRequest(-2.5, 7.0, 0.2, 2.0));
  ASSERT_TRUE(spawned.response.success) << spawned.response.message;
  ros::Publisher cmd_vel = nh_->advertise<geometry_msgs::Twist>("cmd_vel", 1);
  ASSERT_TRUE(spinUntil([&] { return cmd_vel.getNumSubscribers() > 0; }));
  geometry_msgs::Twist twist;
  twist.linear.x = 3.0;   // m/s^2
  twist.linear.y = 9.81;  // holding it up against gravity
  cmd_vel.publish(twist);
  geometry_msgs::Twist too_strong = twist;
  too_strong.linear.x = 2e4;
  cmd_vel.publish(too_strong);
  spinUntil([] { return false; }, kInTransit);  // the node takes them while paused
  // Pushed through every step that starts before the first command is ~cmd_vel_timeout
  // (0.29 s) old, 35 of them (the second, refused, changes nothing); then it flies on under
  // gravity alone.
  const double t = 30 * kTimeStep, driven = 35 * kTimeStep, end = 90 * kTimeStep;
  const BallStateArray pushed = ballsAt(stepBy(30));
  const BallState* b = find(pushed, spawned.response.ball_id);
  ASSERT_NE(b, nullptr);
  EXPECT_NEAR(b->velocity.x, 3.0 * t, 1e-12);
  EXPECT_NEAR(b->position.x, -2.5 + 1.5 * t * t, 1e-12);
  EXPECT_NEAR(b->position.y, 7.0, 1e-12);
  const BallStateArray flying = ballsAt(stepBy(60));
  b = find(flying, spawned.response.ball_id);
  ASSERT_NE(b, nullptr);
  EXPECT_NEAR(b->velocity.x, 3.0 * driven, 1e-12);
  EXPECT_NEAR(b->position.x, -2.5 + 1.5 * driven * driven + 3.0 * driven * (end - driven), 1e-12);
  EXPECT_NEAR(b->position.y, 7.0 - 0.5 * 9.81 * (end - driven) * (end - driven), 1e-12);
}
