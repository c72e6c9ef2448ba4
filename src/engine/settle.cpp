#include "ball_physics_sim/engine/settle.h"

#include <algorithm>
#include <cmath>

#include "ball_physics_sim/engine/friction.h"

namespace ball_physics_sim::engine {

Settled settleTogether(const std::vector<Ball>& balls, const std::vector<double>& inverse_masses,
                       const std::vector<RestingContact>& contacts,
                       const std::vector<double>& frictions, const std::vector<double>& allowed,
                       std::vector<std::array<double, 2>>* impulses) {
  Settled s;
  for (const Ball& b : balls) {
    s.velocities.push_back(b.velocity);
    s.spins.push_back(b.angular_velocity);
  }
  // A unit impulse at a ball's surface turns it by 1 / (k m r) (I = k m r^2), and takes
  // 1/m + r^2/I from its slip.
  auto turnPerImpulse = [&](std::size_t i) {
    return inverse_masses[i] / (balls[i].inertia_factor * balls[i].radius);
  };
  auto slipPerImpulse = [&](std::size_t i) {
    return inverse_masses[i] * (1.0 + 1.0 / balls[i].inertia_factor);
  };
  auto relativeVelocity = [&](const RestingContact& c) {
    return c.other ? Vec2(s.velocities[c.ball] - s.velocities[*c.other]) : s.velocities[c.ball];
  };
  auto otherSurface = [&](const RestingContact& c) {
    return c.other ? balls[*c.other].radius * s.spins[*c.other] : 0.0;
  };
  // Each contact's normal and friction impulses so far, and what a unit of each changes of its
  // own rate (opening, slip).
  std::vector<double> normal(contacts.size(), 0.0), friction(contacts.size(), 0.0);
  std::vector<double> per_normal, per_friction;
  for (const RestingContact& c : contacts) {
    per_normal.push_back(inverse_masses[c.ball] + (c.other ? inverse_masses[*c.other] : 0.0));
    per_friction.push_back(slipPerImpulse(c.ball) + (c.other ? slipPerImpulse(*c.other) : 0.0));
  }
  auto pushNormal = [&](const RestingContact& c, double impulse) {
    s.velocities[c.ball] += inverse_masses[c.ball] * impulse * c.normal;
    if (c.other) s.velocities[*c.other] -= inverse_masses[*c.other] * impulse * c.normal;
  };
  auto pushTangent = [&](const RestingContact& c, double impulse) {
    const Vec2 t = contactTangent(c.normal);
    s.velocities[c.ball] += inverse_masses[c.ball] * impulse * t;
    s.spins[c.ball] -= turnPerImpulse(c.ball) * impulse;
    if (c.other) {
      s.velocities[*c.other] -= inverse_masses[*c.other] * impulse * t;
      s.spins[*c.other] -= turnPerImpulse(*c.other) * impulse;
    }
  };
  // The impulses given start the sweeps.
  if (impulses && impulses->size() == contacts.size())
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      normal[k] = (*impulses)[k][0];
      const double limit = frictions[k] * normal[k];
      friction[k] = std::clamp((*impulses)[k][1], -limit, limit);
      pushNormal(contacts[k], normal[k]);
      pushTangent(contacts[k], friction[k]);
    }
  for (int sweep = 0; sweep < kSettleSweeps; ++sweep)
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const RestingContact& c = contacts[k];
      if (per_normal[k] == 0.0) continue;
      const double opening = c.normal.dot(relativeVelocity(c)) + c.bias;
      const double pushed = std::max(0.0, normal[k] - opening / per_normal[k]);
      pushNormal(c, pushed - normal[k]);
      normal[k] = pushed;
      if (frictions[k] == 0.0) continue;
      const double slip = slipSpeed(relativeVelocity(c), c.normal, balls[c.ball].radius,
                                    s.spins[c.ball], otherSurface(c));
      const double limit = frictions[k] * normal[k];
      const double gripped = std::clamp(friction[k] - slip / per_friction[k], -limit, limit);
      pushTangent(c, gripped - friction[k]);
      friction[k] = gripped;
    }
  if (impulses) {
    impulses->resize(contacts.size());
    for (std::size_t k = 0; k < contacts.size(); ++k) (*impulses)[k] = {normal[k], friction[k]};
  }
  s.pushes = std::move(normal);
  // Exact pushes where the sweeps left a gap closing by more than it may; where pivoting gave
  // up on them, the balls slow down together until none closes faster than allowed. Rounding
  // is measured on the faster of the sweeps' velocities and the exact ones, as pushApart's on
  // the former.
  double fastest = 0.0;
  for (const Vec2& v : s.velocities) fastest = std::max(fastest, v.norm());
  s.velocities = pushApart(s.velocities, inverse_masses, contacts);
  for (const Vec2& v : s.velocities) fastest = std::max(fastest, v.norm());
  const double share =
      shareClosingNoGapTooFast(contacts, s.velocities, allowed, kSettleRounding * fastest);
  for (Vec2& v : s.velocities) v *= share;
  for (double& w : s.spins) w *= share;
  return s;
}

double shareClosingNoGapTooFast(const std::vector<RestingContact>& contacts,
                                const std::vector<Vec2>& velocities,
                                const std::vector<double>& allowed, double rounding) {
  double share = 1.0;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const RestingContact& c = contacts[k];
    const Vec2 relative = c.other ? Vec2(velocities[c.ball] - velocities[*c.other])
                                  : velocities[c.ball];
    const double closing = -c.normal.dot(relative);
    if (closing - allowed[k] > rounding) share = std::min(share, allowed[k] / closing);
  }
  return share;
}

}  // namespace ball_physics_sim::engine
