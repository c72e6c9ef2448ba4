#include <cmath>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/polynomial.h"

using namespace ball_physics_sim::engine;

namespace {

// The crossing of p found over [lo, hi] is `expected`, to `tolerance`, and the last double at
// which p is still positive: a body placed there does not overlap.
void expectCrossingAt(const Polynomial& p, double lo, double hi, double expected,
                      double tolerance) {
  const auto t = firstDownCrossing(p, lo, hi);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, expected, tolerance);
  EXPECT_GT(p(*t), 0.0);
  EXPECT_LE(p(std::nextafter(*t, hi)), 0.0);
}

}  // namespace

TEST(QuadraticRoots, LectureExampleHasRootsHalfAndTwo) {
  // 2x^2 - 5x + 2 = 0: x = (5 -+ 3) / 4.
  const Roots r = quadraticRoots(2.0, -5.0, 2.0);
  ASSERT_EQ(r.count, 2);
  EXPECT_DOUBLE_EQ(r.t[0], 0.5);
  EXPECT_DOUBLE_EQ(r.t[1], 2.0);
}

TEST(QuadraticRoots, NegativeDiscriminantHasNoRealRoot) {
  EXPECT_EQ(quadraticRoots(1.0, 0.0, 1.0).count, 0);
}

TEST(QuadraticRoots, LinearWhenLeadingCoefficientIsZero) {
  const Roots r = quadraticRoots(0.0, 2.0, -3.0);
  ASSERT_EQ(r.count, 1);
  EXPECT_DOUBLE_EQ(r.t[0], 1.5);
}

TEST(QuadraticRoots, SmallRootKeepsItsDigitsDespiteCancellation) {
  // x^2 - 1e8 x + 1: the textbook (-b - sqrt(D)) / 2a would lose the small root 1e-8 to
  // cancellation; the stable form gives it to full precision.
  const Roots r = quadraticRoots(1.0, -1e8, 1.0);
  ASSERT_EQ(r.count, 2);
  EXPECT_NEAR(r.t[0], 1e-8, 1e-22);
  EXPECT_NEAR(r.t[1], 1e8, 1e-6);
}

TEST(FirstDownCrossing, QuarticWithFourRootsCrossesFirstAtOne) {
  // (t-1)(t-2)(t-3)(t-4) = t^4 - 10 t^3 + 35 t^2 - 50 t + 24.
  Polynomial p;
  p.c = {24.0, -50.0, 35.0, -10.0, 1.0};
  expectCrossingAt(p, 0.0, 10.0, 1.0, 1e-15);
}

TEST(FirstDownCrossing, QuarticCrossingAfterTheFirstTurnIsFound) {
  // (t-3)(t-4)(t^2+1): positive on [0, 3), first zero at 3, past two turning points of p'.
  Polynomial p;
  p.c = {12.0, -7.0, 13.0, -7.0, 1.0};
  const auto t = firstDownCrossing(p, 0.0, 5.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 3.0, 1e-14);
}

TEST(FirstDownCrossing, CrossingBeyondTheIntervalIsNone) {
  Polynomial p;
  p.c = {24.0, -50.0, 35.0, -10.0, 1.0};
  EXPECT_FALSE(firstDownCrossing(p, 0.0, 0.99));
}

TEST(FirstDownCrossing, PolynomialThatStaysPositiveNeverCrosses) {
  Polynomial p;  // (t - 1)^2 + 1
  p.c = {2.0, -2.0, 1.0, 0.0, 0.0};
  EXPECT_FALSE(firstDownCrossing(p, 0.0, 10.0));
}

TEST(FirstDownCrossing, NotPositiveAtTheStartIsNotACrossing) {
  Polynomial p;
  p.c = {-1.0, 1.0, 0.0, 0.0, 0.0};
  EXPECT_FALSE(firstDownCrossing(p, 0.0, 10.0));
}

