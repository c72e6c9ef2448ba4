#include "ball_physics_sim/engine/kinematics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

namespace {

constexpr double kNever = std::numeric_limits<double>::infinity();

Vec2 rotated(const Vec2& v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return Vec2(c * v.x() - s * v.y(), s * v.x() + c * v.y());
}

double timeToNextWaypoint(const Segment& segment) {
  if (segment.waypoints.empty()) return kNever;
  return (segment.waypoints[segment.next_waypoint] - segment.pivot).norm() / segment.speed;
}

double timeToTurningLimit(const Segment& segment) {
  const double w = segment.angular_velocity;
  if (w > 0.0) return (segment.max_angle - segment.angle) / w;
  if (w < 0.0) return (segment.min_angle - segment.angle) / w;
  return kNever;
}

// Turns the segment about its pivot by `turn`, then carries it along by `shift`.
void displace(Segment& segment, double turn, const Vec2& shift) {
  if (turn != 0.0) {
    segment.start = segment.pivot + rotated(segment.start - segment.pivot, turn);
    segment.end = segment.pivot + rotated(segment.end - segment.pivot, turn);
    segment.angle += turn;
  }
  segment.start += shift;
  segment.end += shift;
  segment.pivot += shift;
}

}  // namespace

bool moves(const Segment& segment) { return segment.velocity != Vec2::Zero() || turns(segment); }

bool turns(const Segment& segment) { return segment.angular_velocity != 0.0; }

bool mayMove(const Segment& segment) { return moves(segment) || !segment.waypoints.empty(); }

Vec2 surfaceVelocity(const Segment& segment, const Vec2& point) {
  return segment.velocity + segment.angular_velocity * perpendicular(point - segment.pivot);
}

Vec2 velocityUnder(const Segment& segment, const Vec2& position) {
  return moves(segment) ? surfaceVelocity(segment, segment.closestPoint(position))
                        : Vec2(Vec2::Zero());
}

Motion seenFrom(const Segment& segment, const Motion& ball) {
  return ball.relativeTo({Vec2::Zero(), segment.velocity, Vec2::Zero()});
}

Segment movedBy(const Segment& segment, double t) {
  Segment moved = segment;
  displace(moved, segment.angular_velocity * t, t * segment.velocity);
  return moved;
}

Separation carriedSeparation(const Segment& segment, const Vec2& foot, const Vec2& normal,
                             const Vec2& position, double t) {
  const double moving_for = std::min(t, timeToMotionChange(segment));
  const double turn = segment.angular_velocity * moving_for;
  const Vec2 foot_then =
      segment.pivot + moving_for * segment.velocity + rotated(foot - segment.pivot, turn);
  const Vec2 normal_then = rotated(normal, turn);
  return {normal_then, normal_then.dot(position - foot_then)};
}

double timeToMotionChange(const Segment& segment) {
  return std::min(timeToNextWaypoint(segment), timeToTurningLimit(segment));
}

void moveSegment(Segment& segment, double dt) {
  const bool at_waypoint = dt >= timeToNextWaypoint(segment);
  const bool at_limit = dt >= timeToTurningLimit(segment);
  const double limit = segment.angular_velocity > 0.0 ? segment.max_angle : segment.min_angle;
  displace(segment, at_limit ? limit - segment.angle : segment.angular_velocity * dt,
           dt * segment.velocity);
  // Exactly on them, whatever the rounding of the moves so far.
  if (at_limit) segment.angle = limit;
  if (at_waypoint) displace(segment, 0.0, segment.waypoints[segment.next_waypoint] - segment.pivot);
}

void startNextMotion(Segment& segment) {
  if (timeToTurningLimit(segment) == 0.0) segment.angular_velocity = 0.0;
  if (timeToNextWaypoint(segment) == 0.0) headForNextWaypoint(segment);
}

void headForNextWaypoint(Segment& segment) {
  const std::size_t count = segment.waypoints.size();
  if (count == 0) return;
  for (std::size_t k = 0; k < count && segment.waypoints[segment.next_waypoint] == segment.pivot;
       ++k)
    segment.next_waypoint = (segment.next_waypoint + 1) % count;
  const Vec2 leg = segment.waypoints[segment.next_waypoint] - segment.pivot;
  const double length = leg.norm();
  segment.velocity = length > 0.0 ? Vec2(segment.speed / length * leg) : Vec2(Vec2::Zero());
}

double gapAccelerationBias(const Segment& segment, const Vec2& position,
                           const Vec2& relative_velocity, const Vec2& normal, double distance,
                           bool on_cap) {
  const double w = segment.angular_velocity;
  if (on_cap) {
    // Round the cap, which itself goes round the pivot: the ball's centripetal term less the
    // cap's centripetal acceleration -w^2 (cap - pivot) along the normal.
    const Vec2 cap = position - distance * normal;
    return centripetalOpening(relative_velocity, normal, distance) +
           w * w * normal.dot(cap - segment.pivot);
  }
  if (w == 0.0) return 0.0;  // a face that only translates keeps its normal
  // gap = n . (p - pivot) - const with n turning at w: gap'' = n . a - w^2 n . (p - pivot)
  // + 2 w (J n) . (p' - pivot'), J the quarter turn; p' - pivot' is the relative velocity plus
  // the touched point's own turning velocity.
  const Vec2 foot = position - distance * normal;
  const Vec2 turning = w * perpendicular(foot - segment.pivot);
  return -w * w * normal.dot(position - segment.pivot) +
         2.0 * w * perpendicular(normal).dot(relative_velocity + turning);
}

double turningContactLifetime(const Segment& segment, const Vec2& position, const Vec2& velocity,
                              const Vec2& acceleration) {
  const double w = std::abs(segment.angular_velocity);
  if (w == 0.0) return kNever;
  // |gap'''| <= |w|^3 |p - pivot| + 3 w^2 |p' - pivot'| + 3 |w| |a|, and the drift is
  // gap''' t^3 / 6.
  const double jerk = w * w * w * (position - segment.pivot).norm() +
                      3.0 * w * w * (velocity - segment.velocity).norm() +
                      3.0 * w * acceleration.norm();
  return std::cbrt(6.0 * kHeldDrift / jerk);
}

}  // namespace ball_physics_sim::engine
