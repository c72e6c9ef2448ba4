#include "ball_physics_sim/engine/friction.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <optional>
#include <unordered_map>

#include <Eigen/Dense>

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

// Normal and friction forces are solved in turn, and friction forces by Gauss-Seidel sweeps,
// until a round changes no slip rate by more than this fraction of the largest free rate.
constexpr double kRelativeConvergence = 1e-14;
constexpr int kMaxRounds = 1000;
constexpr int kMaxSweeps = 100;
// Friction wedging a ball in makes the rounds escalate geometrically; past this many times the
// largest free rate they have.
constexpr double kEscalation = 1e3;
// Or converge so slowly that they would not be done within kMaxRounds: judged, from
// kRoundsBeforeJudging on, by how much the largest change of a window of kRoundsPerRate rounds
// shrinks from the last window's, twice in a row (a solve may crawl at first, then speed up).
constexpr int kRoundsPerRate = 20;
constexpr int kRoundsBeforeJudging = 200;
// The rounds remembered by the Anderson mixing of the rounds (below).
constexpr std::size_t kMixedRounds = 5;

// Anderson mixing of a fixed-point iteration x = g(x): the start of the next round is the
// combination of the last rounds' results whose changes g(x) - x cancel best, in least squares.
// Where the rounds act linearly it is GMRES on them, and reaches the fixed point in about as
// many rounds as it remembers, however slowly the rounds themselves would crawl towards it.
class AndersonMixing {
 public:
  Eigen::VectorXd nextStart(const Eigen::VectorXd& start, const Eigen::VectorXd& result) {
    starts_.push_back(start);
    results_.push_back(result);
    if (starts_.size() > kMixedRounds + 1) {
      starts_.pop_front();
      results_.pop_front();
    }
    const Eigen::Index remembered = static_cast<Eigen::Index>(starts_.size()) - 1;
    if (remembered == 0) return result;
    Eigen::MatrixXd change_steps(result.size(), remembered);
    Eigen::MatrixXd result_steps(result.size(), remembered);
    for (Eigen::Index j = 0; j < remembered; ++j) {
      change_steps.col(j) = (results_[j + 1] - starts_[j + 1]) - (results_[j] - starts_[j]);
      result_steps.col(j) = results_[j + 1] - results_[j];
    }
    const Eigen::VectorXd weights = change_steps.colPivHouseholderQr().solve(result - start);
    const Eigen::VectorXd mixed = result - result_steps * weights;
    return mixed.allFinite() ? mixed : result;
  }

 private:
  std::deque<Eigen::VectorXd> starts_, results_;
};

// Islands of up to this many contacts are solved by pivoting on their normal and friction forces
// together; larger ones, and any with rolling resistance, by rounds (below).
constexpr std::size_t kPivotedContacts = 64;
// A pivoted solution holds where no contact pushes with a negative force and none breaks its
// condition on its opening or slip rate by more than this fraction of the largest rate (nor
// its friction cone by more than the force that makes such a rate).
constexpr double kPivotTolerance = 1e-12;
// Added, relative to the largest diagonal term, to the diagonal of the pivoted equations:
// redundant contacts (a ball wedged by three) make them singular.
constexpr double kPivotRegularization = 1e-12;
// Pivots allowed an island of n contacts: cold, each contact closes, and may then slide and
// stick; warm, a few.
int mostFrictionalPivots(int contacts) { return 4 * contacts + 16; }

// Whether an island's friction is solved by pivoting (else by rounds).
bool pivoted(const std::vector<ContactFriction>& frictions) {
  return frictions.size() <= kPivotedContacts &&
         std::none_of(frictions.begin(), frictions.end(),
                      [](const ContactFriction& f) { return f.rolling_resistance != 0.0; });
}

