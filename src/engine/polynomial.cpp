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

// Polynomial values are computed to a few ulps of the size of their terms; a lower bound above
// this fraction of it is positive in every value computed.
constexpr double kPositiveMargin = 1e-12;

// Narrows [lo, hi], over which p changes sign, down to adjacent doubles. Returns the end of the
// final bracket on lo's side, so p keeps lo's sign there. The bracket is cut where the chord
// between its ends crosses zero (the Illinois method: an end left in place twice in a row has
// its value halved, so that it does not stick), which near a simple root takes a few cuts
// rather than the fifty-odd of halving; a cut that leaves more than half of the bracket is
// followed by a halving, so it never takes more than twice as many.
double narrowSignChange(const Polynomial& p, double lo, double hi) {
  double p_lo = p(lo), p_hi = p(hi);
  const bool lo_positive = p_lo > 0.0;
  int last_moved = 0;  // the end the last cut moved: -1 lo, 1 hi
  bool halve = false;
  for (;;) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) return lo;
    double cut = mid;
    if (!halve && p_lo != p_hi) {
      const double chord = lo - p_lo * (hi - lo) / (p_hi - p_lo);
      if (chord > lo && chord < hi) cut = chord;
    }
    const double width = hi - lo;
    const double value = p(cut);
    if ((value > 0.0) == lo_positive) {
      lo = cut;
      p_lo = value;
      if (last_moved < 0) p_hi *= 0.5;
      last_moved = -1;
    } else {
      hi = cut;
      p_hi = value;
      if (last_moved > 0) p_lo *= 0.5;
      last_moved = 1;
    }
    halve = !halve && hi - lo > 0.5 * width;
  }
}

// Steps a root found in closed form back to the last double after lo at which p is positive:
// the abc formula is a few ulps off, and a body placed past the root would overlap. A root
// further off than a few ulps (coefficients of rounding size) is narrowed to instead of walked.
double lastPositiveBefore(const Polynomial& p, double t, double lo) {
  constexpr int kUlpSteps = 8;
  for (int i = 0; i < kUlpSteps; ++i) {
    if (t <= lo || p(t) > 0.0) return std::max(t, lo);
    t = std::nextafter(t, lo);
  }
  return narrowSignChange(p, lo, t);
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

// Whether p stays above zero over [lo, hi] by far more than the rounding of its values: with
// p(lo + s) = sum d_i s^i, p >= d_0 - sum_{i > 0} |d_i| h^i over it, h = hi - lo. A cheap
// test: where a gap plainly stays open, the search for a crossing need not find the turning
// points; where it cannot tell, the search decides.
bool staysPositive(const Polynomial& p, double lo, double hi) {
  if (!(hi >= lo)) return false;  // (the bound holds for s >= 0 only)
  // The coefficients at lo, by repeated synthetic division (Taylor shift).
  std::array<double, Polynomial::kMaxDegree + 1> d = p.c;
  for (int k = 0; k < Polynomial::kMaxDegree; ++k)
    for (int i = Polynomial::kMaxDegree - 1; i >= k; --i) d[i] += lo * d[i + 1];
  const double h = hi - lo, reach = std::max({std::abs(lo), std::abs(hi), 1.0});
  double lowest = d[0], size = 0.0, power = 1.0, reach_power = 1.0;
  for (int i = 0; i <= Polynomial::kMaxDegree; ++i) {
    if (i > 0) lowest -= std::abs(d[i]) * power;
    size += std::abs(p.c[i]) * reach_power;
    power *= h;
    reach_power *= reach;
  }
  return lowest > kPositiveMargin * size;
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
    else if ((pa > 0.0 && pb < 0.0) || (pa < 0.0 && pb > 0.0))
      append(inside, narrowSignChange(p, a, b));
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
  if (staysPositive(p, lo, hi)) return std::nullopt;
  // The pieces between turning points are monotone: the first one that ends at or below zero
  // holds the crossing.
  const Roots turns = rootsBetween(p.derivative(), lo, hi);
  double a = lo;
  for (int i = 0; i <= turns.count; ++i) {
    const double b = i < turns.count ? turns.t[i] : hi;
    if (p(b) <= 0.0) return narrowSignChange(p, a, b);
    a = b;
  }
  return std::nullopt;
}

}  // namespace ball_physics_sim::engine
