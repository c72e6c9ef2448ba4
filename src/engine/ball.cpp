#include "ball_physics_sim/engine/ball.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ball_physics_sim::engine {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

}  // namespace

void checkRestitution(double restitution) {
  require(std::isfinite(restitution) && restitution >= 0.0 && restitution <= 1.0,
          "restitution must be within [0, 1], got " + std::to_string(restitution));
}

void checkFriction(double value, const std::string& what) {
  require(std::isfinite(value) && value >= 0.0,
          what + " must be finite and >= 0, got " + std::to_string(value));
}

void checkBall(const Ball& ball) {
  require(ball.position.allFinite(), "position must be finite");
  require(ball.velocity.allFinite(), "velocity must be finite");
  require(ball.position.cwiseAbs().maxCoeff() <= kMaxCoordinate,
          "position must be within " + std::to_string(kMaxCoordinate) + " m of the origin");
  require(ball.velocity.norm() <= kMaxSpeed,
          "speed must be at most " + std::to_string(kMaxSpeed) + " m/s");
  require(std::isfinite(ball.angular_velocity), "angular velocity must be finite");
  require(std::isfinite(ball.angle), "angle must be finite");
  require(std::abs(ball.angular_velocity) * ball.radius <= kMaxSpeed,
          "surface speed |angular velocity| * radius must be at most " +
              std::to_string(kMaxSpeed) + " m/s");
  require(std::isfinite(ball.radius) && ball.radius > 0.0,
          "radius must be > 0, got " + std::to_string(ball.radius));
  require(ball.radius <= kMaxCoordinate,
          "radius must be at most " + std::to_string(kMaxCoordinate) + " m");
  require(std::isfinite(ball.mass) && ball.mass > 0.0,
          "mass must be > 0, got " + std::to_string(ball.mass));
  std::ostringstream range;  // "[1e-06, 1e+06]", as the limits read in code
  range << "[" << kMinMass << ", " << kMaxMass << "]";
  require(ball.mass >= kMinMass && ball.mass <= kMaxMass,
          "mass must be within " + range.str() + " kg, got " + std::to_string(ball.mass));
  checkRestitution(ball.restitution);
  checkFriction(ball.friction, "friction");
  checkFriction(ball.rolling_resistance, "rolling resistance");
  require(std::isfinite(ball.inertia_factor) && ball.inertia_factor > 0.0 &&
              ball.inertia_factor <= 1.0,
          "inertia factor must be within (0, 1], got " + std::to_string(ball.inertia_factor));
  require(ball.group >= 0, "group must be >= 0, got " + std::to_string(ball.group));
}

bool collide(const Ball& a, const Ball& b) { return a.group == 0 || a.group != b.group; }

}  // namespace ball_physics_sim::engine