// What one side of a contact takes from its ball's acceleration (x, y) and angular acceleration:
// its opening rate and its slip rate. The same rows, transposed, are what the contact's normal
// and friction forces give the ball, per unit force and per unit inverse inertia.
struct ContactSide {
  int contact;
  std::size_t ball;
  Eigen::Vector3d opening, slip;
};

// An island's contacts as linear equations in their forces: contact k's opening rate (at 2k) and
// slip rate (2k + 1) are response * forces + free_rates, for its normal force (2k) and its
// friction force (2k + 1).
struct FrictionalEquations {
  std::vector<ContactSide> sides;
  std::vector<Eigen::Vector3d> inverse_inertia;  // per ball: x, y and angular
  Eigen::MatrixXd response;
  Eigen::VectorXd free_rates;
  double slipPerForce(int k) const { return response(2 * k + 1, 2 * k + 1); }
};

FrictionalEquations frictionalEquations(const std::vector<Vec2>& free,
                                        const std::vector<Ball>& balls,
                                        const std::vector<double>& inverse_masses,
                                        const std::vector<RestingContact>& contacts) {
  FrictionalEquations e;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const double im = inverse_masses[i], r = balls[i].radius;
    e.inverse_inertia.emplace_back(im, im, im / (balls[i].inertia_factor * r * r));
  }
  const int n = static_cast<int>(contacts.size());
  e.free_rates = Eigen::VectorXd::Zero(2 * n);
  for (int k = 0; k < n; ++k) {
    const RestingContact& c = contacts[k];
    const Vec2 normal = c.normal, t = contactTangent(normal);
    // As slipSpeed: both surfaces' spins take from the slip, whichever side they are on.
    e.sides.push_back(
        {k, c.ball, {normal.x(), normal.y(), 0.0}, {t.x(), t.y(), -balls[c.ball].radius}});
    if (c.other && inverse_masses[*c.other] != 0.0)
      e.sides.push_back({k, *c.other, {-normal.x(), -normal.y(), 0.0},
                         {-t.x(), -t.y(), -balls[*c.other].radius}});
    e.free_rates[2 * k] = c.bias;
  }
  for (const ContactSide& s : e.sides) {
    const Eigen::Vector3d rate(free[s.ball].x(), free[s.ball].y(), 0.0);
    e.free_rates[2 * s.contact] += s.opening.dot(rate);
    e.free_rates[2 * s.contact + 1] += s.slip.dot(rate);
  }
  // Nonzero only between contacts that share a ball: found from the sides of each ball.
  std::vector<const ContactSide*> by_ball;
  for (const ContactSide& s : e.sides) by_ball.push_back(&s);
  std::sort(by_ball.begin(), by_ball.end(),
            [](const ContactSide* a, const ContactSide* b) { return a->ball < b->ball; });
  e.response = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  for (auto a = by_ball.begin(); a != by_ball.end(); ++a)
    for (auto b = a; b != by_ball.end() && (*b)->ball == (*a)->ball; ++b) {
      const Eigen::Vector3d& im = e.inverse_inertia[(*a)->ball];
      const Eigen::Vector3d rows[2][2] = {{(*a)->opening, (*a)->slip}, {(*b)->opening, (*b)->slip}};
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          const double entry = rows[0][i].dot(im.cwiseProduct(rows[1][j]));
          e.response(2 * (*a)->contact + i, 2 * (*b)->contact + j) += entry;
          if (b != a) e.response(2 * (*b)->contact + j, 2 * (*a)->contact + i) += entry;
        }
    }
  return e;
}

// How a contact holds in a pivoted solve: apart, or pushing; a pushing contact sticks (its
// friction is what keeps its slip rate zero) or slides, pressed by mu N along `slide` times its
// tangent (0 for a smooth contact).
struct Hold {
  bool pushes = false;
  bool sticks = false;
  double slide = 0.0;
  bool operator==(const Hold& h) const {
    return pushes == h.pushes && sticks == h.sticks && slide == h.slide;
  }
};

