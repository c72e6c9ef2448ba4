#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <iterator>
#include <tuple>
#include <unordered_map>

#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/friction.h"
#include "ball_physics_sim/engine/impulse.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/settle.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

namespace {

// Bounds the work of one step. A step normally resolves about one impact per ball or fewer
// (1000 bullets, 0.7). In a pile, balls bounce on each other ever faster, in impacts that
// converge only geometrically, each holding its island anew: past kSequentialImpacts the
// touching balls that still approach stop together in one inelastic push instead (inelastic
// collapse). Past kMaxImpacts (or as many renewals of held contacts, times
// kRenewalsPerImpact) the balls that may meet something settle together for the rest of the
// step, and in the steps after until they rest (see World::settleRestOfStep); where they
// cannot, the rest of the step is given up rather than hang. The hits an impact passes on
// through touching balls at its instant, cheap, are not counted among them, but as many bound
// them. Where no settle can be (World::canSettle), the balls of the struggle wait instead, and
// events go on longer: kSequentialImpacts and kMaxImpacts are then the larger ones.
constexpr std::size_t kSequentialImpactsPerBall = 2;
constexpr std::size_t kMaxImpactsPerBall = 3;
constexpr std::size_t kSequentialImpactsPerBallUnsettled = 16;
constexpr std::size_t kMaxImpactsPerBallUnsettled = 64;
constexpr std::size_t kMinImpactsPerStep = 256;
// Held contacts may be held anew this many times as often as impacts happen: a ball sliding
// round a small cap needs a few hundred renewals in a long step.
constexpr std::size_t kRenewalsPerImpact = 4;
// A settle's pairs are sought again, farther, at most this many times, when it takes a ball
// farther from its untouched path than they were sought within: then this many times as far.
constexpr int kSettleAttempts = 4;
constexpr double kSettleReachGrowth = 1.5;
// A settled ball this slow before and after its settle, touching what holds it up, is still,
// and rests: it moves 2e-6 m in a 1/60 s step. (The settle's sweeps leave slow rolling of this
// order, and a ball rolling so on a floor would roll on for hours.)
constexpr double kSettledRestSpeed = 1e-4;  // m/s
// An impact is sought this share of the horizon past the earliest one found so far: thousands
// of ulps of a step's times, far more than the 8 a closed-form root is walked back (a root of
// coefficients of rounding size, narrowed further, may still lose a tie by ulps).
constexpr double kTieSlack = 1e-12;

// The smallest box holding both.
Box enclosing(const Box& a, const Box& b) { return {a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)}; }

// Accelerations below this are what is left of gravity where normal forces cancel it, once
// the contact solve has converged: the ball is held.
constexpr double kRestingAcceleration = 1e-9;  // m/s^2

// A touching contact separating slower than this is held like a resting one: the inelastic
// push leaves rounding of this order (a few 1e-9 m/s where a light ball is wedged under a heavy
// one on a floor), and left free the ball would fall back at once, again and again, in a
// sequence of zero-time impacts that uses up the step. A ball held still and slower than this
// (its surface turning slower too) is put to rest: held, such a contact keeps its speed.
constexpr double kHeldSeparationSpeed = 1e-6;  // m/s

// A stretch under a changing pull is shortened until the pull's rate at its middle allows it:
// each round at most halves it, so a few rounds meet the rate where it grows from nothing.
constexpr int kStretchRefinements = 8;

bool overlaps(const Ball& ball, const Segment& segment) {
  return surfaceGap(ball, segment) < -kContactSlop;
}

bool overlaps(const Ball& a, const Ball& b) { return surfaceGap(a, b) < -kContactSlop; }

// Whether the ball's contacts can have friction or rolling resistance: a pair's is the geometric
// mean, zero if either body has none.
bool isRough(const Ball& ball) { return ball.friction > 0.0 || ball.rolling_resistance > 0.0; }

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

World::World(const Vec2& gravity) : gravity_(gravity) {
  if (!gravity.allFinite() || gravity.norm() > kMaxGravity)
    throw std::invalid_argument("gravity must be finite and at most " +
                                std::to_string(kMaxGravity) + " m/s^2");
}

BallId World::addBall(Ball ball) {
  checkBall(ball);
  for (const Segment& segment : segments_)
    if (overlaps(ball, segment))
      throw std::invalid_argument("ball would overlap segment " + std::to_string(segment.id));
  for (const Ball& other : balls_)
    if (collide(ball, other) && overlaps(ball, other))
      throw std::invalid_argument("ball would overlap ball " + std::to_string(other.id));
  ball.id = next_ball_id_++;
  ball.at_rest = false;
  balls_.push_back(ball);
  clocks_.push_back(now_);
  is_looked_at_.push_back(false);
  held_.clear();  // keyed by index: a segment's key moves with the number of balls
  settle_impulses_.clear();  // likewise
  drives_.push_back(Vec2::Zero());
  accelerations_.push_back(Vec2::Zero());
  accelerations_.back() = freeAcceleration(balls_.size() - 1);
  angular_accelerations_.push_back(0.0);
  return ball.id;
}

void World::addWind(const Wind& wind) {
  checkWind(wind);
  winds_.push_back(wind);
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (centreInside(wind.region, motionOf(i))) wake(i);
}

void World::addAttractor(const Attractor& attractor) {
  checkAttractor(attractor);
  attractors_.push_back(attractor);
  for (std::size_t i = 0; i < balls_.size(); ++i) wake(i);
}

void World::addWater(const Water& water) {
  checkWater(water);
  // Its surface is level, the top of its region; the water weighs down.
  if (gravity_.x() != 0.0 || gravity_.y() > 0.0)
    throw std::invalid_argument("water needs gravity along -y (its surface is its region's top)");
  waters_.push_back(water);
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (centreInside(wettedRegion(water, balls_[i].radius), motionOf(i))) wake(i);
}

void World::addSensor(const Sensor& sensor) {
  if (sensor.name.empty()) throw std::invalid_argument("a sensor needs a name");
  checkRegion(sensor.region, "sensor '" + sensor.name + "'");
  for (const Sensor& other : sensors_)
    if (other.name == sensor.name)
      throw std::invalid_argument("there is a sensor named '" + sensor.name + "' already");
  sensors_.push_back(sensor);
}

bool World::drive(BallId id, const Vec2& acceleration) {
  if (!acceleration.allFinite() || acceleration.norm() > kMaxGravity)
    throw std::invalid_argument("drive's acceleration must be finite and at most " +
                                std::to_string(kMaxGravity) + " m/s^2, got (" +
                                std::to_string(acceleration.x()) + ", " +
                                std::to_string(acceleration.y()) + ")");
  const std::optional<std::size_t> i = indexOf(id);
  if (!i) return false;
  if (drives_[*i] == acceleration) return true;
  const Vec2 change = acceleration - drives_[*i];
  drives_[*i] = acceleration;
  if (balls_[*i].at_rest)
    wake(*i);  // which gives it its free acceleration
  else
    accelerations_[*i] += change;  // its contacts are held anew at the next step
  return true;
}

std::vector<BallId> World::explode(const Blast& blast, double max_speed) {
  checkBlast(blast);
  max_speed = std::min(max_speed, kMaxSpeed);
  std::vector<std::pair<std::size_t, Vec2>> pushed;  // ball, its velocity after the blast
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    const Vec2 impulse = blastImpulse(blast, balls_[i].position);
    if (impulse == Vec2::Zero()) continue;
    const Vec2 velocity = motionOf(i).velocity + impulse / balls_[i].mass;
    if (!(velocity.norm() <= max_speed))
      throw std::invalid_argument("the blast would throw ball " + std::to_string(balls_[i].id) +
                                  " faster than " + std::to_string(max_speed) + " m/s");
    pushed.emplace_back(i, velocity);
  }
  std::vector<BallId> ids;
  for (const auto& [i, velocity] : pushed) {
    wake(i);
    balls_[i].velocity = velocity;
    ids.push_back(balls_[i].id);
  }
  return ids;
}

SegmentId World::addSegment(Segment segment) {
  checkSegment(segment);
  for (const Ball& ball : balls_)
    if (overlaps(ball, segment))
      throw std::invalid_argument("segment would overlap ball " + std::to_string(ball.id));
  segment.id = next_segment_id_++;
  headForNextWaypoint(segment);
  segments_.push_back(segment);
  held_.clear();  // keyed by index: a rope's key moves with the number of segments
  settle_impulses_.clear();  // (a settle's are the segments' own)
  return segment.id;
}

RopeId World::addRope(Rope rope) {
  checkRope(rope);
  auto ballNamed = [this](BallId id, const char* end) {
    const std::optional<std::size_t> i = indexOf(id);
    if (!i)
      throw std::invalid_argument(std::string("rope's ") + end + " " + std::to_string(id) +
                                  " does not exist");
    return *i;
  };
  const std::size_t ball = ballNamed(rope.ball, "ball");
  std::optional<std::size_t> other;
  if (rope.other_ball) other = ballNamed(*rope.other_ball, "other ball");
  const Vec2 far = other ? balls_[*other].position : rope.anchor;
  const double distance = (balls_[ball].position - far).norm();
  if (distance > rope.length + kContactSlop)
    throw std::invalid_argument("rope's length " + std::to_string(rope.length) +
                                " m is shorter than the " + std::to_string(distance) +
                                " m between its ends");
  rope.id = next_rope_id_++;
  ropes_.push_back(rope);
  rope_ends_.emplace_back(ball, other);
  // A resting end may hang from it now; the step's start holds everything anew.
  wake(ball);
  if (other) wake(*other);
  return rope.id;
}

