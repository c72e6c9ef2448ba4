#pragma once

#include <optional>

#include "ball_physics_sim/engine/motion.h"

namespace ball_physics_sim::engine {

// The strongest uniform field (gravity, wind, a drive) a ball can feel: with positions and
// speeds within the balls' limits, its terms keep the gap functions' precision.
constexpr double kMaxGravity = 1e4;  // m/s^2

// Wind: a uniform force per unit mass (N/kg = m/s^2, like gravity's) on every ball whose centre
// is inside an axis-aligned box. Inside it a ball's acceleration stays constant, so its motion
// stays exact; entering or leaving is an event at its exact time.
struct Wind {
  Vec2 min = Vec2::Zero();  // the box's lower left corner
  Vec2 max = Vec2::Zero();  // and its upper right one
  Vec2 acceleration = Vec2::Zero();
};

// Throws std::invalid_argument naming what is wrong: a non-finite value, a corner beyond
// kMaxCoordinate, min not below max, an acceleration stronger than kMaxGravity.
void checkWind(const Wind& wind);

// Whether a centre moving as `motion` is inside the wind's box from now on: inside it, or on a
// side (within kOnWindSide) and moving in or along it. At the time of a crossing, rounding
// puts the centre on either side of the line; its motion says which way it goes.
bool blowsOn(const Wind& wind, const Motion& motion);
constexpr double kOnWindSide = 1e-9;  // m

// The first time in (0, horizon) at which a centre moving as `motion` crosses the boundary of
// the wind's box, going in or out; none if it does not. (The first root of the quadratic of
// each side's line, where it lies on that side.)
std::optional<double> timeToCrossWind(const Wind& wind, const Motion& motion, double horizon);

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
