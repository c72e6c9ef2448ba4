// World: the event queue. Each ball's earliest impact is predicted, exactly, and the earliest
// of all is resolved first (the lecture's earliest-collision-first rule); after an event only
// what it changed is predicted anew.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/friction.h"
#include "ball_physics_sim/engine/impulse.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

namespace {

// An impact is sought this share of the horizon past the earliest one found so far: thousands
// of ulps of a step's times, far more than the 8 a closed-form root is walked back (a root of
// coefficients of rounding size, narrowed further, may still lose a tie by ulps).
constexpr double kTieSlack = 1e-12;

// The kind of contact a ball makes with the feature of a segment it meets, and which cap.
std::pair<ContactKind, int> segmentContactOf(SegmentFeature feature) {
  if (feature == SegmentFeature::kFace) return {ContactKind::kSegment, 0};
  return {ContactKind::kCap, feature == SegmentFeature::kEndCap ? 1 : 0};
}

// Spin under a constant angular acceleration, like Motion for the centre; the angle is kept
// within (-pi, pi] so that it never loses precision.
void turn(Ball& ball, double angular_acceleration, double dt) {
  ball.angle += dt * (ball.angular_velocity + 0.5 * dt * angular_acceleration);
  if (std::abs(ball.angle) > kPi) ball.angle = normalizedAngle(ball.angle);
  ball.angular_velocity += dt * angular_acceleration;
}

}  // namespace

Box World::keyBox(std::size_t key, double remaining) const {
  if (const auto ball = ballOf(key)) {
    // (A resting ball's is its own square, as sweptBox would make it, with less arithmetic: a
    // world asleep asks for every ball's at each step's start.)
    const Ball& b = ballNow(*ball);
    if (b.at_rest) return ballBox(b.position, b.radius);
    return sweptBox(motionOf(*ball), b.radius, remaining);
  }
  return segmentBox(segments_[*segmentOf(key)], remaining);
}

void World::predictAll(double horizon) {
  const std::size_t n = balls_.size();
  courses_.clear();  // (every ball is as of now, 0 into the step: see step()'s end)
  for (std::size_t i = 0; i < n; ++i) courses_.push_back(courseOf(i));
  balls_meet_ = false;
  for (std::size_t i = 1; i < n && !balls_meet_; ++i)
    balls_meet_ = collide(balls_[0], balls_[i]);
  movable_segments_.clear();
  // (One jammed stands still for the step, but as one that may move: what it holds stays awake.)
  for (std::size_t k = 0; k < segments_.size(); ++k)
    if (mayMove(segments_[k]) || stoppedInStep(k)) movable_segments_.push_back(k);
  updateRooms();
  // Where no two balls meet, the balls' boxes (long, for fast balls) would only be moved about,
  // unless a segment may move in the step: its box finds the balls near it in the grid. (Out
  // of it, each ball's box is found as it is predicted.)
  balls_in_grid_ = balls_meet_ || !movable_segments_.empty();
  std::vector<Box> boxes;
  boxes.reserve(n + segments_.size());
  for (std::size_t key = balls_in_grid_ ? 0 : n; key < n + segments_.size(); ++key)
    boxes.push_back(keyBox(key, horizon));
  grid_.update(balls_in_grid_ ? boxes : std::vector<Box>());
  segment_grid_.update(std::vector<Box>(boxes.end() - segments_.size(), boxes.end()));
  next_impacts_.assign(n, std::nullopt);
  unpredicted_.reset(n);
  for (std::size_t i = 0; i < n; ++i)
    if (settling_[i].goes_on && !balls_[i].at_rest) unpredicted_.insert(i);
  const auto predicted = [&](std::size_t key) { return key >= n || !unpredicted_.contains(key); };
  for (std::vector<std::size_t>& awaiting : awaiting_) awaiting.clear();  // (storage kept)
  awaiting_.resize(n + segments_.size());
  if (balls_meet_) {
    // The pairs near what may move (pairsNearMoving), each pair's impact kept by its lower key.
    std::vector<std::optional<Impact>> earliest(n);
    // (Two balls at rest, or a ball at rest by a segment that stays put, cannot strike each
    // other: a sleeping pile's pairs are not sought, or considerImpact passes them over.)
    for (const auto& [ball, key] : pairsNearMoving())
      if (ball < n && predicted(ball) && predicted(key) && meets(ball, key))
        considerImpact(ball, key, horizon, earliest[ball]);
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
      const auto& [end, other] = rope_ends_[r];
      const std::size_t key = n + segments_.size() + r;
      if (predicted(end)) considerImpact(end, key, horizon, earliest[end]);
      if (other && predicted(*other)) considerImpact(*other, key, horizon, earliest[*other]);
    }
    for (std::size_t i = 0; i < n; ++i) expectImpact(i, earliest[i], 0.0);
  } else {
    for (std::size_t i = 0; i < n; ++i)
      if (predicted(i)) predictBall(i, 0.0, horizon);
  }
  impact_queue_.reset(n, [this](std::size_t a, std::size_t b) { return impactComesFirst(a, b); });
  segment_courses_.clear();
  for (const Segment& segment : segments_) segment_courses_.push_back(courseOf(segment));
  held_changes_.clear();
  // All predicted as they are now. (Not by the list: removing a ball moves the indices after it.)
  is_looked_at_.assign(n, false);
  looked_at_.clear();
}

