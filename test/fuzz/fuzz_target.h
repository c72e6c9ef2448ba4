#pragma once
// What the fuzz targets share: the libFuzzer entry point they define, and how they report a
// finding. The same targets run under libFuzzer (scripts/fuzz.sh) and, over the corpus in
// test/fuzz/corpus/, as unit tests (replay_corpus.cpp).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/world.h"
#include "energy_bound.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace ball_physics_sim::fuzz {

// Overlap the fuzzers accept: a few rounding errors of a pile's resting contacts, far below
// any visible sinking or tunnelling, or what a settling pile may leave (kMostSettledOverlap of
// the smallest ball's radius).
constexpr double kOverlapTolerance = 1e-6;  // m
inline double overlapTolerance(const engine::World& world) {
  return std::max(kOverlapTolerance, engine::mostSettledOverlap(world));
}
// Energy growth the fuzzers accept: rounding, relative to the size of the terms summed, and an
// absolute floor for worlds at rest near the origin.
constexpr double kEnergyRounding = 1e-9;
constexpr double kEnergyFloor = 1e-12;  // J

// A finding: says what broke and aborts, which libFuzzer and the replay test both catch.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
  std::abort();
}

// Steps `world` by dt and checks the invariants everywhere, and that the mechanical energy of
// the balls the step's budget covers (energyBudget) has grown by no more than the work its
// fields, `drives` and ropes can do, plus rounding (restitution is never above 1). Without
// such sources the budget is zero: only rounding is accepted.
inline void stepAndCheck(engine::World& world, double dt, const Drives& drives = {}) {
  const StepStart start(world);
  world.takeContacts();  // those of earlier steps
  world.step(dt);
  if (const auto broken = engine::brokenInvariant(world, overlapTolerance(world)))
    finding(*broken + " at t = " + std::to_string(world.time()));
  const EnergyBudget budget = energyBudget(start, world, world.takeContacts(), drives, dt);
  double before = 0.0, after = 0.0;
  double scale = 0.0;  // the size of the terms the energies are sums of
  for (const engine::Ball& b : start.balls)
    if (budget.balls.count(b.id)) before += energyOf(b, world.gravity());
  for (const engine::Ball& b : world.balls()) {
    if (!budget.balls.count(b.id)) continue;
    after += energyOf(b, world.gravity());
    scale += b.mass * (b.velocity.squaredNorm() + (world.gravity().norm() + 1.0) * b.position.norm());
  }
  if (after - before > budget.bound + kEnergyRounding * scale + kEnergyFloor)
    finding("mechanical energy grew from " + std::to_string(before) + " to " +
            std::to_string(after) + " J, by more than the " + std::to_string(budget.bound) +
            " J its sources can add, at t = " + std::to_string(world.time()));
}

}  // namespace ball_physics_sim::fuzz
