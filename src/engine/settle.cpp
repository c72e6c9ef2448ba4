#include "ball_physics_sim/engine/settle.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/SparseCholesky>

#include "ball_physics_sim/engine/friction.h"
#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

namespace {

// A contact as the sweeps use it: its balls' numbers (a segment is the still body numbered
// after the balls), what a unit impulse does to each, and the impulses so far.
struct Row {
  std::size_t a = 0, b = 0;
  Vec2 normal = Vec2::Zero(), tangent = Vec2::Zero();
  double radius_a = 0.0, radius_b = 0.0;
  double inverse_mass_a = 0.0, inverse_mass_b = 0.0;
  // A unit impulse at a ball's surface turns it by 1 / (k m r) (I = k m r^2).
  double turn_a = 0.0, turn_b = 0.0;
  // What a unit of each impulse changes of the contact's own rate (opening, slip).
  double per_normal = 0.0, per_friction = 0.0;
  double bias = 0.0, friction = 0.0;
  double least_opening = 0.0;  // the rate past which the sweeps go on (see settleTogether)
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

// The velocities (`v`, a segment's the still slot's, zero) and spins (`w`) a settle changes.
struct Rates {
  std::vector<Vec2> v;
  std::vector<double> w;
};

inline void pushNormal(const Row& row, double impulse, Rates& r) {
  r.v[row.a] += row.inverse_mass_a * impulse * row.normal;
  r.v[row.b] -= row.inverse_mass_b * impulse * row.normal;
}

inline void pushTangent(const Row& row, double impulse, Rates& r) {
  r.v[row.a] += row.inverse_mass_a * impulse * row.tangent;
  r.w[row.a] -= row.turn_a * impulse;
  r.v[row.b] -= row.inverse_mass_b * impulse * row.tangent;
  r.w[row.b] -= row.turn_b * impulse;
}

// The opening rate past the bias.
inline double opening(const Row& row, const Rates& r) {
  return row.normal.dot(r.v[row.a] - r.v[row.b]) + row.bias;
}

// The slip (a segment's surface is still).
inline double slip(const Row& row, const Rates& r) {
  return slipAlong(r.v[row.a] - r.v[row.b], row.tangent, row.radius_a, r.w[row.a],
                   row.radius_b * r.w[row.b]);
}

// One projected Gauss-Seidel sweep: each contact's normal push, over-relaxed, then its
// friction within Coulomb's cone.
void sweep(std::vector<Row>& rows, Rates& r) {
  for (Row& row : rows) {
    if (row.per_normal == 0.0) continue;
    const double pushed =
        std::max(0.0, row.normal_impulse - kOverRelaxation * opening(row, r) / row.per_normal);
    pushNormal(row, pushed - row.normal_impulse, r);
    row.normal_impulse = pushed;
    if (row.friction == 0.0) continue;
    const double limit = row.friction * row.normal_impulse;
    const double gripped =
        std::clamp(row.friction_impulse - slip(row, r) / row.per_friction, -limit, limit);
    pushTangent(row, gripped - row.friction_impulse, r);
    row.friction_impulse = gripped;
  }
}

// How far past its least opening the worst contact closes (0 if none does; infinite if a rate
// is not a number).
double worstClosing(const std::vector<Row>& rows, const Rates& r) {
  double worst = 0.0;
  for (const Row& row : rows) {
    const double past = row.least_opening - opening(row, r);
    if (!(past <= worst)) worst = std::isnan(past) ? std::numeric_limits<double>::infinity() : past;
  }
  return worst;
}

// Whether the contacts `pushing` outnumber the ways their balls can move (two each, in the
// plane): then some are redundant.
bool surelyRedundant(const std::vector<Row>& rows, const std::vector<std::size_t>& pushing,
                     std::size_t bodies) {
  std::vector<bool> moved(bodies, false);
  for (const std::size_t k : pushing) {
    if (rows[k].inverse_mass_a > 0.0) moved[rows[k].a] = true;
    if (rows[k].inverse_mass_b > 0.0) moved[rows[k].b] = true;
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
                  const std::vector<double>& inverse_masses, std::vector<Row>& rows, Rates& r) {
  std::vector<std::size_t> pushing;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k].normal_impulse > 0.0 && rows[k].per_normal > 0.0) pushing.push_back(k);
  if (pushing.empty()) return;
  const std::vector<Eigen::Triplet<double>> entries =
      openingPerPush(contacts, inverse_masses, pushing);
  const int m = static_cast<int>(pushing.size());
  // (Every contact's own term is an entry: the diagonal added keeps the pattern.)
  Eigen::SparseMatrix<double> equations(m, m), own(m, m);
  equations.setFromTriplets(entries.begin(), entries.end());
  own = equations.diagonal().asDiagonal();
  Eigen::VectorXd closing(m);
  for (int c = 0; c < m; ++c) closing[c] = -opening(rows[pushing[c]], r);
  const double before = worstClosing(rows, r);
  const Rates kept = r;
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
      pushNormal(row, pushed - row.normal_impulse, r);
      row.normal_impulse = pushed;
    }
    if (change.allFinite() && change.maxCoeff() <= kRunawayPushes * largest &&
        worstClosing(rows, r) <= before)
      return true;
    r = kept;
    for (int c = 0; c < m; ++c) rows[pushing[c]].normal_impulse = kept_pushes[c];
    return false;
  };
  // Redundant, the exact equations are not worth a try.
  if (!surelyRedundant(rows, pushing, r.v.size()) && solved(kExactRegularization)) return;
  solved(kRedundantRegularization);
}

}  // namespace

