// World: what a settle does to its balls: their settled velocities and straight courses, the
// islands that rest, the hits reported, and the energy it keeps from growing.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/impulse.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/settle.h"

namespace ball_physics_sim::engine {

namespace {

// A settled ball this slow before and after its settle, touching what holds it up (within
// kRestingGap), is still, and rests: it moves 2e-6 m in a 1/60 s step.
constexpr double kSettledRestSpeed = 1e-4;  // m/s
// A settled ball touching what holds it up rests too once its settles have left it slower than
// this for kTimeToSleep (Box2D's sleep rule; its tolerance is 0.05 m/s): an island's settles
// stop short of stilling its balls to kSettledRestSpeed, and a ball rolling this slowly on a
// floor would roll on for hours.
constexpr double kSleepSpeed = 1e-2;  // m/s
constexpr double kTimeToSleep = 0.5;  // s
// Whether a ball is slower than `speed` at these velocities, its surface too if it is rough.
bool slowerThan(double speed, const Vec2& velocity, double spin, const Ball& ball) {
  return velocity.norm() <= speed &&
         (ball.friction == 0.0 || std::abs(spin) * ball.radius <= speed);
}

}  // namespace

void World::moveOnSettled(Settled& settled, double duration) {
  reportSettledImpacts(settled, duration);
  // Slowed to keep energy, then those put to rest end where they are, still, and the share's
  // energy counts them so.
  const double slowed = energyKeepingShare(settled, duration);
  for (Vec2& v : settled.velocities) v *= slowed;
  for (double& w : settled.spins) w *= slowed;
  for (std::size_t l = 0; l < settled.members.size(); ++l) {
    const std::size_t i = settled.members[l];
    if (balls_[i].at_rest) continue;
    double& since = settling_[i].slow_since;
    if (!slowerThan(kSleepSpeed, settled.velocities[l], settled.spins[l], balls_[i]))
      since = std::numeric_limits<double>::infinity();
    else
      since = std::min(since, time_ + now_);
  }
  const std::vector<std::size_t> still = stillIslands(settled, duration);
  for (const std::size_t l : still) {
    settled.velocities[l] = Vec2::Zero();
    if (balls_[settled.members[l]].friction > 0.0) settled.spins[l] = 0.0;
  }
  const double share = energyKeepingShare(settled, duration);
  for (std::size_t l = 0; l < settled.members.size(); ++l) {
    const std::size_t i = settled.members[l];
    Ball& ball = ballNow(i);  // (its course changes: settled, if nothing else)
    settled_.insert(i);
    queueHoldEnd(i, std::numeric_limits<double>::infinity());  // (no hold is theirs)
    if (ball.at_rest) continue;
    accelerations_[i] = Vec2::Zero();
    angular_accelerations_[i] = 0.0;
    ball.velocity = share * settled.velocities[l];
    ball.angular_velocity = share * settled.spins[l];
  }
  for (const std::size_t l : still) balls_[settled.members[l]].at_rest = true;
  recordUnheld(settled, duration);
  // Settled again next step while awake (without gravity nothing rests: there, while moving).
  for (const std::size_t i : settled.members)
    settling_[i].goes_on = !balls_[i].at_rest &&
                           (gravity_ != Vec2::Zero() || balls_[i].velocity != Vec2::Zero());
}

std::vector<std::size_t> World::stillIslands(const Settled& settled, double duration) const {
  std::vector<std::size_t> still_balls;
  if (gravity_ == Vec2::Zero()) return still_balls;  // nothing to rest against
  // The contacts that push: a ball held up, not one merely near another.
  std::vector<RestingContact> pushing;
  for (std::size_t k = 0; k < settled.contacts.size(); ++k)
    if (settled.pushes[k] > 0.0) pushing.push_back(settled.contacts[k]);
  // A ball rests where it is, so it must touch what holds it (the searches that wake it look
  // there).
  std::vector<bool> touches(settled.members.size(), false);
  for (const RestingContact& c : pushing) {
    if (touch(settled.members[c.ball], c.body).gap > kRestingGap) continue;
    touches[c.ball] = true;
    if (c.other) touches[*c.other] = true;
  }
  // A ball a moving segment may meet over the stretch does not rest (nor one it was stopped
  // against for the rest of the step: stopSegment), and nor do the balls it pushes, and
  // theirs: resting, they would be struck awake again and again, or crushed (as in Box2D, a
  // moving body keeps its island awake). (No segment may move: none is carried.)
  std::vector<bool> carried(settled.members.size(), false);
  if (!movable_segments_.empty()) {
    DisjointSets pushed_together(settled.members.size());
    for (const RestingContact& c : pushing)
      if (c.other) pushed_together.join(c.ball, *c.other);
    for (const RestingContact& c : settled.contacts)
      if (const auto k = segmentOf(c.body); k && (moves(segments_[*k]) || stoppedInStep(*k)))
        carried[pushed_together.find(c.ball)] = true;
    for (std::size_t l = 0; l < carried.size(); ++l)
      carried[l] = carried[pushed_together.find(l)];
  }
  // Slow before and after, so held up too (not at the turn of a swing), or slow for long.
  const double end = time_ + now_ + duration;
  std::vector<bool> still(settled.members.size());
  for (std::size_t l = 0; l < still.size(); ++l) {
    const std::size_t i = settled.members[l];
    const Ball& b = balls_[i];
    const bool slow = slowerThan(kSettledRestSpeed, b.velocity, b.angular_velocity, b) &&
                      slowerThan(kSettledRestSpeed, settled.velocities[l], settled.spins[l], b);
    // (Not one a drive or a wind pushes: creeping on under it, it would be put to rest with the
    // push still on, for good.)
    const bool slow_for_long =
        end - settling_[i].slow_since >= kTimeToSleep && steadyPush(i) == Vec2::Zero();
    still[l] = b.at_rest || (touches[l] && !carried[l] && (slow || slow_for_long));
  }
  // A still ball that a moving one pushes stays awake, between them: a ball put to rest
  // where a moving one presses on it would be struck awake again and again.
  std::vector<bool> pressed(still.size(), false);
  for (const RestingContact& c : pushing)
    if (c.other && still[c.ball] != still[*c.other])
      pressed[c.ball] = pressed[*c.other] = true;  // (the moving one is not still anyway)
  for (std::size_t l = 0; l < still.size(); ++l)
    still[l] = still[l] && (!pressed[l] || balls_[settled.members[l]].at_rest);
  // Islands of the pushing contacts among the other still balls, and between them and what
  // does not move (a segment, a resting ball): each that what does not move holds up rests,
  // whatever the balls beyond it do. A pile rained on sleeps where it is still.
  std::vector<RestingContact> among_still;
  for (const RestingContact& c : pushing)
    if (still[c.ball] && (!c.other || still[*c.other])) among_still.push_back(c);
  for (const std::vector<std::size_t>& island :
       contactIslands(among_still, settled.inverse_masses)) {
    const bool held_up = std::any_of(island.begin(), island.end(), [&](std::size_t k) {
      return !among_still[k].other || settled.inverse_masses[*among_still[k].other] == 0.0;
    });
    if (!held_up) continue;
    for (const std::size_t k : island)
      for (const std::optional<std::size_t> l :
           {std::optional(among_still[k].ball), among_still[k].other})
        if (l && !balls_[settled.members[*l]].at_rest) still_balls.push_back(*l);
  }
  std::sort(still_balls.begin(), still_balls.end());
  still_balls.erase(std::unique(still_balls.begin(), still_balls.end()), still_balls.end());
  return still_balls;
}

void World::recordUnheld(const Settled& settled, double duration) {
  for (const RestingContact& c : settled.contacts) {
    if (!c.other) continue;
    for (const auto& [l, m] : {std::pair(c.ball, *c.other), std::pair(*c.other, c.ball)}) {
      // (Resting through the settle: one it put to rest is held up by what does not move.)
      const std::size_t resting = settled.members[l], moving = settled.members[m];
      if (settled.inverse_masses[l] != 0.0 || !balls_[resting].at_rest ||
          balls_[moving].at_rest || !pressesOn(resting, moving))
        continue;
      const Ball& on = ballNow(resting);
      Ball under = ballNow(moving);
      const double held_within = kMostSettledOverlap * std::min(on.radius, under.radius);
      if (surfaceGap(on, under) > held_within) continue;
      under.position += under.velocity * duration;  // (its straight course)
      if (surfaceGap(on, under) > held_within) unheld_.push_back(resting);
    }
  }
}

void World::wakeUnheld() {
  for (const std::size_t i : unheld_)
    if (balls_[i].at_rest) wakeWhatItHoldsUp(i);
  unheld_.clear();
}

void World::reportSettledImpacts(const Settled& settled, double duration) {
  std::vector<Contact> hits;
  for (std::size_t k = 0; k < settled.contacts.size(); ++k) {
    const RestingContact& c = settled.contacts[k];
    const std::size_t i = settled.members[c.ball];
    const std::optional<std::size_t> other = ballOf(c.body);
    const Ball& ball = balls_[i];
    const Vec2 against = other ? balls_[*other].velocity
                               : velocityUnder(segments_[*segmentOf(c.body)], ball.position);
    // (A turning segment's row is along its normal where the segment carries the contact: a
    // hit is met along the normal now.)
    const Vec2 normal = !other && turns(segments_[*segmentOf(c.body)])
                            ? touch(i, c.body).separation.normal
                            : c.normal;
    const double approach = -normal.dot(ball.velocity - against);
    if (!(settled.pushes[k] > 0.0) || approach <= kRestingSpeed) continue;
    // About where the gap closes at the speed they come at.
    const Touch t = touch(i, c.body);
    const double met = std::min(duration, std::max(t.gap, 0.0) / approach);
    const Vec2 point = ball.position + ball.velocity * met - ball.radius * normal;
    const ContactKind kind = other      ? ContactKind::kBall
                             : t.curved ? ContactKind::kCap
                                        : ContactKind::kSegment;
    hits.push_back({time_ + now_ + met, ball.id, kind,
                    other ? balls_[*other].id : segments_[*segmentOf(c.body)].id, point, normal,
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
    // A ball an earlier settle of the step sent on straight, against what it ends with so: that
    // settle kept its energy (and a segment under it paid for its climb).
    const Vec2 goes_to = isSettled(settled.members[l])
                             ? Vec2(ball.position + duration * ball.velocity)
                             : ball.position;
    // Its pull as the settle takes it, uniform over the stretch: its potential is -pull.x
    // (drag aside: what drag takes is lost).
    const Vec2 pull = settlePull(settled.members[l], duration);
    now += ball.mass * (0.5 * ball.velocity.squaredNorm() + 0.5 * ball.inertia_factor * surface *
                        surface - pull.dot(goes_to));
    a += 0.5 * ball.mass * (settled.velocities[l].squaredNorm() +
                            ball.inertia_factor * settled_surface * settled_surface);
    b -= ball.mass * duration * pull.dot(settled.velocities[l]);
    c -= ball.mass * pull.dot(ball.position);
  }
  now += settled.work;  // (what moving segments put in)
  if (a + b + c <= now) return 1.0;
  // E(0) = c <= now < E(1): the larger root lies between.
  const double d = c - now;
  return std::clamp((-b + std::sqrt(std::max(0.0, b * b - 4.0 * a * d))) / (2.0 * a), 0.0, 1.0);
}

}  // namespace ball_physics_sim::engine