// Whether static friction may hold a contact: a rough one that does not slip already.
bool mayStick(const ContactFriction& f) {
  return f.friction > 0.0 && std::abs(f.slip) <= kRollingSlip;
}

// Each contact's hold as its forces of a moment ago (`start`) show it; apart if it has none.
std::vector<Hold> lastHolds(const std::vector<ContactFriction>& frictions,
                            const std::vector<ContactForces>& start) {
  std::vector<Hold> holds(frictions.size());
  for (std::size_t k = 0; k < frictions.size(); ++k) {
    const ContactFriction& f = frictions[k];
    const ContactForces last = k < start.size() ? start[k] : ContactForces();
    holds[k].pushes = last.normal > 0.0;
    holds[k].sticks = mayStick(f) && std::abs(last.friction) < f.friction * last.normal;
    if (f.friction > 0.0 && !holds[k].sticks)
      holds[k].slide = std::copysign(1.0, mayStick(f) ? last.friction : -f.slip);
  }
  return holds;
}

// The forces (as FrictionalEquations orders them) that meet the equations of the contacts'
// holds: a pushing contact's opening rate is zero, and a sticking one's slip rate; a sliding
// contact's friction is mu N along its slide.
Eigen::VectorXd forcesOfHolds(const FrictionalEquations& e, const std::vector<Hold>& holds,
                              const std::vector<ContactFriction>& frictions,
                              double regularization) {
  // The unknowns, each with its equation: a pushing contact's normal force (2k), a sticking
  // one's friction force (2k + 1).
  std::vector<int> set;
  for (std::size_t k = 0; k < holds.size(); ++k) {
    if (holds[k].pushes) set.push_back(2 * static_cast<int>(k));
    if (holds[k].pushes && holds[k].sticks) set.push_back(2 * static_cast<int>(k) + 1);
  }
  // A sliding contact's friction per unit of its normal force.
  auto slidingFriction = [&](int u) {
    const Hold& h = holds[u / 2];
    return u % 2 == 0 && !h.sticks ? h.slide * frictions[u / 2].friction : 0.0;
  };
  const int m = static_cast<int>(set.size());
  Eigen::MatrixXd equations(m, m);
  Eigen::VectorXd rhs(m);
  for (int i = 0; i < m; ++i) {
    rhs[i] = -e.free_rates[set[i]];
    for (int j = 0; j < m; ++j)
      equations(i, j) = e.response(set[i], set[j]) +
                        slidingFriction(set[j]) * e.response(set[i], set[j] + 1);
  }
  Eigen::MatrixXd regularized = equations;
  regularized.diagonal().array() += regularization;
  const Eigen::PartialPivLU<Eigen::MatrixXd> factors(regularized);
  Eigen::VectorXd solved = factors.solve(rhs);
  solved += factors.solve(rhs - equations * solved);  // refined once against the exact ones
  Eigen::VectorXd forces = Eigen::VectorXd::Zero(e.free_rates.size());
  for (int i = 0; i < m; ++i) {
    forces[set[i]] = solved[i];
    if (set[i] % 2 == 0) forces[set[i] + 1] = slidingFriction(set[i]) * solved[i];
  }
  return forces;
}

