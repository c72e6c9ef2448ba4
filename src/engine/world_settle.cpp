// World: settles. Piles settle from a step's start, and what meets a settled ball settles with
// it for the rest of the step, island by island.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/friction.h"
#include "ball_physics_sim/engine/impulse.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/settle.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

namespace {

// A settle's pairs are sought again, farther, at most this many times, when it takes a ball
// farther from its untouched path than they were sought within, onto a body they do not pair it
// with (meetUnpaired): then this many times as far.
constexpr int kSettleAttempts = 4;
constexpr double kSettleReachGrowth = 1.5;
// A turning segment's contact is held when its motion changes (see settleMembers), unless
// that comes within this share of the stretch: a bias over so short a time is rounding.
constexpr double kSoonestChange = 1e-6;
// Balls touching together, this many or more, are a pile: moving in lasting contact, they settle
// from the step's start as an island (held, each of their events would hold the group anew,
// milliseconds a step for a few balls landing on each other), and resting, struck, they settle
// where they are struck (pushed apart by holds, a settled pile's overlaps would lift it). A
// pair or a triple is held exactly, at little cost: stacks and pyramids of three stand and
// fall as the friction limit says, and pass a strike on exactly.
constexpr std::size_t kPileBalls = 4;
// The smallest box holding both.
Box enclosing(const Box& a, const Box& b) { return {a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)}; }

}  // namespace

void World::settleAtStart(double dt) {
  settled_.reset(balls_.size());
  BallSet seeds(balls_.size());
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    if (settling_[i].goes_on && !balls_[i].at_rest)
      seeds.insert(i);
    else
      settling_[i] = Settling{};  // (it settles anew, if at all)
    settling_[i].goes_on = false;
  }
  if (pilesForm()) seedLastingContacts(dt, seeds);
  // A pile's settles go on from its last impulses, and a pile asleep wakes with them (as in
  // Box2D).
  if (settle_impulses_.startStep()) {
    std::vector<std::uint64_t> awake;
    for (const Ball& ball : balls_)
      if (!ball.at_rest) awake.push_back(WarmStarts::ballName(ball.id));
    std::sort(awake.begin(), awake.end());
    settle_impulses_.forgetStale(awake);
  }
  if (!seeds.list.empty()) settleRestOfStep(dt, seeds);
}

void World::seedLastingContacts(double dt, BallSet& seeds) const {
  // (A world asleep has no pile to settle.)
  if (std::all_of(balls_.begin(), balls_.end(), [](const Ball& ball) { return ball.at_rest; }))
    return;
  const std::size_t n = balls_.size();
  const double lasting = lastingApproach(dt);
  DisjointSets piles(n);
  std::vector<std::size_t> size(n, 1);
  for (const auto& [ball, key] : touchingPairs(awakeOrHeld())) {
    const std::optional<std::size_t> other = ballOf(key);
    if (!other || balls_[*other].at_rest) continue;
    const Touch t = touch(ball, key);
    if (t.gap > kRestingGap || std::abs(t.separation.normal.dot(t.relative_velocity)) > lasting)
      continue;
    const std::size_t a = piles.find(ball), b = piles.find(*other);
    if (a == b) continue;
    piles.join(a, b);
    size[b] += size[a];
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!balls_[i].at_rest && size[piles.find(i)] >= kPileBalls) seeds.insert(i);
}

bool World::pilesForm() const {
  // (Without gravity nothing piles up: touching balls there meet as exact impacts.)
  return gravity_ != Vec2::Zero();
}

double World::lastingApproach(double duration) const {
  return std::max(kRestingSpeed, gravity_.norm() * duration);
}

bool World::strikesWithin(double approach, double gap, double duration) const {
  return approach > lastingApproach(duration) && gap <= approach * duration;
}

double World::restitutionOf(std::size_t ball, std::size_t key) const {
  const double own = balls_[ball].restitution;
  if (const auto other = ballOf(key)) return combinedRestitution(own, balls_[*other].restitution);
  return combinedRestitution(own, segments_[*segmentOf(key)].restitution);
}

