#include "ball_physics_sim/engine/aiming.h"

#include <cmath>

#include "ball_physics_sim/engine/polynomial.h"

namespace ball_physics_sim::engine {

namespace {

// Below this fraction of the distance the shot counts as vertical: the horizontal distance no
// longer gives the time of flight accurately.
constexpr double kVerticalShotTolerance = 1e-9;

double angleOf(const Vec2& direction) { return std::atan2(direction.y(), direction.x()); }

}  // namespace

std::optional<AimSolution> aimStraight(const Vec2& from, const Vec2& target, double speed) {
  const Vec2 d = target - from;
  if (d == Vec2::Zero()) return std::nullopt;
  return AimSolution{angleOf(d), d.norm() / speed};
}

std::optional<AimSolution> aimBallistic(const Vec2& from, const Vec2& target, double speed,
                                        const Vec2& gravity, bool high_arc) {
  const double g = gravity.norm();
  if (g == 0.0) return aimStraight(from, target, speed);
  const Vec2 d = target - from;
  if (d == Vec2::Zero()) return std::nullopt;
  // Frame with gravity pointing down: x across, y up.
  const Vec2 up = -gravity / g;
  const Vec2 across(up.y(), -up.x());
  const double x = d.dot(across), y = d.dot(up);
  const double v2 = speed * speed;
  const double discriminant = v2 * v2 - g * (g * x * x + 2.0 * y * v2);
  if (discriminant < 0.0) return std::nullopt;
  const double root = std::sqrt(discriminant);
  const double theta = std::atan2(high_arc ? v2 + root : v2 - root, g * x);
  const double cos_theta = std::cos(theta), sin_theta = std::sin(theta);
  const Vec2 direction = cos_theta * across + sin_theta * up;
  double time_of_flight;
  if (std::abs(x) > kVerticalShotTolerance * d.norm()) {
    time_of_flight = x / (speed * cos_theta);
  } else {  // straight up or down: the first time at height y = v sin(theta) t - g t^2 / 2
    const Roots roots = quadraticRoots(0.5 * g, -speed * sin_theta, y);
    // No real root is rounding at the apex: the target is reached there.
    time_of_flight = roots.count > 0 ? roots.t[roots.count - 1] : speed * sin_theta / g;
    for (int i = 0; i < roots.count; ++i)
      if (roots.t[i] > 0.0) {
        time_of_flight = roots.t[i];
        break;
      }
  }
  return AimSolution{angleOf(direction), time_of_flight};
}

std::optional<AimSolution> aimLeading(const Vec2& from, double speed, const Motion& target,
                                      const Vec2& gravity) {
  const Motion d = target.relativeTo({from, Vec2::Zero(), gravity});
  if (d.position == Vec2::Zero()) return std::nullopt;
  const Vec2 &p = d.position, &v = d.velocity, &a = d.acceleration;
  Polynomial gap;  // |D(t)|^2 - (speed t)^2
  gap.c = {p.dot(p), 2.0 * p.dot(v), v.dot(v) + p.dot(a) - speed * speed, v.dot(a),
           0.25 * a.dot(a)};
  const std::optional<double> t = firstDownCrossing(gap, 0.0, rootBound(gap));
  if (!t) return std::nullopt;
  return AimSolution{angleOf(d.positionAt(*t)), *t};
}

namespace {

// The component along `axis` of a motion, as a polynomial in time.
Polynomial along(const Motion& m, const Vec2& axis) {
  Polynomial p;
  p.c = {m.position.dot(axis), m.velocity.dot(axis), 0.5 * m.acceleration.dot(axis), 0.0, 0.0};
  return p;
}

// Keeps the shot with the shorter delay.
void keepEarlier(std::optional<TimedShot>& best, double target_time, double time_of_flight) {
  const double delay = target_time - time_of_flight;
  if (time_of_flight > 0.0 && delay >= 0.0 && (!best || delay < best->delay))
    best = TimedShot{delay, time_of_flight};
}

}  // namespace

std::optional<TimedShot> timeShot(const Vec2& from, double angle, double speed,
                                  const Motion& target, const Vec2& gravity) {
  const Vec2 u = speed * Vec2(std::cos(angle), std::sin(angle));
  const double g = gravity.norm();
  const Vec2 up = g > 0.0 ? Vec2(-gravity / g) : Vec2(-u.y(), u.x()).normalized();
  const Vec2 across(up.y(), -up.x());
  const Motion r = target.relativeTo({from});
  const Polynomial x = along(r, across), y = along(r, up);
  const double ux = u.dot(across), uy = u.dot(up);
  std::optional<TimedShot> best;
  if (std::abs(ux) > kVerticalShotTolerance * speed) {
    // y(s) - (u_y / u_x) x(s) + g x(s)^2 / (2 u_x^2) = 0, with x(s)^2 written out.
    const double k = uy / ux, c = 0.5 * g / (ux * ux);
    const auto& a = x.c;
    Polynomial crossing;
    crossing.c = {y.c[0] - k * a[0] + c * a[0] * a[0], y.c[1] - k * a[1] + c * 2.0 * a[0] * a[1],
                  y.c[2] - k * a[2] + c * (a[1] * a[1] + 2.0 * a[0] * a[2]),
                  c * 2.0 * a[1] * a[2], c * a[2] * a[2]};
    const Roots s = rootsBetween(crossing, 0.0, rootBound(crossing));
    for (int i = 0; i < s.count; ++i) keepEarlier(best, s.t[i], x(s.t[i]) / ux);
  } else {  // a vertical shot: the target must be on its line, then at its height
    const Roots s = rootsBetween(x, 0.0, rootBound(x));
    for (int i = 0; i < s.count; ++i) {
      const Roots t = quadraticRoots(0.5 * g, -uy, y(s.t[i]));
      for (int j = 0; j < t.count; ++j) keepEarlier(best, s.t[i], t.t[j]);
    }
  }
  return best;
}

double minimumBallisticSpeed(const Vec2& from, const Vec2& target, const Vec2& gravity) {
  const double g = gravity.norm();
  const Vec2 d = target - from;
  const double y = g == 0.0 ? 0.0 : d.dot(-gravity / g);
  return std::sqrt(g * (y + d.norm()));
}

}  // namespace ball_physics_sim::engine
