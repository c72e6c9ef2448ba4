#include <algorithm>
#include <cstddef>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/disjoint_sets.h"

using namespace ball_physics_sim::engine;

TEST(DisjointSets, AGroupKeepsTheNameOfTheGroupItWasPutInto) {
  DisjointSets sets(6);
  sets.join(0, 1);
  sets.join(2, 3);
  EXPECT_EQ(sets.find(0), 1u);
  EXPECT_EQ(sets.find(2), 3u);
  sets.join(1, 3);
  for (const std::size_t i : {0u, 1u, 2u, 3u}) EXPECT_EQ(sets.find(i), 3u) << i;
  EXPECT_EQ(sets.find(4), 4u);
  EXPECT_EQ(sets.find(5), 5u);
  sets.join(3, 3);  // a group joined to itself stays as it is
  EXPECT_EQ(sets.find(0), 3u);
}

TEST(DisjointSets, GroupsAreWhatThePairsConnect) {
  // Random pairs, each answer checked against the groups found by spreading labels over every
  // pair until none changes.
  std::mt19937 rng(7);
  for (const std::size_t n : {1u, 2u, 10u, 200u}) {
    DisjointSets sets(n);
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t p = 0; p < n; ++p) {
      pairs.emplace_back(rng() % n, rng() % n);
      sets.join(pairs.back().first, pairs.back().second);
    }
    std::vector<std::size_t> label(n);
    for (std::size_t i = 0; i < n; ++i) label[i] = i;
    for (bool changed = true; changed;) {
      changed = false;
      for (const auto& [a, b] : pairs)
        if (label[a] != label[b]) {
          label[a] = label[b] = std::min(label[a], label[b]);
          changed = true;
        }
    }
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j)
        ASSERT_EQ(sets.find(i) == sets.find(j), label[i] == label[j])
            << "n " << n << ", " << i << " and " << j;
  }
}
