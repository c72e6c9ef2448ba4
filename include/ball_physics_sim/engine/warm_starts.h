#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <unordered_map>
#include <utility>

namespace ball_physics_sim::engine {

// Each pair's normal and friction impulses in its latest settle, from which its next settle
// starts (Box2D's warm starting): a pile settling goes on settling as it was, and a sleeping
// pile struck starts from the pushes that held it up.
class WarmStarts {
 public:
  // A ball's index and a key (see World::keyOf).
  using Pair = std::pair<std::size_t, std::size_t>;
  using Impulses = std::array<double, 2>;

  // Forgets every pair.
  void clear();
  // The pair's impulses in its latest settle; none if it had none.
  Impulses latest(const Pair& pair) const;
  void record(const Pair& pair, const Impulses& impulses);
  // Each pair renamed by `renamed`, or forgotten where it gives none.
  void rename(const std::function<std::optional<Pair>(const Pair&)>& renamed);

 private:
  struct PairHash {
    std::size_t operator()(const Pair& pair) const noexcept {
      return std::hash<std::size_t>{}(pair.first * 0x9E3779B97F4A7C15ull + pair.second);
    }
  };
  std::unordered_map<Pair, Impulses, PairHash> impulses_;
};

}  // namespace ball_physics_sim::engine