// The first contact, in index order, whose forces or rates break its hold's conditions, and the
// hold that mends it.
std::optional<std::pair<int, Hold>> brokenHold(const FrictionalEquations& e,
                                               const std::vector<Hold>& holds,
                                               const std::vector<ContactFriction>& frictions,
                                               const Eigen::VectorXd& forces,
                                               const Eigen::VectorXd& rates, double tolerance) {
  for (int k = 0; k < static_cast<int>(holds.size()); ++k) {
    const Hold& h = holds[k];
    const ContactFriction& f = frictions[k];
    const double normal = forces[2 * k], friction = forces[2 * k + 1];
    const double opening = rates[2 * k], slip = rates[2 * k + 1];
    Hold next = h;
    if (!h.pushes && opening < -tolerance) {
      // It closes: it pushes, and slides against its slip, unless it has none.
      next.pushes = true;
      next.sticks = mayStick(f) && std::abs(slip) <= tolerance;
      if (mayStick(f)) next.slide = next.sticks ? 0.0 : std::copysign(1.0, -slip);
    } else if (h.pushes && h.sticks &&
               std::abs(friction) > f.friction * normal + tolerance / e.slipPerForce(k)) {
      // Before a negative push: sticking may be what pulls it.
      next.sticks = false;
      next.slide = std::copysign(1.0, friction);
    } else if (h.pushes && normal < 0.0) {
      next.pushes = false;
    } else if (h.pushes && mayStick(f) && !h.sticks && h.slide * slip > tolerance) {
      // Its friction would drive the slip rather than resist it.
      next.sticks = true;
      next.slide = 0.0;
    } else {
      continue;
    }
    return std::make_pair(k, next);
  }
  return std::nullopt;
}

// The balls' rates under the contacts' forces.
FrictionalRates frictionalRates(const FrictionalEquations& e, const std::vector<Vec2>& free,
                                const Eigen::VectorXd& forces) {
  std::vector<Eigen::Vector3d> pressed(free.size(), Eigen::Vector3d::Zero());
  for (const ContactSide& s : e.sides)
    pressed[s.ball] += forces[2 * s.contact] * s.opening + forces[2 * s.contact + 1] * s.slip;
  FrictionalRates rates;
  for (std::size_t i = 0; i < free.size(); ++i) {
    const Eigen::Vector3d rate = e.inverse_inertia[i].cwiseProduct(pressed[i]);
    rates.accelerations.push_back(free[i] + Vec2(rate.x(), rate.y()));
    rates.angular_accelerations.push_back(rate.z());
  }
  for (Eigen::Index k = 0; 2 * k < forces.size(); ++k)
    rates.forces.push_back({forces[2 * k], forces[2 * k + 1], 0.0});
  return rates;
}

// holdWithFriction for an island without rolling resistance, by principal pivoting on its
// normal and friction forces together: each contact's hold is guessed from `start`, the
// equations of those holds solved directly, and the first contact whose forces or rates break
// its hold's conditions changes hold, until none does. Friction makes the equations
// unsymmetric, and pivoting need not end; nor need there be an answer (friction wedging balls
// in). If pivoting does not end within its bound, undoes its last change at once, or leaves
// the equations unmet by rounding, there is none.
std::optional<FrictionalRates> holdIslandByPivoting(
    const std::vector<Vec2>& free, const std::vector<Ball>& balls,
    const std::vector<double>& inverse_masses, const std::vector<RestingContact>& contacts,
    const std::vector<ContactFriction>& frictions, const std::vector<ContactForces>& start) {
  const FrictionalEquations e = frictionalEquations(free, balls, inverse_masses, contacts);
  const double regularization = kPivotRegularization * e.response.diagonal().maxCoeff();
  double free_scale = 1.0;
  for (const Vec2& f : free) free_scale = std::max(free_scale, f.norm());
  std::vector<Hold> holds = lastHolds(frictions, start);
  std::optional<std::pair<int, Hold>> last_change;
  Hold before_last_change;
  const int n = static_cast<int>(contacts.size());
  for (int pivot = 0; pivot < mostFrictionalPivots(n); ++pivot) {
    const Eigen::VectorXd forces = forcesOfHolds(e, holds, frictions, regularization);
    if (!forces.allFinite()) return std::nullopt;
    const Eigen::VectorXd rates = e.response * forces + e.free_rates;
    // The rates carry the rounding of the largest force's.
    double largest_rate = free_scale;
    for (int k = 0; k < n; ++k) {
      const double force = std::abs(forces[2 * k]) + std::abs(forces[2 * k + 1]);
      largest_rate = std::max(largest_rate, force * e.slipPerForce(k));
    }
    const double tolerance = kPivotTolerance * largest_rate;
    // Rounding on nearly dependent equations can leave them unmet, which no pivot mends.
    for (int k = 0; k < n; ++k)
      if ((holds[k].pushes && !(std::abs(rates[2 * k]) <= tolerance)) ||
          (holds[k].pushes && holds[k].sticks && !(std::abs(rates[2 * k + 1]) <= tolerance)))
        return std::nullopt;
    const std::optional<std::pair<int, Hold>> change =
        brokenHold(e, holds, frictions, forces, rates, tolerance);
    if (!change) return frictionalRates(e, free, forces);
    const auto [k, next] = *change;
    if (last_change && last_change->first == k && next == before_last_change) return std::nullopt;
    before_last_change = holds[k];
    holds[k] = next;
    last_change = change;
  }
  return std::nullopt;
}