bool World::removeRope(RopeId id) {
  for (std::size_t r = 0; r < ropes_.size(); ++r) {
    if (ropes_[r].id != id) continue;
    const auto& [ball, other] = rope_ends_[r];
    wake(ball);
    if (other) wake(*other);
    ropes_.erase(ropes_.begin() + r);
    rope_ends_.erase(rope_ends_.begin() + r);
    held_.clear();  // keyed by index; the next step holds what touches anew
    return true;
  }
  return false;
}

void World::indexRopeEnds() {
  rope_ends_.clear();
  for (const Rope& rope : ropes_)
    rope_ends_.emplace_back(*indexOf(rope.ball),
                            rope.other_ball ? indexOf(*rope.other_ball) : std::nullopt);
}

bool World::setSegmentMotion(SegmentId id, const Vec2& velocity, double angular_velocity) {
  for (Segment& segment : segments_) {
    if (segment.id != id) continue;
    Segment moving = segment;
    moving.velocity = velocity;
    moving.angular_velocity = angular_velocity;
    moving.waypoints.clear();
    checkSegment(moving);
    wakeTouching(segment);
    segment = moving;
    return true;
  }
  return false;
}

bool World::removeBall(BallId id) {
  const std::optional<std::size_t> i = indexOf(id);
  if (!i) return false;
  balls_[*i].at_rest = true;  // so that wake() takes it and the resting balls it holds up
  wake(*i);
  const auto tied = [id](const Rope& rope) { return rope.ball == id || rope.other_ball == id; };
  ropes_.erase(std::remove_if(ropes_.begin(), ropes_.end(), tied), ropes_.end());
  balls_.erase(balls_.begin() + *i);
  clocks_.erase(clocks_.begin() + *i);
  // Looked-at marks go by index, which the removal moves; a step looks at every ball anew.
  looked_at_.clear();
  is_looked_at_.assign(balls_.size(), false);
  indexRopeEnds();
  held_.clear();  // keyed by index; the next step holds what touches anew
  settle_impulses_.clear();  // likewise
  accelerations_.erase(accelerations_.begin() + *i);
  drives_.erase(drives_.begin() + *i);
  for (std::size_t s = 0; s < sensors_.size(); ++s) in_sensors_.erase({id, s});
  angular_accelerations_.erase(angular_accelerations_.begin() + *i);
  return true;
}

bool World::removeSegment(SegmentId id) {
  for (auto segment = segments_.begin(); segment != segments_.end(); ++segment) {
    if (segment->id != id) continue;
    wakeTouching(*segment);
    segments_.erase(segment);
    held_.clear();  // keyed by index; the next step holds what touches anew
    settle_impulses_.clear();  // likewise
    return true;
  }
  return false;
}

std::vector<Contact> World::takeContacts() {
  std::vector<Contact> taken;
  taken.swap(contacts_);
  // As many again, most likely, by the next take: room for them at once, not by doublings.
  contacts_.reserve(taken.size());
  return taken;
}

std::vector<SensorEvent> World::takeSensorEvents() {
  std::vector<SensorEvent> taken;
  taken.swap(sensor_events_);
  return taken;
}

std::vector<BrickHit> World::takeBrickHits() {
  std::vector<BrickHit> taken;
  taken.swap(brick_hits_);
  return taken;
}

void World::step(double dt) {
  if (!(std::isfinite(dt) && dt > 0.0))
    throw std::invalid_argument("time step must be finite and > 0");
  const bool settles = canSettle();
  const std::size_t sequential_per_ball =
      settles ? kSequentialImpactsPerBall : kSequentialImpactsPerBallUnsettled;
  const std::size_t sequential = kMinImpactsPerStep + sequential_per_ball * balls_.size();
  const std::size_t most =
      kMinImpactsPerStep +
      (settles ? kMaxImpactsPerBall : kMaxImpactsPerBallUnsettled) * balls_.size();
  double elapsed = 0.0;
  std::size_t impacts = 0, passed = 0, renewals = 0;
  predictAll(dt);
  hold_ends_.assign(balls_.size(), std::numeric_limits<double>::infinity());
  hold_end_queue_.reset(balls_.size(),
                        [this](std::size_t a, std::size_t b) { return holdEndComesFirst(a, b); });
  rope_swings_.assign(ropes_.size(), std::numeric_limits<double>::infinity());
  waiting_velocities_.assign(balls_.size(), std::nullopt);
  std::vector<std::size_t> events_of(balls_.size(), 0);  // the impacts and hold ends each met
  bool struggle_waits = false;
  // The balls whose islands are held anew: after an impact, those it changed; after a renewal,
  // those whose holds ended; at the step's start, at a segment's event and once approaches stop
  // all at once, every ball.
  BallSet unsettled = BallSet::every(balls_.size());
  // False where the last impact's balls move freely away from everything they touch.
  bool hold_needed = true;
  // A pile that ran out of a step's budget settles whole, step after step, until it rests.
  const bool settled_whole = settles && settling_ && settleRestOfStep(dt);
  if (settled_whole) advance(0.0, dt);
  for (; !settled_whole;) {
    for (const std::size_t k : movable_segments_) startNextMotion(segments_[k]);
    const double remaining = dt - elapsed;
    step_left_ = remaining;
    if (impacts >= sequential) {
      unsettled = BallSet::every(balls_.size());
      hold_needed = true;
    }
    // (Every way on from here sets `unsettled` anew; held anew, it keeps its storage for that.)
    if (hold_needed)
      unsettled = holdRestingBalls(
          impacts < sequential ? kRestingSpeed : std::numeric_limits<double>::infinity(),
          std::move(unsettled));
    else
      moveFreely(unsettled);
    hold_needed = true;  // (only an impact says otherwise, for the next)
    const BallSet& held_anew = unsettled;
    recordHoldEnds(held_anew, elapsed, remaining);
    // A segment's motion changing is an event like a hold's end.
    const double segment_event = timeToSegmentEvent();
    const std::optional<std::size_t> first_end = hold_end_queue_.first();
    const double hold_end =
        first_end ? hold_ends_[*first_end] : std::numeric_limits<double>::infinity();
    // (Rounding may put a hold's end a hair before now.)
    const double held_for = std::min({remaining, segment_event, std::max(0.0, hold_end - elapsed)});
    predictChanged(elapsed, remaining);
    const std::optional<Impact> impact = earliestImpact(elapsed, held_for);
    if (impacts >= most || renewals >= kRenewalsPerImpact * most) {
      // Out of budget: the balls settle together, or, where they cannot, those of the struggle
      // wait for the rest of the step rather than hang, drift into their held contacts or move
      // through each other; the others go on, with a budget of their own. If that runs out
      // too, every ball waits at the next event.
      if (!struggle_waits && settles && settleRestOfStep(remaining)) {
        advance(elapsed, remaining);
        break;
      }
      if (!struggle_waits && holdStillTheStruggle(events_of, sequential_per_ball)) {
        struggle_waits = true;
        impacts = passed = renewals = 0;
        unsettled = BallSet::every(balls_.size());
        continue;
      }
      advance(elapsed, impact ? impact->time : held_for);
      break;
    }
    if (!impact) {
      advance(elapsed, held_for);
      if (held_for == remaining) break;
      elapsed += held_for;
      BallSet ended(balls_.size());
      for (std::size_t i = 0; i < balls_.size(); ++i)
        if (held_for == segment_event || hold_ends_[i] <= hold_end) ended.insert(i);
      // A held contact ends for both its balls: a resting one's ending lets it go, and the
      // search for touching pairs does not reach the ball that leaned on it from a resting one.
      for (const auto& [contact, forces] : held_)
        if (involves(contact, ended))
          if (const auto other = otherBallOf(contact.first, contact.second)) {
            ended.insert(contact.first);
            ended.insert(*other);
          }
      for (const std::size_t i : ended.list) ++events_of[i];
      const KeyPairs touching = touchingPairs(ended);
      unsettled = touchingTogether(touching, std::move(ended));
      closeHeldContacts(unsettled);  // and they are held anew
      ++renewals;
      continue;
    }
    advance(elapsed, impact->time);
    elapsed += impact->time;
    ++events_of[impact->ball];
    if (const auto other = otherBallOf(impact->ball, keyOf(*impact))) ++events_of[*other];
    resolve(*impact, time_ + elapsed);
    // The balls it woke touch these, so their islands are these balls'; a slow impact changes
    // nothing but is held anew.
    hold_needed = passThroughTouching(*impact, time_ + elapsed, passed, most, unsettled);
    ++impacts;
  }
  for (const std::size_t k : movable_segments_) startNextMotion(segments_[k]);
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    ballNow(i);
    if (waiting_velocities_[i]) leaveRest(i);
  }
  waiting_velocities_.clear();  // outside a step none waits
  clocks_.assign(balls_.size(), 0.0);
  now_ = 0.0;
  time_ += dt;
  removeBrokenAndPocketed();
}

double World::timeToSegmentEvent() const {
  double first = std::numeric_limits<double>::infinity();
  for (const std::size_t k : movable_segments_)
    first = std::min(first, timeToMotionChange(segments_[k]));
  return first;
}

