#pragma once

namespace ball_physics_sim::engine {

// Impacts slower than this are perfectly inelastic, and are stopped together with every other
// contact of the balls involved: a ball bouncing on a floor, or wedged between two others,
// would otherwise bounce infinitely often in finite time (a Zeno sequence) before it rests.
// A bounce this slow rises v^2 / 2g ~ 5e-8 m under Earth's gravity.
constexpr double kRestingSpeed = 1e-3;  // m/s

// Restitution of a pair of materials: the product, so a perfectly inelastic body (e = 0)
// stops any impact and two elastic ones (e = 1) keep all energy.
double combinedRestitution(double restitution_a, double restitution_b);

// Newton's law of impact: the normal impulse that turns the approach speed s into a separation
// speed e s while conserving momentum, j = (1 + e) s / (1/m_a + 1/m_b). An immovable body has
// inverse mass 0.
double normalImpulse(double approach_speed, double restitution, double inverse_mass_sum);

}  // namespace ball_physics_sim::engine
