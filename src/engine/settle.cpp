#include "ball_physics_sim/engine/settle.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/SparseCholesky>

#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

namespace {

// A contact as the sweeps use it, its hot loop's data only (a settle's rows fit a fast cache):
// its bodies' numbers (a segment is the still body numbered after the balls), its normal
// (the tangent is perpendicular to it), and per impulse the share of its own rate a unit of it
// takes away (its effective mass) and the impulse so far.
struct Row {
  std::uint32_t a = 0, b = 0;
  double normal_x = 0.0, normal_y = 0.0;
  double bias = 0.0, friction = 0.0;
  double normal_mass = 0.0, friction_mass = 0.0;
  double normal_impulse = 0.0, friction_impulse = 0.0;
};

// Added to the diagonal of the pushing contacts' equations (pushTogether), as a share of each
// contact's own term: first next to nothing, exact; then enough to keep the pushes in bounds
// where redundant contacts (a ball on three in a packed pile) have biases that disagree, which
// make the exact equations unsolvable (a tall column then falls a little short).
constexpr double kExactRegularization = 1e-10;
constexpr double kRedundantRegularization = 1e-2;
// Pushes that grow past this many times the sweeps' largest have run away: pushes of
// redundant contacts that cancel each other out.
constexpr double kRunawayPushes = 1e3;

// A row waits for the rows just before it that changed one of its balls: rows apart run side by
// side on the processor. So a sweep puts a row off while it shares a ball with one of the
// kIndependentRows - 1 rows before it (at most kMostPutOff rows put off at once; the oldest
// goes when they are): rows after it go ahead, a few sharing a ball with it too, so the order
// is near the one given, not it, and mostly keeps its effect (a push passes bottom-up through a
// pile in a sweep). The sweeps run 1.7x faster (a 32-row pile: 15 ns a row against 9).
// Putting a row off only past rows sharing no ball with it, which gives the given order's
// results exactly, ran 1.1x faster.
constexpr std::size_t kIndependentRows = 3;
constexpr std::size_t kMostPutOff = 16;

// A contact without a push (nor friction: pushTogether may leave some where it took the push
// away) whose gap opens by more than this over the stretch, as a share of the smaller radius,
// is left out of a round's sweeps: it would take none in them (a round rarely pushes its balls
// together that much), and the round's end checks it with the others. A churned pile's settles
// end with a third of their contacts opening without a push (pairs near, not touching).
constexpr double kUnsweptOpening = 1e-2;

// A body as the sweeps change it: its velocity and spin, and what a unit impulse at its surface
// does to them (a segment's still slot: nothing).
struct Body {
  double vx = 0.0, vy = 0.0, w = 0.0;
  double inverse_mass = 0.0;
  double turn = 0.0;  // a unit impulse at its surface turns it by 1 / (k m r) (I = k m r^2)
  double radius = 0.0;
};
using Bodies = std::vector<Body>;

inline void push(const Row& row, double normal, double friction, Bodies& bodies) {
  // (Along the normal and its perpendicular, the tangent.)
  const double x = normal * row.normal_x - friction * row.normal_y;
  const double y = normal * row.normal_y + friction * row.normal_x;
  Body& a = bodies[row.a];
  a.vx += a.inverse_mass * x;
  a.vy += a.inverse_mass * y;
  a.w -= a.turn * friction;
  Body& b = bodies[row.b];
  b.vx -= b.inverse_mass * x;
  b.vy -= b.inverse_mass * y;
  b.w -= b.turn * friction;
}

// The opening rate past the bias.
inline double opening(const Row& row, const Bodies& bodies) {
  const Body& a = bodies[row.a];
  const Body& b = bodies[row.b];
  return row.normal_x * (a.vx - b.vx) + row.normal_y * (a.vy - b.vy) + row.bias;
}

// The slip (see slipSpeed; a segment's surface is still).
inline double slip(const Row& row, const Bodies& bodies) {
  const Body& a = bodies[row.a];
  const Body& b = bodies[row.b];
  return -row.normal_y * (a.vx - b.vx) + row.normal_x * (a.vy - b.vy) - a.radius * a.w -
         b.radius * b.w;
}

// The order of the sweeps: `contacts` in the order given, each put off (see kIndependentRows)
// while it shares a ball with one of the few before it, later ones going ahead.
std::vector<std::size_t> sweepOrder(const std::vector<RestingContact>& contacts,
                                    std::size_t balls) {
  std::vector<std::size_t> order;
  order.reserve(contacts.size());
  // Where each ball's last row is in the order, and the rows put off, oldest first.
  std::vector<std::size_t> last(balls, std::numeric_limits<std::size_t>::max());
  std::vector<std::size_t> put_off;
  const auto apart = [&](std::size_t ball) {
    return last[ball] == std::numeric_limits<std::size_t>::max() ||
           last[ball] + kIndependentRows <= order.size();
  };
  const auto ready = [&](std::size_t k) {
    return apart(contacts[k].ball) && (!contacts[k].other || apart(*contacts[k].other));
  };
  std::size_t next = 0;
  while (order.size() < contacts.size()) {
    // The oldest row put off that is apart now, else the next in line, putting off those that
    // are not; where none is, the oldest put off goes.
    auto taken = std::find_if(put_off.begin(), put_off.end(), ready);
    if (taken == put_off.end()) {
      while (next < contacts.size() && put_off.size() < kMostPutOff && !ready(next))
        put_off.push_back(next++);
      taken = next < contacts.size() && put_off.size() < kMostPutOff
                  ? put_off.insert(put_off.end(), next++)
                  : put_off.begin();
    }
    const std::size_t k = *taken;
    put_off.erase(taken);
    last[contacts[k].ball] = order.size();
    if (contacts[k].other) last[*contacts[k].other] = order.size();
    order.push_back(k);
  }
  return order;
}

// One projected Gauss-Seidel sweep: each contact's normal push, over-relaxed, then its
// friction within Coulomb's cone (a push along the normal leaves the slip as it was).
void sweep(std::vector<Row>& rows, Bodies& bodies) {
  for (Row& row : rows) {
    if (row.normal_mass == 0.0) continue;
    const double pushed = std::max(
        0.0, row.normal_impulse - kOverRelaxation * opening(row, bodies) * row.normal_mass);
    const double limit = row.friction * pushed;
    const double gripped = std::clamp(
        row.friction_impulse - slip(row, bodies) * row.friction_mass, -limit, limit);
    push(row, pushed - row.normal_impulse, gripped - row.friction_impulse, bodies);
    row.normal_impulse = pushed;
    row.friction_impulse = gripped;
  }
}

// A round of kSettleSweeps sweeps over the rows that may push (see kUnsweptOpening), in their
// order.
void sweepRound(std::vector<Row>& rows, const std::vector<double>& least, Bodies& bodies) {
  std::vector<Row> swept;
  std::vector<std::size_t> numbers;  // each swept row's in `rows`
  for (std::size_t j = 0; j < rows.size(); ++j)
    // (least is -kSettleOverlap of the smaller radius over the stretch.)
    if (rows[j].normal_impulse > 0.0 || rows[j].friction_impulse != 0.0 ||
        opening(rows[j], bodies) <= -kUnsweptOpening / kSettleOverlap * least[j]) {
      swept.push_back(rows[j]);
      numbers.push_back(j);
    }
  for (int k = 0; k < kSettleSweeps; ++k) sweep(swept, bodies);
  for (std::size_t i = 0; i < swept.size(); ++i) rows[numbers[i]] = swept[i];
}

// How far past its least opening (`least`, per row) the worst contact closes (0 if none does;
// infinite if a rate is not a number).
double worstClosing(const std::vector<Row>& rows, const std::vector<double>& least,
                    const Bodies& bodies) {
  double worst = 0.0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double past = least[k] - opening(rows[k], bodies);
    if (!(past <= worst)) worst = std::isnan(past) ? std::numeric_limits<double>::infinity() : past;
  }
  return worst;
}

