#include "ball_physics_sim/engine/resting_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ball_physics_sim::engine {

namespace {

// Gauss-Seidel converges geometrically; stop when a sweep changes no rate by more than this
// fraction of the largest free rate, or after the bound on sweeps.
constexpr double kRelativeConvergence = 1e-15;
constexpr int kMaxSweeps = 1000;
// A contact whose gap rate is within this fraction of the largest free rate is closed.
constexpr double kClosedContact = 1e-12;

// How far x is inside (positive) or outside the half-plane n . x + bias >= 0 of a contact.
// For a contact with a fixed body solved per ball, x is the ball's own rate: a body that does
// not move has rate zero (a resting ball), or is a segment.
double margin(const RestingContact& c, const Vec2& x) { return c.normal.dot(x) + c.bias; }

// The point of {x : n_k . x + b_k >= 0 for every k} nearest to `x`. In 2D it is `x` itself, its
// projection onto one boundary line, or the corner of two: the nearest such candidate that is
// inside all. Exact, however nearly opposite the normals (a ball wedged between two others).
Vec2 projectOntoHalfPlanes(const Vec2& x, const std::vector<const RestingContact*>& planes,
                           double tolerance) {
  auto inside = [&](const Vec2& p) {
    return std::all_of(planes.begin(), planes.end(),
                       [&](const RestingContact* c) { return margin(*c, p) >= -tolerance; });
  };
  if (inside(x)) return x;
  Vec2 best = x;
  double best_distance = std::numeric_limits<double>::infinity();
  auto consider = [&](const Vec2& p) {
    const double distance = (p - x).squaredNorm();
    if (distance < best_distance && inside(p)) {
      best = p;
      best_distance = distance;
    }
  };
  for (std::size_t k = 0; k < planes.size(); ++k) {
    const RestingContact& a = *planes[k];
    consider(x - margin(a, x) * a.normal);
    for (std::size_t l = k + 1; l < planes.size(); ++l) {
      const RestingContact& b = *planes[l];
      const double det = a.normal.x() * b.normal.y() - a.normal.y() * b.normal.x();
      if (det == 0.0) continue;  // parallel lines have no corner
      // n_a . p = -b_a and n_b . p = -b_b, by Cramer's rule.
      consider(Vec2((-a.bias * b.normal.y() + b.bias * a.normal.y()) / det,
                    (-b.bias * a.normal.x() + a.bias * b.normal.x()) / det));
    }
  }
  return best;
}

}  // namespace

std::vector<Vec2> pushApart(const std::vector<Vec2>& free, const std::vector<double>& inverse_masses,
                            const std::vector<RestingContact>& contacts,
                            std::vector<double>* pushes) {
  double scale = 0.0;
  for (const Vec2& f : free) scale = std::max(scale, f.norm());
  const double tolerance = kRelativeConvergence * scale;

  // Unbiased contacts of a moving ball with bodies that do not move (a cone of allowed rates)
  // are solved per ball, exactly: Gauss-Seidel crawls where a ball is wedged between nearly
  // opposite normals. The others, one push at a time: with a bias, the corner of two nearly
  // opposite lines lies far away, and a push bounded by the bias is the safe step.
  std::vector<std::vector<const RestingContact*>> fixed_planes(free.size());
  std::vector<std::size_t> one_by_one;
  auto movable = [&](std::optional<std::size_t> ball) {
    return ball && inverse_masses[*ball] != 0.0;
  };
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const RestingContact& c = contacts[k];
    if (inverse_masses[c.ball] == 0.0) continue;
    if (movable(c.other) || c.bias != 0.0)
      one_by_one.push_back(k);
    else
      fixed_planes[c.ball].push_back(&c);
  }

  std::vector<Vec2> a = free;
  std::vector<Vec2> without_fixed = free;  // the rates less what fixed bodies push
  std::vector<double> push(contacts.size(), 0.0);
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    double largest_change = 0.0;
    for (std::size_t i = 0; i < free.size(); ++i) {
      if (fixed_planes[i].empty()) continue;
      const Vec2 projected = projectOntoHalfPlanes(without_fixed[i], fixed_planes[i], tolerance);
      largest_change = std::max(largest_change, (projected - a[i]).norm());
      a[i] = projected;
    }
    for (std::size_t k : one_by_one) {
      const RestingContact& c = contacts[k];
      const double im_a = inverse_masses[c.ball], im_b = movable(c.other) ? inverse_masses[*c.other] : 0.0;
      const double opening = margin(c, c.other ? Vec2(a[c.ball] - a[*c.other]) : a[c.ball]);
      const double pushed = std::max(0.0, push[k] - opening / (im_a + im_b));
      const double change = pushed - push[k];
      if (change == 0.0) continue;
      push[k] = pushed;
      a[c.ball] += change * im_a * c.normal;
      without_fixed[c.ball] += change * im_a * c.normal;
      if (im_b != 0.0) {
        a[*c.other] -= change * im_b * c.normal;
        without_fixed[*c.other] -= change * im_b * c.normal;
      }
      largest_change = std::max(largest_change, std::abs(change) * (im_a + im_b));
    }
    if (largest_change <= tolerance) break;
  }
  if (pushes) {
    // A fixed body pushes where its contact is closed at the solution and the ball's correction
    // has a part along its normal.
    const double closed = kClosedContact * std::max(scale, 1.0);
    for (const auto& planes : fixed_planes)
      for (const RestingContact* plane : planes) {
        const RestingContact& c = *plane;
        const double along = c.normal.dot(a[c.ball] - without_fixed[c.ball]);
        push[plane - contacts.data()] = margin(c, a[c.ball]) <= closed ? std::max(0.0, along) : 0.0;
      }
    *pushes = push;
  }
  return a;
}

}  // namespace ball_physics_sim::engine
