#include "ball_physics_sim/engine/settle.h"

#include <algorithm>
#include <cmath>

#include "ball_physics_sim/engine/friction.h"

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

}  // namespace

Settled settleTogether(const std::vector<Ball>& balls, const std::vector<double>& inverse_masses,
                       const std::vector<RestingContact>& contacts,
                       const std::vector<double>& frictions, double duration,
                       std::vector<std::array<double, 2>>* impulses) {
  const std::size_t still = balls.size();  // a segment's number
  std::vector<Vec2> v(balls.size() + 1, Vec2::Zero());
  std::vector<double> w(balls.size() + 1, 0.0);
  for (std::size_t i = 0; i < balls.size(); ++i) {
    v[i] = balls[i].velocity;
    w[i] = balls[i].angular_velocity;
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
  auto pushNormal = [&](const Row& row, double impulse) {
    v[row.a] += row.inverse_mass_a * impulse * row.normal;
    v[row.b] -= row.inverse_mass_b * impulse * row.normal;
  };
  auto pushTangent = [&](const Row& row, double impulse) {
    v[row.a] += row.inverse_mass_a * impulse * row.tangent;
    w[row.a] -= row.turn_a * impulse;
    v[row.b] -= row.inverse_mass_b * impulse * row.tangent;
    w[row.b] -= row.turn_b * impulse;
  };
  // The opening rate past the bias; the slip as in slipSpeed (a segment's surface is still).
  auto opening = [&](const Row& row) { return row.normal.dot(v[row.a] - v[row.b]) + row.bias; };
  // The impulses given start the sweeps.
  if (impulses && impulses->size() == contacts.size())
    for (std::size_t k = 0; k < rows.size(); ++k) {
      Row& row = rows[k];
      row.normal_impulse = (*impulses)[k][0];
      const double limit = row.friction * row.normal_impulse;
      row.friction_impulse = std::clamp((*impulses)[k][1], -limit, limit);
      pushNormal(row, row.normal_impulse);
      pushTangent(row, row.friction_impulse);
    }
  auto sweep = [&] {
    for (Row& row : rows) {
      if (row.per_normal == 0.0) continue;
      const double pushed =
          std::max(0.0, row.normal_impulse - kOverRelaxation * opening(row) / row.per_normal);
      pushNormal(row, pushed - row.normal_impulse);
      row.normal_impulse = pushed;
      if (row.friction == 0.0) continue;
      const double slip = row.tangent.dot(v[row.a] - v[row.b]) - row.radius_a * w[row.a] -
                          row.radius_b * w[row.b];
      const double limit = row.friction * row.normal_impulse;
      const double gripped =
          std::clamp(row.friction_impulse - slip / row.per_friction, -limit, limit);
      pushTangent(row, gripped - row.friction_impulse);
      row.friction_impulse = gripped;
    }
  };
  // Rounds of sweeps until no gap closes past its bias by more than kSettleOverlap of the
  // smaller radius over the stretch, or the rounds run out: the next settle's bias opens what
  // they leave.
  auto converged = [&] {
    return std::all_of(rows.begin(), rows.end(),
                       [&](const Row& row) { return opening(row) >= row.least_opening; });
  };
  for (int round = 0; round < kSettleRounds; ++round) {
    for (int k = 0; k < kSettleSweeps; ++k) sweep();
    if (converged()) break;
  }
  if (impulses) impulses->resize(rows.size());
  Settled s;
  s.velocities.assign(v.begin(), v.end() - 1);
  s.spins.assign(w.begin(), w.end() - 1);
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