// A segment that stays put through a step is where it was, so the rooms are found anew only
// where the segments, or which of them may move, are not those they were found among.
void World::updateRooms() {
  const bool same_segments =
      rooms_segments_.size() == segments_.size() &&
      std::equal(segments_.begin(), segments_.end(), rooms_segments_.begin(),
                 [](const Segment& segment, SegmentId id) { return segment.id == id; });
  if (same_segments && rooms_movable_ == movable_segments_) return;
  rooms_segments_.clear();
  for (const Segment& segment : segments_) rooms_segments_.push_back(segment.id);
  rooms_movable_ = movable_segments_;
  rooms_ = findRooms(segments_, movable_segments_);
  room_of_.assign(segments_.size(), std::nullopt);
  for (std::size_t r = 0; r < rooms_.size(); ++r)
    for (const std::size_t k : rooms_[r].walls) room_of_[k] = r;
}

// A prediction stays true while the bodies it involves keep their courses: a ball that left its
// course in an event (only one looked at can have) is predicted anew, and so is a ball whose
// predicted impact was with it. A contact held or let go changes whether the pair is sought; a
// segment that moved or changed its motion, the balls its box meets.
void World::predictChanged(double elapsed, double remaining) {
  const std::size_t n = balls_.size();
  BallSet& changed = changed_;
  changed.reset(n);
  if (!unpredicted_.list.empty()) {
    for (const std::size_t i : unpredicted_.list) changed.insert(i);
    unpredicted_.reset(n);
  }
  std::vector<std::size_t> changed_segments;  // their keys
  // (Checking them only reads them: none is marked anew.)
  for (const std::size_t i : looked_at_) {
    if (onCourse(i)) continue;
    changed.insert(i);
    courses_[i] = courseOf(i);
  }
  for (const std::size_t i : looked_at_) is_looked_at_[i] = false;
  looked_at_.clear();  // its storage kept for the next event's
  // A contact held or let go since, and not back as it was (its first change says how it was).
  std::stable_sort(held_changes_.begin(), held_changes_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto change = held_changes_.begin(); change != held_changes_.end();) {
    const auto [contact, was_held] = *change;
    while (change != held_changes_.end() && change->first == contact) ++change;
    if (was_held == held_.contains(contact)) continue;
    const auto [i, key] = contact;
    changed.insert(i);
    if (const auto other = otherBallOf(i, key)) changed.insert(*other);
  }
  held_changes_.clear();
  for (const std::size_t k : movable_segments_) {
    const SegmentCourse course = courseOf(segments_[k]);
    if (course == segment_courses_[k]) continue;
    changed_segments.push_back(n + k);
    segment_courses_[k] = course;
    const Box box = keyBox(n + k, remaining);
    segment_grid_.move(k, box);
    grid_.move(n + k, box);
    for (const std::size_t key : grid_.overlapping(box))
      if (key < n) changed.insert(key);
  }
  // All the awaiting are taken before any prediction, which awaits anew. The balls awaiting a
  // changed body are predicted too; what awaits them stays.
  auto takeAwaiting = [&](std::size_t key) {
    for (const std::size_t i : awaiting_[key])
      if (!changed.contains(i) && next_impacts_[i] && impactInvolves(*next_impacts_[i], key))
        changed.insert(i);
    awaiting_[key].clear();
  };
  const std::size_t changed_balls = changed.list.size();  // those taken add to the list
  for (std::size_t k = 0; k < changed_balls; ++k) takeAwaiting(changed.list[k]);
  for (const std::size_t key : changed_segments) takeAwaiting(key);
  for (const std::size_t ball : changed.list) {
    predictBall(ball, elapsed, remaining);
    queueImpact(ball);
  }
}

