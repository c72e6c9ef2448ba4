#include "ball_physics_sim/engine/rope.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ball_physics_sim::engine {

void checkRope(const Rope& rope) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("rope's " + what);
  };
  require(rope.other_ball != rope.ball,
          "two ends are both ball " + std::to_string(rope.ball) + ": a rope ties two bodies");
  require(std::isfinite(rope.length) && rope.length > 0.0 && rope.length <= kMaxCoordinate,
          "length must be > 0 and at most " + std::to_string(kMaxCoordinate) + " m, got " +
              std::to_string(rope.length));
  require(std::isfinite(rope.restitution) && rope.restitution >= 0.0 && rope.restitution <= 1.0,
          "restitution must be within [0, 1], got " + std::to_string(rope.restitution));
  require(rope.anchor.allFinite() && rope.anchor.cwiseAbs().maxCoeff() <= kMaxCoordinate,
          "anchor must be finite, each coordinate within " + std::to_string(kMaxCoordinate) +
              " m of the origin's");
}

}  // namespace ball_physics_sim::engine
