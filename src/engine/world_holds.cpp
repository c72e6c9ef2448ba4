// World: lasting contact held by the forces of resting contact (holds): the accelerations of
// touching balls found exactly, kept until an event or the contacts' lifetimes end.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/friction.h"
#include "ball_physics_sim/engine/impulse.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

namespace {

// Accelerations below this are what is left of gravity where normal forces cancel it, once
// the contact solve has converged: the ball is held.
constexpr double kRestingAcceleration = 1e-9;  // m/s^2

// A touching contact separating slower than this is held like a resting one: the inelastic
// push leaves rounding of this order (a few 1e-9 m/s where a light ball is wedged under a heavy
// one on a floor), and left free the ball would fall back at once, again and again, in a
// sequence of zero-time impacts that uses up the step. A ball held still and slower than this
// (its surface turning slower too) is put to rest: held, such a contact keeps its speed.
constexpr double kHeldSeparationSpeed = 1e-6;  // m/s

// Whether the ball's contacts can have friction or rolling resistance: a pair's is the geometric
// mean, zero if either body has none.
bool isRough(const Ball& ball) { return ball.friction > 0.0 || ball.rolling_resistance > 0.0; }

}  // namespace

World::KeyPairs World::touchingPairs(const BallSet& from) const {
  KeyPairs pairs;
  BallSet& reached = touching_reached_;
  reached.reset(balls_.size());
  std::vector<std::size_t>& pending = touching_pending_;
  pending.clear();
  // (A settled ball's settle holds it.)
  auto reach = [&](std::size_t ball) {
    if (reached.contains(ball) || balls_[ball].at_rest || isSettled(ball)) return;
    reached.insert(ball);
    pending.push_back(ball);
  };
  // Whether a ball that moves touches the body `key` names, or nearly does.
  auto consider = [&](std::size_t i, std::size_t key) {
    const std::optional<std::size_t> other = ballOf(key);
    if (isSettled(i) || (other && isSettled(*other))) return;
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
  // From every moving ball, all at once the pairs that hold one (pairsNearMoving), not
  // a query per ball (unless the grid is full of balls that do not meet).
  const std::size_t n = balls_.size();
  const bool all_at_once = from.every_moving && balls_meet_;
  // (Each moving ball of a pair is reached, for its ropes: one woken since `from` was made
  // too, see wakePushedSideways.)
  if (all_at_once)
    for (const auto& [ball, key] : pairsNearMoving()) {
      if (ball >= n || !meets(ball, key)) continue;
      if (!balls_[ball].at_rest) {
        reach(ball);
        consider(ball, key);
      } else if (key < n && !balls_[key].at_rest) {
        reach(key);
        consider(key, ball);
      }
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

bool World::held(std::size_t ball, std::size_t key) const {
  return heldForces(ball, key) != nullptr;
}

const ContactForces* World::heldForces(std::size_t ball, std::size_t key) const {
  if (const ContactForces* forces = held_.find({ball, key})) return forces;
  // Held from its other ball: a ball pair under that ball's key for this one, a rope under its own.
  const std::optional<std::size_t> other = otherBallOf(ball, key);
  if (!other) return nullptr;
  return held_.find({*other, ropeOf(key) ? key : ball});
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
  // The pushes are found as if the held contacts did not separate (Baraff's), but one may be
  // separating slower than kHeldSeparationSpeed (a bounce of restitution near 0): its push
  // would do work N v for the whole hold. It stops separating, perfectly inelastic along the
  // normal: momentum is kept, and kinetic energy only lowered in the frame of what it touches.
  auto stopSeparation = [this](std::size_t ball, std::size_t key) {
    const Touch t = touch(ball, key);
    const double separation = t.relative_velocity.dot(t.separation.normal);
    const std::optional<std::size_t> other = otherBallOf(ball, key);
    const double own = inverseMassOf(ball), others = other ? inverseMassOf(*other) : 0.0;
    if (!(separation > 0.0) || !(own + others > 0.0)) return;
    const Vec2 impulse = normalImpulse(separation, 0.0, own + others) * t.separation.normal;
    ballNow(ball).velocity -= own * impulse;
    if (other) ballNow(*other).velocity += others * impulse;
  };
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
    if (rates.forces[k].normal > 0.0) stopSeparation(held_contacts[k].ball, c.body);
    if (rates.forces[k].normal > 0.0 &&
        held_.add(contact, otherBallOf(contact.first, contact.second), rates.forces[k]))
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
  for (const HeldContacts::Contact& contact : held_.of(balls.list)) {
    held_changes_.emplace_back(contact, true);
    held_.erase(contact);
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
    // The island's hold lasts until the first of its ropes drifts, or the motion of a segment
    // it touches changes: each rope is pulled as at the middle of that.
    double hold = step_left_;
    for (const std::size_t k : island)
      if (const auto segment = segmentOf(contacts[k].body);
          segment && std::count(movable_segments_.begin(), movable_segments_.end(), *segment))
        hold = std::min(hold, timeToSegmentEvent());
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
  for (const auto& [i, key] : held_.of(held_anew.list)) {
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

ContactFriction World::frictionOf(std::size_t ball, std::size_t key) const {
  if (ropeOf(key)) return {};  // a rope pulls along itself only
  const Ball& b = ballNow(ball);
  const Touch t = touch(ball, key);
  if (const auto other = ballOf(key)) {
    const Ball& o = ballNow(*other);
    return {coulombFrictionOf(ball, key), 0.0,
            slipSpeed(t.relative_velocity, t.separation.normal, b.radius, b.angular_velocity,
                      o.radius * o.angular_velocity)};
  }
  const Segment& segment = segments_[*segmentOf(key)];
  return {coulombFrictionOf(ball, key),
          combinedFriction(b.rolling_resistance, segment.rolling_resistance),
          slipSpeed(t.relative_velocity, t.separation.normal, b.radius, b.angular_velocity, 0.0)};
}

double World::coulombFrictionOf(std::size_t ball, std::size_t key) const {
  if (ropeOf(key)) return 0.0;
  const auto other = ballOf(key);
  return combinedFriction(balls_[ball].friction,
                          other ? balls_[*other].friction : segments_[*segmentOf(key)].friction);
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
  for (const auto& [ball, key] : held_.of(balls.list)) closeContact(ball, key, true);
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

bool World::holdEndComesFirst(std::size_t a, std::size_t b) const {
  return hold_ends_[a] < hold_ends_[b];
}

void World::queueHoldEnd(std::size_t ball, double end) {
  if (hold_ends_[ball] == end) return;
  hold_ends_[ball] = end;
  hold_end_queue_.update(ball,
                         [this](std::size_t a, std::size_t b) { return holdEndComesFirst(a, b); });
}

}  // namespace ball_physics_sim::engine
