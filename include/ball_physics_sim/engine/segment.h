#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "ball_physics_sim/engine/ball.h"

namespace ball_physics_sim::engine {

using SegmentId = std::uint32_t;

// A double-sided line segment from `start` to `end`, rounded at both ends by its caps. With a
// thickness it is a capsule: every point within thickness / 2 of the line segment. Static by
// default; a kinematic one (a moving platform, a flipper, a spinner) moves as it is told,
// whatever hits it, as if of infinite mass (see kinematics.h).
struct Segment {
  SegmentId id = 0;
  Vec2 start = Vec2::Zero();
  Vec2 end = Vec2::Zero();
  double thickness = 0.0;
  double restitution = 1.0;
  double friction = 0.0;            // Coulomb coefficient
  double rolling_resistance = 0.0;  // see Ball
  // A brick: the hits it takes before it breaks, counting down; it is removed at the end of the
  // step of the last. 0: it never breaks.
  int hits_to_break = 0;
  // A bumper: the speed it adds along the normal to a ball that hits it (m/s), besides the
  // bounce restitution gives. The energy comes from the bumper's own power, as in pinball.
  double kick = 0.0;

  Vec2 velocity = Vec2::Zero();    // m/s, of every point, `pivot` included
  double angular_velocity = 0.0;   // rad/s, counter-clockwise about `pivot`
  Vec2 pivot = Vec2::Zero();       // m, the point it turns about, carried with it
  double angle = 0.0;              // rad, turned since it was added
  // Turning stops (angular_velocity becomes 0) when `angle` reaches one of these.
  double min_angle = -std::numeric_limits<double>::infinity();
  double max_angle = std::numeric_limits<double>::infinity();
  // If any, the pivot goes from waypoint to waypoint at `speed`, round and round: `velocity`
  // is then set by the leg it is on, heading for waypoints[next_waypoint].
  std::vector<Vec2> waypoints;
  double speed = 0.0;  // m/s
  std::size_t next_waypoint = 0;

  double length() const { return (end - start).norm(); }
  Vec2 direction() const { return (end - start) / length(); }
  // The unit normal on the left of start -> end; the other face's normal is its opposite.
  Vec2 normal() const {
    const Vec2 d = direction();
    return Vec2(-d.y(), d.x());
  }
  // How far its line segment reaches from the pivot: the radius its ends turn on.
  double reachFromPivot() const {
    return std::max((start - pivot).norm(), (end - pivot).norm());
  }
  // Which end: 0 is start, 1 is end.
  const Vec2& cap(int which) const { return which == 0 ? start : end; }
  // The point of the line segment nearest to `point`: a cap, or the foot on the face.
  Vec2 closestPoint(const Vec2& point) const;
};

// Throws std::invalid_argument naming what no segment can have: non-finite or coincident ends,
// a negative thickness, hits to break or kick, a kick beyond kMaxSpeed, restitution outside [0, 1], friction or rolling resistance < 0; a
// point moving faster than kMaxSpeed, an angle outside its limits, waypoints without a speed
// > 0 or with a repeated point.
void checkSegment(const Segment& segment);

}  // namespace ball_physics_sim::engine