std::optional<std::size_t> World::indexOf(BallId id) const {
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (balls_[i].id == id) return i;
  return std::nullopt;
}

World::BallSet World::BallSet::every(std::size_t balls) {
  BallSet all(balls);
  for (std::size_t i = 0; i < balls; ++i) all.insert(i);
  return all;
}

void World::BallSet::reset(std::size_t balls) {
  if (has.size() != balls) {
    *this = BallSet(balls);
    return;
  }
  for (const std::size_t ball : list) has[ball] = false;
  list.clear();
}

void World::BallSet::insert(std::size_t ball) {
  if (has[ball]) return;
  has[ball] = true;
  list.push_back(ball);
}

const Ball& World::ballNow(std::size_t ball) const {
  if (clocks_[ball] != now_) {
    moveAlong(courses_[ball], now_, balls_[ball]);
    clocks_[ball] = now_;
  }
  return balls_[ball];
}

Ball& World::ballNow(std::size_t ball) {
  std::as_const(*this).ballNow(ball);
  if (!is_looked_at_[ball]) {
    is_looked_at_[ball] = true;
    looked_at_.push_back(ball);
  }
  return balls_[ball];
}

std::optional<Motion> World::motionOfBall(BallId id) const {
  const std::optional<std::size_t> i = indexOf(id);
  return i ? std::optional<Motion>(motionOf(*i)) : std::nullopt;
}

Motion World::motionOf(std::size_t ball) const {
  const Ball& b = ballNow(ball);
  if (b.at_rest) return {b.position, Vec2::Zero(), Vec2::Zero()};
  return {b.position, b.velocity, accelerations_[ball]};
}

Vec2 World::freeAcceleration(std::size_t ball) const {
  Vec2 acceleration = gravity_ + drives_[ball];
  // No motion to look at: the common case, per event.
  if (winds_.empty() && attractors_.empty() && waters_.empty()) return acceleration;
  const Motion motion = motionOf(ball);
  for (const Wind& wind : winds_)
    if (centreInside(wind.region, motion)) acceleration += wind.acceleration;
  if (attractors_.empty() && waters_.empty()) return acceleration;
  // The pull at the middle of the stretch, where the pull at its start takes the ball.
  const Vec2 start = acceleration + fieldPull(ball, motion.position, motion.velocity);
  const double half = 0.5 * fieldStretchOf(ball);
  return acceleration + fieldPull(ball,
                                  motion.position + half * (motion.velocity + 0.5 * half * start),
                                  motion.velocity + half * start);
}

Vec2 World::fieldPull(std::size_t ball, const Vec2& position, const Vec2& velocity) const {
  Vec2 pull = Vec2::Zero();
  for (const Attractor& attractor : attractors_) pull += attraction(attractor, position);
  for (const Water& water : waters_)
    pull += waterAcceleration(water, ballNow(ball), position, velocity, gravity_.norm());
  return pull;
}

double World::fieldStretchOf(std::size_t ball) const {
  const Ball& b = ballNow(ball);
  const Vec2 acceleration = gravity_ + drives_[ball] + fieldPull(ball, b.position, b.velocity);
  const Motion start{b.position, b.velocity, acceleration};
  // Not into water it is not in yet: its push there starts only at the crossing.
  double stretch = step_left_;
  for (const Water& water : waters_)
    if (const auto crossing = timeToCrossRegion(wettedRegion(water, b.radius), start, stretch))
      stretch = *crossing;
  auto rateAt = [&](double t) {
    const Vec2 p = start.positionAt(t), v = start.velocityAt(t);
    Vec2 rate = Vec2::Zero();
    for (const Attractor& attractor : attractors_) rate += attractionRate(attractor, p, v);
    for (const Water& water : waters_)
      rate += waterAccelerationRate(water, b, p, v, acceleration, gravity_.norm());
    return rate;
  };
  // The pull's rate where the stretch starts and where its middle is: a ball at rest or
  // turning back has none at the start, but gathers it on the way.
  stretch = std::min(stretch, fieldStretch(rateAt(0.0)));
  for (int refinement = 0; refinement < kStretchRefinements; ++refinement)
    stretch = std::min(stretch, fieldStretch(rateAt(0.5 * stretch)));
  return std::max(stretch, kShortestHold);
}

World::KeyPairs World::touchingPairs(const BallSet& from) const {
  KeyPairs pairs;
  BallSet& reached = touching_reached_;
  reached.reset(balls_.size());
  std::vector<std::size_t>& pending = touching_pending_;
  pending.clear();
  auto reach = [&](std::size_t ball) {
    if (reached.contains(ball) || balls_[ball].at_rest) return;
    reached.insert(ball);
    pending.push_back(ball);
  };
  // Whether a ball that moves touches the body `key` names, or nearly does.
  auto consider = [&](std::size_t i, std::size_t key) {
    const std::optional<std::size_t> other = ballOf(key);
    const double gap = other ? surfaceGap(ballNow(i), ballNow(*other))
                             : surfaceGap(ballNow(i), segments_[*segmentOf(key)]);
    if (gap > kBoxMargin) return;
    if (!other || balls_[*other].at_rest) {
      pairs.emplace_back(i, key);
      return;
    }
    pairs.emplace_back(std::min(i, *other), std::max(i, *other));
    reach(*other);
  };
  for (const std::size_t i : from.list) reach(i);
  // From every ball, all pairs at once from the grid's cells rather than a query per ball
  // (unless the grid is full of balls that do not meet).
  const std::size_t n = balls_.size();
  const bool all_at_once = from.list.size() == n && balls_meet_;
  if (all_at_once)
    for (const auto& [ball, key] : grid_.pairs()) {
      if (ball >= n || !meets(ball, key)) continue;
      if (!balls_[ball].at_rest)
        consider(ball, key);
      else if (key < n && !balls_[key].at_rest)
        consider(key, ball);
    }
  while (!pending.empty()) {
    const std::size_t i = pending.back();
    pending.pop_back();
    // Whatever touches a ball has a box that holds its own place, so it meets this one's.
    if (!all_at_once)
      for (const std::size_t key : keysNear(i)) consider(i, key);
    // Ropes, from an end that moves, when nearly taut.
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
      const auto& [ball, other] = rope_ends_[r];
      if (ball != i && other != i) continue;
      const std::size_t key = balls_.size() + segments_.size() + r;
      const std::size_t end = balls_[ball].at_rest && other ? *other : ball;
      if (touch(end, key).gap > kBoxMargin) continue;
      pairs.emplace_back(end, key);
      reach(ball);
      if (other) reach(*other);
    }
  }
  std::sort(pairs.begin(), pairs.end(), [this](const auto& p, const auto& q) {
    return std::make_tuple(p.first, p.second < balls_.size(), p.second) <
           std::make_tuple(q.first, q.second < balls_.size(), q.second);
  });
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

World::BallSet World::touchingTogether(const KeyPairs& pairs, BallSet balls) const {
  // Union-find over the balls of the pairs that join two moving balls only, numbered in order:
  // the work is in those pairs (none, as after most bounces), not in every ball.
  std::vector<std::pair<std::size_t, std::size_t>> joins;
  std::vector<std::size_t> joined;
  for (const auto& [ball, key] : pairs)
    if (const auto other = otherBallOf(ball, key); other && !balls_[*other].at_rest) {
      joins.emplace_back(ball, *other);
      joined.insert(joined.end(), {ball, *other});
    }
  if (joins.empty()) return balls;
  std::sort(joined.begin(), joined.end());
  joined.erase(std::unique(joined.begin(), joined.end()), joined.end());
  auto place = [&](std::size_t ball) {
    return static_cast<std::size_t>(std::lower_bound(joined.begin(), joined.end(), ball) -
                                    joined.begin());
  };
  DisjointSets groups(joined.size());
  for (const auto& [ball, other] : joins) groups.join(place(ball), place(other));
  std::vector<bool> marked(joined.size(), false);
  for (std::size_t l = 0; l < joined.size(); ++l)
    if (balls.contains(joined[l])) marked[groups.find(l)] = true;
  for (std::size_t l = 0; l < joined.size(); ++l)
    if (marked[groups.find(l)]) balls.insert(joined[l]);
  return balls;
}

// Of the touching pairs, the contacts that approach slower than `slowest_approach` and separate
// no faster than `fastest_separation`, with the bias `level` asks for.
std::vector<RestingContact> World::touchingContacts(const KeyPairs& pairs,
                                                    double slowest_approach,
                                                    double fastest_separation,
                                                    ContactLevel level) const {
  std::vector<RestingContact> contacts;
  auto consider = [&](std::size_t i, std::size_t key) {
    const Touch t = touch(i, key);
    const double distance = t.separation.distance;
    if (distance == 0.0 || t.gap > kContactSlop) return;
    const Vec2& n = t.separation.normal;
    const double normal_speed = t.relative_velocity.dot(n);
    if (normal_speed <= -slowest_approach || normal_speed > fastest_separation) return;
    const std::optional<std::size_t> other = otherBallOf(i, key);
    double bias = 0.0;
    if (level == ContactLevel::kAcceleration) {
      const std::optional<std::size_t> segment = segmentOf(key);
      // Sliding round a ball opens the gap; swinging on a rope pulls it tighter.
      bias = segment ? gapAccelerationBias(segments_[*segment], ballNow(i).position,
                                           t.relative_velocity, n, distance, t.curved)
                     : (ropeOf(key) ? -1.0 : 1.0) *
                           centripetalOpening(t.relative_velocity, n, distance);
    }
    if (level == ContactLevel::kVelocity)  // n . (v - v_surface) >= 0
      bias = -n.dot(t.surface_velocity);
    if (level == ContactLevel::kPosition)  // the gap, as it changes with the positions, >= 0
      bias = t.gap - n.dot(ballNow(i).position - (other ? ballNow(*other).position : Vec2::Zero()));
    contacts.push_back({i, other, n, bias, key});
  };
  for (const auto& [ball, key] : pairs) consider(ball, key);
  return contacts;
}