bool World::settlesOnImpact(const Impact& impact, double remaining) {
  const std::optional<std::size_t> other = otherBallOf(impact.ball, keyOf(impact));
  // A resting ball struck wakes the resting balls it touches, a settled one among them too. A
  // pile asleep settles where it is struck (wakeStruck): held exactly, it would be held anew at
  // every event of the step (seconds a step for a few hundred balls).
  const bool piles = pilesForm();
  auto meetsSettled = [&](std::size_t ball) {
    if (isSettled(ball)) return true;
    if (!balls_[ball].at_rest || (settled_.list.empty() && !piles)) return false;
    const std::vector<std::size_t> cluster = restingClusterIndices(ball);
    return (piles && cluster.size() >= kPileBalls) ||
           std::any_of(cluster.begin(), cluster.end(),
                       [this](std::size_t j) { return isSettled(j); });
  };
  if (!meetsSettled(impact.ball) && !(other && meetsSettled(*other))) return false;
  BallSet seeds(balls_.size());
  seeds.insert(impact.ball);
  if (other) seeds.insert(*other);
  // (An island beside the one it meets may settle where that one cannot: unless both its balls
  // are settled now, the impact is met as ever.)
  return settleRestOfStep(remaining, seeds) ||
         (isSettled(impact.ball) && (!other || isSettled(*other)));
}

bool World::isSettled(std::size_t ball) const {
  return ball < settled_.has.size() && settled_.contains(ball);
}

bool World::settleRestOfStep(double remaining, const BallSet& seeds) {
  if (!(remaining > 0.0)) return false;
  const std::size_t n = balls_.size();
  // Each ball's velocity at the end, untouched: a settled one's is its straight path's.
  std::vector<Vec2> free(n, Vec2::Zero());
  for (std::size_t i = 0; i < n; ++i)
    if (!balls_[i].at_rest)
      free[i] = isSettled(i) ? ballNow(i).velocity : settledFreeVelocity(i, remaining);
  // As fast as its island's last settle took a ball off its untouched path, and half as fast
  // again, over the stretch: a pile's settles take its balls a little faster from step to step
  // while it gathers speed, and each search outreached is a settle made again. A ball new to
  // settling may be stopped.
  std::vector<double> reach(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double last = settling_[i].off_path;
    reach[i] = kSettleReachGrowth * (last > 0.0 ? last : free[i].norm()) * remaining;
  }
  std::vector<std::size_t> woken;  // put back to rest if their island does not settle
  // Each island settles on its own, and one that outreaches its search is sought again alone:
  // the islands that kept within theirs wait, settled, unless the search joins them to it.
  // Those that settle move on, whatever becomes of the others.
  std::vector<SettledIsland> ready;
  BallSet left = seeds;
  bool left_out = false;  // an island that cannot settle
  for (int attempt = 0; attempt < kSettleAttempts && !left.list.empty(); ++attempt) {
    BallSet members(n);
    KeyPairs pairs = settlingPairs(free, reach, remaining, left, members, left_out);
    if (wakeStruck(pairs, free, remaining, woken)) continue;
    // (A resting ball's pair with a moving segment is there for wakeStruck only.)
    pairs.erase(std::remove_if(pairs.begin(), pairs.end(),
                               [&](const auto& pair) {
                                 return balls_[pair.first].at_rest && segmentOf(pair.second);
                               }),
                pairs.end());
    ready.erase(std::remove_if(ready.begin(), ready.end(),
                               [&](const SettledIsland& island) {
                                 return std::any_of(
                                     island.members.begin(), island.members.end(),
                                     [&](std::size_t i) { return members.contains(i); });
                               }),
                ready.end());
    left.reset(n);
    std::vector<SettledIsland> islands = islandsOf(pairs);
    // A ball alone among segments (one that has left its pile), in flight or coming at one
    // faster than lasting contact does, is left to events, exact: it follows its parabola and
    // bounces off a wall as its restitution says. (Lying on one, within kRestingGap, it settles
    // on, and sleeps as a pile does; settled already in the step, it settles again, as its
    // event asks.)
    const auto alone = [&](const SettledIsland& island) {
      if (island.members.size() != 1 || isSettled(island.members.front())) return false;
      bool lies = false;
      for (const auto& [ball, key] : island.pairs) {
        const Touch t = touch(ball, key);
        const double approach = -t.separation.normal.dot(t.relative_velocity);
        if (strikesWithin(approach, t.gap, remaining)) return true;
        lies = lies || t.gap <= kRestingGap;
      }
      return !lies;
    };
    // (Tested once each: it finds their touches.)
    const auto alone_from = std::remove_if(islands.begin(), islands.end(), alone);
    if (alone_from != islands.end()) left_out = true;
    islands.erase(alone_from, islands.end());
    for (SettledIsland& island : islands) {
      island.settled = settleIsland(island, free, remaining, woken);
      for (std::size_t l = 0; l < island.members.size(); ++l) {
        const std::size_t i = island.members[l];
        if (balls_[i].at_rest) continue;
        const double away = (island.settled.velocities[l] - free[i]).norm() * remaining;
        island.farthest = std::max(island.farthest, away);
        if (away > reach[i]) island.beyond.push_back(l);
      }
    }
    // A ball crushed between a moving segment and what holds it: the segments pressing its
    // island stop for the rest of the step, as a game engine's lift stops on what it would
    // crush, and every island of this settle that meets one settles again.
    std::vector<std::size_t> stopped;  // their keys
    for (const SettledIsland& island : islands)
      if (island.settled.crushed) stopSegmentsPressing(island.settled, stopped);
    const auto meetsStopped = [&](const SettledIsland& island) {
      return std::any_of(island.pairs.begin(), island.pairs.end(), [&](const auto& pair) {
        return std::find(stopped.begin(), stopped.end(), pair.second) != stopped.end();
      });
    };
    if (!stopped.empty())
      for (std::vector<SettledIsland>* among : {&islands, &ready}) {
        const auto again_from = std::stable_partition(
            among->begin(), among->end(),
            [&](const SettledIsland& island) { return !meetsStopped(island); });
        for (auto island = again_from; island != among->end(); ++island)
          for (const std::size_t i : island->members) left.insert(i);
        among->erase(again_from, among->end());
      }
    // The pairs hold every body a ball may meet if it keeps within reach of its path, or if
    // beyond it meets none they do not hold.
    const std::vector<bool> unpaired = meetUnpaired(islands, free, reach, remaining);
    for (std::size_t k = 0; k < islands.size(); ++k) {
      SettledIsland& island = islands[k];
      // Its balls are sought as far as it took them: sought again, or from an island sought
      // again, they are found where they go.
      if (!island.beyond.empty())
        for (const std::size_t i : island.members)
          reach[i] = std::max(reach[i], kSettleReachGrowth * island.farthest);
      if (!unpaired[k]) {
        ready.push_back(std::move(island));
        continue;
      }
      for (const std::size_t i : island.members) left.insert(i);
    }
  }
  BallSet settling(n);
  for (const SettledIsland& island : ready)
    for (const std::size_t i : island.members) settling.insert(i);
  for (const std::size_t j : woken)
    if (!settling.contains(j)) comeToRest(j);
  letGoHeldContacts(settling);
  for (SettledIsland& island : ready) {
    for (const std::size_t i : island.members)
      settling_[i].off_path = island.farthest / remaining;
    moveOnSettled(island.settled, remaining);
  }
  return left.list.empty() && !left_out;
}

