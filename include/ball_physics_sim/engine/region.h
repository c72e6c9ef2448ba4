#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/motion.h"

namespace ball_physics_sim::engine {

// An axis-aligned box of the plane, where wind blows (forces.h) or a sensor watches. A ball is
// in it while its centre is, boundary included; going in or out is an event at its exact time.
struct Region {
  Vec2 min = Vec2::Zero();  // the lower left corner
  Vec2 max = Vec2::Zero();  // and the upper right one
};

// Throws std::invalid_argument naming what is wrong, as `what`'s: a non-finite corner, one
// beyond kMaxCoordinate, min not below and left of max.
void checkRegion(const Region& region, const std::string& what);

// Whether a centre moving as `motion` is in the region from now on: inside it, or on a side
// (within kOnRegionSide) and moving in or along it. At the time of a crossing, rounding puts
// the centre on either side of the line; its motion says which way it goes.
bool centreInside(const Region& region, const Motion& motion);
constexpr double kOnRegionSide = 1e-9;  // m

// The times in (0, horizon) at which a centre moving as `motion` crosses the region's boundary,
// going in or out, ascending: the roots of the quadratic of each side's line where they lie on
// that side (a corner, on two sides, once).
std::vector<double> regionCrossings(const Region& region, const Motion& motion, double horizon);

// The first of those; none if there is none.
std::optional<double> timeToCrossRegion(const Region& region, const Motion& motion,
                                        double horizon);

// A goal or trigger: reports the balls that go in or out of its region. A pocket also takes
// each ball that goes in out of the world, at the end of that step.
struct Sensor {
  std::string name;
  Region region;
  bool pocket = false;
};

// A ball going in or out of a sensor's region, at the exact time.
struct SensorEvent {
  double time = 0.0;  // s of sim time
  std::string sensor;
  BallId ball = 0;
  bool entered = true;  // false: it left
};

}  // namespace ball_physics_sim::engine