std::optional<std::size_t> World::ballOf(std::size_t key) const {
  return key < balls_.size() ? std::optional<std::size_t>(key) : std::nullopt;
}

std::optional<std::size_t> World::segmentOf(std::size_t key) const {
  const std::size_t n = balls_.size();
  return key >= n && key < n + segments_.size() ? std::optional<std::size_t>(key - n)
                                                : std::nullopt;
}

const std::vector<std::size_t>& World::keysMet(std::size_t ball, const Box& box) const {
  std::vector<std::size_t>& keys = keys_met_;
  if (!balls_meet_) {
    segment_grid_.overlapping(box, keys);
    for (std::size_t& key : keys) key += balls_.size();
    return keys;
  }
  grid_.overlapping(box, keys);
  keys.erase(std::remove_if(keys.begin(), keys.end(),
                            [&](std::size_t key) { return !meets(ball, key); }),
             keys.end());
  return keys;
}

const std::vector<std::size_t>& World::keysNear(std::size_t ball) const {
  const Ball& b = ballNow(ball);
  return keysMet(ball, ballBox(b.position, b.radius));
}

bool World::meets(std::size_t ball, std::size_t key) const {
  const std::optional<std::size_t> other = ballOf(key);
  return !other || (*other != ball && collide(balls_[ball], balls_[*other]));
}

std::optional<std::size_t> World::ropeOf(std::size_t key) const {
  const std::size_t first = balls_.size() + segments_.size();
  return key >= first ? std::optional<std::size_t>(key - first) : std::nullopt;
}

std::size_t World::keyOf(const Impact& impact) const {
  switch (impact.kind) {
    case ContactKind::kBall: return impact.other;
    case ContactKind::kRope: return balls_.size() + segments_.size() + impact.other;
    default: return balls_.size() + impact.other;
  }
}

std::optional<std::size_t> World::otherBallOf(std::size_t ball, std::size_t key) const {
  if (const auto rope = ropeOf(key)) {
    const auto& [end, other] = rope_ends_[*rope];
    return end == ball ? other : std::optional<std::size_t>(end);
  }
  return ballOf(key);
}

Motion World::farEndOf(std::size_t ball, std::size_t key) const {
  if (const auto other = otherBallOf(ball, key)) return motionOf(*other);
  return {ropes_[*ropeOf(key)].anchor, Vec2::Zero(), Vec2::Zero()};
}

World::Touch World::touch(std::size_t ball, std::size_t key) const {
  const Ball& b = ballNow(ball);
  const Vec2 velocity = motionOf(ball).velocity;
  if (const auto rope = ropeOf(key)) {
    const Motion far = farEndOf(ball, key);
    const Separation along = separationAlong(far.position - b.position);
    return {along, ropes_[*rope].length - along.distance, velocity - far.velocity, Vec2::Zero(),
            true};
  }
  if (const auto other = ballOf(key)) {
    const Ball& o = ballNow(*other);
    const Separation apart = separationAlong(b.position - o.position);
    return {apart, apart.distance - (b.radius + o.radius), velocity - motionOf(*other).velocity,
            Vec2::Zero(), true};
  }
  const Segment& segment = segments_[*segmentOf(key)];
  const Vec2 surface = velocityUnder(segment, b.position);
  const Vec2 relative = velocity - surface;
  const SegmentFeature feature = featureUnder(segment, b.position, relative);
  const Separation from = separationFrom(segment, b.position, feature);
  return {from, from.distance - contactDistance(segment, b.radius), relative, surface,
          feature != SegmentFeature::kFace};
}

double World::inverseMassOf(std::size_t ball) const {
  return balls_[ball].at_rest ? 0.0 : 1.0 / balls_[ball].mass;
}

bool World::involves(const std::pair<std::size_t, std::size_t>& held,
                     const BallSet& balls) const {
  const std::optional<std::size_t> other = otherBallOf(held.first, held.second);
  return balls.contains(held.first) || (other && balls.contains(*other));
}

bool World::held(std::size_t ball, std::size_t key) const {
  return heldForces(ball, key) != nullptr;
}

const ContactForces* World::heldForces(std::size_t ball, std::size_t key) const {
  if (const auto at = held_.find({ball, key}); at != held_.end()) return &at->second;
  // Held from its other ball: a ball pair under that ball's key for this one, a rope under its own.
  const std::optional<std::size_t> other = otherBallOf(ball, key);
  if (!other) return nullptr;
  const auto at = held_.find({*other, ropeOf(key) ? key : ball});
  return at != held_.end() ? &at->second : nullptr;
}

