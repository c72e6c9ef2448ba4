#include <cmath>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/toi.h"

using namespace ball_physics_sim::engine;

namespace {

Motion moving(Vec2 position, Vec2 velocity, Vec2 acceleration = Vec2::Zero()) {
  return {position, velocity, acceleration};
}

// From (-1, 0) to (1, 0).
Segment floorSegment(double thickness = 0.0) {
  Segment s;
  s.start = Vec2(-1.0, 0.0);
  s.end = Vec2(1.0, 0.0);
  s.thickness = thickness;
  return s;
}

}  // namespace

// Circle/circle, the lecture's four cases of the abc formula. Relative motion, R = r1 + r2 = 2.

TEST(CircleTimeOfImpact, NoRealRootMeansTheyMiss) {
  // Closest approach 3 > 2.
  EXPECT_FALSE(circleTimeOfImpact(moving({-5.0, 3.0}, {1.0, 0.0}), 2.0, 100.0));
}

TEST(CircleTimeOfImpact, TwoPositiveRootsHitAtTheSmaller) {
  // |(-5 + t, 0)| = 2 at t = 3 and t = 7.
  const auto t = circleTimeOfImpact(moving({-5.0, 0.0}, {1.0, 0.0}), 2.0, 100.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 3.0, 1e-15);
}

TEST(CircleTimeOfImpact, TwoNegativeRootsMeanTheyAlreadyParted) {
  EXPECT_FALSE(circleTimeOfImpact(moving({5.0, 0.0}, {1.0, 0.0}), 2.0, 100.0));
}

TEST(CircleTimeOfImpact, OneRootOfEachSignMeansOverlapAndApproachingCollidesNow) {
  const auto t = circleTimeOfImpact(moving({-1.0, 0.0}, {1.0, 0.0}), 2.0, 100.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t, 0.0);
}

TEST(CircleTimeOfImpact, SlightOverlapAfterAResetStillCollidesInsteadOfPassingThrough) {
  // Attempt 1's bug: rounding puts the reset ball 1e-12 inside, the smaller root is negative
  // and ignored, and the balls pass through each other.
  const auto t = circleTimeOfImpact(moving({-(2.0 - 1e-12), 0.0}, {1.0, 0.0}), 2.0, 100.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t, 0.0);
}

TEST(CircleTimeOfImpact, OverlappingButMovingApartDoesNotStick) {
  // Attempt 2's bug: an overlap that is already separating must not collide again.
  EXPECT_FALSE(circleTimeOfImpact(moving({1.0, 0.0}, {1.0, 0.0}), 2.0, 100.0));
}

TEST(CircleTimeOfImpact, ImpactBeyondTheHorizonIsNotThisStep) {
  EXPECT_FALSE(circleTimeOfImpact(moving({-5.0, 0.0}, {1.0, 0.0}), 2.0, 2.9));
}

TEST(CircleTimeOfImpact, FallingOntoAPointSolvesTheParabola) {
  // Centre 5 above, at rest, g = 10: 5 - 5 t^2 = 1 at t = sqrt(0.8).
  const auto t = circleTimeOfImpact(moving({0.0, 5.0}, {0.0, 0.0}, {0.0, -10.0}), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, std::sqrt(0.8), 1e-15);
}

TEST(CircleTimeOfImpact, ThrownBallHitsAPointAtTheQuarticsFirstRoot) {
  // x = -3 + 3t, y = 6 - 5t^2: at t = 1 the centre is at (0, 1), distance 1 = R, closing.
  const auto t = circleTimeOfImpact(moving({-3.0, 6.0}, {3.0, 0.0}, {0.0, -10.0}), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.0, 1e-14);
}

// Circle/line segment.

TEST(FaceTimeOfImpact, BallFallingOnTheFaceTouchesWhenItsEdgeArrives) {
  // Centre 2 above, radius 0.5, at 1 m/s: t = 1.5.
  const auto t = faceTimeOfImpact(moving({0.0, 2.0}, {0.0, -1.0}), 0.5, floorSegment(), 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.5, 1e-15);
}

TEST(FaceTimeOfImpact, FacesAreDoubleSided) {
  const auto t = faceTimeOfImpact(moving({0.0, -2.0}, {0.0, 1.0}), 0.5, floorSegment(), 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.5, 1e-15);
}

