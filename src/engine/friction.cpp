#include "ball_physics_sim/engine/friction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>
#include <utility>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseLU>

namespace ball_physics_sim::engine {

double combinedFriction(double friction_a, double friction_b) {
  return std::sqrt(friction_a * friction_b);
}

Vec2 contactTangent(const Vec2& normal) { return perpendicular(normal); }

double slipSpeed(const Vec2& relative_velocity, const Vec2& normal, double radius, double spin,
                 double other_surface) {
  // The ball's contact point lies at -r n from its centre, where spin w moves it by
  // w x (-r n) = -w r t; the other body's lies on the far side and moves by -other_surface t.
  return relative_velocity.dot(contactTangent(normal)) - radius * spin - other_surface;
}

double tangentialInverseMass(const Ball& ball) {
  return (1.0 + 1.0 / ball.inertia_factor) / ball.mass;
}

double tangentialImpulse(double slip, double normal_impulse, double friction,
                         double inverse_mass_sum) {
  const double limit = friction * normal_impulse;
  return std::clamp(-slip / inverse_mass_sum, -limit, limit);
}

void pushSurface(Ball& ball, const Vec2& normal, double impulse) {
  ball.velocity += impulse / ball.mass * contactTangent(normal);
  // The impulse acts at -r n from the centre: its torque is (-r n) x (J t) = -r J.
  ball.angular_velocity -= impulse / (ball.inertia_factor * ball.mass * ball.radius);
}

void pushSurfaces(Ball& ball, Ball& other, const Vec2& normal, double impulse) {
  pushSurface(ball, normal, impulse);
  pushSurface(other, -normal, impulse);
}

namespace {

// Pivoted equations of up to this many unknowns are solved with dense matrices, more with
// sparse.
constexpr Eigen::Index kDenselyPivoted = 128;
// A solution holds where no contact pushes with a negative force and none breaks its condition
// on a rate by more than this fraction of the largest rate (nor a cone by more than the force
// that makes such a rate).
constexpr double kPivotTolerance = 1e-12;
// Added, relative to the largest diagonal term, to the diagonal of the pivoted equations:
// redundant contacts (a ball wedged by three) make them singular.
constexpr double kPivotRegularization = 1e-12;
// Equations without a solution, made definite, are answered with forces of the order of
// 1 / kPivotRegularization times the free rates, whose rounding the tolerance would then allow;
// no stack or wedge presses nearly this many times the free rates (a column of 1000 balls, its
// floor 1000 times a ball's weight).
constexpr double kRunawayForces = 1e8;
// Pivots allowed an island of n contacts: cold, each contact closes, and may then slide and
// stick; warm, a few.
int mostPivots(int contacts) { return 4 * contacts + 16; }

// What a pivoted problem is about: the forces of resting contact, which keep rates of change
// (accelerations) from breaking the contacts' conditions; or the impulses of a slow, perfectly
// inelastic impact, which do so for velocities, and with which a slip slower than kRollingSlip
// is stopped, if Coulomb's cone and what stops kRollingSlip allow, at any contact with friction,
// whatever its push (so slow a slip is rolling, to rounding).
enum class Level { kForces, kImpulses };

// Each contact has three forces and three rates, at 3k + one of these: its normal force and
// opening rate; its friction force and slip rate; and, for rolling resistance, its torque over
// the ball's radius (a force at the surface) and the rate at which the ball's turning speeds up
// at its surface, r dw/dt.
enum Part { kNormal = 0, kFriction = 1, kRolling = 2, kParts = 3 };
constexpr Part kResistances[] = {kFriction, kRolling};

// What one side of a contact takes from its ball's acceleration (x, y) and angular acceleration,
// for each of the contact's rates. The same rows, transposed, are what the contact's forces
// give the ball, per unit force and per unit inverse inertia.
struct ContactSide {
  int contact;
  std::size_t ball;
  std::array<Eigen::Vector3d, kParts> rows;
};

// An island's contacts as linear equations in their forces: the rates are
// response * forces + free_rates.
struct FrictionalEquations {
  std::vector<ContactSide> sides;
  std::vector<Eigen::Vector3d> inverse_inertia;  // per ball: x, y and angular
  Eigen::SparseMatrix<double> response;
  Eigen::VectorXd free_rates;
  Eigen::VectorXd rate_per_force;  // response's diagonal: each rate per unit of its own force
};

FrictionalEquations frictionalEquations(Level level, const std::vector<Vec2>& free,
                                        const std::vector<Ball>& balls,
                                        const std::vector<double>& inverse_masses,
                                        const std::vector<RestingContact>& contacts,
                                        const std::vector<ContactFriction>& frictions) {
  FrictionalEquations e;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const double im = inverse_masses[i], r = balls[i].radius;
    e.inverse_inertia.emplace_back(im, im, im / (balls[i].inertia_factor * r * r));
  }
  const int n = static_cast<int>(contacts.size());
  e.free_rates = Eigen::VectorXd::Zero(kParts * n);
  for (int k = 0; k < n; ++k) {
    const RestingContact& c = contacts[k];
    const Vec2 normal = c.normal, t = contactTangent(normal);
    const double r = balls[c.ball].radius;
    // As slipSpeed: both surfaces' spins take from the slip, whichever side they are on.
    // Rolling resistance turns the ball alone (it acts on a segment).
    const double rolling = frictions[k].rolling_resistance != 0.0 ? r : 0.0;
    e.sides.push_back({k, c.ball,
                       {Eigen::Vector3d(normal.x(), normal.y(), 0.0),
                        Eigen::Vector3d(t.x(), t.y(), -r), Eigen::Vector3d(0.0, 0.0, rolling)}});
    if (c.other && inverse_masses[*c.other] != 0.0)
      e.sides.push_back({k, *c.other,
                         {Eigen::Vector3d(-normal.x(), -normal.y(), 0.0),
                          Eigen::Vector3d(-t.x(), -t.y(), -balls[*c.other].radius),
                          Eigen::Vector3d::Zero()}});
    e.free_rates[kParts * k + kNormal] = c.bias;
  }
  for (const ContactSide& s : e.sides)
    for (int p = 0; p < kParts; ++p)
      e.free_rates[kParts * s.contact + p] += s.rows[p].head<2>().dot(free[s.ball]);
  // Free velocities come with spins, and a moving segment's surface: the slip has them all.
  if (level == Level::kImpulses)
    for (int k = 0; k < n; ++k) e.free_rates[kParts * k + kFriction] = frictions[k].slip;
  // Nonzero only between contacts that share a ball: found from the sides of each ball.
  std::vector<const ContactSide*> by_ball;
  for (const ContactSide& s : e.sides) by_ball.push_back(&s);
  std::sort(by_ball.begin(), by_ball.end(),
            [](const ContactSide* a, const ContactSide* b) { return a->ball < b->ball; });
  std::vector<Eigen::Triplet<double>> entries;  // duplicates summed
  for (auto a = by_ball.begin(); a != by_ball.end(); ++a)
    for (auto b = a; b != by_ball.end() && (*b)->ball == (*a)->ball; ++b) {
      const Eigen::Vector3d& im = e.inverse_inertia[(*a)->ball];
      const int first_a = kParts * (*a)->contact, first_b = kParts * (*b)->contact;
      for (int i = 0; i < kParts; ++i)
        for (int j = 0; j < kParts; ++j) {
          const double entry = (*a)->rows[i].dot(im.cwiseProduct((*b)->rows[j]));
          if (entry == 0.0) continue;
          entries.emplace_back(first_a + i, first_b + j, entry);
          if (b != a) entries.emplace_back(first_b + j, first_a + i, entry);
        }
    }
  e.response.resize(kParts * n, kParts * n);
  e.response.setFromTriplets(entries.begin(), entries.end());
  e.rate_per_force = e.response.diagonal();
  return e;
}

// How a contact's friction, or its rolling resistance, resists: it grips (its force is what
// keeps its rate zero) or gives, at the cone's edge, its coefficient times N along `give`
// (0 where the coefficient is).
struct Grip {
  bool grips = false;
  double give = 0.0;
  bool operator==(const Grip& g) const { return grips == g.grips && give == g.give; }
};

// How a contact holds in a pivoted solve: apart, or pushing, with its friction and its rolling
// resistance each gripping or giving.
struct Hold {
  bool pushes = false;
  std::array<Grip, kParts> grips;  // at kFriction and kRolling
  bool operator==(const Hold& h) const { return pushes == h.pushes && grips == h.grips; }
};

// A contact's friction or rolling resistance: its coefficient, how fast what it resists moves
// now (the slip, or the ball's surface turning), and what it may add to the cone's edge,
// pushing or not. Moving, it gives against that motion; still, it may grip, up to
// coefficient * N + allowance.
struct Resistance {
  double coefficient = 0.0;
  double moving = 0.0;
  double allowance = 0.0;
  bool resists() const { return coefficient > 0.0 || allowance > 0.0; }
  bool mayGrip() const { return resists() && std::abs(moving) <= kRollingSlip; }
  double limit(double normal) const { return coefficient * normal + allowance; }
};

std::vector<std::array<Resistance, kParts>> resistances(
    Level level, const FrictionalEquations& e, const std::vector<Ball>& balls,
    const std::vector<RestingContact>& contacts, const std::vector<ContactFriction>& frictions) {
  std::vector<std::array<Resistance, kParts>> all;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Ball& b = balls[contacts[k].ball];
    std::array<Resistance, kParts>& r = all.emplace_back();
    const double slip = frictions[k].slip;
    if (level == Level::kImpulses) {
      // A slip this slow is rolling, to rounding: beyond the cone, static friction has the
      // impulse that stops kRollingSlip, whatever the contact's push (a resting contact's is
      // next to none). Faster slips are left to friction's force; slow spins, to stopSlowSpin.
      if (frictions[k].friction > 0.0 && std::abs(slip) <= kRollingSlip)
        r[kFriction] = {frictions[k].friction, slip,
                        kRollingSlip / e.rate_per_force[kParts * k + kFriction]};
      continue;
    }
    r[kFriction] = {frictions[k].friction, slip};
    r[kRolling] = {frictions[k].rolling_resistance, b.angular_velocity * b.radius};
  }
  return all;
}

