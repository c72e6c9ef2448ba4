#include "ball_physics_sim/engine/warm_starts.h"

#include <algorithm>

namespace ball_physics_sim::engine {

namespace {

// The fewest slots a table has, once it has any.
constexpr std::size_t kFewestSlots = 16;

// The fewest slots, a power of two, that hold `pairs` at most half full.
std::size_t slotsFor(std::size_t pairs) {
  std::size_t slots = kFewestSlots;
  while (slots < 2 * pairs) slots *= 2;
  return slots;
}

}  // namespace

void WarmStarts::clear() {
  slots_.clear();
  used_ = 0;
}

std::size_t WarmStarts::firstSlot(const Pair& pair) const {
  // Multiplicative hashing: the product's middle bits mix both names.
  const std::uint64_t mixed = (pair.first * 0x9E3779B97F4A7C15ull + pair.second) *
                              0xBF58476D1CE4E5B9ull;
  return static_cast<std::size_t>(mixed >> 32) & (slots_.size() - 1);
}

std::size_t WarmStarts::slotOf(const Pair& pair) const {
  std::size_t k = firstSlot(pair);
  while (slots_[k].used && slots_[k].pair != pair) k = (k + 1) & (slots_.size() - 1);
  return k;
}

WarmStarts::Impulses WarmStarts::latest(const Pair& pair) const {
  if (slots_.empty()) return {0.0, 0.0};
  const Slot& slot = slots_[slotOf(pair)];
  return slot.used ? slot.kept.impulses : Impulses{0.0, 0.0};
}

void WarmStarts::prefetch(const Pair& pair) const {
  if (slots_.empty()) return;
  // (Both ends: a slot may straddle two cache lines.)
  const Slot* slot = &slots_[firstSlot(pair)];
  __builtin_prefetch(slot);
  __builtin_prefetch(reinterpret_cast<const char*>(slot + 1) - 1);
}

void WarmStarts::record(const Pair& pair, const Impulses& impulses) {
  std::size_t k = slots_.empty() ? 0 : slotOf(pair);
  // A new pair that would fill the table past half doubles it.
  if (slots_.empty() || (!slots_[k].used && 2 * (used_ + 1) > slots_.size())) {
    keepOnly(used_ + 1, [](const Slot&) { return true; });
    k = slotOf(pair);
  }
  Slot& slot = slots_[k];
  if (!slot.used) {
    slot.pair = pair;
    slot.used = true;
    ++used_;
  }
  slot.kept = {impulses, step_};
}

template <typename Keep>
void WarmStarts::keepOnly(std::size_t pairs, Keep keep) {
  std::vector<Slot> old(slotsFor(pairs));
  old.swap(slots_);
  used_ = 0;
  for (const Slot& slot : old)
    if (slot.used && keep(slot)) {
      slots_[slotOf(slot.pair)] = slot;
      ++used_;
    }
}

void WarmStarts::forget(std::uint64_t name) {
  const auto named = [name](const Slot& slot) {
    return slot.used && (slot.pair.first == name || slot.pair.second == name);
  };
  if (std::any_of(slots_.begin(), slots_.end(), named))
    keepOnly(used_, [&](const Slot& slot) { return !named(slot); });
}

bool WarmStarts::startStep() { return ++step_ % kStepsKept == 0; }

void WarmStarts::forgetStale(const std::vector<std::uint64_t>& awake) {
  if (used_ == 0) return;
  const auto rests = [&](std::uint64_t name) {
    return !std::binary_search(awake.begin(), awake.end(), name);
  };
  // (A segment is never named in `awake`.)
  keepOnly(used_, [&](const Slot& slot) {
    const auto [ball, other] = slot.pair;
    return step_ - slot.kept.step < kStepsKept || (rests(ball) && rests(other));
  });
}

}  // namespace ball_physics_sim::engine
