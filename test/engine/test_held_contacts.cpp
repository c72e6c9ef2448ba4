#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "ball_physics_sim/engine/held_contacts.h"

using namespace ball_physics_sim::engine;

namespace {

using Contact = HeldContacts::Contact;

// Keys as World numbers them for a world of 10 balls and one segment: balls 0-9, the segment,
// then ropes.
constexpr std::size_t kFloor = 10, kRope = 11;

ContactForces pushing(double normal) { return {normal, 0.5 * normal, 0.0}; }

}  // namespace

TEST(HeldContacts, AContactHoldsItsForcesUntilLetGo) {
  HeldContacts held;
  EXPECT_EQ(held.find({0, kFloor}), nullptr);
  EXPECT_TRUE(held.add({0, kFloor}, std::nullopt, pushing(2.0)));
  ASSERT_NE(held.find({0, kFloor}), nullptr);
  EXPECT_EQ(held.find({0, kFloor})->normal, 2.0);
  EXPECT_EQ(held.find({0, kFloor})->friction, 1.0);
  // Held already: the forces stay as first held.
  EXPECT_FALSE(held.add({0, kFloor}, std::nullopt, pushing(5.0)));
  EXPECT_EQ(held.find({0, kFloor})->normal, 2.0);
  held.add({1, kFloor}, std::nullopt, pushing(3.0));
  held.erase({0, kFloor});
  EXPECT_FALSE(held.contains({0, kFloor}));
  held.erase({0, kFloor});  // (letting go of one not held changes nothing)
  EXPECT_EQ(held.of({0, 1}), (std::vector<Contact>{{1, kFloor}}));
  EXPECT_EQ(held.find({1, kFloor})->normal, 3.0);
}

TEST(HeldContacts, ABallPairIsFoundFromEitherBallUnderItsOwnKeyOnly) {
  HeldContacts held;
  held.add({1, 2}, 2, pushing(1.0));
  EXPECT_TRUE(held.contains({1, 2}));
  EXPECT_FALSE(held.contains({2, 1}));  // (World looks the other way round up itself)
  EXPECT_EQ(held.of({1}), (std::vector<Contact>{{1, 2}}));
  EXPECT_EQ(held.of({2}), (std::vector<Contact>{{1, 2}}));
  EXPECT_EQ(held.of({0, 3}), std::vector<Contact>());
  held.erase({2, 1});  // (not held under that key)
  EXPECT_TRUE(held.contains({1, 2}));
}

TEST(HeldContacts, ARopesContactIsFoundFromTheBallAtItsOtherEndAndLetGoFromBoth) {
  HeldContacts held;
  held.add({7, kRope}, 8, pushing(1.0));
  held.add({8, kFloor}, std::nullopt, pushing(2.0));
  EXPECT_EQ(held.of({8}), (std::vector<Contact>{{7, kRope}, {8, kFloor}}));
  held.erase({7, kRope});
  EXPECT_EQ(held.of({7}), std::vector<Contact>());
  EXPECT_EQ(held.of({8}), (std::vector<Contact>{{8, kFloor}}));
}

TEST(HeldContacts, TheContactsOfSomeBallsComeEachOnceInOrderAndTheRestStay) {
  HeldContacts held;
  held.add({3, 4}, 4, pushing(2.0));
  held.add({4, kFloor}, std::nullopt, pushing(1.0));
  held.add({3, kFloor}, std::nullopt, pushing(3.0));
  held.add({5, 6}, 6, pushing(4.0));
  // (3, 4) is both balls', once.
  EXPECT_EQ(held.of({4, 3}), (std::vector<Contact>{{3, 4}, {3, kFloor}, {4, kFloor}}));
  held.erase({3, 4});
  EXPECT_EQ(held.of({4}), (std::vector<Contact>{{4, kFloor}}));
  EXPECT_EQ(held.of({3}), (std::vector<Contact>{{3, kFloor}}));
  EXPECT_EQ(held.find({5, 6})->normal, 4.0);
  EXPECT_EQ(held.find({3, kFloor})->normal, 3.0);
  held.clear();
  EXPECT_EQ(held.of({3, 4, 5, 6}), std::vector<Contact>());
}
