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

namespace {

bool withinCoordinates(const Vec2& point) {
  return point.allFinite() && point.cwiseAbs().maxCoeff() <= kMaxCoordinate;
}

void checkWaypoints(const Segment& segment) {
  const std::vector<Vec2>& points = segment.waypoints;
  if (points.empty()) return;
  if (points.size() < 2) throw std::invalid_argument("waypoints must be at least two");
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!withinCoordinates(points[k]))
      throw std::invalid_argument("waypoints must be finite and within " +
                                  std::to_string(kMaxCoordinate) + " m of the origin");
    if (points[k] == points[(k + 1) % points.size()])
      throw std::invalid_argument("waypoint " + std::to_string(k) + " repeats the one before");
  }
  if (!(segment.speed > 0.0 && segment.speed <= kMaxSpeed))
    throw std::invalid_argument("speed along waypoints must be within (0, " +
                                std::to_string(kMaxSpeed) + "] m/s");
  if (segment.next_waypoint >= points.size())
    throw std::invalid_argument("next waypoint must be one of the waypoints");
}

void checkKinematics(const Segment& segment) {
  if (!withinCoordinates(segment.pivot))
    throw std::invalid_argument("pivot must be finite and within " +
                                std::to_string(kMaxCoordinate) + " m of the origin");
  if (!(segment.min_angle <= segment.angle && segment.angle <= segment.max_angle) ||
      !std::isfinite(segment.angle))
    throw std::invalid_argument("angle must be finite and within [min_angle, max_angle]");
  checkWaypoints(segment);
  // Along waypoints, the speed sets the velocity.
  const double speed = segment.waypoints.empty() ? segment.velocity.norm() : segment.speed;
  const double fastest = speed + std::abs(segment.angular_velocity) * segment.reachFromPivot();
  if (!(fastest <= kMaxSpeed))  // NaN fails too
    throw std::invalid_argument("segment velocity and angular velocity must be finite and move "
                                "no point faster than " + std::to_string(kMaxSpeed) + " m/s");
}

}  // namespace

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
  if (!std::isfinite(segment.kick) || segment.kick < 0.0 || segment.kick > kMaxSpeed)
    throw std::invalid_argument("kick must be within [0, " + std::to_string(kMaxSpeed) +
                                "] m/s, got " + std::to_string(segment.kick));
  if (segment.hits_to_break < 0)
    throw std::invalid_argument("hits to break must be >= 0 (0: never breaks), got " +
                                std::to_string(segment.hits_to_break));
  checkRestitution(segment.restitution);
  checkFriction(segment.friction, "friction");
  checkFriction(segment.rolling_resistance, "rolling resistance");
  checkKinematics(segment);
}

}  // namespace ball_physics_sim::engine
