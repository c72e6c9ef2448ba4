#pragma once

#include <optional>

#include "ball_physics_sim/engine/motion.h"
#include "ball_physics_sim/engine/polynomial.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// Relative normal speeds smaller than this are rounding noise left by the impulse that just
// separated two bodies, not an approach; counting them would resolve the same touch forever.
constexpr double kApproachSpeedTolerance = 1e-9;  // m/s

// A touching pair that neither approaches nor parts, and is not held, collides once its
// accelerations have closed it by this much: far above the rounding of its gap, far below the
// overlap anything tolerates.
constexpr double kUnheldTouchDrift = 1e-10;  // m

// Stepping toward a turning segment stops this close to it (plus the rounding of the
// positions), and after this many steps (a ball grazing it for long).
constexpr double kTurningContactGap = 1e-12;  // m
constexpr int kMaxTurningSteps = 10000;

// Lecture, attempt 3: overlapping (or touching) bodies collide now if they approach and not at
// all if they move apart; `normal_speed` is the rate at which their distance grows.
bool isApproaching(double normal_speed);

// How far the squared distance between two centres is beyond r^2, as a polynomial in time;
// `relative` is the motion of one centre relative to the other.
Polynomial squaredDistanceBeyond(const Motion& relative, double r);

// A ball moving relative to a circle (another ball, or a segment's cap, a circle of radius
// thickness / 2): the first time in [0, horizon] at which the centres are `contact_distance`
// apart. Without relative acceleration this is the lecture's abc formula; with it, a quartic.
std::optional<double> circleTimeOfImpact(const Motion& relative, double contact_distance,
                                         double horizon);

// A ball moving relative to the other end of a rope (an anchor, another ball): the first time in
// [0, horizon] at which the centres are `length` apart and moving apart, pulling it taut. At
// or beyond its length now, it is taut now if they move apart, as an overlapping contact is.
std::optional<double> ropeTimeOfTaut(const Motion& relative, double length, double horizon);

// A ball of `radius` against either face of `segment`: the first time in [0, horizon] at which
// it touches a face with its point of impact between the segment's ends (else the caps hit).
// The face on the centre's side now, or the other one, reached by curving round an end.
std::optional<double> faceTimeOfImpact(const Motion& ball, double radius, const Segment& segment,
                                       double horizon);

// A ball against one of the segment's caps (0: start, 1: end), a circle of radius
// thickness / 2. Where the centre lies over the face, the face is what it touches: an overlap
// with the cap there is the face's to resolve.
std::optional<double> capTimeOfImpact(const Motion& ball, double radius, const Segment& segment,
                                      int cap, double horizon);

// What a ball meets on a segment, and when.
struct SegmentImpact;

// A ball against a segment turning about its pivot (and translating): the first time in
// [0, horizon] at which it touches the capsule while approaching it, within
// kTurningContactGap. A turn makes the gap no polynomial in t; each step goes only as far as a
// bound on the gap's second derivative proves it stays open, so no contact is stepped over.
// After kMaxTurningSteps steps, the time reached (no contact: nothing to resolve there).
std::optional<SegmentImpact> turningTimeOfImpact(const Motion& ball, double radius,
                                                 const Segment& segment, double horizon);

// Distance from the segment's line to a ball centre touching its face or cap.
double contactDistance(const Segment& segment, double radius);

// The unit normal of the face on the side of `point`.
Vec2 faceNormalToward(const Segment& segment, const Vec2& point);

// Whether the foot of the perpendicular from `point` lies on the segment, ends included.
bool projectsOntoSegment(const Segment& segment, const Vec2& point);

// Where a ball centre is relative to what it may touch: the unit normal from the other body
// toward it and their distance along it.
struct Separation {
  Vec2 normal = Vec2::Zero();  // zero for coincident centres
  double distance = 0.0;
};

// From a centre's offset to the other centre (a ball, a cap).
Separation separationAlong(const Vec2& offset);

// The part of a segment a ball touches: a cap, or the face between them.
enum class SegmentFeature { kStartCap, kFace, kEndCap };

// From a segment's `feature` (the one under it, see featureUnder) to a ball centre at
// `position`: over the face, the face's own normal. One from the offset to the nearest point
// would carry that point's rounding, which a ball sliding fast along a long segment turns into
// a false normal speed.
Separation separationFrom(const Segment& segment, const Vec2& position, SegmentFeature feature);

struct SegmentImpact {
  double time = 0.0;
  SegmentFeature feature = SegmentFeature::kFace;
};

// The feature under a ball centre at `position` moving with `velocity`: on the perpendicular
// through an end, the one it moves onto.
SegmentFeature featureUnder(const Segment& segment, const Vec2& position, const Vec2& velocity);

// The first time in [0, horizon) at which the ball's centre crosses the perpendicular through
// an end, from the feature under it onto another; none if it stays over its feature.
std::optional<double> timeOfFeatureChange(const Motion& ball, const Segment& segment,
                                          double horizon);

}  // namespace ball_physics_sim::engine
