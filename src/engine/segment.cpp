#include "ball_physics_sim/engine/segment.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ball_physics_sim::engine {

Vec2 Segment::closestPoint(const Vec2& point) const {
  const Vec2 d = direction();
  return start + std::clamp(d.dot(point - start), 0.0, length()) * d;
}

void checkSegment(const Segment& segment) {
  if (!segment.start.allFinite() || !segment.end.allFinite())
    throw std::invalid_argument("segment ends must be finite");
  if (segment.start.cwiseAbs().maxCoeff() > kMaxCoordinate ||
      segment.end.cwiseAbs().maxCoeff() > kMaxCoordinate)
    throw std::invalid_argument("segment ends must be within " + std::to_string(kMaxCoordinate) +
                                " m of the origin");
  if (segment.start == segment.end) throw std::invalid_argument("segment start and end must differ");
  if (!std::isfinite(segment.thickness) || segment.thickness < 0.0 ||
      segment.thickness > kMaxCoordinate)
    throw std::invalid_argument("thickness must be within [0, " + std::to_string(kMaxCoordinate) +
                                "] m, got " + std::to_string(segment.thickness));
  checkRestitution(segment.restitution);
  checkFriction(segment.friction, "friction");
  checkFriction(segment.rolling_resistance, "rolling resistance");
}

}  // namespace ball_physics_sim::engine
