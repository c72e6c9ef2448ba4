#pragma once

#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

// Slips slower than this are stopped at once by static friction (a tangential impulse), and
// roll: held as sliding, a slip that friction is about to stop would overshoot zero by the
// shortest hold and, in a pile, chatter from side to side. Beyond Coulomb's cone, friction has
// only the impulse that stops a slip this fast, so that this loses an energy of at most about
// m v^2 / 7 ~ 1e-13 J per kg at a contact. Likewise a ball on a segment with rolling resistance
// whose surface turns slower than this stops turning.
constexpr double kRollingSlip = 1e-6;  // m/s

// Coulomb friction (or rolling resistance) of a pair of materials: the geometric mean, so a
// frictionless body (mu = 0) slides on anything and two of the same material keep its value.
double combinedFriction(double friction_a, double friction_b);

// The unit tangent of a contact whose normal points toward the ball: the normal turned a
// quarter counter-clockwise.
Vec2 contactTangent(const Vec2& normal);

// How fast a ball's surface slides over another body's at their contact, along the tangent:
// the relative velocity of the centres (ball minus other) less what the spins carry, for a
// ball of `radius` spinning at `spin` touching a body whose surface turns at `other_surface`
// (radius times spin of another ball; zero for a segment). Rolling is zero slip.
double slipSpeed(const Vec2& relative_velocity, const Vec2& normal, double radius, double spin,
                 double other_surface);
// A ball's inverse mass and inverse moment of inertia times radius squared: the slip a unit
// tangential impulse at its surface takes away, 1/m + r^2/I.
double tangentialInverseMass(const Ball& ball);

// Coulomb's law of impact: the tangential impulse on the ball (along the tangent) that stops
// the slip if the cone |J_t| <= mu J_n allows, else the cone's edge against the slip. It
// never adds energy. `inverse_mass_sum` is tangentialInverseMass of both bodies (0 for one
// that does not move).
double tangentialImpulse(double slip, double normal_impulse, double friction,
                         double inverse_mass_sum);

// Gives a ball a tangential impulse at its surface, where `normal` points from the contact
// toward its centre: it pushes the centre along the contact's tangent and turns the ball
// against it. Given with the same value and opposite normals to both bodies of a contact, it
// conserves momentum and changes their slip by impulse * (sum of tangentialInverseMass).
void pushSurface(Ball& ball, const Vec2& normal, double impulse);

// pushSurface on both balls of a contact whose normal points toward `ball`.
void pushSurfaces(Ball& ball, Ball& other, const Vec2& normal, double impulse);

// The forces at a resting contact: its normal force, its friction force on the ball along
// contactTangent(normal), and the torque of rolling resistance on the ball.
struct ContactForces {
  double normal = 0.0;
  double friction = 0.0;
  double torque = 0.0;
};

// How balls move under resting contacts with Coulomb friction: their accelerations, angular
// accelerations, and each contact's forces.
struct FrictionalRates {
  std::vector<Vec2> accelerations;
  std::vector<double> angular_accelerations;
  std::vector<ContactForces> forces;
};

// What a resting contact's friction needs besides its geometry.
struct ContactFriction {
  double friction = 0.0;            // the pair's Coulomb coefficient
  double rolling_resistance = 0.0;  // the pair's, for a ball on a segment; 0 between balls
  double slip = 0.0;                // slip speed now
};

// Resting contact with friction; `frictions` go with `contacts`. A sliding contact is pushed
// against its slip by mu times its normal force; a rolling one (no slip) by what keeps it
// rolling, if the cone |f| <= mu N allows, else the cone's edge. Rolling resistance c turns a
// ball on a segment against its spin with a torque c N r, or, not spinning, with what keeps it
// from starting, up to that. Each island of contacts is solved on its own, directly, by
// pivoting on each contact's hold: apart, or pushing, with its friction and its rolling
// resistance each gripping (keeping its rate zero) or giving (at the cone's edge). Pivoting
// starts from the holds that `start` shows, if it has each contact's forces (found for nearly
// the same contacts a moment ago, they are mostly right or one pivot off). Where it finds no forces
// (friction wedging balls in can leave none), it tries once more from the holds of the
// frictionless answer; failing that, the island's contacts hold without friction.
FrictionalRates holdWithFriction(const std::vector<Vec2>& free, const std::vector<Ball>& balls,
                                 const std::vector<double>& inverse_masses,
                                 const std::vector<RestingContact>& contacts,
                                 const std::vector<ContactFriction>& frictions,
                                 const std::vector<ContactForces>& start = {});

// A slow, perfectly inelastic impact of touching balls (`contacts` at the level of velocities)
// with static friction: the impulses that stop every contact's approach, as pushApart does, and
// together every slip slower than kRollingSlip where there is friction (so slow a slip is
// rolling, up to rounding; stopped one contact at a time, the impulses at a ball's other
// contacts would start those slipping again). Such a contact's friction impulse is at most mu
// times its push plus the impulse that stops kRollingSlip: it grips, or gives at that limit
// against its slip. Faster slips are left as they are. Returns the balls' velocities (as
// accelerations) and spins (as angular accelerations) after, and each contact's impulses (as
// forces); without friction where pivoting finds none.
FrictionalRates stopSlowMotion(const std::vector<Ball>& balls,
                               const std::vector<double>& inverse_masses,
                               const std::vector<RestingContact>& contacts,
                               const std::vector<ContactFriction>& frictions);

// Resting contact without friction: pushApart on accelerations, from `start`'s normal forces if
// it has each contact's; no friction force, no torque, no angular acceleration.
FrictionalRates holdWithoutFriction(const std::vector<Vec2>& free,
                                    const std::vector<double>& inverse_masses,
                                    const std::vector<RestingContact>& contacts,
                                    const std::vector<ContactForces>& start = {});

}  // namespace ball_physics_sim::engine
