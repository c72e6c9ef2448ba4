// World: the step, as its phases: the events of a step in time order until its end, what is
// held between them, and what its budget of events does where they would not end.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "ball_physics_sim/engine/impulse.h"
#include "ball_physics_sim/engine/kinematics.h"

namespace ball_physics_sim::engine {

namespace {

// Bounds the work of one step. A step normally resolves about one impact per ball or fewer
// (1000 bullets, 0.7). In a pile, balls bounce on each other ever faster, in impacts that
// converge only geometrically, each holding its island anew: past kSequentialImpacts the
// touching balls that still approach stop together in one inelastic push instead (inelastic
// collapse). Past kMaxImpacts (or as many renewals of held contacts, times
// kRenewalsPerImpact) the balls that may meet the struggle settle together for the rest of the
// step, and in the steps after until they rest (see World::settleRestOfStep), while the others
// go on with a budget of their own. Where no settle can be (World::canSettle), the moving
// segments pressing the struggle stop for the rest of the step, or else its balls wait, and
// events go on longer: kSequentialImpacts and kMaxImpacts are then the larger ones. Where none
// of that helps, the rest of the step is given up rather than hang. The hits an impact passes
// on through touching balls at its instant, cheap, are not counted among them, but as many
// bound them.
constexpr std::size_t kSequentialImpactsPerBall = 2;
constexpr std::size_t kMaxImpactsPerBall = 3;
constexpr std::size_t kSequentialImpactsPerBallUnsettled = 16;
constexpr std::size_t kMaxImpactsPerBallUnsettled = 64;
constexpr std::size_t kMinImpactsPerStep = 256;
// Held contacts may be held anew this many times as often as impacts happen: a ball sliding
// round a small cap needs a few hundred renewals in a long step.
constexpr std::size_t kRenewalsPerImpact = 4;

}  // namespace

void World::step(double dt) {
  Stepping stepping = beginStep(dt);
  settleAtStart(stepping.settles, dt);
  for (bool goes_on = true; goes_on;) {
    const Lookahead next = holdAndLookAhead(stepping);
    if (outOfBudget(stepping))
      goes_on = meetTheStruggle(stepping, next);
    else if (!next.impact)
      goes_on = renewEndedHolds(stepping, next);
    else
      goes_on = meetImpact(stepping, *next.impact);
  }
  endStep(stepping.dt);
}

World::Stepping World::beginStep(double dt) {
  if (!(std::isfinite(dt) && dt > 0.0))
    throw std::invalid_argument("time step must be finite and > 0");
  Stepping stepping(balls_.size());
  stepping.dt = dt;
  stepping.settles = canSettle();
  stepping.sequential_per_ball =
      stepping.settles ? kSequentialImpactsPerBall : kSequentialImpactsPerBallUnsettled;
  stepping.sequential = kMinImpactsPerStep + stepping.sequential_per_ball * balls_.size();
  stepping.most =
      kMinImpactsPerStep +
      (stepping.settles ? kMaxImpactsPerBall : kMaxImpactsPerBallUnsettled) * balls_.size();
  predictAll(dt);
  hold_ends_.assign(balls_.size(), std::numeric_limits<double>::infinity());
  hold_end_queue_.reset(balls_.size(),
                        [this](std::size_t a, std::size_t b) { return holdEndComesFirst(a, b); });
  rope_swings_.assign(ropes_.size(), std::numeric_limits<double>::infinity());
  waiting_velocities_.assign(balls_.size(), std::nullopt);
  unheld_.clear();  // (none unless a step threw)
  return stepping;
}

World::Lookahead World::holdAndLookAhead(Stepping& stepping) {
  for (const std::size_t k : movable_segments_) startNextMotion(segments_[k]);
  Lookahead next;
  next.remaining = stepping.dt - stepping.elapsed;
  step_left_ = next.remaining;
  if (stepping.impacts >= stepping.sequential) {
    stepping.unsettled = BallSet::every(balls_.size());
    stepping.hold_needed = true;
  }
  // (Every way on from here sets `unsettled` anew; held anew, it keeps its storage for that.)
  stepping.unsettled.remove(settled_);  // (their settle holds them)
  if (stepping.hold_needed)
    stepping.unsettled = holdRestingBalls(stepping.impacts < stepping.sequential
                                              ? kRestingSpeed
                                              : std::numeric_limits<double>::infinity(),
                                          std::move(stepping.unsettled));
  else
    moveFreely(stepping.unsettled);
  stepping.hold_needed = true;  // (only an impact says otherwise, for the next)
  const BallSet& held_anew = stepping.unsettled;
  recordHoldEnds(held_anew, stepping.elapsed, next.remaining);
  // A segment's motion changing is an event like a hold's end.
  next.segment_event = timeToSegmentEvent();
  const std::optional<std::size_t> first_end = hold_end_queue_.first();
  next.hold_end = first_end ? hold_ends_[*first_end] : std::numeric_limits<double>::infinity();
  // (Rounding may put a hold's end a hair before now.)
  next.held_for = std::min(
      {next.remaining, next.segment_event, std::max(0.0, next.hold_end - stepping.elapsed)});
  predictChanged(stepping.elapsed, next.remaining);
  next.impact = earliestImpact(stepping.elapsed, next.held_for);
  return next;
}

bool World::outOfBudget(const Stepping& stepping) const {
  return stepping.impacts >= stepping.most ||
         stepping.renewals >= kRenewalsPerImpact * stepping.most;
}

bool World::meetTheStruggle(Stepping& stepping, const Lookahead& next) {
  // Out of budget: the balls settle together, or, where they cannot, those of the struggle wait
  // for the rest of the step rather than hang, drift into their held contacts or move through
  // each other; the others go on, with a budget of their own. If that runs out too, every
  // ball waits at the next event.
  if (!stepping.struggle_waits && stepping.settles &&
      settleTheStruggle(stepping.events_of, stepping.sequential_per_ball, next.remaining)) {
    stepping.freshBudget();
    stepping.unsettled.reset(balls_.size());
    return true;
  }
  if (stopSegmentsPressingTheStruggle(stepping.events_of, stepping.sequential_per_ball)) {
    stepping.freshBudget();
    stepping.unsettled = BallSet::every(balls_.size());
    return true;
  }
  if (!stepping.struggle_waits &&
      holdStillTheStruggle(stepping.events_of, stepping.sequential_per_ball)) {
    stepping.struggle_waits = true;
    stepping.freshBudget();
    stepping.unsettled = BallSet::every(balls_.size());
    return true;
  }
  advance(stepping.elapsed, next.impact ? next.impact->time : next.held_for);
  return false;
}

bool World::renewEndedHolds(Stepping& stepping, const Lookahead& next) {
  advance(stepping.elapsed, next.held_for);
  if (next.held_for == next.remaining) return false;
  stepping.elapsed += next.held_for;
  BallSet ended(balls_.size());
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (next.held_for == next.segment_event || hold_ends_[i] <= next.hold_end) ended.insert(i);
  // A held contact ends for both its balls: a resting one's ending lets it go, and the search
  // for touching pairs does not reach the ball that leaned on it from a resting one.
  for (const auto& [contact, forces] : held_)
    if (involves(contact, ended))
      if (const auto other = otherBallOf(contact.first, contact.second)) {
        ended.insert(contact.first);
        ended.insert(*other);
      }
  for (const std::size_t i : ended.list) ++stepping.events_of[i];
  const KeyPairs touching = touchingPairs(ended);
  stepping.unsettled = touchingTogether(touching, std::move(ended));
  closeHeldContacts(stepping.unsettled);  // and they are held anew
  ++stepping.renewals;
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
  if (settlesOnImpact(impact, stepping.dt - stepping.elapsed, stepping.settles)) {
    stepping.unsettled.reset(balls_.size());
    return true;
  }
  ++stepping.events_of[impact.ball];
  if (const auto other = otherBallOf(impact.ball, keyOf(impact))) ++stepping.events_of[*other];
  resolve(impact, time_ + stepping.elapsed);
  // The balls it woke touch these, so their islands are these balls'; a slow impact changes
  // nothing but is held anew.
  stepping.hold_needed = passThroughTouching(impact, time_ + stepping.elapsed, stepping.passed,
                                             stepping.most, stepping.unsettled);
  ++stepping.impacts;
  return true;
}

void World::endStep(double dt) {
  for (const std::size_t k : movable_segments_) startNextMotion(segments_[k]);
  restartStoppedSegments();
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    ballNow(i);
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