std::vector<bool> World::meetUnpaired(const std::vector<SettledIsland>& islands,
                                     const std::vector<Vec2>& free,
                                     const std::vector<double>& reach, double duration) const {
  // Each ball beyond reach, with its island and the box of its settled path (straight, from
  // where it is now).
  struct Beyond {
    std::size_t ball, island;
    Box path;
  };
  std::vector<Beyond> beyond;
  // The pairs of the islands with one, each numbered by its two keys.
  const std::uint64_t bodies = balls_.size() + segments_.size();
  const auto number = [bodies](std::uint64_t a, std::uint64_t b) {
    return std::min(a, b) * bodies + std::max(a, b);
  };
  std::unordered_set<std::uint64_t> paired;
  for (std::size_t k = 0; k < islands.size(); ++k) {
    const SettledIsland& island = islands[k];
    for (const std::size_t l : island.beyond) {
      const Ball& b = ballNow(island.members[l]);
      const Motion settled{b.position, island.settled.velocities[l]};
      beyond.push_back({island.members[l], k, sweptBox(settled, b.radius, duration)});
    }
    if (!island.beyond.empty())
      for (const auto& [i, key] : island.pairs) paired.insert(number(i, key));
  }
  std::vector<bool> unpaired(islands.size(), false);
  // The search's boxes, those of the balls beyond grown to hold their paths: a ball within
  // reach keeps within its box, so two bodies whose boxes do not meet do not meet.
  for (const Beyond& b : beyond)
    settle_grid_.move(b.ball, enclosing(searchBox(b.ball, free[b.ball], reach[b.ball], duration),
                                        b.path));
  std::vector<std::size_t> near;
  for (const Beyond& b : beyond) {
    if (unpaired[b.island]) continue;
    settle_grid_.overlapping(b.path, near);
    unpaired[b.island] = std::any_of(near.begin(), near.end(), [&](std::size_t key) {
      return key != b.ball && (key >= balls_.size() || collide(balls_[b.ball], balls_[key])) &&
             paired.count(number(b.ball, key)) == 0;
    });
  }
  return unpaired;
}

