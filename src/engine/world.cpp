#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

namespace {

// Where fewer than one key in this many may move, pairsNearMoving asks the grid about each of
// them rather than take all its pairs: a query per key costs about twice a key's share of a
// pass over the cells (a 1,000-ball pile's grid: 44 us for every key, 20 for the pass), and a
// step asks two to four times, where the pass's pairs are kept until a box moves.
constexpr std::size_t kFewMovingShare = 4;

bool overlaps(const Ball& ball, const Segment& segment) {
  return surfaceGap(ball, segment) < -kContactSlop;
}

bool overlaps(const Ball& a, const Ball& b) { return surfaceGap(a, b) < -kContactSlop; }

// Throws std::invalid_argument naming the segment or ball that `ball` would overlap, passing
// over the ball `self` (the one being moved, when it is not being added).
void checkRoomFor(const Ball& ball, const std::vector<Segment>& segments,
                  const std::vector<Ball>& balls, std::optional<BallId> self = std::nullopt) {
  for (const Segment& segment : segments)
    if (overlaps(ball, segment))
      throw std::invalid_argument("ball would overlap segment " + std::to_string(segment.id));
  for (const Ball& other : balls)
    if (self != other.id && collide(ball, other) && overlaps(ball, other))
      throw std::invalid_argument("ball would overlap ball " + std::to_string(other.id));
}

// Throws std::invalid_argument if a rope's ends, at `end` and `far`, are farther apart than its
// length allows.
void checkRopeReaches(const Rope& rope, const Vec2& end, const Vec2& far) {
  const double distance = (end - far).norm();
  if (distance > rope.length + kContactSlop)
    throw std::invalid_argument("rope's length " + std::to_string(rope.length) +
                                " m is shorter than the " + std::to_string(distance) +
                                " m between its ends");
}

}  // namespace

World::World(const Vec2& gravity) : gravity_(Vec2::Zero()) { setGravity(gravity); }

BallId World::addBall(Ball ball) {
  checkBall(ball);
  checkRoomFor(ball, segments_, balls_);
  ball.id = next_ball_id_++;
  ball.at_rest = false;
  balls_.push_back(ball);
  clocks_.push_back(now_);
  is_looked_at_.push_back(false);
  settling_.emplace_back();
  held_.clear();  // keyed by index: a segment's key moves with the number of balls
  drives_.push_back(Vec2::Zero());
  accelerations_.push_back(Vec2::Zero());
  accelerations_.back() = freeAcceleration(balls_.size() - 1);
  angular_accelerations_.push_back(0.0);
  return ball.id;
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
  checkRopeReaches(rope, balls_[ball].position, other ? balls_[*other].position : rope.anchor);
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
    retryJams();
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
    retryJams();
    return true;
  }
  return false;
}

bool World::removeBall(BallId id) {
  const std::optional<std::size_t> i = indexOf(id);
  if (!i) return false;
  // What touches it wakes, and what rests on those, directly or through others; the resting
  // balls further beside and below hold still until struck, as a pile's do where a ball lands.
  wakeWhatItHoldsUp(*i);
  const auto tied = [id](const Rope& rope) { return rope.ball == id || rope.other_ball == id; };
  ropes_.erase(std::remove_if(ropes_.begin(), ropes_.end(), tied), ropes_.end());
  balls_.erase(balls_.begin() + *i);
  clocks_.erase(clocks_.begin() + *i);
  settling_.erase(settling_.begin() + *i);
  // Looked-at marks go by index, which the removal moves; a step looks at every ball anew.
  looked_at_.clear();
  is_looked_at_.assign(balls_.size(), false);
  indexRopeEnds();
  held_.clear();  // keyed by index; the next step holds what touches anew
  settle_impulses_.forget(WarmStarts::ballName(id));
  retryJams();
  accelerations_.erase(accelerations_.begin() + *i);
  drives_.erase(drives_.begin() + *i);
  for (std::size_t s = 0; s < sensors_.size(); ++s) in_sensors_.erase({id, s});
  angular_accelerations_.erase(angular_accelerations_.begin() + *i);
  return true;
}

