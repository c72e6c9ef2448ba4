#pragma once

#include <optional>
#include <string>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/segment.h"
#include "ball_physics_sim/engine/world.h"

namespace ball_physics_sim::engine {

// How far apart two surfaces are (negative: overlapping by that much).
double surfaceGap(const Ball& a, const Ball& b);
double surfaceGap(const Ball& ball, const Segment& segment);
// How far the rope's ends are apart beyond its length (negative: slack by that much).
double ropeStretch(const World& world, const Rope& rope);

// The first invariant `world` breaks, described with the bodies involved, or none: every ball
// state finite, no two balls that collide and no ball and segment overlapping by more than
// `overlap_tolerance` metres, and no rope stretched beyond its length by more than that. For
// tests, fuzzers and soak runs (O(N^2)).
std::optional<std::string> brokenInvariant(const World& world, double overlap_tolerance);

// What tests and fuzzers accept of a settling pile's overlaps in `world`: kMostSettledOverlap
// of its smallest ball's radius (0 without balls).
double mostSettledOverlap(const World& world);

// Kinetic energy (of motion and of spin) plus potential energy in the world's gravity (zero at
// the origin): it never grows in a world whose restitutions are all <= 1.
double mechanicalEnergy(const World& world);

}  // namespace ball_physics_sim::engine
