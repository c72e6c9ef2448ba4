#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace ball_physics_sim::engine {

// The first of n entries in an order given by a `comes_first(a, b)` function of two entries'
// indices, kept as entries change one at a time: a change costs log n comparisons and finding
// the first costs none (a tournament tree). The impact queue and the hold ends use it so that
// an event's work does not grow with the number of balls.
class TournamentTree {
 public:
  // Plays every match anew for entries 0 .. n-1.
  template <class ComesFirst>
  void reset(std::size_t n, const ComesFirst& comes_first) {
    entries_ = n;
    leaves_ = 1;
    while (leaves_ < n) leaves_ *= 2;
    winners_.assign(2 * leaves_, n);  // n stands for no entry
    for (std::size_t e = 0; e < n; ++e) winners_[leaves_ + e] = e;
    for (std::size_t node = leaves_ - 1; node > 0; --node) play(node, comes_first);
  }

  // Replays the matches of entry `e` (< n), whose place in the order changed.
  template <class ComesFirst>
  void update(std::size_t e, const ComesFirst& comes_first) {
    for (std::size_t node = (leaves_ + e) / 2; node > 0; node /= 2) play(node, comes_first);
  }

  // The entry that comes first; none if there are no entries.
  std::optional<std::size_t> first() const {
    if (entries_ == 0) return std::nullopt;
    return winners_[1];
  }

 private:
  template <class ComesFirst>
  void play(std::size_t node, const ComesFirst& comes_first) {
    const std::size_t a = winners_[2 * node], b = winners_[2 * node + 1];
    winners_[node] = a == entries_ ? b : b == entries_ ? a : comes_first(b, a) ? b : a;
  }

  std::size_t entries_ = 0;
  std::size_t leaves_ = 1;  // a power of two, at least entries_
  // Node k's children are 2k and 2k + 1; the leaves are leaves_ .. 2 leaves_ - 1, node 1 the root.
  std::vector<std::size_t> winners_;
};

}  // namespace ball_physics_sim::engine
