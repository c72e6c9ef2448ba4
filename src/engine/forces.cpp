#include "ball_physics_sim/engine/forces.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "ball_physics_sim/engine/polynomial.h"

namespace ball_physics_sim::engine {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

void requirePlace(const Vec2& point, const std::string& what) {
  require(point.allFinite() && point.cwiseAbs().maxCoeff() <= kMaxCoordinate,
          what + " must be finite, each coordinate within " + std::to_string(kMaxCoordinate) +
              " m of the origin's");
}

}  // namespace

void checkWind(const Wind& wind) {
  requirePlace(wind.min, "wind's min corner");
  requirePlace(wind.max, "wind's max corner");
  require(wind.min.x() < wind.max.x() && wind.min.y() < wind.max.y(),
          "wind's min corner must be below and left of its max corner");
  require(wind.acceleration.allFinite() && wind.acceleration.norm() <= kMaxGravity,
          "wind's acceleration must be finite and at most " + std::to_string(kMaxGravity) +
              " m/s^2, got (" + std::to_string(wind.acceleration.x()) + ", " +
              std::to_string(wind.acceleration.y()) + ")");
}

bool blowsOn(const Wind& wind, const Motion& motion) {
  for (int axis = 0; axis < 2; ++axis) {
    const double p = motion.position[axis], v = motion.velocity[axis];
    const double a = motion.acceleration[axis];
    const double lo = wind.min[axis], hi = wind.max[axis];
    if (p < lo - kOnWindSide || p > hi + kOnWindSide) return false;
    const bool leaves_low = v < 0.0 || (v == 0.0 && a < 0.0);
    const bool leaves_high = v > 0.0 || (v == 0.0 && a > 0.0);
    if ((std::abs(p - lo) <= kOnWindSide && leaves_low) ||
        (std::abs(p - hi) <= kOnWindSide && leaves_high))
      return false;
  }
  return true;
}

std::optional<double> timeToCrossWind(const Wind& wind, const Motion& motion, double horizon) {
  std::optional<double> first;
  for (int axis = 0; axis < 2; ++axis) {
    const int across = 1 - axis;
    for (const double side : {wind.min[axis], wind.max[axis]}) {
      // The centre's coordinate along `axis`, less the side's, as a polynomial in t.
      const Polynomial gap{{motion.position[axis] - side, motion.velocity[axis],
                            0.5 * motion.acceleration[axis]}};
      const Roots roots = rootsBetween(gap, 0.0, first.value_or(horizon));
      for (int k = 0; k < roots.count; ++k) {
        const double along = motion.positionAt(roots.t[k])[across];
        if (along < wind.min[across] || along > wind.max[across]) continue;
        first = roots.t[k];  // ascending, and below any earlier `first`
        break;
      }
    }
  }
  return first;
}

void checkBlast(const Blast& blast) {
  requirePlace(blast.centre, "blast's centre");
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