// Whether the contacts `pushing` outnumber the ways their balls can move (two each, in the
// plane): then some are redundant.
bool surelyRedundant(const std::vector<Row>& rows, const std::vector<std::size_t>& pushing,
                     const Bodies& bodies) {
  std::vector<bool> moved(bodies.size(), false);
  for (const std::size_t k : pushing) {
    if (bodies[rows[k].a].inverse_mass > 0.0) moved[rows[k].a] = true;
    if (bodies[rows[k].b].inverse_mass > 0.0) moved[rows[k].b] = true;
  }
  const auto balls = static_cast<std::size_t>(std::count(moved.begin(), moved.end(), true));
  return pushing.size() > 2 * balls;
}

// The contacts that push, their pushes found together so that each closes at just its bias
// (friction held as it is), directly: sweeps pass a change of load through a pile a ball a sweep,
// and a landing pile's load changes from top to bottom. Where pushes would turn to pulls they
// stop at none, and the sweeps go on from there. Kept if the worst gap closes no worse and no
// push runs away; friction past its cone with a push made smaller waits for the next sweep.
void pushTogether(const std::vector<RestingContact>& contacts,
                  const std::vector<std::size_t>& order,
                  const std::vector<double>& inverse_masses, const std::vector<double>& least,
                  std::vector<Row>& rows, Bodies& bodies) {
  std::vector<std::size_t> pushing, pushing_contacts;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k].normal_impulse > 0.0 && rows[k].normal_mass > 0.0) {
      pushing.push_back(k);
      pushing_contacts.push_back(order[k]);
    }
  if (pushing.empty()) return;
  const std::vector<Eigen::Triplet<double>> entries =
      openingPerPush(contacts, inverse_masses, pushing_contacts);
  const int m = static_cast<int>(pushing.size());
  // (Every contact's own term is an entry: the diagonal added keeps the pattern.)
  Eigen::SparseMatrix<double> equations(m, m), own(m, m);
  equations.setFromTriplets(entries.begin(), entries.end());
  own = equations.diagonal().asDiagonal();
  Eigen::VectorXd closing(m);
  for (int c = 0; c < m; ++c) closing[c] = -opening(rows[pushing[c]], bodies);
  const double before = worstClosing(rows, least, bodies);
  const Bodies kept = bodies;
  std::vector<double> kept_pushes(m);
  for (int c = 0; c < m; ++c) kept_pushes[c] = rows[pushing[c]].normal_impulse;
  const double largest = *std::max_element(kept_pushes.begin(), kept_pushes.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factors;
  factors.analyzePattern(equations);  // (the order that keeps the factors sparse, found once)
  auto solved = [&](double regularization) {
    factors.factorize(equations + regularization * own);
    if (factors.info() != Eigen::Success) return false;
    const Eigen::VectorXd change = factors.solve(closing);
    for (int c = 0; c < m; ++c) {
      Row& row = rows[pushing[c]];
      const double pushed = std::max(0.0, kept_pushes[c] + change[c]);
      push(row, pushed - row.normal_impulse, 0.0, bodies);
      row.normal_impulse = pushed;
    }
    if (change.allFinite() && change.maxCoeff() <= kRunawayPushes * largest &&
        worstClosing(rows, least, bodies) <= before)
      return true;
    bodies = kept;
    for (int c = 0; c < m; ++c) rows[pushing[c]].normal_impulse = kept_pushes[c];
    return false;
  };
  // Redundant, the exact equations are not worth a try.
  if (!surelyRedundant(rows, pushing, bodies) && solved(kExactRegularization)) return;
  solved(kRedundantRegularization);
}

}  // namespace

