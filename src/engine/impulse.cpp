#include "ball_physics_sim/engine/impulse.h"

namespace ball_physics_sim::engine {

double combinedRestitution(double restitution_a, double restitution_b) {
  return restitution_a * restitution_b;
}

double normalImpulse(double approach_speed, double restitution, double inverse_mass_sum) {
  return (1.0 + restitution) * approach_speed / inverse_mass_sum;
}

}  // namespace ball_physics_sim::engine