void World::predictBall(std::size_t i, double elapsed, double remaining) {
  const Box box = keyBox(i, remaining);
  if (balls_in_grid_) grid_.move(i, box);
  std::optional<Impact> earliest;
  for (const std::size_t key : keysMet(i, box)) {
    if (key < i)  // a pair of balls is taken from its lower index, as comesBefore orders them
      considerImpact(key, i, remaining, earliest);
    else
      considerImpact(i, key, remaining, earliest);
  }
  for (std::size_t r = 0; r < ropes_.size(); ++r)
    if (rope_ends_[r].first == i || rope_ends_[r].second == i)
      considerImpact(i, balls_.size() + segments_.size() + r, remaining, earliest);
  expectImpact(i, earliest, elapsed);
}

void World::expectImpact(std::size_t i, std::optional<Impact> earliest, double elapsed) {
  if (earliest) {
    earliest->time += elapsed;
    // Its other body: the ball that keys the pair, or what that ball meets.
    const std::size_t key = earliest->ball != i ? earliest->ball : keyOf(*earliest);
    if (const auto rope = ropeOf(key)) {
      if (const auto other = otherBallOf(i, key)) awaiting_[*other].push_back(i);
    } else {
      awaiting_[key].push_back(i);
    }
  }
  next_impacts_[i] = earliest;
}

void World::queueImpact(std::size_t ball) {
  impact_queue_.update(ball,
                       [this](std::size_t a, std::size_t b) { return impactComesFirst(a, b); });
}

bool World::impactInvolves(const Impact& impact, std::size_t key) const {
  if (impact.ball == key || (impact.kind != ContactKind::kRope && keyOf(impact) == key))
    return true;
  const std::optional<std::size_t> other = otherBallOf(impact.ball, keyOf(impact));
  return other && *other == key;
}

bool World::impactComesFirst(std::size_t a, std::size_t b) const {
  return next_impacts_[a] &&
         (!next_impacts_[b] || comesBefore(*next_impacts_[a], *next_impacts_[b]));
}

std::optional<World::Impact> World::earliestImpact(double elapsed, double horizon) const {
  const std::optional<std::size_t> first = impact_queue_.first();
  if (!first || !next_impacts_[*first]) return std::nullopt;
  const Impact& earliest = *next_impacts_[*first];
  if (earliest.time - elapsed > horizon) return std::nullopt;
  Impact now = earliest;
  now.time = std::max(0.0, earliest.time - elapsed);
  return now;
}

bool World::SegmentCourse::operator==(const SegmentCourse& other) const {
  return start == other.start && end == other.end && velocity == other.velocity &&
         angular_velocity == other.angular_velocity;
}

World::Course World::courseOf(std::size_t ball) const {
  const Ball& b = ballNow(ball);
  return {now_,           b.position,       b.velocity,
          accelerations_[ball], b.angle,          b.angular_velocity,
          angular_accelerations_[ball], b.at_rest, isSettled(ball)};
}

