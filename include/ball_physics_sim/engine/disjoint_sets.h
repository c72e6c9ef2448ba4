#pragma once

#include <cstddef>
#include <numeric>
#include <vector>

namespace ball_physics_sim::engine {

// Which of n things the pairs joined so far put in one group, each group named by one of its
// things (union-find, with path halving): the islands of touching balls and of contacts.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }

  // The thing that names i's group.
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }

  // Puts a's group into b's, which keeps its name.
  void join(std::size_t a, std::size_t b) {
    const std::size_t group = find(b);
    parent_[find(a)] = group;
  }

 private:
  std::vector<std::size_t> parent_;
};

}  // namespace ball_physics_sim::engine
