#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

namespace ball_physics_sim::engine {

using Vec2 = Eigen::Vector2d;

constexpr double kPi = 3.14159265358979323846;  // C++17 has no named pi
using BallId = std::uint32_t;

// `v` turned a quarter counter-clockwise: the direction turning moves a point, or a tangent.
inline Vec2 perpendicular(const Vec2& v) { return Vec2(-v.y(), v.x()); }

// A rigid disc. Between impacts it follows p + v t + a t^2 / 2 exactly.
struct Ball {
  BallId id = 0;
  Vec2 position = Vec2::Zero();
  Vec2 velocity = Vec2::Zero();
  double angular_velocity = 0.0;  // rad/s, counter-clockwise
  double angle = 0.0;             // rad: how far it has turned since it was added
  double radius = 0.0;
  double mass = 1.0;
  double restitution = 1.0;
  double friction = 0.0;  // Coulomb coefficient
  // Rolling on a segment, the torque against the spin is this times the normal force times r.
  double rolling_resistance = 0.0;
  // Moment of inertia per m r^2: 2/5 for a solid sphere (the default, which rolls down a slope
  // at 5/7 g sin(theta)), 1/2 for a disc, 2/3 for a hollow sphere.
  double inertia_factor = 0.4;
  // Balls of one nonzero group pass through each other (a gun's bullets, a chain's links), as
  // Box2D's bodies of one negative group index do; group 0, the default, meets every ball.
  int group = 0;
  // Asleep: held still by its supports until an impact wakes it.
  bool at_rest = false;
};

// Limits on what a ball can be. Beyond them the squares in the gap functions lose all
// precision (and overflow near 1e154), so impacts would go unseen.
constexpr double kMaxSpeed = 1e5;       // m/s
constexpr double kMaxCoordinate = 1e6;  // m, for positions and radii
// Inverse masses enter the contact solver: a mass ratio beyond 1e12 leaves it no precision.
constexpr double kMinMass = 1e-6;  // kg
constexpr double kMaxMass = 1e6;   // kg

// Throws std::invalid_argument naming the first property that no ball can have: a non-finite
// value, radius <= 0, restitution outside [0, 1], friction or rolling resistance < 0, an
// inertia factor outside (0, 1] (1 is a ring: no body of that radius turns harder), a group
// < 0, a value beyond the limits above.
void checkBall(const Ball& ball);

// Whether two balls can touch: they are not of one nonzero group.
bool collide(const Ball& a, const Ball& b);

// Throws std::invalid_argument unless restitution is within [0, 1].
void checkRestitution(double restitution);

// Throws std::invalid_argument unless a friction coefficient or rolling resistance, named
// `what` in the message, is finite and >= 0.
void checkFriction(double value, const std::string& what);

}  // namespace ball_physics_sim::engine
