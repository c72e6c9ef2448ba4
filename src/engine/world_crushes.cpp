// World: moving segments in settles. A segment that closes on a ball past what a settle may
// leave crushes it and stops for the rest of the step, then stands still for a while before it
// tries again; one that jammed lately tries a few rounds first; balls near a segment whose
// motion changes settle again.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <limits>
#include <utility>

#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/settle.h"

namespace ball_physics_sim::engine {

namespace {

// A settle with a moving segment whose contacts close past the overlap they may leave by more
// than this share of the smaller radius has a ball crushed (see World::takeBackSurfaces): where
// its sweeps converge, they close past it by none.
constexpr double kCrushedOverlap = 3.0 * kSettleOverlap;
// Whether the contact `c` closes, at the settle's `velocities`, past its bias by more than
// kCrushedOverlap of `radius` over `duration`: it crushes its ball.
bool crushes(const RestingContact& c, const std::vector<Vec2>& velocities, double radius,
             double duration) {
  return -opening(c, velocities) * duration > kCrushedOverlap * radius;
}
// The rounds a settle first runs with a segment moving whose jam began at most kJammedTime ago
// (noteJammed): one that converges in them lets the segment go on; one where the segment still
// closes on a ball past kCrushedOverlap crushes (see takeBackSurfaces): the segments pushing
// stop, and the island settles again without them; any other goes on to its full rounds. A
// jammed segment most often jams again, step after step: its full rounds would run out for
// nothing. Once kJammedTime is up, a settle with it runs them all first, and a crush begins a
// new jam.
constexpr int kJammedRounds = 4;
constexpr double kJammedTime = 1.0;  // s
// A segment that stopped on a ball starts each step stopped until this long after (see
// haltJammedSegments), then tries again: a lift on a pile that does not give way would crush
// it, and stop, in a settle of its own every step. Whatever takes a ball, a segment or a rope
// away, moves a ball (set, or blasted) or sets a segment's motion ends the wait (retryJams).
constexpr double kJammedRetry = 0.1;  // s

}  // namespace

Settled World::settleWithSegments(const std::vector<Ball>& settling,
                                  const std::vector<double>& inverse_masses,
                                  std::vector<RestingContact>& contacts,
                                  const std::vector<double>& frictions, double duration,
                                  std::vector<std::array<double, 2>>& impulses,
                                  std::size_t balls) {
  const auto jammedRow = [&](const RestingContact& c) {
    const auto k = segmentOf(c.body);
    return k && moves(segments_[*k]) && jammedLately(*k);
  };
  const bool jammed = std::any_of(contacts.begin(), contacts.end(), jammedRow);
  Settled settled =
      settleTogether(settling, inverse_masses, contacts, frictions, duration, &impulses,
                     SweepLanes::kMost, &settle_scratch_, jammed ? kJammedRounds : kSettleRounds);
  // Not converged, and no jammed segment closing on a ball past what a crush is: the rounds go
  // on from where they got (what has not converged may be far from the segment).
  if (jammed && !settled.converged &&
      std::none_of(contacts.begin(), contacts.end(), [&](const RestingContact& c) {
        return jammedRow(c) &&
               crushes(c, settled.velocities, settling[c.ball].radius, duration);
      })) {
    const int swept = settled.sweeps;
    settled = settleTogether(settling, inverse_masses, contacts, frictions, duration, &impulses,
                             SweepLanes::kMost, &settle_scratch_, kSettleRounds - kJammedRounds);
    settled.sweeps += swept;
  }
  takeBackSurfaces(settled, balls, contacts, settling, impulses, duration);
  return settled;
}

Separation World::carriedSeparationOf(std::size_t ball, std::size_t key, const Touch& t,
                                      double time) const {
  const Vec2& position = ballNow(ball).position;
  return carriedSeparation(segments_[*segmentOf(key)],
                           position - t.separation.distance * t.separation.normal,
                           t.separation.normal, position, time);
}

void World::takeBackSurfaces(Settled& settled, std::size_t balls,
                             std::vector<RestingContact>& contacts,
                             const std::vector<Ball>& settling,
                             const std::vector<std::array<double, 2>>& impulses,
                             double duration) const {
  double fastest_surface = 0.0;
  for (std::size_t l = balls; l < settling.size(); ++l)
    fastest_surface = std::max(fastest_surface, settling[l].velocity.norm());
  if (fastest_surface > 0.0) {
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      RestingContact& c = contacts[k];
      // Closing at the end past what the settle may leave: a moving segment crushes a ball,
      // against another or a wall.
      const double smaller = c.other && *c.other < balls
                                 ? std::min(settling[c.ball].radius, settling[*c.other].radius)
                                 : settling[c.ball].radius;
      settled.crushed = settled.crushed || crushes(c, settled.velocities, smaller, duration);
      if (!c.other || *c.other < balls) continue;
      const Vec2& other = settled.velocities[*c.other];
      // The work the segment does on the ball, with the impulse it gives (pushing, gripping).
      const Vec2 tangent(-c.normal.y(), c.normal.x());
      settled.work +=
          std::max(0.0, (impulses[k][0] * c.normal + impulses[k][1] * tangent).dot(other));
      c.other.reset();  // (to the caller, a segment's contact)
    }
    // Or squeezed out of its way faster than it strikes a ball, (1 + e) times its speed, but
    // for what the island's balls bring: squeezing a ball out of a row takes pushes without
    // bound.
    double fastest_ball = 0.0;
    for (std::size_t l = 0; l < balls; ++l)
      fastest_ball = std::max(fastest_ball, settling[l].velocity.norm());
    for (std::size_t l = 0; l < balls; ++l)
      settled.crushed = settled.crushed ||
                        settled.velocities[l].norm() > fastest_ball + 2.0 * fastest_surface;
    // Crushed by a segment that pushes it, which will stop: where none does, it stands.
    if (settled.crushed) {
      bool pushed = false;
      for (std::size_t k = 0; k < contacts.size() && !pushed; ++k)
        pushed = pushesAsItMoves(settled, contacts[k], k);
      settled.crushed = pushed;
    }
  }
  settled.velocities.resize(balls);
  settled.spins.resize(balls);
}