// Before the next impact is sought, for the balls that touch: overlaps left by rounding are
// pushed apart; approaches slower than `inelastic_below` stop, all at once (one pair at a time,
// a ball wedged between two others would bounce between them forever, a Zeno sequence). Then
// every awake ball of the islands held anew gets its acceleration until its island's next
// event, gravity plus the normal forces of its resting contacts; the contacts those forces
// hold are kept out of impact detection, and the balls they hold still are put to rest. (A
// contact keyed by a ball put to rest stays held until the other ball's island is held anew.)
World::BallSet World::holdRestingBalls(double inelastic_below, BallSet unsettled) {
  const double any_speed = std::numeric_limits<double>::infinity();
  // Found before the overlaps are pushed apart, which moves balls by far less than kBoxMargin.
  KeyPairs touching = touchingPairs(unsettled);
  if (wakePushedSideways(touching, unsettled)) touching = touchingPairs(unsettled);
  const BallSet held_anew = touchingTogether(touching, std::move(unsettled));
  KeyPairs pairs = std::move(touching);
  pairs.erase(std::remove_if(pairs.begin(), pairs.end(),
                             [&](const auto& pair) { return !held_anew.contains(pair.first); }),
              pairs.end());
  // Nothing to hold, stop or push apart: they move freely (the common case, as at a step's start;
  // after a bounce, step() mostly needs no search to know it: see passThroughTouching).
  if (std::all_of(pairs.begin(), pairs.end(), [this](const auto& pair) {
        return separatesFreely(pair.first, pair.second, touch(pair.first, pair.second));
      })) {
    moveFreely(held_anew);
    return held_anew;
  }
  // The balls of the hold, numbered in the order of `members`: those held anew and the resting
  // balls they touch. The solves' arrays are theirs, not every ball's.
  BallSet members = held_anew;
  for (const auto& [ball, key] : pairs)
    if (const auto other = otherBallOf(ball, key)) members.insert(*other);
  const std::size_t m = members.list.size();
  std::unordered_map<std::size_t, std::size_t> place;
  for (std::size_t l = 0; l < m; ++l) place.emplace(members.list[l], l);
  auto numbered = [&](std::vector<RestingContact> contacts) {
    for (RestingContact& c : contacts) {
      c.ball = place.at(c.ball);
      if (c.other) c.other = place.at(*c.other);
    }
    return contacts;
  };
  std::vector<Vec2> positions(m), velocities(m, Vec2::Zero()), free(m, Vec2::Zero());
  std::vector<double> inverse_masses(m);
  for (std::size_t l = 0; l < m; ++l) {
    const std::size_t i = members.list[l];
    positions[l] = ballNow(i).position;
    inverse_masses[l] = inverseMassOf(i);
    if (!balls_[i].at_rest && held_anew.contains(i)) free[l] = freeAcceleration(i);
  }
  positions =
      pushApart(positions, inverse_masses,
                numbered(touchingContacts(pairs, any_speed, any_speed, ContactLevel::kPosition)));
  for (std::size_t l = 0; l < m; ++l)
    if (!balls_[members.list[l]].at_rest) ballNow(members.list[l]).position = positions[l];
  const bool any_rough = std::any_of(members.list.begin(), members.list.end(),
                                     [this](std::size_t i) { return isRough(balls_[i]); });
  if (any_rough)
    for (const RestingContact& c :
         touchingContacts(pairs, any_speed, any_speed, ContactLevel::kVelocity))
      stopSlowSpin(c.ball, c.body);
  const std::vector<RestingContact> slow_contacts =
      touchingContacts(pairs, inelastic_below, any_speed, ContactLevel::kVelocity);
  std::vector<Ball> balls;
  for (const std::size_t i : members.list) balls.push_back(ballNow(i));
  if (any_rough) {
    std::vector<ContactFriction> frictions;
    for (const RestingContact& c : slow_contacts) frictions.push_back(frictionOf(c.ball, c.body));
    const FrictionalRates after =
        stopSlowMotion(balls, inverse_masses, numbered(slow_contacts), frictions);
    velocities = after.accelerations;
    for (std::size_t l = 0; l < m; ++l) balls[l].angular_velocity = after.angular_accelerations[l];
  } else {
    for (std::size_t l = 0; l < m; ++l) velocities[l] = balls[l].velocity;
    velocities = pushApart(velocities, inverse_masses, numbered(slow_contacts));
  }
  for (std::size_t l = 0; l < m; ++l) {
    Ball& ball = ballNow(members.list[l]);
    if (ball.at_rest) continue;
    ball.velocity = balls[l].velocity = velocities[l];
    ball.angular_velocity = balls[l].angular_velocity;
  }

  const std::vector<RestingContact> held_contacts = touchingContacts(
      pairs, kApproachSpeedTolerance, kHeldSeparationSpeed, ContactLevel::kAcceleration);
  std::vector<RestingContact> contacts = numbered(held_contacts);
  std::vector<ContactFriction> frictions(contacts.size());  // none between smooth balls
  if (any_rough)
    for (std::size_t k = 0; k < contacts.size(); ++k)
      frictions[k] = frictionOf(held_contacts[k].ball, held_contacts[k].body);
  // The solve starts from each contact's forces as last held: after an event, most of an
  // island's contacts are as they were.
  std::vector<ContactForces> start;
  for (const RestingContact& c : held_contacts) {
    const ContactForces* last = heldForces(c.ball, c.body);
    start.push_back(last ? *last : ContactForces());
  }
  auto solve = [&] {
    if (std::any_of(frictions.begin(), frictions.end(), [](const ContactFriction& f) {
          return f.friction > 0.0 || f.rolling_resistance > 0.0;
        }))
      return holdWithFriction(free, balls, inverse_masses, contacts, frictions, start);
    return holdWithoutFriction(free, inverse_masses, contacts, start);
  };
  FrictionalRates rates = solve();
  if (!ropes_.empty() &&
      pullFromMiddleOfSwing(contacts, members.list, rates.accelerations, inverse_masses)) {
    FrictionalRates middle = solve();
    // Where the pull falls to nothing on its way (a swing that just reaches its rope's level),
    // the middle would let go of a rope that must pull now: the start's pull holds instead.
    bool lets_go = false;
    for (std::size_t k = 0; k < contacts.size(); ++k)
      lets_go = lets_go || (ropeOf(contacts[k].body) && rates.forces[k].normal > 0.0 &&
                            !(middle.forces[k].normal > 0.0));
    if (!lets_go) rates = std::move(middle);
  }
  // The others' accelerations, found earlier, hold until their contacts' lifetime ends.
  for (std::size_t l = 0; l < m; ++l) {
    const std::size_t i = members.list[l];
    if (!held_anew.contains(i)) continue;
    accelerations_[i] = rates.accelerations[l];
    angular_accelerations_[i] = rates.angular_accelerations[l];
  }
  letGoHeldContacts(held_anew);
  std::vector<bool> in_contact(m, false);
  // Balls whose spin their contacts can change (friction, rolling resistance).
  std::vector<bool> turned(m, false);
  // Balls on a moving segment: held, but carried along, never at rest.
  std::vector<bool> carried(m, false);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const RestingContact& c = contacts[k];
    const bool turns = frictions[k].friction > 0.0 || frictions[k].rolling_resistance > 0.0;
    in_contact[c.ball] = true;
    turned[c.ball] = turned[c.ball] || turns;
    const std::optional<std::size_t> segment = segmentOf(c.body);
    carried[c.ball] = carried[c.ball] || (segment && moves(segments_[*segment]));
    if (c.other) {
      in_contact[*c.other] = true;
      turned[*c.other] = turned[*c.other] || turns;
    }
    const auto contact = std::make_pair(held_contacts[k].ball, c.body);
    if (rates.forces[k].normal > 0.0 && held_.emplace(contact, rates.forces[k]).second)
      held_changes_.emplace_back(contact, false);
  }

  // Nothing to rest against.
  if (gravity_ == Vec2::Zero() && winds_.empty() && attractors_.empty() && waters_.empty())
    return held_anew;
  for (std::size_t l = 0; l < m; ++l) {
    const std::size_t i = members.list[l];
    if (!held_anew.contains(i)) continue;
    Ball& ball = ballNow(i);
    // A ball rests with the spin it has only if its contacts cannot change it and it has no
    // friction: resting, it is not turned by what it touches, and a rough surface spinning
    // would drive a rough ball that comes to touch it, without end.
    const bool rough = turned[l] || ball.friction > 0.0;
    const bool turning = rough && (std::abs(ball.angular_velocity) * ball.radius >
                                       kHeldSeparationSpeed ||
                                   std::abs(angular_accelerations_[i]) * ball.radius >
                                       kRestingAcceleration);
    // Held still and not moving: a ball sliding, or turning at its surface, faster than
    // kHeldSeparationSpeed keeps on (slower, rough balls rocked in a pile's pockets for ever).
    if (!ball.at_rest && in_contact[l] && !carried[l] &&
        accelerations_[i].norm() <= kRestingAcceleration &&
        ball.velocity.norm() <= kHeldSeparationSpeed && !turning) {
      comeToRest(i);
      if (rough) ball.angular_velocity = 0.0;
    }
  }
  return held_anew;
}

void World::moveFreely(const BallSet& balls) {
  for (const std::size_t i : balls.list) {
    const Vec2 free = balls_[i].at_rest ? Vec2::Zero() : freeAcceleration(i);
    // A ball whose course this keeps (every free ball at a step's start) is left unmarked.
    if (free == accelerations_[i] && angular_accelerations_[i] == 0.0) continue;
    ballNow(i);  // (its course changes: noted as looked at)
    accelerations_[i] = free;
    angular_accelerations_[i] = 0.0;
  }
  letGoHeldContacts(balls);
}

void World::letGoHeldContacts(const BallSet& balls) {
  for (auto held = held_.begin(); held != held_.end();) {
    if (!involves(held->first, balls)) {
      ++held;
      continue;
    }
    held_changes_.emplace_back(held->first, true);
    held = held_.erase(held);
  }
}

bool World::pullFromMiddleOfSwing(std::vector<RestingContact>& contacts,
                                  const std::vector<std::size_t>& balls,
                                  const std::vector<Vec2>& accelerations,
                                  const std::vector<double>& inverse_masses) {
  auto relativeMotion = [&](const RestingContact& c) {
    auto motion = [&](std::size_t i) {
      const Ball& b = ballNow(balls[i]);
      return b.at_rest ? Motion{b.position} : Motion{b.position, b.velocity, accelerations[i]};
    };
    return motion(c.ball).relativeTo(c.other ? motion(*c.other)
                                             : Motion{ropes_[*ropeOf(c.body)].anchor});
  };
  // Two tied balls that touch: their contact turns with their rope, or the two nearly opposite
  // pushes, taken at different times, would push them sideways.
  std::set<std::pair<std::size_t, std::size_t>> tied;
  for (const RestingContact& c : contacts)
    if (ropeOf(c.body) && c.other) tied.insert(std::minmax(c.ball, *c.other));
  auto turnsWithRope = [&](const RestingContact& c) {
    return ropeOf(c.body) || (ballOf(c.body) && tied.count(std::minmax(c.ball, *c.other)) > 0);
  };
  bool any = false;
  for (const std::vector<std::size_t>& island : contactIslands(contacts, inverse_masses)) {
    // The island's hold lasts until the first of its ropes drifts, or a segment's motion
    // changes: each rope is pulled as at the middle of that.
    double hold = std::min(step_left_, timeToSegmentEvent());
    for (const std::size_t k : island)
      if (ropeOf(contacts[k].body)) hold = curvedContactLifetime(relativeMotion(contacts[k]), hold);
    for (const std::size_t k : island) {
      RestingContact& c = contacts[k];
      if (!turnsWithRope(c)) continue;
      if (const auto rope = ropeOf(c.body)) rope_swings_[*rope] = hold;
      const Motion relative = relativeMotion(c);
      const Vec2 offset = relative.positionAt(0.5 * hold);  // from the other end to the ball
      const double distance = offset.norm();
      if (distance == 0.0) continue;
      // A contact pushes the ball away from the other centre and the swing opens its gap; a
      // rope pulls it toward the other end and the swing takes up its slack.
      const double sign = ropeOf(c.body) ? -1.0 : 1.0;
      c.normal = sign * offset / distance;
      c.bias = sign * centripetalOpening(relative.velocityAt(0.5 * hold), c.normal, distance);
      any = true;
    }
  }
  return any;
}

bool World::wakePushedSideways(const KeyPairs& pairs, const BallSet& unsettled) {
  bool woke = false;
  for (const auto& [ball, key] : pairs) {
    const std::optional<std::size_t> other = otherBallOf(ball, key);
    if (!other || !unsettled.contains(ball) || !balls_[*other].at_rest || !pushedSideways(ball))
      continue;
    wake(*other);
    woke = true;
  }
  return woke;
}

bool World::separatesFreely(std::size_t ball, std::size_t key, const Touch& t) const {
  const std::optional<std::size_t> other = otherBallOf(ball, key);
  return !isRough(balls_[ball]) && !(other && isRough(balls_[*other])) &&
         (t.gap > kContactSlop ||
          t.relative_velocity.dot(t.separation.normal) > kHeldSeparationSpeed);
}

bool World::pushedSideways(std::size_t ball) const { return freeAcceleration(ball) != gravity_; }