World::SegmentCourse World::courseOf(const Segment& segment) {
  return {segment.start, segment.end, segment.velocity, segment.angular_velocity};
}

void World::moveAlong(const Course& course, double time, Ball& ball) {
  const double dt = time - course.time;
  ball.position = course.position;
  ball.velocity = course.velocity;
  ball.angle = course.angle;
  ball.angular_velocity = course.angular_velocity;
  if (course.at_rest) {
    turn(ball, 0.0, dt);  // a frictionless ball rests with the spin it had
    return;
  }
  const Motion motion{course.position, course.velocity, course.acceleration};
  ball.position = motion.positionAt(dt);
  ball.velocity = motion.velocityAt(dt);
  turn(ball, course.angular_acceleration, dt);
}

bool World::onCourse(std::size_t i) const {
  const Ball& ball = ballNow(i);
  const Course& course = courses_[i];
  Ball expected = ball;
  moveAlong(course, now_, expected);
  return ball.position == expected.position && ball.velocity == expected.velocity &&
         ball.angle == expected.angle && ball.angular_velocity == expected.angular_velocity &&
         ball.at_rest == course.at_rest && isSettled(i) == course.settled &&
         accelerations_[i] == course.acceleration &&
         angular_accelerations_[i] == course.angular_acceleration;
}

void World::considerImpact(std::size_t i, std::size_t key, double horizon,
                           std::optional<Impact>& earliest) const {
  auto keep = [&](std::optional<double> t, ContactKind kind, std::size_t other, int cap) {
    if (!t) return;
    const Impact impact{*t, i, kind, other, cap};
    if (!earliest || comesBefore(impact, *earliest)) earliest = impact;
  };
  // An impact after the earliest one found so far would not be kept: it is sought no further,
  // which spares most searches' root refinement. A hair further (kTieSlack), so that one at
  // the same time, whose raw root may lie a few ulps past it, is still found and ordered by
  // comesBefore. (A turning segment's steps are sized by bounds over its horizon: a shorter
  // one would change the time it finds.)
  auto until = [&] {
    return earliest ? std::min(horizon, earliest->time + kTieSlack * horizon) : horizon;
  };
  // A settle moves its balls clear of each other and of the segments, and bodies still together
  // cannot meet.
  if ((isSettled(i) && (!ballOf(key) || isSettled(key))) || stillTogether(i, key)) return;
  const Ball& ball = ballNow(i);
  const Motion motion = motionOf(i);
  if (const auto rope = ropeOf(key)) {
    const std::optional<std::size_t> other = otherBallOf(i, key);
    if ((ball.at_rest && (!other || balls_[*other].at_rest)) || held(i, key)) return;
    keep(ropeTimeOfTaut(motion.relativeTo(farEndOf(i, key)), ropes_[*rope].length, until()),
         ContactKind::kRope, *rope, 0);
    return;
  }
  if (const auto j = ballOf(key)) {
    if (held(i, key)) return;
    keep(circleTimeOfImpact(motion.relativeTo(motionOf(*j)), ball.radius + balls_[*j].radius,
                            until()),
         ContactKind::kBall, *j, 0);
    return;
  }
  const std::size_t k = *segmentOf(key);
  const Segment& segment = segments_[k];
  if (held(i, key)) return;
  if (turns(segment)) {
    if (const auto hit = turningTimeOfImpact(motion, ball.radius, segment, horizon)) {
      const auto [kind, cap] = segmentContactOf(hit->feature);
      keep(hit->time, kind, k, cap);
    }
    return;
  }
  const Motion relative = seenFrom(segment, motion);
  keep(faceTimeOfImpact(relative, ball.radius, segment, until()), ContactKind::kSegment, k, 0);
  // Its caps are corners of the room the ball is in, if it is in one: reached only through a
  // face (see Room).
  if (const std::optional<std::size_t> room = room_of_[k];
      room && shieldsCorners(rooms_[*room], relative.position,
                             contactDistance(segment, ball.radius)))
    return;
  for (int cap = 0; cap < 2; ++cap)
    keep(capTimeOfImpact(relative, ball.radius, segment, cap, until()), ContactKind::kCap, k, cap);
}

