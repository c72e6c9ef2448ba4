#include <gtest/gtest.h>

#include "ball_physics_sim/engine/impulse.h"

using namespace ball_physics_sim::engine;

TEST(NormalImpulse, ElasticImpactOnAWallReversesTheNormalSpeed) {
  // m = 2 kg at 3 m/s into an immovable wall (inverse mass 0): j = (1 + 1) * 3 * 2.
  EXPECT_DOUBLE_EQ(normalImpulse(3.0, 1.0, 1.0 / 2.0), 12.0);
}

TEST(NormalImpulse, UsesTheReducedMassOfTwoBalls) {
  // Masses 1 and 3, approach 2 m/s, e = 0.5: j = 1.5 * 2 / (1 + 1/3) = 2.25.
  EXPECT_DOUBLE_EQ(normalImpulse(2.0, 0.5, 1.0 + 1.0 / 3.0), 2.25);
}

TEST(CombinedRestitution, IsTheProductOfBothMaterials) {
  EXPECT_DOUBLE_EQ(combinedRestitution(0.8, 0.5), 0.4);
  EXPECT_DOUBLE_EQ(combinedRestitution(1.0, 1.0), 1.0);
}