// Whether a part acts: at a pushing contact, or with an allowance.
bool acts(const Hold& hold, const Resistance& resistance) {
  return hold.pushes || resistance.allowance > 0.0;
}

// Whether a part's force is an unknown of the pivoted equations, its rate kept zero.
bool gripsNow(const Hold& hold, const Resistance& resistance, Part part) {
  return hold.grips[part].grips && acts(hold, resistance);
}

// A contact's forces, one per part, from its normal force, friction force and torque.
std::array<double, kParts> parts(const ContactForces& f, double radius) {
  return {f.normal, f.friction, f.torque / radius};
}

// Each contact's hold as its forces of a moment ago (`start`) show it; apart if it has none.
std::vector<Hold> lastHolds(const std::vector<Ball>& balls,
                            const std::vector<RestingContact>& contacts,
                            const std::vector<std::array<Resistance, kParts>>& resisting,
                            const std::vector<ContactForces>& start) {
  std::vector<Hold> holds(contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const ContactForces last = k < start.size() ? start[k] : ContactForces();
    const std::array<double, kParts> force = parts(last, balls[contacts[k].ball].radius);
    holds[k].pushes = last.normal > 0.0;
    for (const Part p : kResistances) {
      const Resistance& r = resisting[k][p];
      Grip& g = holds[k].grips[p];
      g.grips = r.mayGrip() && std::abs(force[p]) < r.limit(last.normal);
      if (r.resists() && !g.grips)
        g.give = std::copysign(1.0, r.mayGrip() ? force[p] : -r.moving);
    }
  }
  return holds;
}