TEST(FirstDownCrossing, DownwardParabolaCrossesAtItsLargerRoot) {
  // 4 - t^2, positive at 0, crosses down at 2 (its smaller root -2 lies in the past).
  Polynomial p;
  p.c = {4.0, 0.0, -1.0, 0.0, 0.0};
  const auto t = firstDownCrossing(p, 0.0, 5.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 2.0, 1e-15);
  EXPECT_GT(p(*t), 0.0);
}

TEST(FirstDownCrossing, RootOfRoundingSizedCoefficientsIsFoundWithoutWalkingEveryUlp) {
  // 3.9e-323 - 3.3e-16 t: the root near 1e-307 lies ~1e16 doubles below where the abc formula
  // puts it first; it is bisected, not walked to.
  Polynomial p;
  p.c = {3.9e-323, -3.3e-16, 0.0, 0.0, 0.0};
  const auto t = firstDownCrossing(p, 0.0, 1.0);
  ASSERT_TRUE(t);
  EXPECT_GT(p(*t), 0.0);
  EXPECT_LE(*t, 1e-306);
}

TEST(FirstDownCrossing, ConvexQuarticIsNarrowedToAdjacentDoubles) {
  // 1/2 - t^4 crosses down at 2^(-1/4), curving the same way all along: cuts at the chord alone
  // would keep one end and creep up on the root from the other.
  Polynomial p;
  p.c = {0.5, 0.0, 0.0, 0.0, -1.0};
  expectCrossingAt(p, 0.0, 2.0, std::pow(0.5, 0.25), 1e-15);
}

TEST(FirstDownCrossing, CrossingInAnIntervalAwayFromZeroIsFound) {
  // 2 - t^4 over [1, 3/2]: 1 at its start, crossing at 2^(1/4). (Over [0, 1/2] the same
  // coefficients would bound it above 2 - 1/16: the bound must be taken at the interval's start.)
  Polynomial p;
  p.c = {2.0, 0.0, 0.0, 0.0, -1.0};
  expectCrossingAt(p, 1.0, 1.5, std::pow(2.0, 0.25), 1e-15);
}

TEST(FirstDownCrossing, GapThatClosesByAHairIsFoundAndOneThatDoesNotIsNot) {
  // (t - 1)^2 (t^2 + 1) -+ 1e-10: dips 1e-10 below zero at t = 1 and crosses at
  // 1 - sqrt(5e-11) to first order, or stays 1e-10 above it. Far from zero at both ends, it is
  // not plainly positive between them, and the search decides.
  Polynomial closes;
  closes.c = {1.0 - 1e-10, -2.0, 2.0, -2.0, 1.0};
  expectCrossingAt(closes, 0.0, 2.0, 1.0 - std::sqrt(5e-11), 1e-9);
  Polynomial stays_open;
  stays_open.c = {1.0 + 1e-10, -2.0, 2.0, -2.0, 1.0};
  EXPECT_FALSE(firstDownCrossing(stays_open, 0.0, 2.0));
}

TEST(FirstDownCrossing, QuarticPlainlyPositiveOverTheIntervalNeverCrosses) {
  // (t^2 + 1)^2 over [0, 1/2]: at least 1 - (2 / 4 + 1 / 16) there by its coefficients.
  Polynomial p;
  p.c = {1.0, 0.0, 2.0, 0.0, 1.0};
  EXPECT_FALSE(firstDownCrossing(p, 0.0, 0.5));
}

TEST(RootBound, NoRootLiesBeyondCauchysBound) {
  // (t - 3)(t + 5)(t - 0.5) = t^3 + 1.5 t^2 - 16 t + 7.5: roots within 1 + 16.
  Polynomial p;
  p.c = {7.5, -16.0, 1.5, 1.0, 0.0};
  EXPECT_EQ(rootBound(p), 17.0);
  EXPECT_EQ(rootsBetween(p, -rootBound(p), rootBound(p)).count, 3);
  const Roots positive = positiveRoots(p);
  ASSERT_EQ(positive.count, 2);
  EXPECT_NEAR(positive.t[0], 0.5, 1e-15);
  EXPECT_NEAR(positive.t[1], 3.0, 1e-15);
  p.c = {2.0, 0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(rootBound(p), 0.0);  // a constant has no root
}