void World::noteJammed(std::size_t k) {
  const double now = time_ + now_;
  const auto jam = std::find_if(jammed_segments_.begin(), jammed_segments_.end(),
                                [&](const Jam& j) { return j.segment == segments_[k].id; });
  if (jam == jammed_segments_.end()) {
    jammed_segments_.push_back({segments_[k].id, now, now});
    return;
  }
  jam->stopped = now;
  // (A jam older than kJammedTime begins anew: its settle ran its full rounds first.)
  if (now - jam->began >= kJammedTime) jam->began = now;
}

bool World::jammedLately(std::size_t k) const {
  const double now = time_ + now_;
  return std::any_of(jammed_segments_.begin(), jammed_segments_.end(), [&](const Jam& jam) {
    return jam.segment == segments_[k].id && now - jam.began < kJammedTime;
  });
}

void World::haltJammedSegments() {
  const double now = time_ + now_;
  jammed_segments_.erase(std::remove_if(jammed_segments_.begin(), jammed_segments_.end(),
                                        [&](const Jam& jam) {
                                          return now - jam.began >= kJammedTime &&
                                                 now - jam.stopped >= kJammedRetry;
                                        }),
                         jammed_segments_.end());
  for (const Jam& jam : jammed_segments_) {
    if (now - jam.stopped >= kJammedRetry) continue;
    for (std::size_t k = 0; k < segments_.size(); ++k)
      if (segments_[k].id == jam.segment && mayMove(segments_[k])) haltSegment(k);
  }
}

void World::retryJams() {
  for (Jam& jam : jammed_segments_) jam.stopped = -std::numeric_limits<double>::infinity();
}

void World::stopSegment(std::size_t k) {
  noteJammed(k);
  haltSegment(k);
  holds_stale_ = true;
}

void World::haltSegment(std::size_t k) {
  if (stoppedInStep(k)) return;  // (its motion is kept already)
  Segment& segment = segments_[k];
  stopped_segments_.push_back({k, segment.velocity, segment.angular_velocity,
                               std::move(segment.waypoints)});
  segment.velocity = Vec2::Zero();
  segment.angular_velocity = 0.0;
  segment.waypoints.clear();  // (or it would be at the next one when its time came)
}

void World::restartStoppedSegments() {
  holds_stale_ = false;  // (a step's end holds nothing)
  for (StoppedSegment& stopped : stopped_segments_) {
    Segment& segment = segments_[stopped.segment];
    segment.velocity = stopped.velocity;
    segment.angular_velocity = stopped.angular_velocity;
    segment.waypoints = std::move(stopped.waypoints);
  }
  stopped_segments_.clear();
}

bool World::stoppedInStep(std::size_t k) const {
  return std::any_of(stopped_segments_.begin(), stopped_segments_.end(),
                     [k](const StoppedSegment& stopped) { return stopped.segment == k; });
}

bool World::pushesAsItMoves(const Settled& settled, const RestingContact& c,
                            std::size_t k) const {
  const auto segment = segmentOf(c.body);
  return segment && settled.pushes[k] > 0.0 && moves(segments_[*segment]);
}

void World::stopSegmentsPressing(const Settled& settled, std::vector<std::size_t>& stopped) {
  for (std::size_t k = 0; k < settled.contacts.size(); ++k)
    if (pushesAsItMoves(settled, settled.contacts[k], k)) {
      stopSegment(*segmentOf(settled.contacts[k].body));
      stopped.push_back(settled.contacts[k].body);
    }
}

void World::settleAgainNear(const std::vector<std::size_t>& segments, double remaining,
                            BallSet& unsettled) {
  BallSet near(balls_.size());
  for (const std::size_t k : segments)
    for (const std::size_t key : grid_.overlapping(keyBox(balls_.size() + k, remaining)))
      if (key < balls_.size()) (isSettled(key) ? near : unsettled).insert(key);
  if (near.list.empty()) return;
  // (Each with its new motion, which the next look ahead would start.)
  for (const std::size_t k : segments) startNextMotion(segments_[k]);
  if (settleRestOfStep(remaining, near)) return;
  settled_.remove(near);
  for (const std::size_t i : near.list) unsettled.insert(i);
}

}  // namespace ball_physics_sim::engine
