#pragma once
// The energy check's budget for one step: over which balls the fuzz targets compare mechanical
// energy, and how much the world's sources can add to theirs. Without sources the budget is
// zero and the check is rounding only.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/world.h"

namespace ball_physics_sim::fuzz {

// The pushes World does not show: each driven ball's drive() acceleration, by id. (A blast
// acts at once, between steps, so no step has to allow for one.)
using Drives = std::map<engine::BallId, engine::Vec2>;

// What a step starts from: its balls, segments and ropes, before the step changes them.
struct StepStart {
  explicit StepStart(const engine::World& world)
      : balls(world.balls()), segments(world.segments()), ropes(world.ropes()) {}
  std::vector<engine::Ball> balls;
  std::vector<engine::Segment> segments;
  std::vector<engine::Rope> ropes;
};

// How many times a ball's assumed reach may grow (doubling past the reach it gives) before the
// ball, whose pushes keep outrunning it, is left out of the check.
constexpr int kReachRounds = 32;
// A held rope's error, as derived at ropeTolerance, is of the order of its drift times its
// pull; this factor covers the order-one constants that derivation leaves out. (ropes.yaml
// gains at most 3e-6 J a step, a thousandth of its tolerance, whose speeds are bounded by the
// whole world's kinetic energy.)
constexpr double kRopeSafety = 4.0;

inline double kineticEnergyOf(const engine::Ball& b) {
  const double spin = b.radius * b.angular_velocity;  // I w^2 = k m (r w)^2
  return 0.5 * b.mass * (b.velocity.squaredNorm() + b.inertia_factor * spin * spin);
}

// A ball's share of engine::mechanicalEnergy.
inline double energyOf(const engine::Ball& b, const engine::Vec2& gravity) {
  return kineticEnergyOf(b) - b.mass * gravity.dot(b.position);
}

// The strongest pull the attractor gives a centre at least `distance` from its own: strength
// d / (d^2 + core^2)^(3/2) peaks at d = core / sqrt(2) and falls off on both sides. Infinite
// for a point (core 0) that the ball may reach.
inline double pullBound(const engine::Attractor& a, double distance) {
  const double d = std::max(distance, a.core / std::sqrt(2.0));
  if (d == 0.0) return a.strength > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return engine::attraction(a, a.centre + engine::Vec2(d, 0.0)).norm();
}

// How far a centre at `p` is from the region (0 inside it).
inline double distanceTo(const engine::Region& region, const engine::Vec2& p) {
  return (region.min - p).cwiseMax(p - region.max).cwiseMax(0.0).norm();
}

// The segments that can do work on a ball: a bumper's kick, or a segment that moves, turns or
// travels between waypoints.
inline bool doesWork(const engine::Segment& s) {
  return s.kick > 0.0 || engine::moves(s) || !s.waypoints.empty();
}

// The balls of a step whose energy the fuzzers check, and the most the sources can add to it.
struct EnergyBudget {
  std::set<engine::BallId> balls;
  double bound = 0.0;  // J
};

namespace detail {

// Each pair of balls that met or touched, both ways round.
using Links = std::multimap<engine::BallId, engine::BallId>;

inline void link(Links& links, engine::BallId a, engine::BallId b) {
  links.emplace(a, b);
  links.emplace(b, a);
}

// Which balls touch (within kBoxMargin, as the engine's holds count it) a segment that does
// work, into `seeds`; which touch each other, into `links`.
inline void touchesOf(const std::vector<engine::Ball>& balls,
                      const std::vector<engine::Segment>& segments, std::set<engine::BallId>& seeds,
                      Links& links) {
  for (std::size_t i = 0; i < balls.size(); ++i) {
    for (const engine::Segment& s : segments)
      if (doesWork(s) && engine::surfaceGap(balls[i], s) <= engine::kBoxMargin)
        seeds.insert(balls[i].id);
    for (std::size_t j = i + 1; j < balls.size(); ++j)
      if (engine::collide(balls[i], balls[j]) &&
          engine::surfaceGap(balls[i], balls[j]) <= engine::kBoxMargin)
        link(links, balls[i].id, balls[j].id);
  }
}

// `excluded`, grown by every ball linked to one of it, and to those, and so on.
inline void closeOver(const Links& links, std::set<engine::BallId>& excluded) {
  std::vector<engine::BallId> pending(excluded.begin(), excluded.end());
  while (!pending.empty()) {
    const engine::BallId id = pending.back();
    pending.pop_back();
    const auto [first, last] = links.equal_range(id);
    for (auto l = first; l != last; ++l)
      if (excluded.insert(l->second).second) pending.push_back(l->second);
  }
}

}  // namespace detail

// A held rope pulls as at the middle of its hold (World::pullFromMiddleOfSwing) while its ball
// leaves the circle by up to kHeldDrift; the pull T does work of the order of T times that
// drift, and closing the drift moves the ball by it against gravity. A hold of length t drifts
// by at most jerk t^3 / 6, and no hold is longer than drift reaching kHeldDrift, so the holds of
// a step (dt in all) drift by at most jerk^(1/3) (6 kHeldDrift)^(2/3) dt / 6: shorter holds only
// lower it. Swinging at speed v on a rope of length L, jerk <= v^3 / L^2 + 3 v a / L.
// `speeds` bounds each ball's speed, `weight` the sum of m (g + a) that may hang on a rope,
// `pushes` the g + a on one ball, `kinetic` the kinetic energy within the step.
inline double ropeTolerance(const engine::Rope& rope, const std::map<engine::BallId, double>& speeds,
                            double weight, double pushes, double kinetic, double dt) {
  double speed = speeds.at(rope.ball);
  if (rope.other_ball) speed += speeds.at(*rope.other_ball);
  const double length = rope.length;
  // m v^2 <= 2 K for each ball, so the pull that bends the swing is at most 4 K / L for two.
  const double pull = weight + 4.0 * kinetic / length;
  const double jerk = std::pow(speed, 3) / (length * length) + 3.0 * speed * pushes / length;
  const double drift = std::cbrt(jerk) * std::pow(6.0 * engine::kHeldDrift, 2.0 / 3.0) * dt / 6.0;
  // The holds cut at the step's ends each add a drift of at most kHeldDrift.
  return kRopeSafety * (pull + weight) * (drift + 2.0 * engine::kHeldDrift);
}

// Over one step from `start` to `world` (with the impacts it reported, `contacts`): the balls
// that touched no segment doing work, through other balls or ropes, and were not taken out of
// the world; and the most work the fields, drives and ropes can do on them. A segment's
// pushes are left out, not bounded: two walls closing on a ball or an elevator under a stack
// add energy no simple bound holds.
inline EnergyBudget energyBudget(const StepStart& start, const engine::World& world,
                                 const std::vector<engine::Contact>& contacts,
                                 const Drives& drives, double dt) {
  using engine::BallId;
  std::set<BallId> excluded, after;
  detail::Links links;
  for (const engine::Ball& b : world.balls()) after.insert(b.id);
  for (const engine::Ball& b : start.balls)
    if (!after.count(b.id)) excluded.insert(b.id);  // a pocket took it
  detail::touchesOf(start.balls, start.segments, excluded, links);
  detail::touchesOf(world.balls(), world.segments(), excluded, links);
  std::set<engine::SegmentId> working;
  for (const engine::Segment& s : start.segments)
    if (doesWork(s)) working.insert(s.id);
  for (const engine::Contact& c : contacts) {
    if (c.other_kind == engine::ContactKind::kBall)
      detail::link(links, c.ball_id, c.other_id);
    else if (working.count(c.other_id))
      excluded.insert(c.ball_id);
  }
  for (const engine::Rope& r : start.ropes)
    if (r.other_ball) detail::link(links, r.ball, *r.other_ball);

  const double g = world.gravity().norm();
  // Each ball's push besides gravity is bounded by the fields it may meet within an assumed
  // reach: the winds and water whose regions it may enter (buoyed as if wholly sunk; drag only
  // takes energy), each attractor's pull that much nearer, and its drive. The reach is
  // assumed, then checked against the speeds those pushes allow: where every ball's reach is
  // below what was assumed, no ball can be the first to leave it, so the pushes hold.
  const bool fields =
      !world.winds().empty() || !world.waters().empty() || !world.attractors().empty();
  std::map<BallId, double> assumed;  // reach, m
  int round = 0;
  EnergyBudget budget;
  for (;;) {
    detail::closeOver(links, excluded);
    budget.balls.clear();
    double kinetic = 0.0, pushed = 0.0, accelerated = 0.0, weight = 0.0, most_push = 0.0;
    bool left_out = false;
    for (const engine::Ball& b : start.balls) {
      if (excluded.count(b.id)) continue;
      const double reach = assumed[b.id];
      double a = 0.0;
      if (const auto drive = drives.find(b.id); drive != drives.end()) a += drive->second.norm();
      for (const engine::Wind& w : world.winds())
        if (distanceTo(w.region, b.position) <= reach) a += w.acceleration.norm();
      for (const engine::Water& w : world.waters())
        if (distanceTo(engine::wettedRegion(w, b.radius), b.position) <= reach)
          a += w.density * g * engine::sunkVolume(b.radius, 2.0 * b.radius) / b.mass;
      for (const engine::Attractor& at : world.attractors())
        a += pullBound(at, (b.position - at.centre).norm() - reach);
      if (std::isinf(a)) {  // it may reach a point attractor's centre
        left_out = excluded.insert(b.id).second;
        break;
      }
      budget.balls.insert(b.id);
      kinetic += kineticEnergyOf(b);
      pushed += b.mass * a * a;
      accelerated += b.mass * (g + a) * (g + a);
      weight += b.mass * (g + a);
      most_push = std::max(most_push, a);
    }
    if (left_out) continue;
    // Speeds bound the work: by Cauchy-Schwarz, sum m a |v| <= sqrt(sum m a^2) sqrt(2 K). The
    // same with g + a bounds how fast K grows (contacts and impacts without sources take
    // energy, never give it), dK/dt <= beta sqrt(K), so sqrt(K) <= sqrt(K0) + beta t / 2 and
    // the work is at most alpha (sqrt(K0) dt + beta dt^2 / 4).
    const double alpha = std::sqrt(2.0 * pushed), beta = std::sqrt(2.0 * accelerated);
    const double root_most = std::sqrt(kinetic) + beta * dt / 2.0;
    budget.bound = alpha * (std::sqrt(kinetic) * dt + beta * dt * dt / 4.0);
    std::map<BallId, double> speeds;  // m v^2 / 2 <= K bounds each ball's speed
    bool outran = false;
    for (const engine::Ball& b : start.balls) {
      if (!budget.balls.count(b.id)) continue;
      speeds[b.id] = std::sqrt(2.0 / b.mass) * root_most;
      const double reach = speeds[b.id] * dt;
      if (!fields || reach < assumed[b.id] || reach == 0.0) continue;
      outran = true;
      if (round < kReachRounds)
        assumed[b.id] = 2.0 * reach;
      else
        excluded.insert(b.id);
    }
    if (outran) {
      ++round;
      continue;
    }
    for (const engine::Rope& r : start.ropes)
      if (budget.balls.count(r.ball))
        budget.bound += ropeTolerance(r, speeds, weight, most_push + g, root_most * root_most, dt);
    return budget;
  }
}

}  // namespace ball_physics_sim::fuzz