double World::heldContactLifetime(std::size_t i, std::size_t key, double horizon) const {
  if (const auto stop = timeFrictionChanges(i, key))
    horizon = std::min(horizon, std::max(*stop, kShortestHold));
  if (const auto rope = ropeOf(key)) return std::min(horizon, rope_swings_[*rope]);
  const Motion motion = motionOf(i);
  if (const auto other = ballOf(key))
    return curvedContactLifetime(motion.relativeTo(motionOf(*other)), horizon);
  // Exact against a segment that stands or translates; one that turns drifts from its present
  // motion, which a short lifetime bounds.
  const Segment& segment = segments_[*segmentOf(key)];
  const Motion relative = seenFrom(segment, motion);
  if (const auto change = timeOfFeatureChange(relative, segment, horizon))
    horizon = std::min(horizon, std::max(*change, kShortestHold));
  const SegmentFeature feature = featureUnder(segment, relative.position, relative.velocity);
  if (feature != SegmentFeature::kFace) {
    const Motion cap{segment.cap(feature == SegmentFeature::kStartCap ? 0 : 1)};
    horizon = curvedContactLifetime(relative.relativeTo(cap), horizon);
  }
  return std::min(horizon, std::max(turningContactLifetime(segment, motion.position,
                                                           motion.velocity, motion.acceleration),
                                    kShortestHold));
}

void World::recordHoldEnds(const BallSet& held_anew, double elapsed, double remaining) {
  for (const std::size_t i : held_anew.list)
    queueHoldEnd(i, std::numeric_limits<double>::infinity());
  for (const auto& [contact, forces] : held_) {
    if (!involves(contact, held_anew)) continue;
    const auto [i, key] = contact;
    const double lifetime = heldContactLifetime(i, key, remaining);
    if (lifetime >= remaining) continue;  // the step's end comes first
    const double end = elapsed + lifetime;
    queueHoldEnd(i, std::min(hold_ends_[i], end));
    if (const auto other = otherBallOf(i, key))
      queueHoldEnd(*other, std::min(hold_ends_[*other], end));
  }
  if (winds_.empty() && attractors_.empty() && waters_.empty()) return;
  for (const std::size_t i : held_anew.list) {
    if (balls_[i].at_rest) continue;
    auto endAtCrossing = [&](const Region& region) {
      if (const auto crossing = timeToCrossRegion(region, motionOf(i), remaining))
        queueHoldEnd(i, std::min(hold_ends_[i], elapsed + std::max(*crossing, kShortestHold)));
    };
    for (const Wind& wind : winds_) endAtCrossing(wind.region);
    for (const Water& water : waters_) endAtCrossing(wettedRegion(water, balls_[i].radius));
    if (!attractors_.empty() || !waters_.empty()) {
      const double stretch = fieldStretchOf(i);
      if (stretch < remaining) queueHoldEnd(i, std::min(hold_ends_[i], elapsed + stretch));
    }
  }
}

void World::watchSensors(double from, double dt) {
  if (sensors_.empty()) return;
  const std::size_t first_new = sensor_events_.size();
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    const Motion motion = motionOf(i);
    for (std::size_t s = 0; s < sensors_.size(); ++s) {
      const Region& region = sensors_[s].region;
      noteSensor(i, s, centreInside(region, motion), from);
      for (const double t : regionCrossings(region, motion, dt)) {
        const Motion then{motion.positionAt(t), motion.velocityAt(t), motion.acceleration};
        noteSensor(i, s, centreInside(region, then), from + t);
      }
    }
  }
  // In the order they happened, whichever ball they are of.
  std::stable_sort(sensor_events_.begin() + first_new, sensor_events_.end(),
                   [](const SensorEvent& a, const SensorEvent& b) { return a.time < b.time; });
}

void World::noteSensor(std::size_t ball, std::size_t s, bool inside, double time) {
  const std::pair<BallId, std::size_t> key{balls_[ball].id, s};
  if (inside == (in_sensors_.count(key) > 0)) return;
  if (inside)
    in_sensors_.insert(key);
  else
    in_sensors_.erase(key);
  sensor_events_.push_back({time, sensors_[s].name, balls_[ball].id, inside});
  if (inside && sensors_[s].pocket) pocketed_.push_back(balls_[ball].id);
}

void World::hitBrick(std::size_t segment, std::size_t ball, double time) {
  Segment& brick = segments_[segment];
  --brick.hits_to_break;
  brick_hits_.push_back({time, brick.id, balls_[ball].id, brick.hits_to_break});
  if (brick.hits_to_break == 0) broken_bricks_.push_back(brick.id);
}

void World::removeBrokenAndPocketed() {
  for (const SegmentId id : broken_bricks_) removeSegment(id);
  broken_bricks_.clear();
  for (const BallId id : pocketed_) removeBall(id);
  pocketed_.clear();
}

ContactFriction World::frictionOf(std::size_t ball, std::size_t key) const {
  if (ropeOf(key)) return {};  // a rope pulls along itself only
  const Ball& b = ballNow(ball);
  const Touch t = touch(ball, key);
  if (const auto other = ballOf(key)) {
    const Ball& o = ballNow(*other);
    return {combinedFriction(b.friction, o.friction), 0.0,
            slipSpeed(t.relative_velocity, t.separation.normal, b.radius, b.angular_velocity,
                      o.radius * o.angular_velocity)};
  }
  const Segment& segment = segments_[*segmentOf(key)];
  return {combinedFriction(b.friction, segment.friction),
          combinedFriction(b.rolling_resistance, segment.rolling_resistance),
          slipSpeed(t.relative_velocity, t.separation.normal, b.radius, b.angular_velocity, 0.0)};
}

void World::stopSlowSpin(std::size_t ball, std::size_t key) {
  Ball& b = ballNow(ball);
  if (frictionOf(ball, key).rolling_resistance > 0.0 &&
      std::abs(b.angular_velocity) * b.radius <= kRollingSlip)
    b.angular_velocity = 0.0;
}

std::optional<double> World::timeFrictionChanges(std::size_t ball, std::size_t key) const {
  if (!isRough(balls_[ball])) return std::nullopt;  // no pair with it has friction
  const ContactFriction f = frictionOf(ball, key);
  const Ball& b = ballNow(ball);
  const double spin_rate = angular_accelerations_[ball];
  std::optional<double> first;
  auto untilZero = [&first](double value, double rate) {
    if (value * rate < 0.0) first = std::min(first.value_or(-value / rate), -value / rate);
  };
  if (f.friction > 0.0 && std::abs(f.slip) > kRollingSlip) {
    const auto other = ballOf(key);
    const Vec2 relative = motionOf(ball).acceleration -
                          (other ? motionOf(*other).acceleration : Vec2::Zero());
    const double other_turning =
        other ? balls_[*other].radius * angular_accelerations_[*other] : 0.0;
    untilZero(f.slip, slipSpeed(relative, touch(ball, key).separation.normal, b.radius, spin_rate,
                                other_turning));
  }
  if (f.rolling_resistance > 0.0 && std::abs(b.angular_velocity) * b.radius > kRollingSlip)
    untilZero(b.angular_velocity, spin_rate);
  return first;
}

// A held contact's normal force keeps its gap and normal speed at zero; its constant
// accelerations do so only to within kHeldDrift. Before it is held anew, the drift is undone,
// shared between the two bodies by their inverse masses (a ball put to rest meanwhile has none).
void World::closeHeldContacts(const BallSet& balls) {
  for (const auto& [contact, forces] : held_)
    if (involves(contact, balls)) closeContact(contact.first, contact.second, true);
}

void World::closeContact(std::size_t i, std::size_t key, bool gap_too) {
  const Touch t = touch(i, key);
  const std::optional<std::size_t> other = otherBallOf(i, key);
  const double inverse_mass = inverseMassOf(i);
  const double other_inverse_mass = other ? inverseMassOf(*other) : 0.0;
  if (t.separation.distance == 0.0 || inverse_mass + other_inverse_mass == 0.0) return;
  const Vec2& n = t.separation.normal;
  const Vec2 gap = gap_too ? Vec2(t.gap * n) : Vec2::Zero();
  const Vec2 normal_velocity = t.relative_velocity.dot(n) * n;
  const double share = inverse_mass / (inverse_mass + other_inverse_mass);
  if (inverse_mass > 0.0) {
    ballNow(i).position -= share * gap;
    ballNow(i).velocity -= share * normal_velocity;
  }
  if (other_inverse_mass > 0.0) {
    ballNow(*other).position += (1.0 - share) * gap;
    ballNow(*other).velocity += (1.0 - share) * normal_velocity;
  }
}