TEST(FaceTimeOfImpact, ThicknessMovesTheFaceOutByHalfOfIt) {
  const auto t = faceTimeOfImpact(moving({0.0, 2.0}, {0.0, -1.0}), 0.5, floorSegment(0.2), 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.4, 1e-15);
}

TEST(FaceTimeOfImpact, UnderGravityTheGapClosesAsAParabola) {
  // 2.5 - 5 t^2 = 0.5 at t = sqrt(0.4).
  const auto t =
      faceTimeOfImpact(moving({0.0, 2.5}, {0.0, 0.0}, {0.0, -10.0}), 0.5, floorSegment(), 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, std::sqrt(0.4), 1e-15);
}

TEST(FaceTimeOfImpact, PointOfImpactPastTheEndIsNoFaceHit) {
  EXPECT_FALSE(faceTimeOfImpact(moving({2.0, 2.0}, {0.0, -1.0}), 0.5, floorSegment(), 10.0));
}

TEST(FaceTimeOfImpact, CheckingOnlyTheEndPositionWouldMissAHitOnTheSegment) {
  // The lecture's false negative: at the end of the move the centre is past the segment's end,
  // but at the time of impact (t = 1.5) it is at x = 0.75, on the segment.
  const auto t = faceTimeOfImpact(moving({0.0, 2.0}, {0.5, -1.0}), 0.5, floorSegment(), 3.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.5, 1e-15);
}

TEST(FaceTimeOfImpact, CentreWithinReachAndApproachingCollidesNow) {
  // The lecture's -r <= a < 0 rule: rounding left the ball 1e-12 inside.
  const auto t =
      faceTimeOfImpact(moving({0.0, 0.5 - 1e-12}, {0.0, -1.0}), 0.5, floorSegment(), 10.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t, 0.0);
}

TEST(FaceTimeOfImpact, SlowBounceThatFallsBackWithinTheStepIsCaught) {
  // Leaving the floor from (rounding-level) overlap at 0.1 m/s under g = 10: back at the same
  // gap when 0.1 t - 5 t^2 = 0, t = 0.02. Attempt 3 alone would let it sink.
  const auto t = faceTimeOfImpact(moving({0.0, 0.5 - 1e-13}, {0.0, 0.1}, {0.0, -10.0}), 0.5,
                                  floorSegment(), 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.02, 1e-15);
}

TEST(FaceTimeOfImpact, BallStillOnTheFaceCollidesOnlyIfSomethingPressesItIn) {
  // Touching, still, and not held: sliding along it, nothing; under g = 10 it sinks by 5 t^2,
  // and collides once that is kUnheldTouchDrift.
  EXPECT_FALSE(faceTimeOfImpact(moving({0.0, 0.5}, {0.3, 0.0}), 0.5, floorSegment(), 1.0));
  const auto t = faceTimeOfImpact(moving({0.0, 0.5}, {0.3, 0.0}, {0.0, -10.0}), 0.5,
                                  floorSegment(), 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, std::sqrt(kUnheldTouchDrift / 5.0), 1e-9 * *t);
}

TEST(FaceTimeOfImpact, CentreWithinReachButLeavingDoesNotCollide) {
  EXPECT_FALSE(faceTimeOfImpact(moving({0.0, 0.5 - 1e-12}, {0.0, 1.0}), 0.5, floorSegment(), 10.0));
}

TEST(CapTimeOfImpact, BallAlongTheLineHitsTheCapAsAZeroRadiusCircle) {
  // Centre at (3, 0) moving left; the cap at (1, 0) is reached when 3 - t - 1 = 0.5.
  const Motion relative = moving({3.0, 0.0}, {-1.0, 0.0}).relativeTo(moving({1.0, 0.0}, {0, 0}));
  const auto t = circleTimeOfImpact(relative, contactDistance(floorSegment(), 0.5), 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.5, 1e-15);
  EXPECT_FALSE(faceTimeOfImpact(moving({3.0, 0.0}, {-1.0, 0.0}), 0.5, floorSegment(), 10.0));
}

