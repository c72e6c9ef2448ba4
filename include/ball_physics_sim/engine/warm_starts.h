#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <utility>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// Each touching pair's normal and friction impulses in its latest settle, from which its next
// settle starts (Box2D's warm starting): while settles go on from step to step, a pile
// settling goes on as it was. The bodies go by names made of their ids, which stay theirs
// while other bodies come and go.
class WarmStarts {
 public:
  // A ball's name and the name of what it touches.
  using Pair = std::pair<std::uint64_t, std::uint64_t>;
  using Impulses = std::array<double, 2>;

  static std::uint64_t ballName(BallId id) { return 2 * std::uint64_t{id}; }
  static std::uint64_t segmentName(SegmentId id) { return 2 * std::uint64_t{id} + 1; }

  // Forgets every pair.
  void clear();
  // The pair's impulses in its latest settle; none if it had none.
  Impulses latest(const Pair& pair) const;
  void record(const Pair& pair, const Impulses& impulses);
  // Forgets the pairs of the body named `name` (removed, or set elsewhere).
  void forget(std::uint64_t name);

 private:
  struct PairHash {
    std::size_t operator()(const Pair& pair) const noexcept {
      return std::hash<std::uint64_t>{}(pair.first * 0x9E3779B97F4A7C15ull + pair.second);
    }
  };
  std::unordered_map<Pair, Impulses, PairHash> impulses_;
};

}  // namespace ball_physics_sim::engine
