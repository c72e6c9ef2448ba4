#pragma once

#include "ball_physics_sim/engine/motion.h"
#include "ball_physics_sim/engine/segment.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

// Kinematic segments: between events a segment translates with constant velocity and turns at
// a constant rate about its pivot; events are a waypoint reached or a turning limit.

// Whether the segment moves now.
bool moves(const Segment& segment);
// Whether it turns now (about its pivot): its faces' normals turn with it.
bool turns(const Segment& segment);
// Whether it may move within a step: it moves now, or has waypoints to start it.
bool mayMove(const Segment& segment);

// The velocity of the segment's point at `point` (a point of the segment, or fixed to it).
Vec2 surfaceVelocity(const Segment& segment, const Vec2& point);

// The velocity of the segment's point nearest to a ball centre at `position`.
Vec2 velocityUnder(const Segment& segment, const Vec2& position);

// A ball's motion as the segment, translating only, sees it: against it the segment stands.
Motion seenFrom(const Segment& segment, const Motion& ball);

// The segment after `t` more seconds of its present motion, events aside.
Segment movedBy(const Segment& segment, double t);

// The line through `foot` (a point of the segment, or fixed to it) across `normal`, carried
// with the segment by `t` more seconds of its present motion, no further than its next change
// of motion: `position`'s separation from it then.
Separation carriedSeparation(const Segment& segment, const Vec2& foot, const Vec2& normal,
                             const Vec2& position, double t);

// How long until the segment's motion changes: it reaches its next waypoint or a turning
// limit. Infinity if never.
double timeToMotionChange(const Segment& segment);

// Moves the segment by `dt` <= timeToMotionChange of its motion; if that is when it changes,
// exactly onto the waypoint or the turning limit.
void moveSegment(Segment& segment, double dt);

// On its waypoint, sets it on its way to the next; on the turning limit it turns toward,
// stops its turning. Apart, the change of motion would be taken for drift by held contacts.
void startNextMotion(Segment& segment);

// Points `velocity` at the next waypoint, at `speed`, passing over any the pivot is already on.
// Nothing for a segment without waypoints.
void headForNextWaypoint(Segment& segment);

// The acceleration of the gap between a ball and the segment it touches, less the part the
// ball's own acceleration makes: gap'' = n . a + this. On a static face 0; where it curves (a cap), the
// centripetal |tangential velocity|^2 / distance; a turning segment adds its own centripetal
// and Coriolis terms. `relative_velocity` is the ball's velocity less the touched point's.
double gapAccelerationBias(const Segment& segment, const Vec2& position,
                           const Vec2& relative_velocity, const Vec2& normal, double distance,
                           bool on_cap);

// How long a ball held against a turning segment with constant accelerations stays within
// kHeldDrift of it: the gap's third derivative, from the turn, is what it drifts by.
double turningContactLifetime(const Segment& segment, const Vec2& position, const Vec2& velocity,
                              const Vec2& acceleration);

}  // namespace ball_physics_sim::engine
