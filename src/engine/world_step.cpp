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
  Stepping s = beginStep(dt);
  settleAtStart(s.settles, dt);
  for (bool goes_on = true; goes_on;) {
    const Lookahead next = holdAndLookAhead(s);
    if (outOfBudget(s))
      goes_on = meetTheStruggle(s, next);
    else if (!next.impact)
      goes_on = renewEndedHolds(s, next);
    else
      goes_on = meetImpact(s, *next.impact);
  }
  endStep(s.dt);
}

World::Stepping World::beginStep(double dt) {
  if (!(std::isfinite(dt) && dt > 0.0))
    throw std::invalid_argument("time step must be finite and > 0");
  Stepping s(balls_.size());
  s.dt = dt;
  s.settles = canSettle();
  s.sequential_per_ball =
      s.settles ? kSequentialImpactsPerBall : kSequentialImpactsPerBallUnsettled;
  s.sequential = kMinImpactsPerStep + s.sequential_per_ball * balls_.size();
  s.most = kMinImpactsPerStep +
           (s.settles ? kMaxImpactsPerBall : kMaxImpactsPerBallUnsettled) * balls_.size();
  predictAll(dt);
  hold_ends_.assign(balls_.size(), std::numeric_limits<double>::infinity());
  hold_end_queue_.reset(balls_.size(),
                        [this](std::size_t a, std::size_t b) { return holdEndComesFirst(a, b); });
  rope_swings_.assign(ropes_.size(), std::numeric_limits<double>::infinity());
  waiting_velocities_.assign(balls_.size(), std::nullopt);
  unheld_.clear();  // (none unless a step threw)
  return s;
}

World::Lookahead World::holdAndLookAhead(Stepping& s) {
  for (const std::size_t k : movable_segments_) startNextMotion(segments_[k]);
  Lookahead next;
  next.remaining = s.dt - s.elapsed;
  step_left_ = next.remaining;
  if (s.impacts >= s.sequential) {
    s.unsettled = BallSet::every(balls_.size());
    s.hold_needed = true;
  }
  // (Every way on from here sets `unsettled` anew; held anew, it keeps its storage for that.)
  s.unsettled.remove(settled_);  // (their settle holds them)
  if (s.hold_needed)
    s.unsettled = holdRestingBalls(
        s.impacts < s.sequential ? kRestingSpeed : std::numeric_limits<double>::infinity(),
        std::move(s.unsettled));
  else
    moveFreely(s.unsettled);
  s.hold_needed = true;  // (only an impact says otherwise, for the next)
  const BallSet& held_anew = s.unsettled;
  recordHoldEnds(held_anew, s.elapsed, next.remaining);
  // A segment's motion changing is an event like a hold's end.
  next.segment_event = timeToSegmentEvent();
  const std::optional<std::size_t> first_end = hold_end_queue_.first();
  next.hold_end = first_end ? hold_ends_[*first_end] : std::numeric_limits<double>::infinity();
  // (Rounding may put a hold's end a hair before now.)
  next.held_for = std::min(
      {next.remaining, next.segment_event, std::max(0.0, next.hold_end - s.elapsed)});
  predictChanged(s.elapsed, next.remaining);
  next.impact = earliestImpact(s.elapsed, next.held_for);
  return next;
}

bool World::outOfBudget(const Stepping& s) const {
  return s.impacts >= s.most || s.renewals >= kRenewalsPerImpact * s.most;
}

bool World::meetTheStruggle(Stepping& s, const Lookahead& next) {
  // Out of budget: the balls settle together, or, where they cannot, those of the struggle wait
  // for the rest of the step rather than hang, drift into their held contacts or move through
  // each other; the others go on, with a budget of their own. If that runs out too, every
  // ball waits at the next event.
  if (!s.struggle_waits && s.settles &&
      settleTheStruggle(s.events_of, s.sequential_per_ball, next.remaining)) {
    s.freshBudget();
    s.unsettled.reset(balls_.size());
    return true;
  }
  if (stopSegmentsPressingTheStruggle(s.events_of, s.sequential_per_ball)) {
    s.freshBudget();
    s.unsettled = BallSet::every(balls_.size());
    return true;
  }
  if (!s.struggle_waits && holdStillTheStruggle(s.events_of, s.sequential_per_ball)) {
    s.struggle_waits = true;
    s.freshBudget();
    s.unsettled = BallSet::every(balls_.size());
    return true;
  }
  advance(s.elapsed, next.impact ? next.impact->time : next.held_for);
  return false;
}

bool World::renewEndedHolds(Stepping& s, const Lookahead& next) {
  advance(s.elapsed, next.held_for);
  if (next.held_for == next.remaining) return false;
  s.elapsed += next.held_for;
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
  for (const std::size_t i : ended.list) ++s.events_of[i];
  const KeyPairs touching = touchingPairs(ended);
  s.unsettled = touchingTogether(touching, std::move(ended));
  closeHeldContacts(s.unsettled);  // and they are held anew
  ++s.renewals;
  return true;
}

bool World::meetImpact(Stepping& s, const Impact& impact) {
  advance(s.elapsed, impact.time);
  s.elapsed += impact.time;
  if (strike_stop_ && impact.kind == ContactKind::kBall &&
      (impact.ball == *strike_stop_ || impact.other == *strike_stop_)) {
    resolve(impact, time_ + s.elapsed);
    s.dt = s.elapsed;  // (the step ends here)
    return false;
  }
  // A ball that meets a settled one, or a sleeping pile, settles with it.
  if (settlesOnImpact(impact, s.dt - s.elapsed, s.settles)) {
    s.unsettled.reset(balls_.size());
    return true;
  }
  ++s.events_of[impact.ball];
  if (const auto other = otherBallOf(impact.ball, keyOf(impact))) ++s.events_of[*other];
  resolve(impact, time_ + s.elapsed);
  // The balls it woke touch these, so their islands are these balls'; a slow impact changes
  // nothing but is held anew.
  s.hold_needed = passThroughTouching(impact, time_ + s.elapsed, s.passed, s.most, s.unsettled);
  ++s.impacts;
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