// The contacts of an island held without friction: where friction's forces are not found
// (friction wedging balls in can leave its conditions without an answer).
FrictionalRates holdIslandWithoutFriction(const std::vector<Vec2>& free,
                                          const std::vector<double>& inverse_masses,
                                          const std::vector<RestingContact>& contacts) {
  FrictionalRates rates;
  std::vector<double> normal_forces;
  rates.accelerations = pushApart(free, inverse_masses, contacts, &normal_forces);
  rates.angular_accelerations.assign(free.size(), 0.0);
  for (const double normal : normal_forces) rates.forces.push_back({normal, 0.0, 0.0});
  return rates;
}

// holdWithFriction for the contacts of one island, by rounds.
FrictionalRates holdIslandByRounds(const std::vector<Vec2>& free, const std::vector<Ball>& balls,
                                   const std::vector<double>& inverse_masses,
                                   const std::vector<RestingContact>& contacts,
                                   const std::vector<ContactFriction>& frictions,
                                   const std::vector<ContactForces>& start) {
  // Per ball, found once (every sweep takes them): the angular acceleration per unit tangential
  // force at the surface, r / I, and per unit torque, 1 / I; 0 if it does not move.
  std::vector<double> turning, spinning;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const double inertia_per_mass_radius = balls[i].inertia_factor * balls[i].radius;
    turning.push_back(inverse_masses[i] / inertia_per_mass_radius);
    spinning.push_back(inverse_masses[i] / (inertia_per_mass_radius * balls[i].radius));
  }
  auto other = [&](const RestingContact& c) {
    return c.other && inverse_masses[*c.other] != 0.0 ? c.other : std::nullopt;
  };
  // As pushSurface, for forces on both bodies of contact c.
  auto apply = [&](const RestingContact& c, double force, std::vector<Vec2>& accelerations,
                   std::vector<double>& angular) {
    const Vec2 t = contactTangent(c.normal);
    accelerations[c.ball] += force * inverse_masses[c.ball] * t;
    angular[c.ball] -= force * turning[c.ball];
    if (const auto o = other(c)) {
      accelerations[*o] -= force * inverse_masses[*o] * t;
      angular[*o] -= force * turning[*o];
    }
  };
  auto slipRate = [&](const RestingContact& c, const FrictionalRates& rates) {
    const auto o = other(c);
    return slipSpeed(rates.accelerations[c.ball] - (o ? rates.accelerations[*o] : Vec2::Zero()),
                     c.normal, balls[c.ball].radius, rates.angular_accelerations[c.ball],
                     o ? balls[*o].radius * rates.angular_accelerations[*o] : 0.0);
  };
  // Each contact's slip rate per unit friction force, found once: every sweep takes it.
  std::vector<double> slip_per_force;
  for (const RestingContact& c : contacts) {
    const auto o = other(c);
    slip_per_force.push_back(tangentialInverseMass(balls[c.ball]) +
                             (o ? tangentialInverseMass(balls[*o]) : 0.0));
  }

  double scale = 0.0;
  for (const Vec2& f : free) scale = std::max(scale, f.norm());
  std::vector<double> normal_forces, forces, torques;
  for (const ContactForces& f : start) {
    normal_forces.push_back(f.normal);
    forces.push_back(f.friction);
    torques.push_back(f.torque);
  }
  forces.resize(contacts.size(), 0.0);
  torques.resize(contacts.size(), 0.0);
  FrictionalRates rates;
  auto withForces = [&](FrictionalRates& solved) {
    solved.forces.clear();
    for (std::size_t k = 0; k < contacts.size(); ++k)
      solved.forces.push_back({normal_forces[k], forces[k], torques[k]});
    return solved;
  };
  // The rounds' unknowns, friction forces and torques, as one vector for their mixing.
  const Eigen::Index n = static_cast<Eigen::Index>(contacts.size());
  auto frictionForces = [&] {
    Eigen::VectorXd x(2 * n);
    for (Eigen::Index k = 0; k < n; ++k) {
      x[k] = forces[k];
      x[n + k] = torques[k];
    }
    return x;
  };
  ContactPushes normal(inverse_masses, contacts);  // the same contacts pushed every round
  // A leaning column of sliding balls, pressed the harder the harder friction presses them,
  // crawls to its forces (by a factor 0.97 a round, in hundreds of rounds): the rounds are mixed.
  AndersonMixing mixing;
  bool mixed = true;
  std::vector<double> mixed_changes;
  const Eigen::VectorXd first_start = frictionForces();
  const std::vector<double> first_normal_forces = normal_forces;
  double window_change = 0.0, last_window_change = 0.0;
  int predicted_failures = 0;
  for (int round = 0; round < kMaxRounds; ++round) {
    const Eigen::VectorXd round_start = mixed ? frictionForces() : Eigen::VectorXd();
    std::vector<Vec2> pushed = free;
    rates.angular_accelerations.assign(balls.size(), 0.0);
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      apply(contacts[k], forces[k], pushed, rates.angular_accelerations);
      rates.angular_accelerations[contacts[k].ball] += torques[k] * spinning[contacts[k].ball];
    }
    rates.accelerations = normal.apart(pushed, &normal_forces);
    // The rates carry the rounding of the largest push, which under a stack is many times a
    // ball's weight: measured against the free rates alone, a converged round could look
    // unconverged for ever.
    double pushed_rate = std::max(scale, 1.0);
    for (std::size_t k = 0; k < contacts.size(); ++k)
      pushed_rate = std::max(pushed_rate,
                             (normal_forces[k] + std::abs(forces[k])) * slip_per_force[k]);
    const double tolerance = kRelativeConvergence * pushed_rate;
    double round_change = 0.0;
    for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
      double sweep_change = 0.0;
      for (std::size_t k = 0; k < contacts.size(); ++k) {
        const RestingContact& c = contacts[k];
        const ContactFriction& f = frictions[k];
        if (f.rolling_resistance != 0.0) {
          const Ball& b = balls[c.ball];
          const double limit = f.rolling_resistance * normal_forces[k] * b.radius;
          const double torque =
              std::abs(b.angular_velocity) * b.radius > kRollingSlip
                  ? std::copysign(limit, -b.angular_velocity)
                  : std::clamp(torques[k] - rates.angular_accelerations[c.ball] / spinning[c.ball],
                               -limit, limit);
          const double change = torque - torques[k];
          torques[k] = torque;
          rates.angular_accelerations[c.ball] += change * spinning[c.ball];
          sweep_change = std::max(sweep_change, std::abs(change) * spinning[c.ball] * b.radius);
        }
        if (f.friction == 0.0) continue;
        const double limit = f.friction * normal_forces[k];
        const double per_force = slip_per_force[k];
        const double force =
            std::abs(f.slip) > kRollingSlip
                ? std::copysign(limit, -f.slip)
                : std::clamp(forces[k] - slipRate(c, rates) / per_force, -limit, limit);
        const double change = force - forces[k];
        if (change == 0.0) continue;
        forces[k] = force;
        apply(c, change, rates.accelerations, rates.angular_accelerations);
        sweep_change = std::max(sweep_change, std::abs(change) * per_force);
      }
      round_change = std::max(round_change, sweep_change);
      if (sweep_change <= tolerance) break;
    }
    if (round_change <= tolerance) return withForces(rates);
    const bool escalated = !(round_change <= kEscalation * std::max(scale, 1.0));  // NaN too
    if (mixed) {
      // Mixed rounds that escalate, or whose change has not shrunk over as many rounds as the
      // mixing remembers, have found no forces it can reach: the rounds start over, plain, from
      // the forces they started from, judged as below. (Where several sets of forces meet the
      // contacts' conditions, the mixed rounds may find another than the plain ones would.)
      mixed_changes.push_back(round_change);
      mixed = !escalated && (mixed_changes.size() <= kMixedRounds ||
                             round_change < mixed_changes[mixed_changes.size() - 1 - kMixedRounds]);
      const Eigen::VectorXd next =
          mixed ? mixing.nextStart(round_start, frictionForces()) : first_start;
      for (Eigen::Index k = 0; k < n; ++k) {
        forces[k] = next[k];
        torques[k] = next[n + k];
      }
      if (!mixed) {
        normal_forces = first_normal_forces;
        continue;
      }
    }
    if (escalated) break;
    window_change = std::max(window_change, round_change);
    if ((round + 1) % kRoundsPerRate != 0) continue;
    if (round + 1 > kRoundsBeforeJudging) {
      // Shrinking by `shrink` every kRoundsPerRate rounds, the change reaches the tolerance in
      // log(tolerance / change) / log(shrink) times as many.
      const double shrink = window_change / last_window_change;
      const bool fails = !(shrink < 1.0) || std::log(tolerance / round_change) /
                                                    std::log(shrink) * kRoundsPerRate >
                                                kMaxRounds - round;
      predicted_failures = fails ? predicted_failures + 1 : 0;
      if (predicted_failures == 2) break;
    }
    last_window_change = window_change;
    window_change = 0.0;
  }
  // The rounds did not converge: where friction presses balls in harder the harder they press
  // (wedged in a corner) the turns of this solve escalate, or crawl.
  return holdIslandWithoutFriction(free, inverse_masses, contacts);
}

}  // namespace