bool World::setBallState(BallId id, const Vec2& position, const Vec2& velocity,
                         double angular_velocity) {
  const std::optional<std::size_t> i = indexOf(id);
  if (!i) return false;
  Ball moved = balls_[*i];
  moved.position = position;
  moved.velocity = velocity;
  moved.angular_velocity = angular_velocity;
  checkBall(moved);
  checkRoomFor(moved, segments_, balls_, id);
  for (std::size_t r = 0; r < ropes_.size(); ++r) {
    const auto& [end, other] = rope_ends_[r];
    if (end == *i)
      checkRopeReaches(ropes_[r], position, other ? balls_[*other].position : ropes_[r].anchor);
    else if (other == *i)
      checkRopeReaches(ropes_[r], position, balls_[end].position);
  }
  // Marked at rest, wake() takes it with the resting balls it touches: where it leaves, then
  // where it lands, so that none stays held up by, or sunk into, a ball no longer there.
  balls_[*i].at_rest = true;
  wake(*i);
  moved.at_rest = true;
  balls_[*i] = moved;
  wake(*i);
  held_.clear();  // its held contacts were where it left; the next step holds what touches anew
  settle_impulses_.forget(WarmStarts::ballName(id));  // (its pairs were where it left)
  settling_[*i] = Settling{};  // (it settles again only where it lands in a pile)
  retryJams();
  return true;
}

