// World: a step's budgets of events, group by group of balls that may meet in it, and what a
// group out of its budget does: its struggle settles, or stops the segments pressing it, or
// waits.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <iterator>
#include <limits>
#include <optional>
#include <vector>

#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/kinematics.h"

namespace ball_physics_sim::engine {

namespace {

// Bounds the work of one step, group by group of balls that may meet in it (each budget
// kMinImpactsPerStep plus so many per ball of the group: joined groups add up what they spent,
// so a join may put a group past a budget at once). A step normally resolves about one impact
// per ball or fewer (1000 bullets, 0.7). In a pile, balls bounce on each other ever faster, in
// impacts that converge only geometrically, each holding its island anew: past
// kSequentialImpactsPerBall the group's touching balls that still approach stop together in one
// inelastic push instead (inelastic collapse). Past kMaxImpactsPerBall (or as many renewals of held
// contacts, times kRenewalsPerImpact) the group's balls that may meet the struggle settle
// together for the rest of the step, and in the steps after until they rest (see
// World::settleRestOfStep), and the group's budgets start again. Of those that cannot settle
// (islands with a body World::settleTakes refuses), the moving segments pressing the struggle
// stop for the rest of the step, or else its balls wait. Where none of that helps, the rest of
// the step is given up for every ball rather than hang. The hits an impact passes on through
// touching balls at its instant, cheap, are not counted among them, but as many bound them.
constexpr std::size_t kSequentialImpactsPerBall = 2;
constexpr std::size_t kMaxImpactsPerBall = 3;
constexpr std::size_t kMinImpactsPerStep = 256;
// Held contacts may be held anew this many times as often as impacts happen: a ball sliding
// round a small cap needs a few hundred renewals in a long step.
constexpr std::size_t kRenewalsPerImpact = 4;

// The groups (by their balls) of the balls in `went` that are still `past` a budget, each
// named once by the ball that names it; `went` keeps only those.
template <typename Past>
std::vector<std::size_t> stillPast(std::vector<std::size_t>& went, DisjointSets& groups,
                                   Past past) {
  if (went.empty()) return went;
  for (std::size_t& ball : went) ball = groups.find(ball);
  std::sort(went.begin(), went.end());
  went.erase(std::unique(went.begin(), went.end()), went.end());
  went.erase(std::remove_if(went.begin(), went.end(), [&](std::size_t g) { return !past(g); }),
             went.end());
  return went;
}

}  // namespace

void World::Stepping::join(std::size_t a, std::size_t b) {
  const std::size_t from = groups.find(a), into = groups.find(b);
  if (from == into) return;
  groups.join(from, into);
  Spent& joined = spent[into];
  const Spent& other = spent[from];
  joined.balls += other.balls;
  joined.impacts += other.impacts;
  joined.passed += other.passed;
  joined.renewals += other.renewals;
  joined.waits = joined.waits || other.waits;
  noteBudgets(into);
}

void World::Stepping::countImpact(std::size_t ball) {
  const std::size_t g = group(ball);
  ++spent[g].impacts;
  noteBudgets(g);
}

void World::Stepping::countRenewal(std::size_t ball) {
  const std::size_t g = group(ball);
  ++spent[g].renewals;
  noteBudgets(g);
}

std::size_t World::Stepping::sequential(std::size_t group) const {
  return kMinImpactsPerStep + kSequentialImpactsPerBall * spent[group].balls;
}

std::size_t World::Stepping::most(std::size_t group) const {
  return kMinImpactsPerStep + kMaxImpactsPerBall * spent[group].balls;
}

void World::Stepping::noteBudgets(std::size_t group) {
  const Spent& g = spent[group];
  if (g.impacts >= sequential(group)) went_past_sequential.push_back(group);
  if (g.impacts >= most(group) || g.renewals >= kRenewalsPerImpact * most(group))
    went_out.push_back(group);
}

std::vector<std::size_t> World::Stepping::pastSequential() {
  return stillPast(went_past_sequential, groups,
                   [this](std::size_t g) { return spent[g].impacts >= sequential(g); });
}

std::vector<std::size_t> World::Stepping::outOfBudget() {
  return stillPast(went_out, groups, [this](std::size_t g) {
    return spent[g].impacts >= most(g) || spent[g].renewals >= kRenewalsPerImpact * most(g);
  });
}

std::vector<std::size_t> World::Stepping::changedGroups(const std::vector<std::size_t>& named) {
  if (named.empty()) return {};
  std::vector<std::size_t> changed;
  for (const std::size_t i : unsettled.list) changed.push_back(group(i));
  std::sort(changed.begin(), changed.end());
  std::vector<std::size_t> both;
  std::set_intersection(named.begin(), named.end(), changed.begin(), changed.end(),
                        std::back_inserter(both));
  return both;
}

World::BallSet World::Stepping::ballsOf(const std::vector<std::size_t>& named) {
  std::vector<bool> is_named(events_of.size(), false);  // by the ball naming a group
  for (const std::size_t g : named) is_named[g] = true;
  BallSet balls(events_of.size());
  for (std::size_t i = 0; i < events_of.size(); ++i)
    if (is_named[group(i)]) balls.insert(i);
  return balls;
}

void World::Stepping::freshBudget() {
  for (const std::size_t g : outOfBudget())
    spent[g].impacts = spent[g].passed = spent[g].renewals = 0;
  went_out.clear();
}

bool World::meetTheStruggle(Stepping& stepping, const Lookahead& next) {
  // Out of budget: the balls of the struggle (in the groups out of budget) settle together, or,
  // where they cannot, those of the struggle wait for the rest of the step rather than hang,
  // drift into their held contacts or move through each other; the others go on. If that runs
  // out too, every ball waits at the next event.
  const std::vector<std::size_t> out = stepping.outOfBudget();
  bool waits = false;
  for (const std::size_t g : out) waits = waits || stepping.spent[g].waits;
  BallSet struggle = stepping.ballsOf(out);
  std::vector<std::size_t> events_of = stepping.events_of;  // (the struggle's only)
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (!struggle.contains(i)) events_of[i] = 0;
  if (!waits && settleTheStruggle(events_of, next.remaining)) {
    stepping.freshBudget();
    stepping.unsettled.reset(balls_.size());
    return true;
  }
  if (stopSegmentsPressingTheStruggle(events_of)) {
    stepping.freshBudget();
    stepping.unsettled = BallSet::every(balls_.size());  // (a segment may touch any)
    return true;
  }
  if (!waits && holdStillTheStruggle(events_of)) {
    for (const std::size_t g : out) stepping.spent[g].waits = true;
    stepping.freshBudget();
    stepping.unsettled = std::move(struggle);
    return true;
  }
  advance(stepping.elapsed, next.impact ? next.impact->time : next.held_for);
  return false;
}

World::BallSet World::strugglingBalls(const std::vector<std::size_t>& events_of,
                                     std::size_t least) const {
  BallSet struggling(balls_.size());
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (!balls_[i].at_rest && !isSettled(i) && events_of[i] >= least) struggling.insert(i);
  return struggling;
}

bool World::holdStillTheStruggle(const std::vector<std::size_t>& events_of) {
  // (Least 0: every moving ball in the world, the struggle's or not.)
  const std::size_t moving = strugglingBalls(events_of, 0).list.size();
  BallSet struggling = strugglingBalls(events_of, kSequentialImpactsPerBall);
  const KeyPairs pairs = touchingPairs(struggling);
  // A moving segment would strike a waiting ball it touches at once (a ball it crushes against
  // a wall): the struggle would start again, and run out again.
  for (const auto& [ball, key] : pairs)
    if (const auto segment = segmentOf(key); segment && moves(segments_[*segment])) return false;
  struggling = touchingTogether(pairs, std::move(struggling));
  if (struggling.list.empty() || struggling.list.size() == moving) return false;
  for (const std::size_t i : struggling.list) {
    waiting_velocities_[i] = ballNow(i).velocity;
    comeToRest(i);
    queueHoldEnd(i, std::numeric_limits<double>::infinity());
  }
  letGoHeldContacts(struggling);
  return true;
}

bool World::settleTheStruggle(const std::vector<std::size_t>& events_of, double remaining) {
  // The balls met by the most events, or, if the budget went on many balls, every one met.
  BallSet seeds = strugglingBalls(events_of, kSequentialImpactsPerBall);
  if (seeds.list.empty()) seeds = strugglingBalls(events_of, 1);
  if (seeds.list.empty() || !settleRestOfStep(remaining, seeds)) return false;
  // A seed the settle did not take meets nothing to the step's end: none struggles on.
  for (const std::size_t i : seeds.list) {
    ballNow(i);  // (its course changes: settled)
    settled_.insert(i);
  }
  return true;
}

bool World::stopSegmentsPressingTheStruggle(const std::vector<std::size_t>& events_of) {
  bool stopped = false;
  const BallSet struggling = strugglingBalls(events_of, kSequentialImpactsPerBall);
  for (const auto& [ball, key] : touchingPairs(struggling)) {
    const std::optional<std::size_t> k = segmentOf(key);
    if (!k || !moves(segments_[*k])) continue;
    stopSegment(*k);
    stopped = true;
  }
  return stopped;
}

}  // namespace ball_physics_sim::engine
