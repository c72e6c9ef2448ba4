#pragma once

#include "ball_physics_sim/engine/motion.h"
#include "ball_physics_sim/engine/region.h"

namespace ball_physics_sim::engine {

// The strongest uniform field (gravity, wind, a drive) a ball can feel: with positions and
// speeds within the balls' limits, its terms keep the gap functions' precision.
constexpr double kMaxGravity = 1e4;  // m/s^2

// Wind: a uniform force per unit mass (N/kg = m/s^2, like gravity's) on every ball whose centre
// is in its region. There a ball's acceleration stays constant, so its motion stays exact;
// going in or out is an event at its exact time.
struct Wind {
  Region region;
  Vec2 acceleration = Vec2::Zero();
};

// Throws std::invalid_argument naming what is wrong: a region checkRegion refuses, an
// acceleration not finite or stronger than kMaxGravity.
void checkWind(const Wind& wind);

// An explosion: an impulse on every ball whose centre lies within `radius` of `centre`, away
// from it, of `impulse` (N s) at the centre falling linearly to zero at `radius`.
struct Blast {
  Vec2 centre = Vec2::Zero();
  double impulse = 0.0;  // N s
  double radius = 0.0;   // m
};

// Throws std::invalid_argument naming what is wrong: a non-finite value, a centre beyond
// kMaxCoordinate, an impulse < 0, a radius <= 0 or beyond kMaxCoordinate.
void checkBlast(const Blast& blast);

// The impulse the blast gives a ball whose centre is at `position`: impulse (1 - d / radius)
// away from the centre at distance d < radius; none further out, nor at the centre itself,
// which has no direction away from it.
Vec2 blastImpulse(const Blast& blast, const Vec2& position);

}  // namespace ball_physics_sim::engine