// The solution of the square equations `entries` x = rhs, made definite by `regularization`
// on their diagonal and refined once against the exact ones: dense for a few unknowns, sparse
// for many (each contact shares balls with a few others). NaN if the sparse factoring fails.
Eigen::VectorXd solveRegularized(const std::vector<Eigen::Triplet<double>>& entries,
                                 const Eigen::VectorXd& rhs, double regularization) {
  const Eigen::Index m = rhs.size();
  if (m <= kDenselyPivoted) {
    Eigen::MatrixXd equations = Eigen::MatrixXd::Zero(m, m);
    for (const Eigen::Triplet<double>& t : entries) equations(t.row(), t.col()) += t.value();
    Eigen::MatrixXd regularized = equations;
    regularized.diagonal().array() += regularization;
    const Eigen::PartialPivLU<Eigen::MatrixXd> factors(regularized);
    const Eigen::VectorXd solved = factors.solve(rhs);
    return solved + factors.solve(rhs - equations * solved);
  }
  Eigen::SparseMatrix<double> equations(m, m), diagonal(m, m);
  equations.setFromTriplets(entries.begin(), entries.end());
  diagonal.setIdentity();
  const Eigen::SparseMatrix<double> regularized = equations + regularization * diagonal;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> factors(regularized);
  if (factors.info() != Eigen::Success)
    return Eigen::VectorXd::Constant(m, std::numeric_limits<double>::quiet_NaN());
  const Eigen::VectorXd solved = factors.solve(rhs);
  return solved + factors.solve(rhs - equations * solved);
}

