// World: what wakes a resting ball that a settle reaches: a strike, a moving segment, or an
// island driven by a steady push the ball does not feel.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <limits>

#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/forces.h"
#include "ball_physics_sim/engine/kinematics.h"

namespace ball_physics_sim::engine {

namespace {

// A resting ball struck wakes with the resting balls this few touches from it: those beyond
// hold still, as a floor would, and a strike on a sleeping pile is settled where it lands.
constexpr std::size_t kStruckHops = 2;

}  // namespace

bool World::wakeStruck(const KeyPairs& pairs, std::vector<Vec2>& free, double duration,
                       std::vector<std::size_t>& woken) {
  bool woke = false;
  const auto wakeNear = [&](std::size_t struck, std::size_t hops, const Vec2& ahead) {
    for (const std::size_t j : restingClusterIndices(struck, hops, false, ahead)) {
      leaveRest(j);
      free[j] = settledFreeVelocity(j, duration);
      woken.push_back(j);
    }
    woke = true;
  };
  SteadyLoads loads = steadyLoadsOf(pairs);
  for (const auto& [i, key] : pairs) {
    const std::optional<std::size_t> other = ballOf(key);
    const bool segment_reaches_rest = !other && balls_[i].at_rest;
    if (!segment_reaches_rest && (!other || !balls_[*other].at_rest)) continue;
    const Touch t = touch(i, key);
    if (segment_reaches_rest) {
      // A moving segment that reaches a resting ball over the stretch, however slowly, wakes
      // it and every resting ball touching it, through others too: it pushes them on, unlike a
      // strike, which the balls beyond two touches hold.
      // (A turning one closes faster than along a straight line: as the stretch carries
      // their contact.)
      const double closing =
          !turns(segments_[*segmentOf(key)])
              ? -t.separation.normal.dot(t.relative_velocity) * duration
              : t.separation.distance - carriedSeparationOf(i, key, t, duration).distance;
      if (closing > 0.0 && t.gap <= closing)
        wakeNear(i, std::numeric_limits<std::size_t>::max(), Vec2::Zero());
      continue;
    }
    // Struck: coming at it faster than lasting contact does, near enough to meet in the stretch
    // (a ball lying on it, landing on it gently or creeping against it does not wake it).
    const double approach = -t.separation.normal.dot(balls_[i].velocity);
    if (strikesWithin(approach, t.gap, duration))
      wakeNear(*other, kStruckHops, Vec2::Zero());  // (and those ahead, if pushed on too)
    // Pushed on by an island that a steady push it does not feel itself drives toward it (a
    // drive, a wind it is out of), touching it or meeting it in the stretch: it is pushed on,
    // as by a moving segment, and the resting balls ahead of it along the push. Held still, it
    // would hold the island at rest against the push, through a row of balls too.
    if (loads.force.empty()) continue;
    const std::size_t island = loads.joined.find(i);
    const Vec2 own = steadyPush(*other);
    if (!loads.mixed[island] && loads.push[island] == own) continue;  // the push it feels too
    const Vec2 beyond = loads.force[island] - loads.mass[island] * own;
    const double closing = -t.separation.normal.dot(free[i]) * duration;
    if (t.gap <= std::max(kRestingGap, closing) && beyond != Vec2::Zero() &&
        pushesToward(beyond, -t.separation.normal))
      wakeNear(*other, std::numeric_limits<std::size_t>::max(), beyond);
  }
  return woke;
}

World::SteadyLoads World::steadyLoadsOf(const KeyPairs& pairs) const {
  SteadyLoads loads{DisjointSets(0), {}, {}, {}, {}};
  const auto pushedBall = [&](std::optional<std::size_t> j) {
    return j && !balls_[*j].at_rest && steadyPush(*j) != Vec2::Zero();
  };
  const bool pushed = std::any_of(pairs.begin(), pairs.end(), [&](const auto& pair) {
    return pushedBall(pair.first) || pushedBall(ballOf(pair.second));
  });
  if (!pushed) return loads;
  const std::size_t n = balls_.size();
  loads.joined = DisjointSets(n);
  for (const auto& [i, key] : pairs)
    if (const auto other = ballOf(key); other && !balls_[i].at_rest && !balls_[*other].at_rest)
      loads.joined.join(i, *other);
  loads.force.assign(n, Vec2::Zero());
  loads.mass.assign(n, 0.0);
  loads.push.assign(n, Vec2::Zero());
  loads.mixed.assign(n, false);
  std::vector<bool> counted(n, false);
  for (const auto& [i, key] : pairs)
    for (const std::optional<std::size_t> j : {std::optional(i), ballOf(key)}) {
      if (!j || balls_[*j].at_rest || counted[*j]) continue;
      counted[*j] = true;
      const std::size_t island = loads.joined.find(*j);
      const Vec2 push = steadyPush(*j);
      if (loads.mass[island] == 0.0)
        loads.push[island] = push;
      else
        loads.mixed[island] = loads.mixed[island] || push != loads.push[island];
      loads.force[island] += balls_[*j].mass * push;
      loads.mass[island] += balls_[*j].mass;
    }
  return loads;
}

}  // namespace ball_physics_sim::engine
