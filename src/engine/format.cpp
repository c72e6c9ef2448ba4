#include "ball_physics_sim/engine/format.h"

namespace ball_physics_sim::engine {

std::string format(const Vec2& v) { return "(" + format(v.x()) + ", " + format(v.y()) + ")"; }

}  // namespace ball_physics_sim::engine