TEST(CapTimeOfImpact, OverlapOverTheFaceIsTheFacesNotTheCaps) {
  // Rounding leaves a ball sliding along the floor 1e-13 inside, 1e-7 before the end (1, 0) and
  // moving toward it: inside the cap's circle too (1e-14 + (0.5 - 1e-13)^2 < 0.25), but the
  // face is what it touches, and it does not approach the face. A cap impact now could never be
  // resolved along the face: the step would repeat it forever.
  const Motion sliding = moving({1.0 - 1e-7, 0.5 - 1e-13}, {1.0, 0.0});
  ASSERT_LT((sliding.position - Vec2(1.0, 0.0)).norm(), 0.5);
  EXPECT_FALSE(capTimeOfImpact(sliding, 0.5, floorSegment(), 1, 1.0));
  EXPECT_FALSE(faceTimeOfImpact(sliding, 0.5, floorSegment(), 1.0));
  // Past the end, the same overlap is the cap's.
  const auto t = capTimeOfImpact(moving({1.1, 0.45}, {-1.0, 0.0}), 0.5, floorSegment(), 1, 1.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t, 0.0);
}

TEST(CircleTimeOfImpact, TouchingContactThatStaysClosedIsNoImpactWhateverItsRoundingNoise) {
  // Touching, normal speed 1e-20 (noise), sliding round at 3 m/s and pulled in by exactly the
  // centripetal 3^2 / 2 m/s^2: the distance stays 2, and the roots of the noise are no impacts.
  const Motion sliding = moving({0.0, 2.0}, {3.0, 1e-20}, {0.0, -4.5});
  EXPECT_FALSE(circleTimeOfImpact(sliding, 2.0, 1.0));
}

TEST(CircleTimeOfImpact, TouchingContactPressedTogetherCollidesOnceClosedByTheUnheldDrift) {
  // As above but pulled in by 10 m/s^2: the distance closes as (10 - 4.5) t^2 / 2 (to terms in
  // t^4, here 1e-20 m), which reaches kUnheldTouchDrift at t = sqrt(2 drift / 5.5). A held
  // contact is never sought; one not held, which its accelerations close, must collide.
  const Motion pressed = moving({0.0, 2.0}, {3.0, 1e-20}, {0.0, -10.0});
  const auto t = circleTimeOfImpact(pressed, 2.0, 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, std::sqrt(2.0 * kUnheldTouchDrift / 5.5), 1e-9 * *t);
}

TEST(TimeOfFeatureChange, SlidingAlongTheFaceReachesTheEndAtDistanceOverSpeed) {
  Segment s;
  s.start = Vec2(0.0, 0.0);
  s.end = Vec2(4.0, 0.0);
  const Motion sliding{Vec2(1.0, 0.5), Vec2(2.0, 0.0), Vec2::Zero()};
  EXPECT_EQ(featureUnder(s, sliding.position, sliding.velocity), SegmentFeature::kFace);
  EXPECT_DOUBLE_EQ(*timeOfFeatureChange(sliding, s, 10.0), 1.5);
  EXPECT_FALSE(timeOfFeatureChange(sliding, s, 1.0).has_value());
  // On the perpendicular through the end, moving out: already over the cap, which it leaves
  // only if it comes back.
  const Motion leaving{Vec2(4.0, 0.5), Vec2(2.0, 0.0), Vec2(-1.0, 0.0)};
  EXPECT_EQ(featureUnder(s, leaving.position, leaving.velocity), SegmentFeature::kEndCap);
  EXPECT_DOUBLE_EQ(*timeOfFeatureChange(leaving, s, 10.0), 4.0);  // 2 t - t^2 / 2 = 0
  // Still on the perpendicular, but pulled outward: it leaves the face at once.
  const Motion pulled{Vec2(4.0, 0.5), Vec2::Zero(), Vec2(1.0, -1.0)};
  EXPECT_EQ(featureUnder(s, pulled.position, pulled.velocity), SegmentFeature::kFace);
  EXPECT_EQ(*timeOfFeatureChange(pulled, s, 10.0), 0.0);
}

TEST(FaceTimeOfImpact, ACentreCurvingRoundTheEndHitsTheFarFace) {
  // Found by fuzzing: the centre passes below the line beyond the end, then its parabola turns
  // back up into the underside. y = 0.3 - 2 t + 2 t^2 reaches -r = -0.1 again at
  // t = (2 + sqrt(0.8)) / 4, at x = 2.5 - t, over the face.
  Segment s;
  s.start = Vec2(0.0, 0.0);
  s.end = Vec2(2.0, 0.0);
  const Motion ball{Vec2(2.5, 0.3), Vec2(-1.0, -2.0), Vec2(0.0, 4.0)};
  EXPECT_NEAR(*faceTimeOfImpact(ball, 0.1, s, 1.0), (2.0 + std::sqrt(0.8)) / 4.0, 1e-15);
}
