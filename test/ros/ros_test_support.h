#pragma once
// What the rostest clients share: waiting on callbacks, requests, and tables of refused
// requests.

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "ball_physics_sim/AddSegment.h"
#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ball_physics_sim/Step.h"

namespace ball_physics_sim::test {

constexpr double kTimeStep = 1.0 / 120.0;  // s, the node's default ~time_step
constexpr double kStampResolution = 1e-9;  // s, of a ros::Time
// Longer than a message takes over loopback, shorter than a few publish periods.
constexpr double kInTransit = 0.1;  // s

// Spins until `done` holds or `seconds` of wall time pass; whether it holds.
inline bool spinUntil(const std::function<bool()>& done, double seconds = 10.0) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(0.005).sleep();
  }
  return done();
}

// The next message kept in `latest` (by a subscriber) that satisfies `ready`, published after
// this call: what was already on its way is let pass first.
template <typename Message>
Message nextMessage(std::optional<Message>& latest,
                    const std::function<bool(const Message&)>& ready) {
  spinUntil([] { return false; }, kInTransit);
  latest.reset();
  EXPECT_TRUE(spinUntil([&] { return latest && ready(*latest); })) << "no such message";
  return latest ? *latest : Message();
}

// The next `balls` state kept in `latest` at sim time `time` (a stamp holds it to the
// nanosecond).
inline BallStateArray ballsAt(std::optional<BallStateArray>& latest, double time) {
  return nextMessage<BallStateArray>(latest, [&](const BallStateArray& b) {
    return std::abs(b.header.stamp.toSec() - time) <= kStampResolution;
  });
}

// Calls service `name`, expecting the call to go through and to answer success; the service
// with its answer.
template <typename Service>
Service callSucceeding(const std::string& name, Service service) {
  EXPECT_TRUE(ros::service::call(name, service)) << name;
  EXPECT_TRUE(service.response.success) << name << ": " << service.response.message;
  return service;
}

// Steps the paused node `steps` times; the sim time it answers.
inline double stepBy(std::uint32_t steps) {
  Step step;
  step.request.steps = steps;
  return callSucceeding("step", step).response.time;
}

// Runs a rostest client's tests as ROS node `name`, kept alive across the tests.
inline int runClient(int argc, char** argv, const char* name) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, name);
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}

// A spawn_ball request for a ball of `radius` and `mass` at (x, y), moving along x at `vx`.
inline SpawnBall spawnRequest(double x, double y, double radius, double mass, double vx = 0.0) {
  SpawnBall s;
  s.request.position.x = x;
  s.request.position.y = y;
  s.request.velocity.x = vx;
  s.request.radius = radius;
  s.request.mass = mass;
  s.request.restitution = 0.5;
  return s;
}

// An add_segment request for a segment from (x0, y0) to (x1, y1).
inline AddSegment segmentRequest(double x0, double y0, double x1, double y1) {
  AddSegment a;
  a.request.start.x = x0;
  a.request.start.y = y0;
  a.request.end.x = x1;
  a.request.end.y = y1;
  return a;
}

// A valid request spoiled one way, and what the refusal must say.
template <typename Service>
struct BadRequest {
  std::string what;
  std::function<void(Service&)> spoil;
  std::string expected;
};

// Calls `name` with each spoiled copy of `valid`: each must be refused, saying why.
template <typename Service>
void expectRefused(const std::string& name, const Service& valid,
                   const std::vector<BadRequest<Service>>& cases) {
  for (const BadRequest<Service>& c : cases) {
    Service bad = valid;
    c.spoil(bad);
    ASSERT_TRUE(ros::service::call(name, bad)) << name << ": " << c.what;
    EXPECT_FALSE(bad.response.success) << name << ": " << c.what;
    EXPECT_NE(bad.response.message.find(c.expected), std::string::npos)
        << name << ": " << c.what << ": " << bad.response.message;
  }
}

}  // namespace ball_physics_sim::test