Box World::searchBox(std::size_t i, const Vec2& free, double reach, double duration) const {
  const Ball& b = ballNow(i);
  if (b.at_rest) return ballBox(b.position, b.radius);
  // Its path as it goes freely, and its straight one, untouched or within reach of it.
  const Box path =
      sweptBox(Motion{b.position, b.velocity, settlePull(i, duration)}, b.radius, duration);
  return enclosing(path, sweptBox(Motion{b.position, free}, b.radius + reach, duration));
}

std::vector<World::SettledIsland> World::islandsOf(const KeyPairs& pairs) const {
  // Joined through the balls that move: a resting ball or a segment holds up each island
  // alike.
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  DisjointSets joined(balls_.size());
  for (const auto& [ball, key] : pairs)
    if (const auto other = ballOf(key); other && !balls_[ball].at_rest && !balls_[*other].at_rest)
      joined.join(ball, *other);
  std::vector<SettledIsland> islands;
  std::vector<std::size_t> island_of(balls_.size(), kNone);  // each root's island
  for (const auto& pair : pairs) {
    std::size_t& island = island_of[joined.find(pair.first)];
    if (island == kNone) {
      island = islands.size();
      islands.emplace_back();
    }
    islands[island].pairs.push_back(pair);
  }
  // Each island's balls, in the order its pairs name them (a resting one may be in several).
  std::vector<std::size_t> counted_in(balls_.size(), islands.size());
  for (std::size_t k = 0; k < islands.size(); ++k)
    for (const auto& [ball, key] : islands[k].pairs)
      for (const std::optional<std::size_t> i : {std::optional(ball), ballOf(key)})
        if (i && counted_in[*i] != k) {
          counted_in[*i] = k;
          islands[k].members.push_back(*i);
        }
  return islands;
}

Settled World::settleIsland(const SettledIsland& island, const std::vector<Vec2>& free,
                            double duration, const std::vector<std::size_t>& woken) {
  Settled settled = settleMembers(island.pairs, island.members, free, duration, true, woken);
  // Opening overlaps lifts balls: where the balls' own energy cannot pay for that (a pile all
  // but still), the island's overlaps open no further, rather than the pile stand still awake.
  if (settled.opens && energyKeepingShare(settled, duration) < 1.0)
    settled = settleMembers(island.pairs, island.members, free, duration, false, woken);
  return settled;
}

bool World::settleTakes(std::size_t key) const {
  if (const auto k = segmentOf(key)) {
    const Segment& segment = segments_[*k];
    return segment.hits_to_break == 0 && segment.kick == 0.0;
  }
  if (ropeOf(key)) return false;
  for (const auto& [end, other] : rope_ends_)
    if (end == key || other == key) return false;
  return true;
}

