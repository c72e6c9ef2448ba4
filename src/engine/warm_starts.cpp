#include "ball_physics_sim/engine/warm_starts.h"

#include <iterator>

namespace ball_physics_sim::engine {

void WarmStarts::clear() { impulses_.clear(); }

WarmStarts::Impulses WarmStarts::latest(const Pair& pair) const {
  const auto found = impulses_.find(pair);
  return found != impulses_.end() ? found->second : Impulses{0.0, 0.0};
}

void WarmStarts::record(const Pair& pair, const Impulses& impulses) { impulses_[pair] = impulses; }

void WarmStarts::forget(std::uint64_t name) {
  for (auto pair = impulses_.begin(); pair != impulses_.end();)
    pair = pair->first.first == name || pair->first.second == name ? impulses_.erase(pair)
                                                                   : std::next(pair);
}

}  // namespace ball_physics_sim::engine
