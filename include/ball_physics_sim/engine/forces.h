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

// A magnet, or a planet: pulls every ball toward `centre` with strength / d^2 at distance d
// (a point mass's gravity, strength = G M), softened within `core` to strength d / (d^2 +
// core^2)^(3/2), which stays finite at the centre. Its pull changes along a path, so a ball
// under it moves in short stretches, each with the pull at the stretch's middle (the midpoint
// rule), none longer than what keeps the pull's change from moving the ball by kFieldDrift.
struct Attractor {
  Vec2 centre = Vec2::Zero();
  double strength = 0.0;  // m^3/s^2
  double core = 0.0;      // m
};

// Throws std::invalid_argument naming what is wrong: a non-finite value, a centre beyond
// kMaxCoordinate, a strength or core < 0.
void checkAttractor(const Attractor& attractor);

// The acceleration the attractor gives a ball at `position`.
Vec2 attraction(const Attractor& attractor, const Vec2& position);

// How fast that acceleration changes for a ball at `position` moving at `velocity`.
Vec2 attractionRate(const Attractor& attractor, const Vec2& position, const Vec2& velocity);

// How far a stretch of motion under constant acceleration may drift from the changing pull.
constexpr double kFieldDrift = 1e-9;  // m

// The longest stretch over which an acceleration changing at `rate` moves a ball by at most
// kFieldDrift from where constant acceleration puts it (|rate| t^3 / 6); infinity at rate 0.
double fieldStretch(const Vec2& rate);

// Water: a region whose top side is a level surface. A ball dipping into it is buoyed up (+y)
// by the weight of the water it displaces, density g V(d) for a sphere sunk to depth d
// (V = pi d^2 (3 r - d) / 3, g the magnitude of the world's gravity), and slowed by a drag of
// `drag` times the sunk fraction of its volume times its velocity; a floating ball settles at
// the depth where the water it displaces weighs what it does (Archimedes). It is in the water
// while its centre is over the region and its bottom below the surface; the push changes
// along its path, and it moves there in stretches as under an attractor.
struct Water {
  Region region;
  double density = 1000.0;  // kg/m^3
  double drag = 0.0;        // 1/s
};

// Throws std::invalid_argument naming what is wrong: a region checkRegion refuses, a density
// or drag not finite or < 0.
void checkWater(const Water& water);

// The volume of a sphere of `radius` below a plane `depth` above its bottom (0 to 2 radius).
double sunkVolume(double radius, double depth);

// The region a ball of `radius` is in the water within: the water's, reaching up by the radius.
Region wettedRegion(const Water& water, double radius);

// The acceleration the water gives `ball` at `position` moving at `velocity` under gravity of
// magnitude `g`, and its rate of change there given the ball's acceleration `acceleration`.
Vec2 waterAcceleration(const Water& water, const Ball& ball, const Vec2& position,
                       const Vec2& velocity, double g);
Vec2 waterAccelerationRate(const Water& water, const Ball& ball, const Vec2& position,
                           const Vec2& velocity, const Vec2& acceleration, double g);

// How fast the water's push on `ball` at `position` falls (under gravity of magnitude `g`), per
// unit of the ball's velocity (drag's, 1/s) and per metre it rises (buoyancy's, 1/s^2): both 0
// out of the water.
struct WaterStiffness {
  double drag = 0.0;      // 1/s
  double buoyancy = 0.0;  // 1/s^2
};
WaterStiffness waterStiffness(const Water& water, const Ball& ball, const Vec2& position,
                              double g);

// Whether a steady push along `push` (not zero) presses on a body that lies along `to` from what
// it pushes: within 60 degrees of it (at 60 too, up to rounding).
bool pushesToward(const Vec2& push, const Vec2& to);

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