// The forces that meet the equations of the contacts' holds: a pushing contact's opening rate
// is zero, and the rate of each part that grips; a part that gives is at its limit.
Eigen::VectorXd forcesOfHolds(const FrictionalEquations& e, const std::vector<Hold>& holds,
                              const std::vector<std::array<Resistance, kParts>>& resisting,
                              double regularization) {
  // The unknowns, each with its equation: a pushing contact's normal force, and the force of
  // each part that grips now.
  std::vector<int> set;
  for (std::size_t k = 0; k < holds.size(); ++k) {
    const int first = kParts * static_cast<int>(k);
    if (holds[k].pushes) set.push_back(first + kNormal);
    for (const Part p : kResistances)
      if (gripsNow(holds[k], resisting[k][p], p)) set.push_back(first + p);
  }
  // The force of a part that gives, per unit of its contact's normal force, and its allowance.
  auto given = [&](std::size_t k, Part p) {
    const Grip& g = holds[k].grips[p];
    return g.grips ? 0.0 : g.give * resisting[k][p].coefficient;
  };
  Eigen::VectorXd allowed = Eigen::VectorXd::Zero(e.free_rates.size());
  for (std::size_t k = 0; k < holds.size(); ++k)
    for (const Part p : kResistances)
      if (!holds[k].grips[p].grips && acts(holds[k], resisting[k][p]))
        allowed[kParts * k + p] = holds[k].grips[p].give * resisting[k][p].allowance;
  const Eigen::VectorXd free_rates = e.free_rates + e.response * allowed;
  std::vector<int> place(e.free_rates.size(), -1);
  for (std::size_t i = 0; i < set.size(); ++i) place[set[i]] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t j = 0; j < set.size(); ++j) {
    auto add = [&](int column, double factor) {
      for (Eigen::SparseMatrix<double>::InnerIterator r(e.response, column); r; ++r)
        if (place[r.row()] >= 0)
          entries.emplace_back(place[r.row()], static_cast<int>(j), factor * r.value());
    };
    add(set[j], 1.0);
    if (set[j] % kParts == kNormal)
      for (const Part p : kResistances)
        if (const double g = given(set[j] / kParts, p); g != 0.0) add(set[j] + p, g);
  }
  Eigen::VectorXd rhs(set.size());
  for (std::size_t i = 0; i < set.size(); ++i) rhs[i] = -free_rates[set[i]];
  const Eigen::VectorXd solved = solveRegularized(entries, rhs, regularization);
  Eigen::VectorXd forces = allowed;
  for (std::size_t i = 0; i < set.size(); ++i) {
    forces[set[i]] = solved[i];
    if (set[i] % kParts == kNormal)
      for (const Part p : kResistances) forces[set[i] + p] += given(set[i] / kParts, p) * solved[i];
  }
  return forces;
}

