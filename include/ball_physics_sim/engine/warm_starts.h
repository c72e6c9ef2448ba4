#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// Each touching pair's normal and friction impulses in its latest settle, from which its next
// settle starts (Box2D's warm starting): while settles go on from step to step, a pile
// settling goes on as it was. The bodies go by names made of their ids, which stay theirs
// while other bodies come and go.
class WarmStarts {
 public:
  // A pair's impulses are kept this many steps after its latest settle, and up to twice as
  // many: a ball that leaves its pile for a bounce or two comes back to it warm, and the pairs
  // of balls that no longer touch go.
  static constexpr std::uint64_t kStepsKept = 16;

  // A ball's name and the name of what it touches (see pairOf).
  using Pair = std::pair<std::uint64_t, std::uint64_t>;
  using Impulses = std::array<double, 2>;

  static std::uint64_t ballName(BallId id) { return 2 * std::uint64_t{id}; }
  static std::uint64_t segmentName(SegmentId id) { return 2 * std::uint64_t{id} + 1; }
  // The pair of the ball named `ball` and the body named `other`, the same whichever of two
  // balls comes first: the smaller name first. (Swapped, a contact's normal turns round and
  // its impulses, along the normal and the tangent, change both balls alike.)
  static Pair pairOf(std::uint64_t ball, std::uint64_t other) {
    return isSegment(other) || ball < other ? Pair{ball, other} : Pair{other, ball};
  }
  static bool isSegment(std::uint64_t name) { return name % 2 == 1; }

  // Forgets every pair.
  void clear();
  // The pair's impulses in its latest settle; none if it had none.
  Impulses latest(const Pair& pair) const;
  // Has the processor fetch where `pair` would be found, ahead of latest or record: a settle
  // knows its pairs before it looks them up, and a table of every pair settled lately is far
  // larger than a cache.
  void prefetch(const Pair& pair) const;
  void record(const Pair& pair, const Impulses& impulses);
  // Forgets the pairs of the body named `name` (removed, or set elsewhere).
  void forget(std::uint64_t name);
  // A new step; whether forgetStale is due (every kStepsKept steps).
  bool startStep();
  // Forgets the pairs no settle has recorded for kStepsKept steps or more, except those of
  // which no ball is named in `awake` (sorted): a pile asleep keeps its impulses. A name not
  // there counts as resting, so a ball removed must be forgotten (see forget).
  void forgetStale(const std::vector<std::uint64_t>& awake);

 private:
  struct Kept {
    Impulses impulses;
    std::uint64_t step;  // in which it was recorded
  };
  struct Slot {
    Pair pair;
    Kept kept;
    bool used = false;
  };
  // The slot where the search for `pair` starts.
  std::size_t firstSlot(const Pair& pair) const;
  // The slot holding `pair`, or the empty one where it would go.
  std::size_t slotOf(const Pair& pair) const;
  // Lays the table out anew, for `pairs` pairs, with only those `keep` says.
  template <typename Keep>
  void keepOnly(std::size_t pairs, Keep keep);

  // An open-addressed table (linear probing, a power of two slots, at most half of them used):
  // every settle looks up each pair it sweeps, and a node-based map's lookups missed the cache.
  std::vector<Slot> slots_;
  std::size_t used_ = 0;
  std::uint64_t step_ = 0;  // steps started
};

}  // namespace ball_physics_sim::engine