bool World::removeSegment(SegmentId id) {
  for (auto segment = segments_.begin(); segment != segments_.end(); ++segment) {
    if (segment->id != id) continue;
    wakeTouching(*segment);
    settle_impulses_.forget(WarmStarts::segmentName(id));
    segments_.erase(segment);
    held_.clear();  // keyed by index; the next step holds what touches anew
    retryJams();
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

double World::stepUntilStrike(double dt, BallId ball) {
  const double before = time_;
  strike_stop_ = indexOf(ball);
  try {
    step(dt);
  } catch (...) {
    strike_stop_.reset();
    throw;
  }
  strike_stop_.reset();
  return time_ - before;
}

std::uint64_t World::warmStartName(std::size_t key) const {
  if (const auto other = ballOf(key)) return WarmStarts::ballName(balls_[*other].id);
  return WarmStarts::segmentName(segments_[*segmentOf(key)].id);
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
  all.every_moving = true;
  return all;
}

void World::BallSet::reset(std::size_t balls) {
  if (has.size() != balls) {
    *this = BallSet(balls);
    return;
  }
  for (const std::size_t ball : list) has[ball] = false;
  list.clear();
  every_moving = false;
}

void World::BallSet::insert(std::size_t ball) {
  if (has[ball]) return;
  has[ball] = true;
  list.push_back(ball);
}

void World::BallSet::remove(const BallSet& other) {
  if (other.list.empty()) return;
  const std::size_t before = list.size();
  list.erase(std::remove_if(list.begin(), list.end(),
                            [&](std::size_t ball) { return other.contains(ball); }),
             list.end());
  if (list.size() != before) every_moving = false;
  for (const std::size_t ball : other.list) has[ball] = false;
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

const std::vector<std::size_t>& World::keysMet(std::size_t ball, const Box& box) const {
  std::vector<std::size_t>& keys = keys_met_;
  if (!balls_meet_) {
    segment_grid_.overlapping(box, keys);
    for (std::size_t& key : keys) key += balls_.size();
  } else {
    grid_.overlapping(box, keys);
    keys.erase(std::remove_if(keys.begin(), keys.end(),
                              [&](std::size_t key) { return !meets(ball, key); }),
               keys.end());
  }
  // In order: what is done with them in turn (hits passed on at one instant) must not hang on
  // the grid's cells, which every body in the world lays out.
  std::sort(keys.begin(), keys.end());
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

bool World::stillTogether(std::size_t ball, std::size_t key) const {
  if (!balls_[ball].at_rest) return false;
  if (const auto other = ballOf(key)) return balls_[*other].at_rest;
  const auto segment = segmentOf(key);
  return segment && !moves(segments_[*segment]);
}

const std::vector<std::pair<std::size_t, std::size_t>>& World::pairsNearMoving() const {
  const std::size_t n = balls_.size();
  moving_keys_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (!balls_[i].at_rest) moving_keys_.push_back(i);
  for (const std::size_t k : movable_segments_) moving_keys_.push_back(n + k);
  if (kFewMovingShare * moving_keys_.size() >= n + segments_.size()) return grid_.pairs();
  grid_.pairsOf(moving_keys_, moving_pairs_);
  return moving_pairs_;
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

void World::wakeTouching(const Segment& segment) {
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    if (balls_[i].at_rest && surfaceGap(ballNow(i), segment) <= kRestingGap) wake(i);
  }
}

std::vector<std::size_t> World::restingClusterIndices(std::size_t ball, std::size_t hops,
                                                      bool above, const Vec2& ahead) const {
  std::vector<bool> taken(balls_.size(), false);
  // Breadth first, each ball with the touches that reached it.
  std::vector<std::size_t> cluster, pending{ball}, hops_to{0};
  taken[ball] = true;
  std::size_t i_hops = 0;
  auto take = [&](std::size_t j) {
    if (taken[j] || !balls_[j].at_rest || i_hops == hops) return;
    taken[j] = true;
    pending.push_back(j);
    hops_to.push_back(i_hops + 1);
  };
  // The resting balls in a grid, each box grown to reach what it touches: a pile's cluster is
  // found in time about linear in the world's balls, not in their number times its own.
  std::vector<std::size_t> resting;
  std::vector<Box> boxes;
  for (std::size_t j = 0; j < balls_.size(); ++j)
    if (balls_[j].at_rest) {
      resting.push_back(j);
      boxes.push_back(ballBox(ballNow(j).position, balls_[j].radius + kRestingGap));
    }
  BoxGrid grid;
  grid.reset(boxes);
  std::vector<std::size_t> near;
  for (std::size_t next = 0; next < pending.size(); ++next) {
    const std::size_t i = pending[next];
    i_hops = hops_to[next];
    cluster.push_back(i);
    grid.overlapping(ballBox(ballNow(i).position, ballNow(i).radius), near);
    std::sort(near.begin(), near.end());  // (in the order of the balls, as ever)
    for (const std::size_t k : near)
      if (const std::size_t j = resting[k];
          !taken[j] && meets(i, j) && surfaceGap(ballNow(i), ballNow(j)) <= kRestingGap &&
          (!above || i == ball || pressesOn(j, i)) &&
          (ahead == Vec2::Zero() ||
           pushesToward(ahead, ballNow(j).position - ballNow(i).position)))
        take(j);
    for (std::size_t r = 0; r < ropes_.size(); ++r) {  // a ball may hang from it, taut
      const auto& [end, other] = rope_ends_[r];
      if (other && (end == i || *other == i) &&
          touch(end, balls_.size() + segments_.size() + r).gap <= kRestingGap)
        take(end == i ? *other : end);
    }
  }
  return cluster;
}

bool World::pressesOn(std::size_t ball, std::size_t other) const {
  return freeAcceleration(ball).dot(ballNow(other).position - ballNow(ball).position) > 0.0;
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

// Wakes a resting ball and, since they may rest on it, every resting ball touching it.
void World::wake(std::size_t ball) {
  if (!balls_[ball].at_rest) return;
  for (std::size_t i : restingClusterIndices(ball)) leaveRest(i);
}

void World::wakeWhatItHoldsUp(std::size_t ball) {
  for (const std::size_t i :
       restingClusterIndices(ball, std::numeric_limits<std::size_t>::max(), true))
    leaveRest(i);
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
  settling_[i].slow_since = std::numeric_limits<double>::infinity();  // (woken, not slow yet)
  if (i < waiting_velocities_.size() && waiting_velocities_[i]) {
    ball.velocity = *waiting_velocities_[i];
    waiting_velocities_[i].reset();
  }
  accelerations_[i] = freeAcceleration(i);  // until its contacts are held at the next event
}

}  // namespace ball_physics_sim::engine