Box World::keyBox(std::size_t key, double remaining) const {
  if (const auto ball = ballOf(key))
    return sweptBox(motionOf(*ball), balls_[*ball].radius, remaining);
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
  for (std::size_t k = 0; k < segments_.size(); ++k)
    if (moves(segments_[k]) || !segments_[k].waypoints.empty()) movable_segments_.push_back(k);
  updateRooms();
  // Where no two balls meet, the balls' boxes (long, for fast balls) would only be moved about,
  // unless a segment may move in the step: its box finds the balls near it in the grid. (Out
  // of it, each ball's box is found as it is predicted.)
  balls_in_grid_ = balls_meet_ || !movable_segments_.empty();
  std::vector<Box> boxes;
  boxes.reserve(n + segments_.size());
  for (std::size_t key = balls_in_grid_ ? 0 : n; key < n + segments_.size(); ++key)
    boxes.push_back(keyBox(key, horizon));
  grid_.reset(balls_in_grid_ ? boxes : std::vector<Box>());
  segment_grid_.reset(std::vector<Box>(boxes.end() - segments_.size(), boxes.end()));
  next_impacts_.assign(n, std::nullopt);
  awaiting_.assign(n + segments_.size(), {});
  if (balls_meet_) {
    // Every pair at once from the grid's cells, each pair's impact kept by its lower key.
    std::vector<std::optional<Impact>> earliest(n);
    for (const auto& [ball, key] : grid_.pairs())
      if (ball < n && meets(ball, key)) considerImpact(ball, key, horizon, earliest[ball]);
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
      const auto& [end, other] = rope_ends_[r];
      const std::size_t key = n + segments_.size() + r;
      considerImpact(end, key, horizon, earliest[end]);
      if (other) considerImpact(*other, key, horizon, earliest[*other]);
    }
    for (std::size_t i = 0; i < n; ++i) expectImpact(i, earliest[i], 0.0);
  } else {
    for (std::size_t i = 0; i < n; ++i) predictBall(i, 0.0, horizon);
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
    if (was_held == (held_.count(contact) > 0)) continue;
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
  return {now_,       b.position, b.velocity, accelerations_[ball], b.angle, b.angular_velocity,
          angular_accelerations_[ball], b.at_rest};
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
         ball.at_rest == course.at_rest && accelerations_[i] == course.acceleration &&
         angular_accelerations_[i] == course.angular_acceleration;
}

bool World::holdEndComesFirst(std::size_t a, std::size_t b) const {
  return hold_ends_[a] < hold_ends_[b];
}

void World::queueHoldEnd(std::size_t ball, double end) {
  if (hold_ends_[ball] == end) return;
  hold_ends_[ball] = end;
  hold_end_queue_.update(ball,
                         [this](std::size_t a, std::size_t b) { return holdEndComesFirst(a, b); });
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
    if ((ball.at_rest && balls_[*j].at_rest) || held(i, key)) return;
    keep(circleTimeOfImpact(motion.relativeTo(motionOf(*j)), ball.radius + balls_[*j].radius,
                            until()),
         ContactKind::kBall, *j, 0);
    return;
  }
  const std::size_t k = *segmentOf(key);
  const Segment& segment = segments_[k];
  if ((ball.at_rest && !moves(segment)) || held(i, key)) return;
  if (segment.angular_velocity != 0.0) {
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
      const Touch t = touch(i, key);
      const std::optional<std::size_t> other = ballOf(key);
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
  if (segment.angular_velocity != 0.0 && surfaceGap(ball, segment) > kContactSlop) return;
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

void World::wakeTouching(const Segment& segment) {
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    if (balls_[i].at_rest && surfaceGap(ballNow(i), segment) <= kContactSlop) wake(i);
  }
}

std::vector<std::size_t> World::restingClusterIndices(std::size_t ball) const {
  std::vector<bool> taken(balls_.size(), false);
  std::vector<std::size_t> cluster, pending{ball};
  taken[ball] = true;
  auto take = [&](std::size_t j) {
    if (taken[j] || !balls_[j].at_rest) return;
    taken[j] = true;
    pending.push_back(j);
  };
  while (!pending.empty()) {
    const std::size_t i = pending.back();
    pending.pop_back();
    cluster.push_back(i);
    for (std::size_t j = 0; j < balls_.size(); ++j)
      if (!taken[j] && balls_[j].at_rest && meets(i, j) &&
          surfaceGap(ballNow(i), ballNow(j)) <= kContactSlop)
        take(j);
    for (std::size_t r = 0; r < ropes_.size(); ++r) {  // a ball may hang from it, taut
      const auto& [end, other] = rope_ends_[r];
      if (other && (end == i || *other == i) &&
          touch(end, balls_.size() + segments_.size() + r).gap <= kContactSlop)
        take(end == i ? *other : end);
    }
  }
  return cluster;
}

std::vector<BallId> World::restingClusterOf(BallId id) const {
  std::vector<BallId> ids;
  if (const std::optional<std::size_t> i = indexOf(id))
    for (std::size_t j : restingClusterIndices(*i)) ids.push_back(balls_[j].id);
  return ids;
}

const Ball* World::findBall(BallId id) const {
  const std::optional<std::size_t> i = indexOf(id);
  return i ? &balls_[*i] : nullptr;
}

bool World::holdStillTheStruggle(const std::vector<std::size_t>& events_of,
                                 std::size_t struggling_from) {
  BallSet struggling(balls_.size());
  std::size_t moving = 0;
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    if (balls_[i].at_rest) continue;
    ++moving;
    if (events_of[i] >= struggling_from) struggling.insert(i);
  }
  const KeyPairs pairs = touchingPairs(struggling);
  // A moving segment would strike a waiting ball it touches at once (a ball it crushes against
  // a wall): the struggle would start again, and run out again.
  for (const auto& [ball, key] : pairs)
    if (const auto segment = segmentOf(key); segment && moves(segments_[*segment])) return false;
  struggling = touchingTogether(pairs, std::move(struggling));
  if (struggling.list.empty() || struggling.list.size() == moving) return false;
  for (const std::size_t i : struggling.list) {
    waiting_velocities_[i] = ballNow(i).velocity;
    comeToRest(i);
    queueHoldEnd(i, std::numeric_limits<double>::infinity());
  }
  letGoHeldContacts(struggling);
  return true;
}

bool World::settleRestOfStep(double remaining) {
  settling_ = false;
  if (!(remaining > 0.0)) return false;
  const std::size_t n = balls_.size();
  std::vector<Vec2> free(n, Vec2::Zero());  // each ball's velocity at the end, untouched
  for (std::size_t i = 0; i < n; ++i)
    if (!balls_[i].at_rest) free[i] = ballNow(i).velocity + gravity_ * remaining;
  double reach = settle_reach_;
  std::vector<std::size_t> woken;  // put back to rest if no settle is found
  auto giveUp = [&] {
    for (const std::size_t j : woken) comeToRest(j);
    return false;
  };
  for (int attempt = 0; attempt < kSettleAttempts; ++attempt) {
    BallSet members(n);
    const std::optional<KeyPairs> pairs = settlingPairs(free, reach, remaining, members);
    if (!pairs) return giveUp();
    if (wakeStruck(*pairs, free, remaining, woken)) continue;
    Settled settled = settleMembers(*pairs, members, free, remaining);
    // The pairs hold every body a ball may meet only if it keeps within `reach` of its path.
    double farthest = 0.0;
    for (std::size_t l = 0; l < settled.members.size(); ++l) {
      const std::size_t i = settled.members[l];
      if (!balls_[i].at_rest)
        farthest = std::max(farthest, (settled.velocities[l] - free[i]).norm());
    }
    farthest *= remaining;
    if (farthest > reach) {
      reach = kSettleReachGrowth * farthest;
      continue;
    }
    settle_reach_ = farthest;
    moveOnSettled(members, settled, remaining);
    return true;
  }
  return giveUp();
}

bool World::canSettle() const {
  if (!ropes_.empty() || !movable_segments_.empty()) return false;
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (!balls_[i].at_rest && freeAcceleration(i) != gravity_) return false;
  return true;
}

std::optional<World::KeyPairs> World::settlingPairs(const std::vector<Vec2>& free, double reach,
                                                    double duration, BallSet& members) const {
  const std::size_t n = balls_.size();
  std::vector<Box> boxes;
  for (std::size_t i = 0; i < n; ++i) {
    const Ball& b = ballNow(i);
    if (b.at_rest) {
      boxes.push_back(ballBox(b.position, b.radius));
      continue;
    }
    // Its path as it goes freely, and its straight one, untouched or within reach of it.
    const Box path = sweptBox(Motion{b.position, b.velocity, gravity_}, b.radius, duration);
    boxes.push_back(enclosing(
        path, sweptBox(Motion{b.position, free[i]}, b.radius + reach, duration)));
  }
  for (const Segment& segment : segments_) boxes.push_back(segmentBox(segment, duration));
  KeyPairs pairs;  // (moving ball, key)
  for (const auto& [a, b] : overlappingPairs(boxes)) {
    if (a >= n) continue;  // two segments
    const bool a_rests = balls_[a].at_rest;
    if (b >= n) {
      if (a_rests) continue;
      const Segment& segment = segments_[b - n];
      if (segment.hits_to_break > 0 || segment.kick > 0.0) return std::nullopt;
      pairs.emplace_back(a, b);
    } else {
      if ((a_rests && balls_[b].at_rest) || !collide(balls_[a], balls_[b])) continue;
      pairs.push_back(a_rests ? std::make_pair(b, a) : std::make_pair(a, b));
      members.insert(b);
    }
    members.insert(a);
  }
  return pairs;
}

bool World::wakeStruck(const KeyPairs& pairs, std::vector<Vec2>& free, double duration,
                       std::vector<std::size_t>& woken) {
  bool woke = false;
  for (const auto& [i, key] : pairs) {
    const std::optional<std::size_t> other = ballOf(key);
    if (!other || !balls_[*other].at_rest) continue;
    const Touch t = touch(i, key);
    // Struck: coming at it faster than kRestingSpeed, near enough to meet in the stretch (a
    // ball lying on it, or landing on it gently, does not wake it).
    const double approach = -t.separation.normal.dot(balls_[i].velocity);
    if (approach <= kRestingSpeed || t.gap > approach * duration) continue;
    for (const std::size_t j : restingClusterIndices(*other)) {
      leaveRest(j);
      free[j] = ballNow(j).velocity + gravity_ * duration;
      woken.push_back(j);
    }
    woke = true;
  }
  return woke;
}

