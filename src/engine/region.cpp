#include "ball_physics_sim/engine/region.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ball_physics_sim/engine/polynomial.h"

namespace ball_physics_sim::engine {

void checkRegion(const Region& region, const std::string& what) {
  for (const Vec2* corner : {&region.min, &region.max})
    if (!corner->allFinite() || corner->cwiseAbs().maxCoeff() > kMaxCoordinate)
      throw std::invalid_argument(what + "'s " + (corner == &region.min ? "min" : "max") +
                                  " corner must be finite, each coordinate within " +
                                  std::to_string(kMaxCoordinate) + " m of the origin's");
  if (!(region.min.x() < region.max.x() && region.min.y() < region.max.y()))
    throw std::invalid_argument(what + "'s min corner must be below and left of its max corner");
}

bool centreInside(const Region& region, const Motion& motion) {
  for (int axis = 0; axis < 2; ++axis) {
    const double p = motion.position[axis], v = motion.velocity[axis];
    const double a = motion.acceleration[axis];
    const double lo = region.min[axis], hi = region.max[axis];
    if (p < lo - kOnRegionSide || p > hi + kOnRegionSide) return false;
    const bool leaves_low = v < 0.0 || (v == 0.0 && a < 0.0);
    const bool leaves_high = v > 0.0 || (v == 0.0 && a > 0.0);
    if ((std::abs(p - lo) <= kOnRegionSide && leaves_low) ||
        (std::abs(p - hi) <= kOnRegionSide && leaves_high))
      return false;
  }
  return true;
}

std::vector<double> regionCrossings(const Region& region, const Motion& motion, double horizon) {
  std::vector<double> crossings;
  for (int axis = 0; axis < 2; ++axis) {
    const int across = 1 - axis;
    for (const double side : {region.min[axis], region.max[axis]}) {
      // The centre's coordinate along `axis`, less the side's, as a polynomial in t.
      const Polynomial gap{{motion.position[axis] - side, motion.velocity[axis],
                            0.5 * motion.acceleration[axis]}};
      const Roots roots = rootsBetween(gap, 0.0, horizon);
      for (int k = 0; k < roots.count; ++k) {
        const double along = motion.positionAt(roots.t[k])[across];
        if (along >= region.min[across] && along <= region.max[across])
          crossings.push_back(roots.t[k]);
      }
    }
  }
  std::sort(crossings.begin(), crossings.end());
  crossings.erase(std::unique(crossings.begin(), crossings.end()), crossings.end());
  return crossings;
}

std::optional<double> timeToCrossRegion(const Region& region, const Motion& motion,
                                        double horizon) {
  const std::vector<double> crossings = regionCrossings(region, motion, horizon);
  if (crossings.empty()) return std::nullopt;
  return crossings.front();
}

}  // namespace ball_physics_sim::engine
