#pragma once
// What the fuzz targets share: the libFuzzer entry point they define, and how they report a
// finding. The same targets run under libFuzzer (scripts/fuzz.sh) and, over the corpus in
// test/fuzz/corpus/, as unit tests (replay_corpus.cpp).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/kinematics.h"
#include "ball_physics_sim/engine/world.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace ball_physics_sim::fuzz {

// Overlap the fuzzers accept: a few rounding errors of a pile's resting contacts, far below
// any visible sinking or tunnelling.
constexpr double kOverlapTolerance = 1e-6;  // m
// Energy growth the fuzzers accept: rounding, relative to the size of the terms summed, and an
// absolute floor for worlds at rest near the origin.
constexpr double kEnergyRounding = 1e-9;
constexpr double kEnergyFloor = 1e-12;  // J

// A finding: says what broke and aborts, which libFuzzer and the replay test both catch.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
  std::abort();
}

// Whether anything in `world` can do work on its balls: a bumper's kick, a segment that moves,
// turns or follows waypoints, wind, an attractor or water (mechanicalEnergy counts neither the
// fields' potential nor the water's buoyancy). Drives and blasts cannot be seen through World:
// a target that calls drive() or explode() must not rely on this.
inline bool hasEnergySource(const engine::World& world) {
  if (!world.winds().empty() || !world.attractors().empty() || !world.waters().empty())
    return true;
  return std::any_of(world.segments().begin(), world.segments().end(),
                     [](const engine::Segment& s) {
                       return s.kick > 0.0 || engine::moves(s) || !s.waypoints.empty();
                     });
}

// Steps `world` by dt and checks the invariants everywhere; where nothing can do work on the
// balls (hasEnergySource, as of the step's start: only calls between steps add sources) and no
// rope swings one, also that the mechanical energy has not grown beyond rounding (restitution
// is never above 1). A swing is held in stretches of constant pull that each keep the rope's
// length only within kHeldDrift, not to rounding: ropes.yaml's 20 kg wrecking ball gains up to
// 5e-6 J a 1/60 s step as it swings down (4e-9 of its energy, above kEnergyRounding).
inline void stepAndCheck(engine::World& world, double dt) {
  const bool energy_kept = !hasEnergySource(world) && world.ropes().empty();
  const double before = energy_kept ? engine::mechanicalEnergy(world) : 0.0;
  world.step(dt);
  if (const auto broken = engine::brokenInvariant(world, kOverlapTolerance))
    finding(*broken + " at t = " + std::to_string(world.time()));
  if (!energy_kept) return;
  const double after = engine::mechanicalEnergy(world);
  double scale = 0.0;  // the size of the terms the energies are sums of
  for (const engine::Ball& b : world.balls())
    scale += b.mass * (b.velocity.squaredNorm() + (world.gravity().norm() + 1.0) * b.position.norm());
  if (after - before > kEnergyRounding * scale + kEnergyFloor)
    finding("mechanical energy grew from " + std::to_string(before) + " to " +
            std::to_string(after) + " J at t = " + std::to_string(world.time()));
}

}  // namespace ball_physics_sim::fuzz
