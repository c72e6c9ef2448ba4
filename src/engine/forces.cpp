#include "ball_physics_sim/engine/forces.h"

#include <cmath>
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