Settled World::settleMembers(const KeyPairs& pairs, const BallSet& members,
                             const std::vector<Vec2>& free, double duration) {
  std::unordered_map<std::size_t, std::size_t> place;  // each member's number in the settle
  std::vector<Ball> settling;
  std::vector<double> inverse_masses;
  for (const std::size_t i : members.list) {
    place.emplace(i, settling.size());
    settling.push_back(ballNow(i));
    settling.back().velocity = free[i];
    inverse_masses.push_back(inverseMassOf(i));
  }
  // An overlap left by rounding stays as it is: pushed out over a short time, it would launch
  // its ball.
  std::vector<RestingContact> contacts;
  std::vector<double> frictions;
  // Each pair's impulses start as the last settle (or attempt) left them: in a pile still
  // settling, its sweeps go on from there.
  std::vector<std::array<double, 2>> impulses;
  for (const auto& pair : pairs) {
    const auto [i, key] = pair;
    const Touch t = touch(i, key);
    const std::optional<std::size_t> other = ballOf(key);
    contacts.push_back({place.at(i), other ? std::optional(place.at(*other)) : std::nullopt,
                        t.separation.normal, std::max(t.gap, 0.0) / duration, key});
    frictions.push_back(frictionOf(i, key).friction);
    const auto last = settle_impulses_.find(pair);
    impulses.push_back(last != settle_impulses_.end() ? last->second : std::array<double, 2>{});
  }
  Settled settled = settleTogether(settling, inverse_masses, contacts, frictions, &impulses);
  settle_impulses_.clear();
  for (std::size_t k = 0; k < pairs.size(); ++k) settle_impulses_.emplace(pairs[k], impulses[k]);
  settled.contacts = std::move(contacts);
  settled.inverse_masses = std::move(inverse_masses);
  settled.members = members.list;
  return settled;
}

void World::moveOnSettled(const BallSet& members, Settled& settled, double duration) {
  reportSettledImpacts(settled, duration);
  // Those put to rest end where they are, still: the share's energy counts them so.
  const std::vector<std::size_t> still = stillIslands(settled, duration);
  for (const std::size_t l : still) {
    settled.velocities[l] = Vec2::Zero();
    if (balls_[settled.members[l]].friction > 0.0) settled.spins[l] = 0.0;
  }
  const double share = energyKeepingShare(settled, duration);
  letGoHeldContacts(members);
  // The others meet nothing to the step's end.
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    if (balls_[i].at_rest) continue;
    ballNow(i);  // (its course changes)
    accelerations_[i] = members.contains(i) ? Vec2::Zero() : gravity_;
    angular_accelerations_[i] = 0.0;
  }
  for (std::size_t l = 0; l < settled.members.size(); ++l) {
    Ball& ball = balls_[settled.members[l]];
    if (ball.at_rest) continue;
    ball.velocity = share * settled.velocities[l];
    ball.angular_velocity = share * settled.spins[l];
  }
  for (const std::size_t l : still) balls_[settled.members[l]].at_rest = true;
  for (std::size_t i = 0; i < balls_.size(); ++i) courses_[i] = courseOf(i);
  // Settled again next step while a settled ball is awake (without gravity nothing rests:
  // there, while one moves).
  for (const std::size_t i : settled.members)
    settling_ = settling_ || (!balls_[i].at_rest && (gravity_ != Vec2::Zero() ||
                                                     balls_[i].velocity != Vec2::Zero()));
}

std::vector<std::size_t> World::stillIslands(const Settled& settled, double duration) const {
  std::vector<std::size_t> still_balls;
  if (gravity_ == Vec2::Zero()) return still_balls;  // nothing to rest against
  const std::vector<RestingContact>& contacts = settled.contacts;
  // Islands of the contacts that push: a ball held up, not one merely near another. A ball
  // rests where it is, so it must touch what holds it (the searches that wake it look there).
  std::vector<RestingContact> pushing;
  std::vector<bool> touches(settled.members.size(), false);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (!(settled.pushes[k] > 0.0)) continue;
    pushing.push_back(contacts[k]);
    if (contacts[k].bias * duration > kContactSlop) continue;
    touches[contacts[k].ball] = true;
    if (contacts[k].other) touches[*contacts[k].other] = true;
  }
  // Slow before and after, so held up too: not at the turn of a swing.
  auto slow = [&](const Vec2& velocity, double spin, const Ball& b) {
    return velocity.norm() <= kSettledRestSpeed &&
           (b.friction == 0.0 || std::abs(spin) * b.radius <= kSettledRestSpeed);
  };
  auto still = [&](std::size_t l) {
    const Ball& b = balls_[settled.members[l]];
    return b.at_rest || (touches[l] && slow(b.velocity, b.angular_velocity, b) &&
                         slow(settled.velocities[l], settled.spins[l], b));
  };
  for (const std::vector<std::size_t>& island : contactIslands(pushing, settled.inverse_masses)) {
    std::vector<std::size_t> island_balls;  // as the contacts number them
    for (const std::size_t k : island) {
      island_balls.push_back(pushing[k].ball);
      if (pushing[k].other) island_balls.push_back(*pushing[k].other);
    }
    if (!std::all_of(island_balls.begin(), island_balls.end(), still)) continue;
    for (const std::size_t l : island_balls)
      if (!balls_[settled.members[l]].at_rest) still_balls.push_back(l);
  }
  std::sort(still_balls.begin(), still_balls.end());
  still_balls.erase(std::unique(still_balls.begin(), still_balls.end()), still_balls.end());
  return still_balls;
}

void World::reportSettledImpacts(const Settled& settled, double duration) {
  std::vector<Contact> hits;
  for (std::size_t k = 0; k < settled.contacts.size(); ++k) {
    const RestingContact& c = settled.contacts[k];
    const std::size_t i = settled.members[c.ball];
    const std::optional<std::size_t> other = ballOf(c.body);
    const Ball& ball = balls_[i];
    const double approach =
        -c.normal.dot(other ? Vec2(ball.velocity - balls_[*other].velocity) : ball.velocity);
    if (!(settled.pushes[k] > 0.0) || approach <= kRestingSpeed) continue;
    // About where the gap closes at the speed they come at.
    const double met = std::min(duration, c.bias * duration / approach);
    const Vec2 point = ball.position + ball.velocity * met - ball.radius * c.normal;
    const ContactKind kind = other                     ? ContactKind::kBall
                             : touch(i, c.body).curved ? ContactKind::kCap
                                                       : ContactKind::kSegment;
    hits.push_back({time_ + now_ + met, ball.id, kind,
                    other ? balls_[*other].id : segments_[*segmentOf(c.body)].id, point, c.normal,
                    approach, settled.pushes[k]});
  }
  std::stable_sort(hits.begin(), hits.end(),
                   [](const Contact& a, const Contact& b) { return a.time < b.time; });
  contacts_.insert(contacts_.end(), hits.begin(), hits.end());
}

double World::energyKeepingShare(const Settled& settled, double duration) const {
  // The energy at the end as a function of the share s, each ball moved on by s v t:
  // a s^2 + b s + c, against what they have now.
  double now = 0.0, a = 0.0, b = 0.0, c = 0.0;
  for (std::size_t l = 0; l < settled.members.size(); ++l) {
    const Ball& ball = balls_[settled.members[l]];
    if (ball.at_rest) continue;
    const double surface = ball.radius * ball.angular_velocity;
    const double settled_surface = ball.radius * settled.spins[l];
    now += ball.mass * (0.5 * ball.velocity.squaredNorm() + 0.5 * ball.inertia_factor * surface *
                        surface - gravity_.dot(ball.position));
    a += 0.5 * ball.mass * (settled.velocities[l].squaredNorm() +
                            ball.inertia_factor * settled_surface * settled_surface);
    b -= ball.mass * duration * gravity_.dot(settled.velocities[l]);
    c -= ball.mass * gravity_.dot(ball.position);
  }
  if (a + b + c <= now) return 1.0;
  // E(0) = c <= now < E(1): the larger root lies between.
  const double d = c - now;
  return std::clamp((-b + std::sqrt(std::max(0.0, b * b - 4.0 * a * d))) / (2.0 * a), 0.0, 1.0);
}

// Wakes a resting ball and, since they may rest on it, every resting ball touching it.
void World::wake(std::size_t ball) {
  if (!balls_[ball].at_rest) return;
  for (std::size_t i : restingClusterIndices(ball)) leaveRest(i);
}

void World::comeToRest(std::size_t i) {
  Ball& ball = ballNow(i);
  ball.at_rest = true;
  ball.velocity = Vec2::Zero();
  accelerations_[i] = Vec2::Zero();
  angular_accelerations_[i] = 0.0;
}

void World::leaveRest(std::size_t i) {
  Ball& ball = ballNow(i);
  ball.at_rest = false;
  if (i < waiting_velocities_.size() && waiting_velocities_[i]) {
    ball.velocity = *waiting_velocities_[i];
    waiting_velocities_[i].reset();
  }
  accelerations_[i] = freeAcceleration(i);  // until its contacts are held at the next event
}

}  // namespace ball_physics_sim::engine
