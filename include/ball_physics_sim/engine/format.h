#pragma once

#include <sstream>
#include <string>

#include "ball_physics_sim/engine/ball.h"

namespace ball_physics_sim::engine {

// Numbers in answers and errors, in the shortest form that reads well ("9", "9.93194"), where
// std::to_string would print "9.000000".
template <typename T>
std::string format(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}
// A point or vector as "(x, y)".
std::string format(const Vec2& v);

}  // namespace ball_physics_sim::engine
