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

// Below this fraction of its speed across gravity a timed shot is taken for vertical: the time
// of flight x / u_x would be ill-conditioned (the polish below makes up the difference).
constexpr double kNearlyVerticalShot = 1e-6;
// A delay this far below zero, relative to the target's time, is the rounding of zero.
constexpr double kDelayRounding = 1e-12;
constexpr int kPolishIterations = 4;

// The z component of the cross product of two plane vectors.
double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Newton's method on target(s) = shot(t) itself: the roots found through the eliminated
// quartic (or the vertical approximation) become exact for the meeting in the plane. A step
// is kept only if it brings the two closer (near a tangential meeting it would not).
void polishMeeting(const Motion& target, const Motion& shot, double& s, double& t) {
  Vec2 f = target.positionAt(s) - shot.positionAt(t);
  for (int i = 0; i < kPolishIterations; ++i) {
    // Cramer's rule on the Jacobian's columns d/ds and d/dt.
    const Vec2 ds = target.velocityAt(s), dt = -shot.velocityAt(t);
    const double det = cross(ds, dt);
    if (det == 0.0) return;
    const double next_s = s - cross(f, dt) / det;
    const double next_t = t - cross(ds, f) / det;
    const Vec2 next_f = target.positionAt(next_s) - shot.positionAt(next_t);
    if (!(next_f.norm() < f.norm())) return;
    s = next_s;
    t = next_t;
    f = next_f;
  }
}

// Keeps the meeting at target time s and shot time t if its delay is the shortest yet.
void keepEarlier(std::optional<TimedShot>& best, const Motion& target, const Motion& shot,
                 double s, double t) {
  polishMeeting(target, shot, s, t);
  double delay = s - t;
  if (delay < 0.0 && delay >= -kDelayRounding * s) delay = 0.0;
  if (t > 0.0 && delay >= 0.0 && (!best || delay < best->delay)) best = TimedShot{delay, t};
}

// A target that stays on the shot's path is met, by a shot fired now, when their gap along
// `axis` closes.
void keepShotsFiredNow(std::optional<TimedShot>& best, const Motion& target, const Motion& shot,
                       const Vec2& axis) {
  const Roots t = positiveRoots(along(target.relativeTo(shot), axis));
  for (int i = 0; i < t.count; ++i) keepEarlier(best, target, shot, t.t[i], t.t[i]);
}

bool isZero(const Polynomial& p) { return p.degree() == 0 && p.c[0] == 0.0; }

}  // namespace

std::optional<TimedShot> timeShot(const Vec2& from, double angle, double speed,
                                  const Motion& target, const Vec2& gravity) {
  const Vec2 u = speed * Vec2(std::cos(angle), std::sin(angle));
  const double g = gravity.norm();
  const Vec2 up = g > 0.0 ? Vec2(-gravity / g) : Vec2(-u.y(), u.x()).normalized();
  const Vec2 across(up.y(), -up.x());
  const Motion r = target.relativeTo({from});
  const Motion shot{Vec2::Zero(), u, gravity};
  const Polynomial x = along(r, across), y = along(r, up);
  const double ux = u.dot(across), uy = u.dot(up);
  std::optional<TimedShot> best;
  if (std::abs(ux) > kNearlyVerticalShot * speed) {
    // y(s) - (u_y / u_x) x(s) + g x(s)^2 / (2 u_x^2) = 0, with x(s)^2 written out.
    const double k = uy / ux, c = 0.5 * g / (ux * ux);
    const auto& a = x.c;
    Polynomial crossing;
    crossing.c = {y.c[0] - k * a[0] + c * a[0] * a[0], y.c[1] - k * a[1] + c * 2.0 * a[0] * a[1],
                  y.c[2] - k * a[2] + c * (a[1] * a[1] + 2.0 * a[0] * a[2]),
                  c * 2.0 * a[1] * a[2], c * a[2] * a[2]};
    if (isZero(crossing)) keepShotsFiredNow(best, r, shot, across);  // it moves along the path
    const Roots s = positiveRoots(crossing);
    for (int i = 0; i < s.count; ++i) keepEarlier(best, r, shot, s.t[i], x(s.t[i]) / ux);
  } else {  // (nearly) vertical: the target must be on its line, then at its height
    if (isZero(x)) keepShotsFiredNow(best, r, shot, up);  // it moves along the line
    const Roots s = positiveRoots(x);
    for (int i = 0; i < s.count; ++i) {
      const Roots t = quadraticRoots(0.5 * g, -uy, y(s.t[i]));
      for (int j = 0; j < t.count; ++j) keepEarlier(best, r, shot, s.t[i], t.t[j]);
    }
  }
  return best;
}

double normalizedAngle(double angle) { return std::atan2(std::sin(angle), std::cos(angle)); }

Vec2 launchVelocityFor(const Vec2& from, const Vec2& target, double time_of_flight,
                       const Vec2& gravity) {
  return (target - from) / time_of_flight - 0.5 * time_of_flight * gravity;
}

double minimumBallisticSpeed(const Vec2& from, const Vec2& target, const Vec2& gravity) {
  const double g = gravity.norm();
  const Vec2 d = target - from;
  const double y = g == 0.0 ? 0.0 : d.dot(-gravity / g);
  return std::sqrt(g * (y + d.norm()));
}

}  // namespace ball_physics_sim::engine
