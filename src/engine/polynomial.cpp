#include "ball_physics_sim/engine/polynomial.h"

#include <algorithm>
#include <cmath>

namespace ball_physics_sim::engine {

double Polynomial::operator()(double t) const {
  double value = 0.0;
  for (int i = kMaxDegree; i >= 0; --i) value = value * t + c[i];  // Horner
  return value;
}

int Polynomial::degree() const {
  for (int i = kMaxDegree; i > 0; --i)
    if (c[i] != 0.0) return i;
  return 0;
}

Polynomial Polynomial::derivative() const {
  Polynomial d;
  for (int i = 1; i <= kMaxDegree; ++i) d.c[i - 1] = i * c[i];
  return d;
}

namespace {

void append(Roots& roots, double t) { roots.t[roots.count++] = t; }

// Bisects [lo, hi], over which p changes sign, down to adjacent doubles. Returns the end of the
// final bracket on lo's side, so p keeps lo's sign there.
double bisectSignChange(const Polynomial& p, double lo, double hi) {
  const bool lo_positive = p(lo) > 0.0;
  for (;;) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) return lo;
    if ((p(mid) > 0.0) == lo_positive)
      lo = mid;
    else
      hi = mid;
  }
}

// Steps a root found in closed form back to the last double after lo at which p is positive:
// the abc formula is a few ulps off, and a body placed past the root would overlap. A root
// further off than a few ulps (coefficients of rounding size) is bisected instead of walked.
double lastPositiveBefore(const Polynomial& p, double t, double lo) {
  constexpr int kUlpSteps = 8;
  for (int i = 0; i < kUlpSteps; ++i) {
    if (t <= lo || p(t) > 0.0) return std::max(t, lo);
    t = std::nextafter(t, lo);
  }
  return bisectSignChange(p, lo, t);
}

// The closed-form crossing of a polynomial of degree <= 2 that is positive at lo.
std::optional<double> quadraticDownCrossing(const Polynomial& p, double lo, double hi) {
  const Roots roots = quadraticRoots(p.c[2], p.c[1], p.c[0]);
  // Positive at lo, a parabola opening upwards first crosses down at its smaller root; one
  // opening downwards (or a line) at its larger (only) root.
  for (int i = 0; i < roots.count; ++i) {
    const double t = roots.t[p.c[2] > 0.0 ? i : roots.count - 1 - i];
    if (t > lo && t <= hi) return lastPositiveBefore(p, t, lo);
    if (p.c[2] > 0.0 && t > lo) break;
  }
  return std::nullopt;
}

}  // namespace

Roots quadraticRoots(double a, double b, double c) {
  Roots roots;
  if (a == 0.0) {
    if (b != 0.0) append(roots, -c / b);
    return roots;
  }
  const double discriminant = b * b - 4.0 * a * c;
  if (discriminant < 0.0) return roots;
  const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
  if (q == 0.0) {  // b == 0 and c == 0: a double root at zero
    append(roots, 0.0);
    append(roots, 0.0);
    return roots;
  }
  double r1 = q / a, r2 = c / q;
  if (r1 > r2) std::swap(r1, r2);
  append(roots, r1);
  append(roots, r2);
  return roots;
}

Roots rootsBetween(const Polynomial& p, double lo, double hi) {
  Roots inside;
  if (p.degree() <= 2) {
    const Roots all = quadraticRoots(p.c[2], p.c[1], p.c[0]);
    for (int i = 0; i < all.count; ++i)
      if (all.t[i] > lo && all.t[i] < hi) append(inside, all.t[i]);
    return inside;
  }
  const Roots turns = rootsBetween(p.derivative(), lo, hi);
  double a = lo;
  for (int i = 0; i <= turns.count; ++i) {
    const double b = i < turns.count ? turns.t[i] : hi;
    const double pa = p(a), pb = p(b);
    if (pb == 0.0 && b < hi) append(inside, b);
    else if ((pa > 0.0 && pb < 0.0) || (pa < 0.0 && pb > 0.0)) append(inside, bisectSignChange(p, a, b));
    a = b;
  }
  return inside;
}

double rootBound(const Polynomial& p) {
  const int n = p.degree();
  if (n == 0) return 0.0;
  double largest = 0.0;
  for (int i = 0; i < n; ++i) largest = std::max(largest, std::abs(p.c[i] / p.c[n]));
  return 1.0 + largest;
}

Roots positiveRoots(const Polynomial& p) { return rootsBetween(p, 0.0, rootBound(p)); }

std::optional<double> firstDownCrossing(const Polynomial& p, double lo, double hi) {
  if (!(p(lo) > 0.0)) return std::nullopt;
  if (p.degree() <= 2) return quadraticDownCrossing(p, lo, hi);
  // The pieces between turning points are monotone: the first one that ends at or below zero
  // holds the crossing.
  const Roots turns = rootsBetween(p.derivative(), lo, hi);
  double a = lo;
  for (int i = 0; i <= turns.count; ++i) {
    const double b = i < turns.count ? turns.t[i] : hi;
    if (p(b) <= 0.0) return bisectSignChange(p, a, b);
    a = b;
  }
  return std::nullopt;
}

}  // namespace ball_physics_sim::engine