bool World::comesBefore(const Impact& a, const Impact& b) const {
  if (a.time != b.time) return a.time < b.time;  // (most often, and cheaper than the keys)
  auto order = [this](const Impact& impact) {
    return std::make_tuple(impact.time, impact.ball, keyOf(impact),
                           impact.kind == ContactKind::kCap ? 1 + impact.cap : 0);
  };
  return order(a) < order(b);
}

void World::advance(double elapsed, double dt) {
  watchSensors(time_ + elapsed, dt);
  for (const std::size_t k : movable_segments_)
    if (moves(segments_[k])) moveSegment(segments_[k], dt);
  now_ = elapsed + dt;  // the balls follow when looked at
}

void World::resolve(const Impact& impact, double time) {
  // A waiting ball struck moves on as it was, and is struck so.
  if (waiting_velocities_[impact.ball]) wake(impact.ball);
  const std::optional<std::size_t> other = otherBallOf(impact.ball, keyOf(impact));
  if (other && waiting_velocities_[*other]) wake(*other);
  if (impact.kind == ContactKind::kBall)
    resolveBallImpact(impact, time);
  else if (impact.kind == ContactKind::kRope)
    resolveRopeImpact(impact);
  else
    resolveSegmentImpact(impact, time);
}

bool World::passThroughTouching(const Impact& impact, double time, std::size_t& passed,
                                std::size_t budget, BallSet& changed) {
  changed.reset(balls_.size());
  const std::size_t passed_before = passed;
  // Whether the balls struck leave freely every body near them that the hold's search would
  // find (a segment, or a ball within kBoxMargin, which must be one of them: the search would
  // take in its neighbours too), so that the hold would find nothing to hold: see
  // holdRestingBalls. The touches read here are the search's.
  bool leave_freely = ropes_.empty() && movable_segments_.empty();
  // Balls whose touching neighbours are to be looked at, first in first out from `head`.
  std::vector<bool>& queued = struck_queued_;
  queued.resize(balls_.size(), false);
  std::vector<std::size_t>& pending = struck_pending_;
  pending.clear();
  std::size_t head = 0;
  auto struck = [&](std::size_t ball) {
    changed.insert(ball);
    if (!queued[ball]) pending.push_back(ball);
    queued[ball] = true;
  };
  struck(impact.ball);
  if (const auto other = otherBallOf(impact.ball, keyOf(impact))) struck(*other);
  auto hit = [&](const Impact& next) {
    resolve(next, time);
    ++passed;
    struck(next.ball);
    if (next.kind == ContactKind::kBall) struck(next.other);
  };
  while (head < pending.size() && passed < budget) {
    const std::size_t i = pending[head++];
    queued[i] = false;
    // (Resolving a hit queries no keys.)
    leave_freely = leave_freely && !balls_[i].at_rest;
    for (const std::size_t key : keysNear(i)) {
      if (passed >= budget) continue;
      const std::optional<std::size_t> other = ballOf(key);
      if (other && isSettled(*other)) continue;  // (its settle holds it)
      const Touch t = touch(i, key);
      leave_freely = leave_freely && ((other && t.gap > kBoxMargin) ||
                                      ((!other || changed.contains(*other)) &&
                                       separatesFreely(i, key, t)));
      if (t.gap > kContactSlop || -t.relative_velocity.dot(t.separation.normal) < kRestingSpeed)
        continue;
      if (other) {
        hit({0.0, std::min(i, *other), ContactKind::kBall, std::max(i, *other), 0});
        continue;
      }
      const std::size_t k = *segmentOf(key);
      const auto [kind, cap] =
          segmentContactOf(featureUnder(segments_[k], ballNow(i).position, t.relative_velocity));
      hit({0.0, i, kind, k, cap});
    }
  }
  for (; head < pending.size(); ++head) queued[pending[head]] = false;  // as the next pass needs
  // (A hit passed on changes velocities the touches read before it; with the budget spent
  // before this impact, none were read.)
  return !(leave_freely && passed == passed_before && passed_before < budget);
}