Settled settleTogether(const std::vector<Ball>& balls, const std::vector<double>& inverse_masses,
                       const std::vector<RestingContact>& contacts,
                       const std::vector<double>& frictions, double duration,
                       std::vector<std::array<double, 2>>* impulses) {
  const std::size_t still = balls.size();  // a segment's number
  Bodies bodies(balls.size() + 1);
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Ball& ball = balls[i];
    Body& body = bodies[i];
    body.vx = ball.velocity.x();
    body.vy = ball.velocity.y();
    body.w = ball.angular_velocity;
    body.inverse_mass = inverse_masses[i];
    body.turn = body.inverse_mass / (ball.inertia_factor * ball.radius);
    body.radius = ball.radius;
  }
  // What a unit impulse at a ball's surface changes of a contact's rates: along the normal, its
  // inverse mass; across it, that and the turn, r / I = 1 / (k m r) times r.
  const auto perNormal = [&](std::size_t i) { return bodies[i].inverse_mass; };
  const auto perFriction = [&](std::size_t i) {
    return bodies[i].inverse_mass * (1.0 + 1.0 / balls[i].inertia_factor);
  };
  // Row j is contact order[j].
  const std::vector<std::size_t> order = sweepOrder(contacts, balls.size());
  std::vector<Row> rows(contacts.size());
  std::vector<double> least(contacts.size());  // the rate past which the sweeps go on
  for (std::size_t j = 0; j < rows.size(); ++j) {
    const std::size_t k = order[j];
    const RestingContact& c = contacts[k];
    Row& row = rows[j];
    row.a = static_cast<std::uint32_t>(c.ball);
    row.b = static_cast<std::uint32_t>(c.other.value_or(still));
    row.normal_x = c.normal.x();
    row.normal_y = c.normal.y();
    double per_normal = perNormal(c.ball), per_friction = perFriction(c.ball);
    double smaller = balls[c.ball].radius;
    if (c.other) {
      per_normal += perNormal(*c.other);
      per_friction += perFriction(*c.other);
      smaller = std::min(smaller, balls[*c.other].radius);
    }
    row.bias = c.bias;
    row.friction = frictions[k];
    if (per_normal > 0.0) {
      row.normal_mass = 1.0 / per_normal;
      row.friction_mass = 1.0 / per_friction;
    }
    least[j] = -kSettleOverlap * smaller / duration;
  }
  // The impulses given start the sweeps.
  if (impulses && impulses->size() == contacts.size())
    for (std::size_t j = 0; j < rows.size(); ++j) {
      Row& row = rows[j];
      const std::array<double, 2>& given = (*impulses)[order[j]];
      row.normal_impulse = given[0];
      const double limit = row.friction * row.normal_impulse;
      row.friction_impulse = std::clamp(given[1], -limit, limit);
      push(row, row.normal_impulse, row.friction_impulse, bodies);
    }
  // Rounds of sweeps until no gap closes past its bias by more than kSettleOverlap of the
  // smaller radius over the stretch, or the rounds run out: the next settle's bias opens what
  // they leave. Rounds that have not converged by the last have a load the sweeps pass too
  // slowly (a tall column, a deep pile landing): the pushing contacts are solved together.
  for (int round = 0; round < kSettleRounds; ++round) {
    sweepRound(rows, least, bodies);
    if (worstClosing(rows, least, bodies) == 0.0) break;
    if (round + 2 == kSettleRounds)
      pushTogether(contacts, order, inverse_masses, least, rows, bodies);
  }
  if (impulses) impulses->resize(rows.size());
  Settled s;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    s.velocities.emplace_back(bodies[i].vx, bodies[i].vy);
    s.spins.push_back(bodies[i].w);
  }
  s.pushes.resize(rows.size());
  for (std::size_t j = 0; j < rows.size(); ++j) {
    s.pushes[order[j]] = rows[j].normal_impulse;
    if (impulses) (*impulses)[order[j]] = {rows[j].normal_impulse, rows[j].friction_impulse};
  }
  return s;
}

double settleBias(double gap, double duration, bool open) {
  if (gap >= 0.0 || !open) return std::max(gap, 0.0) / duration;
  return -std::min(kOverlapRecovery * -gap / duration, kMostOpeningSpeed);
}

}  // namespace ball_physics_sim::engine