FrictionalRates holdWithFriction(const std::vector<Vec2>& free, const std::vector<Ball>& balls,
                                 const std::vector<double>& inverse_masses,
                                 const std::vector<RestingContact>& contacts,
                                 const std::vector<ContactFriction>& frictions,
                                 const std::vector<ContactForces>& start) {
  FrictionalRates rates{free, std::vector<double>(balls.size(), 0.0),
                        std::vector<ContactForces>(contacts.size())};
  // Each island is solved as a problem of its own, its balls numbered locally: its rounds go on
  // until it converges, and their work is in its contacts, not in every ball of the world.
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
    std::optional<FrictionalRates> solved;
    if (!pivoted(island_frictions))
      solved = holdIslandByRounds(island_free, island_balls, island_inverse_masses,
                                  island_contacts, island_frictions, island_start);
    else if (!(solved = holdIslandByPivoting(island_free, island_balls, island_inverse_masses,
                                             island_contacts, island_frictions, island_start)))
      solved = holdIslandWithoutFriction(island_free, island_inverse_masses, island_contacts);
    for (std::size_t l = 0; l < global.size(); ++l) {
      rates.accelerations[global[l]] = solved->accelerations[l];
      rates.angular_accelerations[global[l]] = solved->angular_accelerations[l];
    }
    for (std::size_t i = 0; i < island.size(); ++i)
      rates.forces[island[i]] = solved->forces[i];
  }
  return rates;
}

}  // namespace ball_physics_sim::engine