World::KeyPairs World::settlingPairs(const std::vector<Vec2>& free,
                                     const std::vector<double>& reach, double duration,
                                     const BallSet& seeds, BallSet& members,
                                     bool& left_out) const {
  const std::size_t n = balls_.size();
  std::vector<Box> boxes;
  for (std::size_t i = 0; i < n; ++i) boxes.push_back(searchBox(i, free[i], reach[i], duration));
  for (const Segment& segment : segments_) boxes.push_back(segmentBox(segment, duration));
  settle_grid_.update(boxes);  // (a sleeping pile's boxes stay in their cells)
  // Each seed's island, found outward from it: two balls whose boxes meet, and that collide,
  // join, resting ones too (one struck wakes the other). Only the islands' pairs are tested.
  std::vector<bool> reached(n, false);
  // Whether a settle takes each body, asked once (a ball is in several pairs, a floor in many).
  std::vector<signed char> takes_body(boxes.size(), -1);
  const auto takesOnce = [&](std::size_t key) {
    if (takes_body[key] < 0) takes_body[key] = settleTakes(key);
    return takes_body[key] == 1;
  };
  std::vector<std::size_t> island, near;
  KeyPairs pairs, candidates;  // (moving ball, key)
  for (const std::size_t seed : seeds.list) {
    if (reached[seed]) continue;
    reached[seed] = true;
    island.assign(1, seed);
    candidates.clear();
    // An island with a body a settle does not take as it is is left to events, a seed's on its
    // own too.
    bool takes = takesOnce(seed);
    for (std::size_t k = 0; k < island.size(); ++k) {
      const std::size_t a = island[k];
      const bool a_rests = balls_[a].at_rest;
      settle_grid_.overlapping(boxes[a], near);
      for (const std::size_t b : near) {
        if (b >= n) {
          // (A resting ball meets a segment only if the segment may move: see wakeStruck.)
          if (!a_rests || (mayMove(segments_[b - n]) && takesOnce(b)))
            candidates.emplace_back(a, b);
          continue;
        }
        if (b == a || !collide(balls_[a], balls_[b])) continue;
        if (!reached[b]) {
          reached[b] = true;
          island.push_back(b);
          takes = takes && (!seeds.contains(b) || takesOnce(b));
        }
        // (Each pair of balls once, from its lower key; two resting ones meet nothing.)
        if (b < a || (a_rests && balls_[b].at_rest)) continue;
        candidates.push_back(a_rests ? std::make_pair(b, a) : std::make_pair(a, b));
      }
    }
    for (const auto& [ball, key] : candidates)
      takes = takes && takesOnce(ball) && takesOnce(key);
    if (!takes) {
      left_out = true;
      continue;
    }
    for (const auto& [ball, key] : candidates) {
      pairs.emplace_back(ball, key);
      members.insert(ball);
      if (const auto other = ballOf(key)) members.insert(*other);
    }
  }
  // In the order of a sweep over their boxes' left sides, not as the grid found them (its cells
  // are laid out over every body): an island's own, whatever else the world holds, and a
  // floor's, reaching farthest left, first. (A settle's sweeps take pairs of one height so.)
  // Each body's place in that sweep, found once, orders the pairs by a number.
  std::vector<std::size_t> swept = members.list;
  for (const auto& [ball, key] : pairs)
    if (key >= n) swept.push_back(key);
  std::sort(swept.begin(), swept.end(), [&](std::size_t a, std::size_t b) {
    return boxes[a].min.x() < boxes[b].min.x() || (boxes[a].min.x() == boxes[b].min.x() && a < b);
  });
  swept.erase(std::unique(swept.begin(), swept.end()), swept.end());
  std::vector<std::uint64_t> place(boxes.size());
  for (std::size_t k = 0; k < swept.size(); ++k) place[swept[k]] = k;
  std::vector<std::pair<std::uint64_t, std::pair<std::size_t, std::size_t>>> in_order;
  in_order.reserve(pairs.size());
  for (const auto& pair : pairs) {
    const std::uint64_t a = place[pair.first], b = place[pair.second];
    in_order.emplace_back(std::min(a, b) << 32 | std::max(a, b), pair);
  }
  // (Each pair is sought once, so no two share a number: std::sort's instability cannot show.)
  std::sort(in_order.begin(), in_order.end(),
            [](const auto& p, const auto& q) { return p.first < q.first; });
  for (std::size_t k = 0; k < pairs.size(); ++k) pairs[k] = in_order[k].second;
  return pairs;
}

