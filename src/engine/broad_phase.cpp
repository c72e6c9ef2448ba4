#include "ball_physics_sim/engine/broad_phase.h"

#include <algorithm>
#include <numeric>

namespace ball_physics_sim::engine {

namespace {

Box grown(Box box, double by) {
  box.min -= Vec2::Constant(by);
  box.max += Vec2::Constant(by);
  return box;
}

}  // namespace

Box sweptBox(const Motion& motion, double radius, double horizon) {
  const Vec2 start = motion.position;
  const Vec2 end = motion.positionAt(horizon);
  Box box{start.cwiseMin(end), start.cwiseMax(end)};
  for (int axis = 0; axis < 2; ++axis) {
    const double a = motion.acceleration[axis];
    if (a == 0.0) continue;
    const double turn = -motion.velocity[axis] / a;  // where this coordinate stops and turns
    if (!(turn > 0.0 && turn < horizon)) continue;
    const double extreme = motion.positionAt(turn)[axis];
    box.min[axis] = std::min(box.min[axis], extreme);
    box.max[axis] = std::max(box.max[axis], extreme);
  }
  return grown(box, radius + kBoxMargin);
}

Box segmentBox(const Segment& segment, double horizon) {
  Box box{segment.start.cwiseMin(segment.end), segment.start.cwiseMax(segment.end)};
  if (segment.angular_velocity != 0.0) {  // its ends may go anywhere round the pivot
    const double reach = segment.reachFromPivot();
    box = {segment.pivot - Vec2::Constant(reach), segment.pivot + Vec2::Constant(reach)};
  }
  if (segment.velocity != Vec2::Zero()) {
    const Vec2 shift = horizon * segment.velocity;
    box.min += shift.cwiseMin(Vec2::Zero());
    box.max += shift.cwiseMax(Vec2::Zero());
  }
  return grown(box, 0.5 * segment.thickness + kBoxMargin);
}

std::vector<std::pair<std::size_t, std::size_t>> overlappingPairs(const std::vector<Box>& boxes) {
  std::vector<std::size_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return boxes[a].min.x() < boxes[b].min.x();
  });
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Box& box = boxes[order[k]];
    // Every later box starts at or right of this one's left side: those starting beyond its
    // right side, and all after them, miss it in x.
    for (std::size_t m = k + 1; m < order.size(); ++m) {
      const Box& other = boxes[order[m]];
      if (other.min.x() > box.max.x()) break;
      if (other.min.y() > box.max.y() || other.max.y() < box.min.y()) continue;
      pairs.emplace_back(std::min(order[k], order[m]), std::max(order[k], order[m]));
    }
  }
  return pairs;
}

}  // namespace ball_physics_sim::engine
