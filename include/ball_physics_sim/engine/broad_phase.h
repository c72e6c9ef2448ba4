#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/motion.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// An axis-aligned box.
struct Box {
  Vec2 min = Vec2::Zero();
  Vec2 max = Vec2::Zero();
};

// Boxes are grown by this much so that rounding in positions (~1e-10 m within kMaxCoordinate)
// does not hide a pair that the exact tests find touching. (A near-graze that the impact
// polynomials' own cancellation reports from further away, possible only for long fast sweeps
// of tiny balls, is dropped instead.)
constexpr double kBoxMargin = 1e-6;  // m

// The box a ball of `radius` sweeps moving with `motion` over [0, horizon], grown by
// kBoxMargin: per axis the path's ends and, if it turns within the horizon, its turning point.
Box sweptBox(const Motion& motion, double radius, double horizon);

// The box a segment's capsule sweeps over [0, horizon], grown by kBoxMargin: a turning one's
// is the box of the circle its ends go round.
Box segmentBox(const Segment& segment, double horizon);

// The pairs (a, b), a < b, of boxes that overlap or touch, in no particular order: found by
// sorting the boxes on their lower x and sweeping, O(n log n + pairs with overlapping x)
// instead of testing all n^2 / 2 pairs.
std::vector<std::pair<std::size_t, std::size_t>> overlappingPairs(const std::vector<Box>& boxes);

}  // namespace ball_physics_sim::engine
