#include <algorithm>
#include <cstddef>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/tournament_tree.h"

using namespace ball_physics_sim::engine;

TEST(TournamentTree, KeepsTheFirstEntryAsEntriesChangeOneAtATime) {
  // Sizes round a power of two, values with many ties (the lower entry comes first on a tie),
  // each change checked against a scan of every entry.
  std::mt19937 rng(5);
  for (const std::size_t n : {1u, 2u, 3u, 7u, 8u, 9u, 100u}) {
    std::vector<int> values(n);
    for (int& v : values) v = static_cast<int>(rng() % 10);
    auto comesFirst = [&](std::size_t a, std::size_t b) {
      return values[a] < values[b] || (values[a] == values[b] && a < b);
    };
    TournamentTree tree;
    tree.reset(n, comesFirst);
    for (int change = 0; change < 300; ++change) {
      const std::size_t e = rng() % n;
      values[e] = static_cast<int>(rng() % 10);
      tree.update(e, comesFirst);
      const std::size_t first = static_cast<std::size_t>(
          std::min_element(values.begin(), values.end()) - values.begin());
      ASSERT_EQ(tree.first(), first) << "n " << n << ", change " << change;
    }
  }
}

TEST(TournamentTree, HasNoFirstEntryWhenItHasNoEntries) {
  TournamentTree tree;
  EXPECT_FALSE(tree.first());
  tree.reset(0, [](std::size_t, std::size_t) { return false; });
  EXPECT_FALSE(tree.first());
}
