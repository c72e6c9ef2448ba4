#include "ball_physics_sim/engine/resting_contact.h"

#include <algorithm>
#include <cmath>

namespace ball_physics_sim::engine {

namespace {

// Gauss-Seidel converges geometrically; stop when a sweep changes no acceleration by more
// than this fraction of the largest free rate, or after the bound on sweeps.
constexpr double kRelativeConvergence = 1e-15;
constexpr int kMaxSweeps = 1000;

}  // namespace

std::vector<Vec2> pushApart(const std::vector<Vec2>& free, const std::vector<double>& inverse_masses,
                            const std::vector<RestingContact>& contacts) {
  std::vector<Vec2> a = free;
  std::vector<double> push(contacts.size(), 0.0);
  double scale = 0.0;
  for (const Vec2& f : free) scale = std::max(scale, f.norm());
  const double tolerance = kRelativeConvergence * scale;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    double largest_change = 0.0;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const RestingContact& c = contacts[k];
      const double inverse_mass_other = c.other ? inverse_masses[*c.other] : 0.0;
      const double inverse_mass_sum = inverse_masses[c.ball] + inverse_mass_other;
      if (inverse_mass_sum == 0.0) continue;
      const Vec2 relative = c.other ? Vec2(a[c.ball] - a[*c.other]) : a[c.ball];
      const double opening = c.normal.dot(relative) + c.bias;
      const double pushed = std::max(0.0, push[k] - opening / inverse_mass_sum);
      const double change = pushed - push[k];
      if (change == 0.0) continue;
      push[k] = pushed;
      a[c.ball] += change * inverse_masses[c.ball] * c.normal;
      if (c.other) a[*c.other] -= change * inverse_mass_other * c.normal;
      largest_change = std::max(largest_change, std::abs(change) * inverse_mass_sum);
    }
    if (largest_change <= tolerance) break;
  }
  return a;
}

}  // namespace ball_physics_sim::engine
