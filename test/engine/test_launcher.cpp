#include <cmath>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/launcher.h"

using namespace ball_physics_sim::engine;

TEST(Launcher, LaunchedBallLeavesTheMuzzleAlongTheAimAtTheGivenSpeed) {
  Launcher launcher;
  launcher.position = Vec2(1.0, 2.0);
  launcher.angle = std::atan2(3.0, 4.0);
  launcher.projectile.radius = 0.2;
  launcher.projectile.mass = 3.0;
  launcher.projectile.restitution = 0.5;
  const Ball ball = launcher.launch(10.0);
  EXPECT_EQ(ball.position, Vec2(1.0, 2.0));
  EXPECT_NEAR((ball.velocity - Vec2(8.0, 6.0)).norm(), 0.0, 1e-14);
  EXPECT_EQ(ball.radius, 0.2);
  EXPECT_EQ(ball.mass, 3.0);
  EXPECT_EQ(ball.restitution, 0.5);
}