Settled settleTogether(const std::vector<Ball>& balls, const std::vector<double>& inverse_masses,
                       const std::vector<RestingContact>& contacts,
                       const std::vector<double>& frictions, double duration,
                       std::vector<std::array<double, 2>>* impulses) {
  const std::size_t still = balls.size();  // a segment's number
  Rates r{std::vector<Vec2>(balls.size() + 1, Vec2::Zero()),
          std::vector<double>(balls.size() + 1, 0.0)};
  for (std::size_t i = 0; i < balls.size(); ++i) {
    r.v[i] = balls[i].velocity;
    r.w[i] = balls[i].angular_velocity;
  }
  std::vector<Row> rows(contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const RestingContact& c = contacts[k];
    Row& row = rows[k];
    row.a = c.ball;
    row.b = c.other.value_or(still);
    row.normal = c.normal;
    row.tangent = contactTangent(c.normal);
    const Ball& a = balls[c.ball];
    row.radius_a = a.radius;
    row.inverse_mass_a = inverse_masses[c.ball];
    row.turn_a = row.inverse_mass_a / (a.inertia_factor * a.radius);
    row.per_normal = row.inverse_mass_a;
    row.per_friction = row.inverse_mass_a * (1.0 + 1.0 / a.inertia_factor);
    double smaller = a.radius;
    if (c.other) {
      const Ball& b = balls[*c.other];
      row.radius_b = b.radius;
      row.inverse_mass_b = inverse_masses[*c.other];
      row.turn_b = row.inverse_mass_b / (b.inertia_factor * b.radius);
      row.per_normal += row.inverse_mass_b;
      row.per_friction += row.inverse_mass_b * (1.0 + 1.0 / b.inertia_factor);
      smaller = std::min(smaller, b.radius);
    }
    row.bias = c.bias;
    row.friction = frictions[k];
    row.least_opening = -kSettleOverlap * smaller / duration;
  }
  // The impulses given start the sweeps.
  if (impulses && impulses->size() == contacts.size())
    for (std::size_t k = 0; k < rows.size(); ++k) {
      Row& row = rows[k];
      row.normal_impulse = (*impulses)[k][0];
      const double limit = row.friction * row.normal_impulse;
      row.friction_impulse = std::clamp((*impulses)[k][1], -limit, limit);
      pushNormal(row, row.normal_impulse, r);
      pushTangent(row, row.friction_impulse, r);
    }
  // Rounds of sweeps until no gap closes past its bias by more than kSettleOverlap of the
  // smaller radius over the stretch, or the rounds run out: the next settle's bias opens what
  // they leave. Rounds that have not converged by the last have a load the sweeps pass too
  // slowly (a tall column, a deep pile landing): the pushing contacts are solved together.
  for (int round = 0; round < kSettleRounds; ++round) {
    for (int k = 0; k < kSettleSweeps; ++k) sweep(rows, r);
    if (worstClosing(rows, r) == 0.0) break;
    if (round + 2 == kSettleRounds) pushTogether(contacts, inverse_masses, rows, r);
  }
  if (impulses) impulses->resize(rows.size());
  Settled s;
  s.velocities.assign(r.v.begin(), r.v.end() - 1);
  s.spins.assign(r.w.begin(), r.w.end() - 1);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    s.pushes.push_back(rows[k].normal_impulse);
    if (impulses) (*impulses)[k] = {rows[k].normal_impulse, rows[k].friction_impulse};
  }
  return s;
}

double settleBias(double gap, double duration, bool open) {
  if (gap >= 0.0 || !open) return std::max(gap, 0.0) / duration;
  return -std::min(kOverlapRecovery * -gap / duration, kMostOpeningSpeed);
}

}  // namespace ball_physics_sim::engine