void World::resolveBallImpact(const Impact& impact, double time) {
  Ball& a = ballNow(impact.ball);
  Ball& b = ballNow(impact.other);
  const Vec2 n = (a.position - b.position).normalized();
  const double approach_speed = -(a.velocity - b.velocity).dot(n);
  if (approach_speed < kRestingSpeed) return;  // holdRestingBalls stops it, with its neighbours
  if (a.at_rest) wake(impact.ball);
  if (b.at_rest) wake(impact.other);
  const double j = normalImpulse(approach_speed, combinedRestitution(a.restitution, b.restitution),
                                 1.0 / a.mass + 1.0 / b.mass);
  a.velocity += j / a.mass * n;
  b.velocity -= j / b.mass * n;
  const double slip = slipSpeed(a.velocity - b.velocity, n, a.radius, a.angular_velocity,
                                b.radius * b.angular_velocity);
  const double jt = tangentialImpulse(slip, j, combinedFriction(a.friction, b.friction),
                                      tangentialInverseMass(a) + tangentialInverseMass(b));
  pushSurfaces(a, b, n, jt);
  contacts_.push_back({time, a.id, ContactKind::kBall, b.id, a.position - a.radius * n, n,
                       approach_speed, j});
}

void World::resolveSegmentImpact(const Impact& impact, double time) {
  Ball& ball = ballNow(impact.ball);
  const Segment& segment = segments_[impact.other];
  // A turning segment's search may end short of it, after its most steps.
  if (turns(segment) && surfaceGap(ball, segment) > kContactSlop) return;
  const Vec2 n = impact.kind == ContactKind::kCap
                     ? Vec2((ball.position - segment.cap(impact.cap)).normalized())
                     : faceNormalToward(segment, ball.position);
  const Vec2 surface = velocityUnder(segment, ball.position);
  const double approach_speed = -(ball.velocity - surface).dot(n);
  // Met by a moving segment: awake, its contact with the segment is one holdRestingBalls
  // takes up, however slow.
  if (ball.at_rest) wake(impact.ball);
  if (approach_speed < kRestingSpeed) return;  // holdRestingBalls stops it
  const double j = normalImpulse(approach_speed,
                                 combinedRestitution(ball.restitution, segment.restitution),
                                 1.0 / ball.mass) +
                   std::clamp(kMaxSpeed - ball.velocity.norm(), 0.0, segment.kick) * ball.mass;
  ball.velocity += j / ball.mass * n;
  const double slip =
      slipSpeed(ball.velocity - surface, n, ball.radius, ball.angular_velocity, 0.0);
  pushSurface(ball, n, tangentialImpulse(slip, j, combinedFriction(ball.friction, segment.friction),
                                         tangentialInverseMass(ball)));
  contacts_.push_back({time, ball.id, impact.kind, segment.id, ball.position - ball.radius * n, n,
                       approach_speed, j});
  if (segment.hits_to_break > 0) hitBrick(impact.other, impact.ball, time);
}

void World::resolveRopeImpact(const Impact& impact) {
  const std::size_t key = keyOf(impact);
  const Touch t = touch(impact.ball, key);
  const Vec2& n = t.separation.normal;  // along the rope, toward its other end
  const double approach_speed = -t.relative_velocity.dot(n);
  if (approach_speed < kRestingSpeed) return;  // holdRestingBalls holds it taut
  const std::optional<std::size_t> other = otherBallOf(impact.ball, key);
  if (balls_[impact.ball].at_rest) wake(impact.ball);
  if (other && balls_[*other].at_rest) wake(*other);
  Ball& a = ballNow(impact.ball);
  const double j = normalImpulse(approach_speed, ropes_[impact.other].restitution,
                                 1.0 / a.mass + (other ? 1.0 / balls_[*other].mass : 0.0));
  a.velocity += j / a.mass * n;
  if (other) ballNow(*other).velocity -= j / balls_[*other].mass * n;
}

}  // namespace ball_physics_sim::engine
