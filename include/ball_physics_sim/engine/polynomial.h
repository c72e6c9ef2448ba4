#pragma once

#include <array>
#include <optional>

namespace ball_physics_sim::engine {

// A real polynomial of degree <= 4, coefficients lowest power first:
// c[0] + c[1] t + c[2] t^2 + c[3] t^3 + c[4] t^4. Gap functions of bodies moving with
// constant acceleration are of this form (a quartic for a ball against a point under gravity).
struct Polynomial {
  static constexpr int kMaxDegree = 4;
  std::array<double, kMaxDegree + 1> c{};

  double operator()(double t) const;
  // The highest power with a non-zero coefficient (0 for the zero polynomial).
  int degree() const;
  Polynomial derivative() const;
};

// Up to kMaxDegree real roots in ascending order.
struct Roots {
  std::array<double, Polynomial::kMaxDegree> t{};
  int count = 0;
};

// Real roots of a t^2 + b t + c = 0 by the abc formula, in ascending order. Uses the form
// that avoids cancellation: with q = -(b + sign(b) sqrt(D)) / 2 the roots are q / a and c / q.
Roots quadraticRoots(double a, double b, double c);

// All roots of p strictly inside (lo, hi), ascending. Between two roots of p' the polynomial
// is monotone, so each such piece holds at most one root, narrowed to the last bit (cuts at the
// chord, and halvings).
Roots rootsBetween(const Polynomial& p, double lo, double hi);

// A bound no real root of p exceeds in magnitude (Cauchy's: 1 + max |c_i / c_n| over i < n,
// n the degree); 0 for a polynomial of degree 0, which has none.
double rootBound(const Polynomial& p);

// All roots of p greater than zero (up to rootBound), ascending.
Roots positiveRoots(const Polynomial& p);

// The first time in (lo, hi] at which p, positive at lo, drops to zero or below: the moment a
// gap closes. Returns the last representable time at which p is still positive, so a body
// placed there does not overlap.
std::optional<double> firstDownCrossing(const Polynomial& p, double lo, double hi);

}  // namespace ball_physics_sim::engine
