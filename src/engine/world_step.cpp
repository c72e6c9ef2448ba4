// World: the step, as its phases: the events of a step in time order until its end, and what is
// held between them (its budgets of events: world_budgets.cpp).

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include "ball_physics_sim/engine/impulse.h"
#include "ball_physics_sim/engine/kinematics.h"

namespace ball_physics_sim::engine {

void World::step(double dt) {
  Stepping stepping = beginStep(dt);
  try {
    settleAtStart(dt);
    stepping.unsettled = awakeOrHeld();  // (after the settles, which wake and still balls)
    for (bool goes_on = true; goes_on;) {
      const Lookahead next = holdAndLookAhead(stepping);
      if (!stepping.outOfBudget().empty())
        goes_on = meetTheStruggle(stepping, next);
      else if (!next.impact)
        goes_on = renewEndedHolds(stepping, next);
      else
        goes_on = meetImpact(stepping, *next.impact);
    }
  } catch (...) {
    restartStoppedSegments();  // (none is left standing, its motion lost)
    throw;
  }
  endStep(stepping.dt);
}

World::Stepping World::beginStep(double dt) {
  if (!(std::isfinite(dt) && dt > 0.0))
    throw std::invalid_argument("time step must be finite and > 0");
  Stepping stepping(balls_.size());
  stepping.dt = dt;
  haltJammedSegments();
  predictAll(dt);
  groupMeetingBalls(stepping);
  hold_ends_.assign(balls_.size(), std::numeric_limits<double>::infinity());
  hold_end_queue_.reset(balls_.size(),
                        [this](std::size_t a, std::size_t b) { return holdEndComesFirst(a, b); });
  rope_swings_.assign(ropes_.size(), std::numeric_limits<double>::infinity());
  waiting_velocities_.assign(balls_.size(), std::nullopt);
  unheld_.clear();  // (none unless a step threw)
  return stepping;
}

World::BallSet World::awakeOrHeld() const {
  BallSet balls(balls_.size());
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (!balls_[i].at_rest || held_.holdsAny(i)) balls.insert(i);
  balls.every_moving = true;
  return balls;
}

void World::groupMeetingBalls(Stepping& stepping) {
  // Balls whose paths over the step may meet (their boxes overlap), or meet one segment that
  // may move or break, or that a rope ties, share their budgets: a struggle's work is bounded
  // where it is, and spends no other group's. (Heaps landing far apart on one floor are groups
  // apart.)
  const std::size_t n = balls_.size();
  std::vector<std::size_t> first_on(segments_.size(), n);  // the first ball met by each
  // (Two resting balls would not join: a sleeping pile's pairs are not sought.)
  if (balls_in_grid_)
    for (const auto& [a, b] : pairsNearMoving()) {
      // (Not two segments, nor a resting ball beside a segment or another resting ball: struck,
      // it joins the group of what struck it.)
      if (a >= n || (balls_[a].at_rest && (b >= n || balls_[b].at_rest))) continue;
      if (b < n) {
        stepping.join(a, b);
        continue;
      }
      // (A segment that stays as it is passes nothing from one ball to another.)
      const Segment& segment = segments_[b - n];
      if (!mayMove(segment) && segment.hits_to_break == 0) continue;
      std::size_t& first = first_on[b - n];
      if (first == n)
        first = a;
      else
        stepping.join(a, first);
    }
  for (const auto& [end, other] : rope_ends_)
    if (other) stepping.join(end, *other);
}

World::Lookahead World::holdAndLookAhead(Stepping& stepping) {
  for (const std::size_t k : movable_segments_) startNextMotion(segments_[k]);
  Lookahead next;
  next.remaining = stepping.dt - stepping.elapsed;
  step_left_ = next.remaining;
  holdAnew(stepping);
  const BallSet& held_anew = stepping.unsettled;
  recordHoldEnds(held_anew, stepping.elapsed, next.remaining);
  // A segment's motion changing is an event like a hold's end.
  next.segment_event = timeToSegmentEvent();
  const std::optional<std::size_t> first_end = hold_end_queue_.first();
  next.hold_end = first_end ? hold_ends_[*first_end] : std::numeric_limits<double>::infinity();
  // (Rounding may put a hold's end a hair before now.)
  next.held_for = std::min(next.remaining, std::max(0.0, next.hold_end - stepping.elapsed));
  // A segment's event at the same instant of the step, to rounding, is met then, by its own
  // time, so that the segment reaches it: a hold cut short by it ends there too, and met first,
  // it would be held anew for no time, again and again.
  next.holds_end = true;
  if (next.segment_event <= next.remaining &&
      stepping.elapsed + next.segment_event <= stepping.elapsed + next.held_for) {
    next.holds_end = stepping.elapsed + next.segment_event == stepping.elapsed + next.held_for;
    next.held_for = next.segment_event;
  }
  predictChanged(stepping.elapsed, next.remaining);
  next.impact = earliestImpact(stepping.elapsed, next.held_for);
  return next;
}

void World::holdAnew(Stepping& stepping) {
  if (std::exchange(holds_stale_, false)) {
    stepping.unsettled = BallSet::every(balls_.size());
    stepping.hold_needed = true;
  }
  // (Every way on from here sets `unsettled` anew; held anew, it keeps its storage for that.)
  const std::vector<std::size_t> past = stepping.changedGroups(stepping.pastSequential());
  if (past.empty()) {
    stepping.unsettled.remove(settled_);  // (their settle holds them)
    if (stepping.hold_needed)
      stepping.unsettled = holdRestingBalls(kRestingSpeed, std::move(stepping.unsettled));
    else
      moveFreely(stepping.unsettled);
    stepping.hold_needed = true;  // (only an impact says otherwise, for the next)
    return;
  }
  // Past its budget of impacts one after another, a group's balls are held anew at each of its
  // events and their approaches stop together, inelastically; the other balls changed are held
  // as ever.
  BallSet collapsing = stepping.ballsOf(past), others(balls_.size());
  collapsing.remove(settled_);  // (their settle holds them)
  for (const std::size_t i : stepping.unsettled.list)
    if (!collapsing.contains(i) && !isSettled(i)) others.insert(i);
  BallSet held =
      holdRestingBalls(std::numeric_limits<double>::infinity(), std::move(collapsing));
  if (!others.list.empty())
    for (const std::size_t i : holdRestingBalls(kRestingSpeed, std::move(others)).list)
      held.insert(i);
  stepping.unsettled = std::move(held);
  stepping.hold_needed = true;
}

bool World::renewEndedHolds(Stepping& stepping, const Lookahead& next) {
  advance(stepping.elapsed, next.held_for);
  if (next.held_for == next.remaining) return false;
  stepping.elapsed += next.held_for;
  BallSet ended(balls_.size());
  if (next.holds_end)
    for (std::size_t i = 0; i < balls_.size(); ++i)
      if (hold_ends_[i] <= next.hold_end) ended.insert(i);
  // A segment's motion changing ends the holds of the balls near a movable segment only, and
  // the settled balls near one settle again, or are held if they cannot: their settle took
  // the segment to go on as it went.
  if (next.held_for == next.segment_event)
    settleAgainNear(movable_segments_, stepping.dt - stepping.elapsed, ended);
  // A held contact ends for both its balls, and theirs for theirs: a resting one's ending lets
  // it go, and the search for touching pairs does not reach the ball that leaned on it from a
  // resting one. (The set grows as it is walked.)
  for (std::size_t k = 0; k < ended.list.size(); ++k)
    for (const auto& [ball, key] : held_.of({ended.list[k]}))
      if (const auto other = otherBallOf(ball, key)) {
        ended.insert(ball);
        ended.insert(*other);
      }
  std::vector<std::size_t> groups;
  for (const std::size_t i : ended.list) {
    ++stepping.events_of[i];
    groups.push_back(stepping.group(i));
  }
  std::sort(groups.begin(), groups.end());
  groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
  for (const std::size_t g : groups) stepping.countRenewal(g);
  const KeyPairs touching = touchingPairs(ended);
  stepping.unsettled = touchingTogether(touching, std::move(ended));
  closeHeldContacts(stepping.unsettled);  // and they are held anew
  return true;
}

bool World::meetImpact(Stepping& stepping, const Impact& impact) {
  advance(stepping.elapsed, impact.time);
  stepping.elapsed += impact.time;
  if (strike_stop_ && impact.kind == ContactKind::kBall &&
      (impact.ball == *strike_stop_ || impact.other == *strike_stop_)) {
    resolve(impact, time_ + stepping.elapsed);
    stepping.dt = stepping.elapsed;  // (the step ends here)
    return false;
  }
  // A ball that meets a settled one, or a sleeping pile, settles with it.
  if (settlesOnImpact(impact, stepping.dt - stepping.elapsed)) {
    stepping.unsettled.reset(balls_.size());
    return true;
  }
  ++stepping.events_of[impact.ball];
  if (const auto other = otherBallOf(impact.ball, keyOf(impact))) {
    ++stepping.events_of[*other];
    stepping.join(*other, impact.ball);
  }
  resolve(impact, time_ + stepping.elapsed);
  // The balls it woke touch these, so their islands are these balls'; a slow impact changes
  // nothing but is held anew.
  const std::size_t g = stepping.group(impact.ball);
  stepping.hold_needed = passThroughTouching(impact, time_ + stepping.elapsed,
                                             stepping.spent[g].passed, stepping.most(g),
                                             stepping.unsettled);
  for (const std::size_t i : stepping.unsettled.list) stepping.join(i, impact.ball);
  stepping.countImpact(impact.ball);
  return true;
}

void World::endStep(double dt) {
  for (const std::size_t k : movable_segments_) startNextMotion(segments_[k]);
  restartStoppedSegments();
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    // (Not noted as looked at: nothing predicts anew before the next step's predictAll.)
    std::as_const(*this).ballNow(i);
    if (waiting_velocities_[i]) leaveRest(i);
  }
  waiting_velocities_.clear();  // outside a step none waits
  wakeUnheld();
  settled_.reset(balls_.size());  // nor is settled
  clocks_.assign(balls_.size(), 0.0);
  now_ = 0.0;
  time_ += dt;
  removeBrokenAndPocketed();
}

}  // namespace ball_physics_sim::engine
