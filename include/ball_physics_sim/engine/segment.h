#pragma once

#include <cstdint>

#include "ball_physics_sim/engine/ball.h"

namespace ball_physics_sim::engine {

using SegmentId = std::uint32_t;

// A static, double-sided line segment from `start` to `end`, rounded at both ends by its caps.
// With a thickness it is a capsule: every point within thickness / 2 of the line segment.
struct Segment {
  SegmentId id = 0;
  Vec2 start = Vec2::Zero();
  Vec2 end = Vec2::Zero();
  double thickness = 0.0;
  double restitution = 1.0;
  double friction = 0.0;            // Coulomb coefficient
  double rolling_resistance = 0.0;  // see Ball

  double length() const { return (end - start).norm(); }
  Vec2 direction() const { return (end - start) / length(); }
  // The unit normal on the left of start -> end; the other face's normal is its opposite.
  Vec2 normal() const {
    const Vec2 d = direction();
    return Vec2(-d.y(), d.x());
  }
  // Which end: 0 is start, 1 is end.
  const Vec2& cap(int which) const { return which == 0 ? start : end; }
  // The point of the line segment nearest to `point`: a cap, or the foot on the face.
  Vec2 closestPoint(const Vec2& point) const;
};

// Throws std::invalid_argument naming what no segment can have: non-finite or coincident ends,
// a negative thickness, restitution outside [0, 1], friction or rolling
// resistance < 0.
void checkSegment(const Segment& segment);

}  // namespace ball_physics_sim::engine
