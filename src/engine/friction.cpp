#include "ball_physics_sim/engine/friction.h"

#include <algorithm>
#include <cmath>
#include <deque>
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

// holdWithFriction for the contacts of one island.
FrictionalRates holdIslandWithFriction(const std::vector<Vec2>& free, const std::vector<Ball>& balls,
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
  // (wedged in a corner) the turns of this solve escalate, or crawl. The contacts hold without
  // friction.
  normal_forces.clear();  // not from the escalated (or NaN) pushes of the last round
  forces.assign(contacts.size(), 0.0);
  torques.assign(contacts.size(), 0.0);
  rates.accelerations = normal.apart(free, &normal_forces);
  rates.angular_accelerations.assign(balls.size(), 0.0);
  return withForces(rates);
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
    const FrictionalRates solved = holdIslandWithFriction(
        island_free, island_balls, island_inverse_masses, island_contacts, island_frictions,
        island_start);
    for (std::size_t l = 0; l < global.size(); ++l) {
      rates.accelerations[global[l]] = solved.accelerations[l];
      rates.angular_accelerations[global[l]] = solved.angular_accelerations[l];
    }
    for (std::size_t i = 0; i < island.size(); ++i)
      rates.forces[island[i]] = solved.forces[i];
  }
  return rates;
}

}  // namespace ball_physics_sim::engine
