#include "ball_physics_sim/engine/warm_starts.h"

namespace ball_physics_sim::engine {

void WarmStarts::clear() { impulses_.clear(); }

WarmStarts::Impulses WarmStarts::latest(const Pair& pair) const {
  const auto found = impulses_.find(pair);
  return found != impulses_.end() ? found->second : Impulses{0.0, 0.0};
}

void WarmStarts::record(const Pair& pair, const Impulses& impulses) { impulses_[pair] = impulses; }

void WarmStarts::rename(const std::function<std::optional<Pair>(const Pair&)>& renamed) {
  std::unordered_map<Pair, Impulses, PairHash> kept;
  kept.reserve(impulses_.size());
  for (const auto& [pair, impulses] : impulses_)
    if (const std::optional<Pair> name = renamed(pair)) kept.emplace(*name, impulses);
  impulses_.swap(kept);
}

}  // namespace ball_physics_sim::engine