Settled World::settleMembers(KeyPairs pairs, const std::vector<std::size_t>& members,
                             const std::vector<Vec2>& free, double duration, bool open,
                             const std::vector<std::size_t>& woken) {
  std::vector<bool> was_resting(balls_.size(), false);
  for (const std::size_t j : woken) was_resting[j] = true;
  // Swept from the bottom up: a pile's weight rests on its lowest contacts, and Gauss-Seidel
  // passes a push along the sweep's order in one sweep, against it a ball a sweep.
  // Pairs as high keep their order (the sweep's across): sorted by height, then by place.
  std::vector<std::pair<double, std::size_t>> by_height;
  by_height.reserve(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [ball, key] = pairs[k];
    const std::optional<std::size_t> other = ballOf(key);
    const double own = -gravity_.dot(ballNow(ball).position);
    by_height.emplace_back(other ? std::min(own, -gravity_.dot(ballNow(*other).position)) : own,
                           k);
  }
  std::sort(by_height.begin(), by_height.end());
  const KeyPairs listed = std::move(pairs);
  pairs.clear();
  for (const auto& [height, k] : by_height) pairs.push_back(listed[k]);
  std::vector<std::size_t>& place = settle_place_;  // each member's number in the settle
  place.resize(balls_.size());
  std::vector<Ball> settling;
  std::vector<double> inverse_masses;
  settling.reserve(members.size());
  inverse_masses.reserve(members.size());
  for (const std::size_t i : members) {
    place[i] = settling.size();
    settling.push_back(ballNow(i));
    settling.back().velocity = free[i];
    inverse_masses.push_back(inverseMassOf(i));
  }
  std::vector<RestingContact> contacts;
  std::vector<double> frictions;
  // Each pair's impulses start as the last settle (or attempt) left them: in a pile still
  // settling, its sweeps go on from there.
  std::vector<std::array<double, 2>> impulses;
  std::vector<WarmStarts::Pair> names;
  contacts.reserve(pairs.size());
  frictions.reserve(pairs.size());
  impulses.reserve(pairs.size());
  names.reserve(pairs.size());
  for (const auto& [i, key] : pairs) {
    names.push_back(WarmStarts::pairOf(WarmStarts::ballName(balls_[i].id), warmStartName(key)));
    settle_impulses_.prefetch(names.back());
  }
  bool opens = false;  // an overlap to open, or a strike
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, key] = pairs[k];
    const Touch t = touch(i, key);
    const std::optional<std::size_t> other = ballOf(key);
    // A gap may close to kSettleOverlap of the smaller radius past touching.
    const double radius =
        other ? std::min(balls_[i].radius, balls_[*other].radius) : balls_[i].radius;
    // A turning segment's face turns under a ball moving straight: along the normal now, the
    // gap misses terms in the turn (Coriolis', centripetal). Its contact is held where the
    // segment carries it, where the gap is linear in the ball's velocity (the surface's
    // velocity now kept for friction), and when the segment's motion changes, if that comes
    // first: the balls near it settle again then (settleAgainNear), and a ball held to the
    // stretch's end would lag behind a segment that gets there sooner.
    const bool turning = !other && turns(segments_[*segmentOf(key)]);
    const double change = turning ? timeToMotionChange(segments_[*segmentOf(key)]) : duration;
    // (A change all but now: held at the stretch's end, the segment as the change leaves it.)
    const double until =
        change > kSoonestChange * duration ? std::min(duration, change) : duration;
    double bias = settleBias(t.gap + kSettleOverlap * radius, until, open);
    // A sleeping pile struck: touching, one of them woken, coming together faster than gravity
    // brings lasting contact together. It bounces at its restitution's share of its approach.
    // Of the two, the one below is taken to be held up (a pile struck from above): over the
    // stretch, gravity slows the bounce of the one above as it would have. (A ball landing on
    // a pile awake meets it inelastically, as a speculative contact: bouncing there, a landing
    // pile's balls scatter, and some roll clear of it for minutes.)
    const double approach = -t.separation.normal.dot(t.relative_velocity);
    if (t.gap <= kRestingGap && approach > lastingApproach(duration) &&
        (was_resting[i] || (other && was_resting[*other])))
      bias = std::min(bias, duration * std::abs(t.separation.normal.dot(gravity_)) -
                                restitutionOf(i, key) * approach);
    opens = opens || bias < 0.0;  // (before a turn's terms, which may make it negative)
    Vec2 normal = t.separation.normal;
    if (turning) {
      const Separation then = carriedSeparationOf(i, key, t, until);
      bias += (then.distance - t.separation.distance) / until +
              then.normal.dot(t.surface_velocity);
      normal = then.normal;
    }
    std::optional<std::size_t> body = other ? std::optional(place[*other]) : std::nullopt;
    if (!other && t.surface_velocity != Vec2::Zero()) {
      // A moving segment's surface: a body of its own that the settle does not move.
      body = settling.size();
      Ball& surface = settling.emplace_back(balls_[i]);
      surface.velocity = t.surface_velocity;
      surface.angular_velocity = 0.0;
      inverse_masses.push_back(0.0);
    }
    contacts.push_back({place[i], body, normal, bias, key});
    frictions.push_back(coulombFrictionOf(i, key));
    impulses.push_back(settle_impulses_.latest(names[k]));
  }
  Settled settled = settleWithSegments(settling, inverse_masses, contacts, frictions, duration,
                                       impulses, members.size());
  settled.opens = opens;
  // (A crushing segment's pushes are no start for the settle without it, which comes next.)
  if (!settled.crushed)
    for (std::size_t k = 0; k < pairs.size(); ++k) settle_impulses_.record(names[k], impulses[k]);
  settled.contacts = std::move(contacts);
  inverse_masses.resize(members.size());
  settled.inverse_masses = std::move(inverse_masses);
  settled.members = members;
  return settled;
}

}  // namespace ball_physics_sim::engine
