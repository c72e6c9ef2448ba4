#include "ball_physics_sim/engine/forces.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ball_physics_sim::engine {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
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
  require(attractor.centre.allFinite() &&
              attractor.centre.cwiseAbs().maxCoeff() <= kMaxCoordinate,
          "attractor's centre must be finite, each coordinate within " +
              std::to_string(kMaxCoordinate) + " m of the origin's");
  require(std::isfinite(attractor.strength) && attractor.strength >= 0.0,
          "attractor's strength must be finite and >= 0, got " +
              std::to_string(attractor.strength));
  require(std::isfinite(attractor.core) && attractor.core >= 0.0,
          "attractor's core must be finite and >= 0, got " + std::to_string(attractor.core));
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

void checkBlast(const Blast& blast) {
  require(blast.centre.allFinite() && blast.centre.cwiseAbs().maxCoeff() <= kMaxCoordinate,
          "blast's centre must be finite, each coordinate within " +
              std::to_string(kMaxCoordinate) + " m of the origin's");
  require(std::isfinite(blast.impulse) && blast.impulse >= 0.0,
          "blast's impulse must be finite and >= 0, got " + std::to_string(blast.impulse));
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
