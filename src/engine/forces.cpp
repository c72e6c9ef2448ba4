#include "ball_physics_sim/engine/forces.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace ball_physics_sim::engine {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

// `what` names the quantity in the message, as "blast's centre".
void requireCentre(const Vec2& centre, const std::string& what) {
  require(centre.allFinite() && centre.cwiseAbs().maxCoeff() <= kMaxCoordinate,
          what + " must be finite, each coordinate within " + std::to_string(kMaxCoordinate) +
              " m of the origin's");
}

void requireNonNegative(double value, const std::string& what) {
  require(std::isfinite(value) && value >= 0.0,
          what + " must be finite and >= 0, got " + std::to_string(value));
}

}  // namespace

void checkWind(const Wind& wind) {
  checkRegion(wind.region, "wind");
  require(wind.acceleration.allFinite() && wind.acceleration.norm() <= kMaxGravity,
          "wind's acceleration must be finite and at most " + std::to_string(kMaxGravity) +
              " m/s^2, got (" + std::to_string(wind.acceleration.x()) + ", " +
              std::to_string(wind.acceleration.y()) + ")");
}

void checkAttractor(const Attractor& attractor) {
  requireCentre(attractor.centre, "attractor's centre");
  requireNonNegative(attractor.strength, "attractor's strength");
  requireNonNegative(attractor.core, "attractor's core");
}

Vec2 attraction(const Attractor& attractor, const Vec2& position) {
  const Vec2 toward = attractor.centre - position;
  const double s = toward.squaredNorm() + attractor.core * attractor.core;
  if (s == 0.0) return Vec2::Zero();  // at the centre of a point: no direction
  return attractor.strength / (s * std::sqrt(s)) * toward;
}

Vec2 attractionRate(const Attractor& attractor, const Vec2& position, const Vec2& velocity) {
  // d/dt of S r / s^(3/2), with r = centre - p, s = |r|^2 + core^2, dr/dt = -v.
  const Vec2 toward = attractor.centre - position;
  const double s = toward.squaredNorm() + attractor.core * attractor.core;
  if (s == 0.0) return Vec2::Zero();
  const double root = std::sqrt(s);
  return attractor.strength / (s * root) *
         (3.0 * toward.dot(velocity) / s * toward - velocity);
}

double fieldStretch(const Vec2& rate) {
  const double jerk = rate.norm();
  if (jerk == 0.0) return std::numeric_limits<double>::infinity();
  return std::cbrt(6.0 * kFieldDrift / jerk);
}

void checkWater(const Water& water) {
  checkRegion(water.region, "water");
  requireNonNegative(water.density, "water's density");
  requireNonNegative(water.drag, "water's drag");
}

double sunkVolume(double radius, double depth) {
  const double d = std::clamp(depth, 0.0, 2.0 * radius);
  return kPi * d * d * (3.0 * radius - d) / 3.0;
}

Region wettedRegion(const Water& water, double radius) {
  return {water.region.min - Vec2(0.0, radius), water.region.max + Vec2(0.0, radius)};
}

namespace {

// How deep the ball at `position` is sunk, if it is in the water at all.
std::optional<double> sunkDepth(const Water& water, double radius, const Vec2& position) {
  const Region wet = wettedRegion(water, radius);
  if ((position.array() < wet.min.array()).any() || (position.array() > wet.max.array()).any())
    return std::nullopt;
  return std::clamp(water.region.max.y() - (position.y() - radius), 0.0, 2.0 * radius);
}

}  // namespace

Vec2 waterAcceleration(const Water& water, const Ball& ball, const Vec2& position,
                       const Vec2& velocity, double g) {
  const std::optional<double> depth = sunkDepth(water, ball.radius, position);
  if (!depth) return Vec2::Zero();
  const double sunk = sunkVolume(ball.radius, *depth);
  const double whole = sunkVolume(ball.radius, 2.0 * ball.radius);
  return water.density * g * sunk / ball.mass * Vec2(0.0, 1.0) - water.drag * sunk / whole * velocity;
}

Vec2 waterAccelerationRate(const Water& water, const Ball& ball, const Vec2& position,
                           const Vec2& velocity, const Vec2& acceleration, double g) {
  const std::optional<double> depth = sunkDepth(water, ball.radius, position);
  if (!depth) return Vec2::Zero();
  const double r = ball.radius, d = *depth;
  // dV/dt = pi d (2 r - d) dd/dt, and the depth grows as the ball goes down.
  const double sunk_rate = d > 0.0 && d < 2.0 * r ? kPi * d * (2.0 * r - d) * -velocity.y() : 0.0;
  const double whole = sunkVolume(r, 2.0 * r);
  return water.density * g * sunk_rate / ball.mass * Vec2(0.0, 1.0) -
         water.drag * (sunk_rate / whole * velocity + sunkVolume(r, d) / whole * acceleration);
}

WaterStiffness waterStiffness(const Water& water, const Ball& ball, const Vec2& position,
                              double g) {
  const std::optional<double> depth = sunkDepth(water, ball.radius, position);
  if (!depth) return {};
  const double r = ball.radius, d = *depth;
  // dV/dd = pi d (2 r - d): the sphere's cross-section at the surface.
  return {water.drag * sunkVolume(r, d) / sunkVolume(r, 2.0 * r),
          water.density * g * kPi * d * (2.0 * r - d) / ball.mass};
}

bool pushesToward(const Vec2& push, const Vec2& to) {
  // cos 60 degrees, less rounding: a hex pile's balls lie at 60 degrees, and are pressed on.
  return push.dot(to) >= (0.5 - 1e-9) * push.norm() * to.norm();
}

void checkBlast(const Blast& blast) {
  requireCentre(blast.centre, "blast's centre");
  requireNonNegative(blast.impulse, "blast's impulse");
  require(std::isfinite(blast.radius) && blast.radius > 0.0 && blast.radius <= kMaxCoordinate,
          "blast's radius must be > 0 and at most " + std::to_string(kMaxCoordinate) +
              " m, got " + std::to_string(blast.radius));
}

Vec2 blastImpulse(const Blast& blast, const Vec2& position) {
  const Vec2 away = position - blast.centre;
  const double distance = away.norm();
  if (distance == 0.0 || distance >= blast.radius) return Vec2::Zero();
  return blast.impulse * (1.0 - distance / blast.radius) / distance * away;
}

}  // namespace ball_physics_sim::engine
