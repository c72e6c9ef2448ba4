#pragma once

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// What a ball hit. (A rope going taut is an impact too, kRope, but not reported as a contact.)
enum class ContactKind { kBall, kSegment, kCap, kRope };

// One resolved impact, as the world reports it.
struct Contact {
  double time = 0.0;  // exact sim time of impact, s
  BallId ball_id = 0;
  ContactKind other_kind = ContactKind::kBall;
  std::uint32_t other_id = 0;  // a ball or segment id
  Vec2 point = Vec2::Zero();   // point of impact
  Vec2 normal = Vec2::Zero();  // unit, pointing toward the ball
  double approach_speed = 0.0;  // normal speed at which they closed, m/s
  double impulse = 0.0;         // normal impulse on the ball, N s
};

// A hit on a brick (a segment with hits to break) that counted.
struct BrickHit {
  double time = 0.0;  // exact sim time of the impact, s
  SegmentId segment = 0;
  BallId ball = 0;
  int hits_left = 0;  // 0: it broke, and is gone at the end of the step
};

}  // namespace ball_physics_sim::engine
