#include "ball_physics_sim/engine/warm_starts.h"

#include <algorithm>
#include <iterator>

namespace ball_physics_sim::engine {

void WarmStarts::clear() { impulses_.clear(); }

WarmStarts::Impulses WarmStarts::latest(const Pair& pair) const {
  const auto found = impulses_.find(pair);
  return found != impulses_.end() ? found->second.impulses : Impulses{0.0, 0.0};
}

void WarmStarts::record(const Pair& pair, const Impulses& impulses) {
  impulses_[pair] = {impulses, step_};
}

void WarmStarts::forget(std::uint64_t name) {
  for (auto pair = impulses_.begin(); pair != impulses_.end();)
    pair = pair->first.first == name || pair->first.second == name ? impulses_.erase(pair)
                                                                   : std::next(pair);
}

bool WarmStarts::startStep() { return ++step_ % kStepsKept == 0; }

void WarmStarts::forgetStale(const std::vector<std::uint64_t>& awake) {
  const auto rests = [&](std::uint64_t name) {
    return !std::binary_search(awake.begin(), awake.end(), name);
  };
  for (auto pair = impulses_.begin(); pair != impulses_.end();) {
    const auto [ball, other] = pair->first;
    // (A segment is never named in `awake`.)
    const bool kept = step_ - pair->second.step < kStepsKept || (rests(ball) && rests(other));
    pair = kept ? std::next(pair) : impulses_.erase(pair);
  }
}

}  // namespace ball_physics_sim::engine