// The first contact, in index order, whose forces or rates break its hold's conditions, and the
// hold that mends it.
std::optional<std::pair<int, Hold>> brokenHold(
    const FrictionalEquations& e, const std::vector<Hold>& holds,
    const std::vector<std::array<Resistance, kParts>>& resisting, const Eigen::VectorXd& forces,
    const Eigen::VectorXd& rates, double tolerance) {
  for (int k = 0; k < static_cast<int>(holds.size()); ++k) {
    const Hold& h = holds[k];
    const int first = kParts * k;
    const double normal = forces[first + kNormal];
    Hold next = h;
    if (!h.pushes && rates[first + kNormal] < -tolerance) {
      // It closes: it pushes, and each part grips if still, else gives against its motion.
      next.pushes = true;
      for (const Part p : kResistances)
        if (resisting[k][p].mayGrip()) {
          const double rate = rates[first + p];
          next.grips[p] = {std::abs(rate) <= tolerance,
                           std::abs(rate) <= tolerance ? 0.0 : std::copysign(1.0, -rate)};
        }
      return std::make_pair(k, next);
    }
    for (const Part p : kResistances) {
      if (!acts(h, resisting[k][p])) continue;
      const Grip& g = h.grips[p];
      const double force = forces[first + p], rate = rates[first + p];
      // Before a negative push: gripping may be what pulls it.
      if (g.grips && std::abs(force) > resisting[k][p].limit(normal) +
                                           tolerance / e.rate_per_force[first + p]) {
        next.grips[p] = {false, std::copysign(1.0, force)};
        return std::make_pair(k, next);
      }
      // Giving, it would drive the motion rather than resist it.
      if (!g.grips && resisting[k][p].mayGrip() && g.give * rate > tolerance) {
        next.grips[p] = {true, 0.0};
        return std::make_pair(k, next);
      }
    }
    if (h.pushes && normal < 0.0) {
      next.pushes = false;
      return std::make_pair(k, next);
    }
  }
  return std::nullopt;
}

// The balls' rates under the contacts' forces.
FrictionalRates frictionalRates(const FrictionalEquations& e, const std::vector<Vec2>& free,
                                const std::vector<Ball>& balls,
                                const std::vector<RestingContact>& contacts,
                                const Eigen::VectorXd& forces) {
  std::vector<Eigen::Vector3d> pressed(free.size(), Eigen::Vector3d::Zero());
  for (const ContactSide& s : e.sides)
    for (int p = 0; p < kParts; ++p) pressed[s.ball] += forces[kParts * s.contact + p] * s.rows[p];
  FrictionalRates rates;
  for (std::size_t i = 0; i < free.size(); ++i) {
    const Eigen::Vector3d rate = e.inverse_inertia[i].cwiseProduct(pressed[i]);
    rates.accelerations.push_back(free[i] + rate.head<2>());
    rates.angular_accelerations.push_back(rate.z());
  }
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const int first = kParts * static_cast<int>(k);
    rates.forces.push_back({forces[first + kNormal], forces[first + kFriction],
                            forces[first + kRolling] * balls[contacts[k].ball].radius});
  }
  return rates;
}

// The scale of an island's rates, against which rounding is judged: at least 1 (m/s or m/s^2).
double rateScale(const std::vector<Vec2>& free) {
  double scale = 1.0;
  for (const Vec2& f : free) scale = std::max(scale, f.norm());
  return scale;
}

// The rates without forces, if they meet every contact's conditions: no gap closes, and no
// part with an allowance (which acts without a push) has more than rounding to stop (an impact
// on a pile held still). Found without a factorization.
std::optional<FrictionalRates> unforcedRates(
    const FrictionalEquations& e, const std::vector<std::array<Resistance, kParts>>& resisting,
    const std::vector<Vec2>& free, const std::vector<Ball>& balls,
    const std::vector<RestingContact>& contacts) {
  const double tolerance = kPivotTolerance * rateScale(free);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (e.free_rates[kParts * k + kNormal] < -tolerance) return std::nullopt;
    for (const Part p : kResistances)
      if (resisting[k][p].allowance > 0.0 && std::abs(e.free_rates[kParts * k + p]) > tolerance)
        return std::nullopt;
  }
  return frictionalRates(e, free, balls, contacts, Eigen::VectorXd::Zero(e.free_rates.size()));
}

