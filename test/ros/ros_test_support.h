#pragma once
// What the rostest clients share: waiting on callbacks, and tables of refused requests.

#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

namespace ball_physics_sim::test {

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
