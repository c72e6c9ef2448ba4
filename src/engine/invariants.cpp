#include "ball_physics_sim/engine/invariants.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "ball_physics_sim/engine/settle.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

double surfaceGap(const Ball& a, const Ball& b) {
  return (a.position - b.position).norm() - (a.radius + b.radius);
}

double surfaceGap(const Ball& ball, const Segment& segment) {
  return (ball.position - segment.closestPoint(ball.position)).norm() -
         contactDistance(segment, ball.radius);
}

namespace {

bool finite(const Ball& ball) {
  return ball.position.allFinite() && ball.velocity.allFinite() &&
         std::isfinite(ball.angular_velocity);
}

template <typename Other>
std::string overlapMessage(const Ball& ball, const char* kind, const Other& other, double gap) {
  std::ostringstream out;
  out << "ball " << ball.id << " overlaps " << kind << " " << other.id << " by " << -gap << " m";
  return out.str();
}

}  // namespace

double ropeStretch(const World& world, const Rope& rope) {
  const Vec2 far = rope.other_ball ? world.findBall(*rope.other_ball)->position : rope.anchor;
  return (world.findBall(rope.ball)->position - far).norm() - rope.length;
}

std::optional<std::string> brokenInvariant(const World& world, double overlap_tolerance) {
  const auto& balls = world.balls();
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (!finite(balls[i])) return "ball " + std::to_string(balls[i].id) + " has a non-finite state";
    for (std::size_t j = i + 1; j < balls.size(); ++j) {
      if (!collide(balls[i], balls[j])) continue;
      const double gap = surfaceGap(balls[i], balls[j]);
      if (gap < -overlap_tolerance) return overlapMessage(balls[i], "ball", balls[j], gap);
    }
    for (const Segment& segment : world.segments()) {
      const double gap = surfaceGap(balls[i], segment);
      if (gap < -overlap_tolerance) return overlapMessage(balls[i], "segment", segment, gap);
    }
  }
  for (const Rope& rope : world.ropes()) {
    const double stretch = ropeStretch(world, rope);
    if (stretch > overlap_tolerance) {
      std::ostringstream out;
      out << "rope " << rope.id << " is stretched " << stretch << " m beyond its length";
      return out.str();
    }
  }
  return std::nullopt;
}

double mostSettledOverlap(const World& world) {
  double smallest = std::numeric_limits<double>::infinity();
  for (const Ball& b : world.balls()) smallest = std::min(smallest, b.radius);
  return std::isfinite(smallest) ? kMostSettledOverlap * smallest : 0.0;
}

double mechanicalEnergy(const World& world) {
  double energy = 0.0;
  for (const Ball& ball : world.balls()) {
    const double spin = ball.radius * ball.angular_velocity;  // I w^2 = k m (r w)^2
    energy += ball.mass * (0.5 * ball.velocity.squaredNorm() - world.gravity().dot(ball.position) +
                           0.5 * ball.inertia_factor * spin * spin);
  }
  return energy;
}

}  // namespace ball_physics_sim::engine