// holdWithFriction (or stopSlowMotion) for one island, by principal pivoting on its forces (or
// impulses), given as equations with their resistances: each contact's hold is
// guessed from `start`, the equations of those holds solved directly, and the first contact
// whose forces or rates break its hold's conditions changes hold, until none does. Friction
// makes the equations unsymmetric, and pivoting need not end; nor need there be an answer
// (friction wedging balls in). If pivoting does not end within its bound, undoes its last
// change at once, or leaves the equations unmet by rounding or answered by runaway forces,
// there is none.
std::optional<FrictionalRates> holdIslandByPivoting(
    const FrictionalEquations& e, const std::vector<std::array<Resistance, kParts>>& resisting,
    const std::vector<Vec2>& free, const std::vector<Ball>& balls,
    const std::vector<RestingContact>& contacts, const std::vector<ContactForces>& start) {
  const double regularization = kPivotRegularization * e.rate_per_force.maxCoeff();
  const double free_scale = rateScale(free);
  const int n = static_cast<int>(contacts.size());
  std::vector<Hold> holds = lastHolds(balls, contacts, resisting, start);
  std::optional<std::pair<int, Hold>> last_change;
  Hold before_last_change;
  for (int pivot = 0; pivot < mostPivots(n); ++pivot) {
    const Eigen::VectorXd forces = forcesOfHolds(e, holds, resisting, regularization);
    if (!forces.allFinite()) return std::nullopt;
    const Eigen::VectorXd rates = e.response * forces + e.free_rates;
    // The rates carry the rounding of the largest force's.
    double largest_rate = free_scale;
    for (int u = 0; u < kParts * n; ++u)
      largest_rate = std::max(largest_rate, std::abs(forces[u]) * e.rate_per_force[u]);
    if (largest_rate > kRunawayForces * free_scale) return std::nullopt;
    const double tolerance = kPivotTolerance * largest_rate;
    // Rounding on nearly dependent equations can leave them unmet, which no pivot mends.
    for (int k = 0; k < n; ++k) {
      bool met = !holds[k].pushes || std::abs(rates[kParts * k + kNormal]) <= tolerance;
      for (const Part p : kResistances)
        met = met && (!gripsNow(holds[k], resisting[k][p], p) ||
                      std::abs(rates[kParts * k + p]) <= tolerance);
      if (!met) return std::nullopt;
    }
    const std::optional<std::pair<int, Hold>> change =
        brokenHold(e, holds, resisting, forces, rates, tolerance);
    if (!change) return frictionalRates(e, free, balls, contacts, forces);
    const auto [k, next] = *change;
    if (last_change && last_change->first == k && next == before_last_change) return std::nullopt;
    before_last_change = holds[k];
    holds[k] = next;
    last_change = change;
  }
  return std::nullopt;
}

}  // namespace

FrictionalRates holdWithoutFriction(const std::vector<Vec2>& free,
                                    const std::vector<double>& inverse_masses,
                                    const std::vector<RestingContact>& contacts,
                                    const std::vector<ContactForces>& start) {
  std::vector<double> normal_forces;
  if (start.size() == contacts.size())
    for (const ContactForces& f : start) normal_forces.push_back(f.normal);
  FrictionalRates rates;
  rates.accelerations = pushApart(free, inverse_masses, contacts, &normal_forces);
  rates.angular_accelerations.assign(free.size(), 0.0);
  for (const double normal : normal_forces) rates.forces.push_back({normal, 0.0, 0.0});
  return rates;
}

