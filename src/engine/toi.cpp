#include "ball_physics_sim/engine/toi.h"

#include <cmath>
#include <limits>

#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/polynomial.h"

namespace ball_physics_sim::engine {

bool isApproaching(double normal_speed) { return normal_speed < -kApproachSpeedTolerance; }

namespace {

// The first time in [0, horizon] at which `gap` closes, given the normal speed now; `drift` is
// kUnheldTouchDrift in the gap's units.
std::optional<double> firstContact(const Polynomial& gap, double normal_speed, double horizon,
                                   double drift) {
  if (gap.c[0] > 0.0) return firstDownCrossing(gap, 0.0, horizon);
  // Touching or overlapping (lecture, attempt 3): approaching collides now.
  if (isApproaching(normal_speed)) return 0.0;
  // Neither approaching nor leaving. Held, World keeps it out of impact detection. Not held (it
  // needed no force, or its hold was let go), it collides once the accelerations have closed it
  // by more than rounding: the roots of its coefficients' noise are no impacts.
  if (normal_speed <= kApproachSpeedTolerance) {
    Polynomial closing = gap;
    closing.c[0] = drift;
    return firstDownCrossing(closing, 0.0, horizon);
  }
  // Moving apart, but under acceleration they may come back within the step (a ball bouncing
  // off a floor at low speed). Attempt 3 would miss that return and let the ball sink. They
  // are back where they are now at the root of (gap(t) - gap(0)) / t.
  Polynomial returning;
  for (int i = 0; i < Polynomial::kMaxDegree; ++i) returning.c[i] = gap.c[i + 1];
  return firstDownCrossing(returning, 0.0, horizon);
}

}  // namespace

Polynomial squaredDistanceBeyond(const Motion& relative, double r) {
  // |u + v t + h t^2|^2 - R^2 with h = a / 2, expanded; c[0] is the lecture's overlap test c.
  const Vec2& u = relative.position;
  const Vec2& v = relative.velocity;
  const Vec2 h = 0.5 * relative.acceleration;
  Polynomial beyond;
  beyond.c = {u.squaredNorm() - r * r, 2.0 * u.dot(v), v.squaredNorm() + 2.0 * u.dot(h),
              2.0 * v.dot(h), h.squaredNorm()};
  return beyond;
}

std::optional<double> circleTimeOfImpact(const Motion& relative, double contact_distance,
                                         double horizon) {
  const double distance = relative.position.norm();
  if (distance == 0.0) return std::nullopt;  // concentric: no direction to resolve along
  // (A squared distance closes by 2 R d when the distance closes by d.)
  return firstContact(squaredDistanceBeyond(relative, contact_distance),
                      relative.position.dot(relative.velocity) / distance, horizon,
                      2.0 * contact_distance * kUnheldTouchDrift);
}

std::optional<double> ropeTimeOfTaut(const Motion& relative, double length, double horizon) {
  const double distance = relative.position.norm();
  if (distance == 0.0) return std::nullopt;  // at the other end: slack whichever way it goes
  // The rope's slack, in squares, closes as the gap of a contact does.
  Polynomial slack = squaredDistanceBeyond(relative, length);
  for (double& c : slack.c) c = -c;
  const double normal_speed = -relative.position.dot(relative.velocity) / distance;
  if (slack.c[0] > 0.0 || std::abs(normal_speed) > kApproachSpeedTolerance)
    return firstContact(slack, normal_speed, horizon, 2.0 * length * kUnheldTouchDrift);
  // Taut, the ends neither closing nor parting. World holds a rope that must pull; one that need
  // not yet (a ball at the top of its swing, where gravity slackens it) is not held, but a path
  // curves out of the rope's circle: it is taut again where the slack comes back to what it is
  // now, at the root of (slack(t) - slack(0)) / t^2.
  Polynomial returning;
  returning.c = {slack.c[2], slack.c[3], slack.c[4], 0.0, 0.0};
  return firstDownCrossing(returning, 0.0, horizon);
}

std::optional<double> capTimeOfImpact(const Motion& ball, double radius, const Segment& segment,
                                      int cap, double horizon) {
  const Motion relative = ball.relativeTo({segment.cap(cap), Vec2::Zero(), Vec2::Zero()});
  const double contact_distance = contactDistance(segment, radius);
  if (relative.position.norm() <= contact_distance && projectsOntoSegment(segment, ball.position))
    return std::nullopt;
  // A path whose box, grown by the contact distance, misses the cap's centre never reaches it:
  // most caps of the walls near a ball are far from its path.
  const Box reach = sweptBox(relative, contact_distance, horizon);
  if ((reach.min.array() > 0.0).any() || (reach.max.array() < 0.0).any()) return std::nullopt;
  return circleTimeOfImpact(relative, contact_distance, horizon);
}

std::optional<SegmentImpact> turningTimeOfImpact(const Motion& ball, double radius,
                                                 const Segment& segment, double horizon) {
  const double contact_distance = contactDistance(segment, radius);
  // Bounds over [0, horizon] on the ball's offset from the pivot, its rate, and so on the
  // motion of the ball seen from the segment's turning frame: there the capsule stands still
  // and the gap, a distance to it, has |gap''| <= |q''| + |q'|^2 / distance.
  const double w = std::abs(segment.angular_velocity);
  const double a = ball.acceleration.norm();
  const double speed = (ball.velocity - segment.velocity).norm();
  const double rate = speed + a * horizon;
  const double offset =
      (ball.position - segment.pivot).norm() + horizon * (speed + 0.5 * a * horizon);
  const double frame_speed = rate + w * offset;
  const double curvature = a + 2.0 * w * rate + w * w * offset +
                           frame_speed * frame_speed / contact_distance;
  // Plus the rounding of the coordinates the gap is computed from.
  const double scale = ball.position.norm() + segment.pivot.norm() + offset + segment.length();
  const double touching = kTurningContactGap + 4.0 * std::numeric_limits<double>::epsilon() * scale;
  double t = 0.0;
  for (int step = 0; step < kMaxTurningSteps; ++step) {
    const Segment moved = movedBy(segment, t);
    const Vec2 position = ball.positionAt(t);
    const Vec2 nearest = moved.closestPoint(position);
    const Separation separation = separationAlong(position - nearest);
    const Vec2 relative = ball.velocityAt(t) - surfaceVelocity(moved, nearest);
    const double normal_speed = separation.normal.dot(relative);
    double gap = separation.distance - contact_distance;
    if (gap <= touching) {
      if (isApproaching(normal_speed))
        return SegmentImpact{t, featureUnder(moved, position, relative)};
      gap = touching;  // touching but not approaching: step on as if just apart
    }
    if (curvature == 0.0) return std::nullopt;  // nothing moves relative to the capsule
    // The largest step over which gap + normal_speed h - curvature h^2 / 2 stays >= 0.
    t += (normal_speed + std::sqrt(normal_speed * normal_speed + 2.0 * curvature * gap)) /
         curvature;
    if (t > horizon) return std::nullopt;
  }
  return SegmentImpact{t, SegmentFeature::kFace};  // not touching: World resolves nothing
}

double contactDistance(const Segment& segment, double radius) {
  return radius + 0.5 * segment.thickness;
}

Vec2 faceNormalToward(const Segment& segment, const Vec2& point) {
  const Vec2 n = segment.normal();
  return n.dot(point - segment.start) >= 0.0 ? n : Vec2(-n);
}

bool projectsOntoSegment(const Segment& segment, const Vec2& point) {
  const double along = segment.direction().dot(point - segment.start);
  return along >= 0.0 && along <= segment.length();
}

Separation separationAlong(const Vec2& offset) {
  const double distance = offset.norm();
  return {distance == 0.0 ? Vec2(Vec2::Zero()) : Vec2(offset / distance), distance};
}

Separation separationFrom(const Segment& segment, const Vec2& position, SegmentFeature feature) {
  switch (feature) {
    case SegmentFeature::kStartCap: return separationAlong(position - segment.start);
    case SegmentFeature::kEndCap: return separationAlong(position - segment.end);
    case SegmentFeature::kFace: break;
  }
  const Vec2 n = faceNormalToward(segment, position);
  return {n, n.dot(position - segment.start)};
}

SegmentFeature featureUnder(const Segment& segment, const Vec2& position, const Vec2& velocity) {
  const Vec2 d = segment.direction();
  const double along = d.dot(position - segment.start);
  const double speed = d.dot(velocity);
  if (along < 0.0 || (along == 0.0 && speed < 0.0)) return SegmentFeature::kStartCap;
  const double length = segment.length();
  if (along > length || (along == length && speed > 0.0)) return SegmentFeature::kEndCap;
  return SegmentFeature::kFace;
}

std::optional<double> timeOfFeatureChange(const Motion& ball, const Segment& segment,
                                          double horizon) {
  const Vec2 d = segment.direction();
  const double along = d.dot(ball.position - segment.start), speed = d.dot(ball.velocity),
               acceleration = d.dot(ball.acceleration);
  std::optional<double> first;
  // Crossings of along = `end` in the direction `outward` (+1: increasing) leave the feature;
  // a rounding root the other way near t = 0 is where it already is. At rest on the
  // perpendicular, the acceleration says which way it goes.
  auto leavesAcross = [&](double end, double outward) {
    const Roots roots = quadraticRoots(0.5 * acceleration, speed, along - end);
    for (int k = 0; k < roots.count; ++k) {
      const double t = roots.t[k];
      const double rate = speed + acceleration * t;
      if (t >= 0.0 && t < horizon && outward * (rate != 0.0 ? rate : acceleration) > 0.0 &&
          (!first || t < *first))
        first = t;
    }
  };
  switch (featureUnder(segment, ball.position, ball.velocity)) {
    case SegmentFeature::kStartCap: leavesAcross(0.0, 1.0); break;
    case SegmentFeature::kFace:
      leavesAcross(0.0, -1.0);
      leavesAcross(segment.length(), 1.0);
      break;
    case SegmentFeature::kEndCap: leavesAcross(segment.length(), -1.0); break;
  }
  return first;
}

std::optional<double> faceTimeOfImpact(const Motion& ball, double radius, const Segment& segment,
                                       double horizon) {
  std::optional<double> first;
  const Vec2 normal = segment.normal();
  const bool over_face = projectsOntoSegment(segment, ball.position);
  for (const Vec2& n : {normal, Vec2(-normal)}) {
    // The lecture's a: the distance the edge has to go. Over the face, a centre within reach of
    // the line but still on its side (-r <= a < 0) is rounding after a reset to the point of
    // impact.
    Polynomial gap;
    gap.c = {n.dot(ball.position - segment.start) - contactDistance(segment, radius),
             n.dot(ball.velocity), 0.5 * n.dot(ball.acceleration), 0.0, 0.0};
    const bool near_side = n.dot(ball.position - segment.start) >= 0.0;
    std::optional<double> t;
    if (gap.c[0] >= 0.0 || (near_side && over_face)) {
      t = firstContact(gap, gap.c[1], horizon, kUnheldTouchDrift);
    } else if (!over_face) {
      // Past an end the line is no surface, and being within reach of it no overlap: the face
      // is hit only once the centre has left its reach and comes back (the far face, or the
      // near one beyond a cap), on a parabola opening toward the face.
      const Roots roots = quadraticRoots(gap.c[2], gap.c[1], gap.c[0]);
      if (gap.c[2] < 0.0 && roots.count == 2 && roots.t[0] > 0.0 && roots.t[0] < horizon)
        t = firstDownCrossing(gap, 0.5 * (roots.t[0] + roots.t[1]), horizon);
    }
    if (t && projectsOntoSegment(segment, ball.positionAt(*t)) && (!first || *t < *first)) first = t;
  }
  return first;
}

}  // namespace ball_physics_sim::engine