namespace {

// holdWithFriction, or stopSlowMotion, island by island.
FrictionalRates holdIslands(Level level, const std::vector<Vec2>& free,
                            const std::vector<Ball>& balls,
                            const std::vector<double>& inverse_masses,
                            const std::vector<RestingContact>& contacts,
                            const std::vector<ContactFriction>& frictions,
                            const std::vector<ContactForces>& start) {
  FrictionalRates rates{free, std::vector<double>(balls.size(), 0.0),
                        std::vector<ContactForces>(contacts.size())};
  // Each island is solved as a problem of its own, its balls numbered locally: its work is in
  // its contacts, not in every ball of the world.
  for (const std::vector<std::size_t>& island : contactIslands(contacts, inverse_masses)) {
    std::unordered_map<std::size_t, std::size_t> local;
    std::vector<std::size_t> global;
    auto localOf = [&](std::size_t ball) {
      const auto [at, added] = local.emplace(ball, global.size());
      if (added) global.push_back(ball);
      return at->second;
    };
    std::vector<RestingContact> island_contacts;
    std::vector<ContactFriction> island_frictions;
    std::vector<ContactForces> island_start;
    for (const std::size_t k : island) {
      if (start.size() == contacts.size()) island_start.push_back(start[k]);
      RestingContact c = contacts[k];
      c.ball = localOf(c.ball);
      if (c.other) c.other = localOf(*c.other);
      island_contacts.push_back(c);
      island_frictions.push_back(frictions[k]);
    }
    std::vector<Vec2> island_free;
    std::vector<Ball> island_balls;
    std::vector<double> island_inverse_masses;
    for (const std::size_t ball : global) {
      island_free.push_back(free[ball]);
      island_balls.push_back(balls[ball]);
      island_inverse_masses.push_back(inverse_masses[ball]);
    }
    const FrictionalEquations e = frictionalEquations(
        level, island_free, island_balls, island_inverse_masses, island_contacts, island_frictions);
    const std::vector<std::array<Resistance, kParts>> resisting =
        resistances(level, e, island_balls, island_contacts, island_frictions);
    const bool resists = std::any_of(resisting.begin(), resisting.end(), [](const auto& r) {
      return std::any_of(r.begin(), r.end(), [](const Resistance& part) { return part.resists(); });
    });
    const bool pushed = std::any_of(island_start.begin(), island_start.end(),
                                    [](const ContactForces& f) { return f.normal > 0.0; });
    // Where the last forces pushed, pivoting starts from them even if none are needed now:
    // where friction's are not unique, it keeps to those.
    std::optional<FrictionalRates> solved;
    if (!pushed) solved = unforcedRates(e, resisting, island_free, island_balls, island_contacts);
    // An impact's impulses are not those of a moment ago: they start from the frictionless
    // impact's, where most contacts push as they do with friction.
    if (!solved && resists && level == Level::kForces)
      solved = holdIslandByPivoting(e, resisting, island_free, island_balls, island_contacts,
                                    island_start);
    if (!solved) {
      // Pivoting from the last holds can cycle where forces exist: then (or first, for an
      // impact) from the holds of the frictionless answer (pushing where it pushes, gripping
      // where it may), else that, which is the answer where nothing resists.
      FrictionalRates frictionless =
          holdWithoutFriction(island_free, island_inverse_masses, island_contacts, island_start);
      if (resists)
        solved = holdIslandByPivoting(e, resisting, island_free, island_balls, island_contacts,
                                      frictionless.forces);
      if (!solved) solved = std::move(frictionless);
    }
    for (std::size_t l = 0; l < global.size(); ++l) {
      rates.accelerations[global[l]] = solved->accelerations[l];
      rates.angular_accelerations[global[l]] = solved->angular_accelerations[l];
    }
    for (std::size_t i = 0; i < island.size(); ++i)
      rates.forces[island[i]] = solved->forces[i];
  }
  return rates;
}

}  // namespace

FrictionalRates holdWithFriction(const std::vector<Vec2>& free, const std::vector<Ball>& balls,
                                 const std::vector<double>& inverse_masses,
                                 const std::vector<RestingContact>& contacts,
                                 const std::vector<ContactFriction>& frictions,
                                 const std::vector<ContactForces>& start) {
  return holdIslands(Level::kForces, free, balls, inverse_masses, contacts, frictions, start);
}

FrictionalRates stopSlowMotion(const std::vector<Ball>& balls,
                               const std::vector<double>& inverse_masses,
                               const std::vector<RestingContact>& contacts,
                               const std::vector<ContactFriction>& frictions) {
  std::vector<Vec2> velocities;
  for (const Ball& ball : balls) velocities.push_back(ball.velocity);
  FrictionalRates after =
      holdIslands(Level::kImpulses, velocities, balls, inverse_masses, contacts, frictions, {});
  for (std::size_t i = 0; i < balls.size(); ++i)
    after.angular_accelerations[i] += balls[i].angular_velocity;
  return after;
}

}  // namespace ball_physics_sim::engine
