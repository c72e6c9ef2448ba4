#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/resting_contact.h"

using namespace ball_physics_sim::engine;

namespace {

constexpr double g = 9.81;
const Vec2 kGravity(0.0, -g);

RestingContact onImmovable(std::size_t ball, Vec2 normal) {
  return {ball, std::nullopt, normal, 0.0};
}
RestingContact onBall(std::size_t ball, std::size_t other, Vec2 normal) {
  return {ball, other, normal.normalized(), 0.0};
}

}  // namespace

TEST(PushApart, BallOnAFloorIsHeldStillExactly) {
  const auto a = pushApart({kGravity}, {1.0}, {onImmovable(0, {0.0, 1.0})});
  EXPECT_EQ(a[0], Vec2::Zero());
}

TEST(PushApart, BallOnAFrictionlessSlopeAcceleratesAtGSinTheta) {
  const double theta = 0.4;
  const Vec2 n(-std::sin(theta), std::cos(theta));
  const auto a = pushApart({kGravity}, {1.0}, {onImmovable(0, n)});
  const Vec2 downhill = -Vec2(std::cos(theta), std::sin(theta));
  EXPECT_NEAR((a[0] - g * std::sin(theta) * downhill).norm(), 0.0, 1e-14);
}

TEST(PushApart, BallInAVIsHeldStill) {
  const Vec2 left = Vec2(1.0, 1.0).normalized(), right = Vec2(-1.0, 2.0).normalized();
  const auto a = pushApart({kGravity}, {1.0}, {onImmovable(0, left), onImmovable(0, right)});
  EXPECT_LE(a[0].norm(), 1e-13);
}

TEST(PushApart, BallUnderACeilingFallsFreely) {
  // The ceiling could only push down; gravity already pulls the ball away from it.
  const auto a = pushApart({kGravity}, {1.0}, {onImmovable(0, {0.0, -1.0})});
  EXPECT_EQ(a[0], kGravity);
}

TEST(PushApart, StackOfTwoOnAFloorIsHeldStill) {
  const auto a = pushApart({kGravity, kGravity}, {1.0, 0.5},
                           {onImmovable(0, {0.0, 1.0}), onBall(1, 0, {0.0, 1.0})});
  EXPECT_LE(a[0].norm(), 1e-13);
  EXPECT_LE(a[1].norm(), 1e-13);
}

TEST(PushApart, TopOfAFrictionlessPyramidSinksAtASeventhOfG) {
  // Equal balls of radius 1: two on the floor at x = -1 and 1, one on them at (0, sqrt 3), its
  // contacts 30 degrees from vertical. With N the normal force of each upper contact:
  // m a_top = m g - 2 N cos 30, m a_side = N sin 30 and a_top cos 30 = a_side sin 30 give
  // N = m g cos 30 / (1 + cos^2 30), a_top = g / 7 and a_side = sqrt(3) g / 7.
  const auto a = pushApart({kGravity, kGravity, kGravity}, {1.0, 1.0, 1.0},
                           {onImmovable(0, {0.0, 1.0}), onImmovable(1, {0.0, 1.0}),
                            onBall(2, 0, {1.0, std::sqrt(3.0)}), onBall(2, 1, {-1.0, std::sqrt(3.0)})});
  EXPECT_NEAR((a[2] - Vec2(0.0, -g / 7.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a[0] - Vec2(-std::sqrt(3.0) * g / 7.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a[1] - Vec2(std::sqrt(3.0) * g / 7.0, 0.0)).norm(), 0.0, 1e-12);
}

TEST(PushApart, CentripetalBiasLetsABallSlideRoundAnotherWithoutForce) {
  // Sliding over the top of a fixed ball fast enough (v^2 / d >= g) it leaves the surface:
  // the contact pushes nothing.
  RestingContact over_the_top = onImmovable(0, {0.0, 1.0});
  over_the_top.bias = 12.0;  // v^2 / d
  const auto a = pushApart({kGravity}, {1.0}, {over_the_top});
  EXPECT_EQ(a[0], kGravity);
}

TEST(PushApart, OnVelocitiesItIsAPerfectlyInelasticImpactOfAllContactsAtOnce) {
  // Moving into a corner of floor and wall: both normal components stop, nothing else.
  const auto corner = pushApart({Vec2(-1.0, -2.0)}, {1.0},
                                {onImmovable(0, {0.0, 1.0}), onImmovable(0, {1.0, 0.0})});
  EXPECT_EQ(corner[0], Vec2::Zero());
  const auto sliding = pushApart({Vec2(3.0, -0.5)}, {1.0}, {onImmovable(0, {0.0, 1.0})});
  EXPECT_EQ(sliding[0], Vec2(3.0, 0.0));
}

TEST(PushApart, ImmovableBodiesAreNotPushed) {
  // A resting ball has inverse mass 0: the falling one stops on it and it stays.
  const auto a = pushApart({kGravity, Vec2::Zero()}, {1.0, 0.0}, {onBall(0, 1, {0.0, 1.0})});
  EXPECT_EQ(a[0], Vec2::Zero());
  EXPECT_EQ(a[1], Vec2::Zero());
}

TEST(PushApart, BallFallingIntoASlotBetweenNearlyOppositeWallsStopsAtOnce) {
  // Two fixed bodies with normals 2.4e-5 rad from horizontal: Gauss-Seidel would need billions
  // of sweeps; the exact cone projection stops the ball (the only allowed rates point up).
  const double e = 2.4e-5;
  const auto v = pushApart({Vec2(8.8e-5, -1.82)}, {1.0},
                           {onImmovable(0, Vec2(-1.0, e).normalized()),
                            onImmovable(0, Vec2(1.0, e).normalized())});
  EXPECT_LE(v[0].norm(), 1e-12);
}

TEST(PushApart, OnPositionsItSeparatesAnOverlapUntilTheyJustTouch) {
  // Balls of radius 1 at x = 0 (fixed) and x = 1.999 (free): bias -2 asks n . (p - q) >= 2.
  RestingContact overlap = onBall(1, 0, {1.0, 0.0});
  overlap.bias = -2.0;
  const auto p = pushApart({Vec2(0.0, 0.0), Vec2(1.999, 0.0)}, {0.0, 1.0}, {overlap});
  EXPECT_EQ(p[0], Vec2(0.0, 0.0));
  EXPECT_NEAR(p[1].x(), 2.0, 1e-15);
}

TEST(PushApart, ALightBallWedgedUnderAHeavyOneInAVIsHeldStillExactly) {
  // A 0.07 kg ball in a V of two walls, an 8.5 kg ball resting on it and on a slope: all held
  // still. Gauss-Seidel alone stalls here (still 0.02 m/s^2 into a wall after its thousand
  // sweeps); the direct solve of the island is exact to rounding.
  const RestingContact left = onImmovable(0, Vec2(1.0, 0.35).normalized());
  const RestingContact right = onImmovable(0, Vec2(-1.0, 0.35).normalized());
  const RestingContact heavy_on_light = onBall(1, 0, Vec2(0.3, 1.0));
  const RestingContact heavy_on_slope = onImmovable(1, Vec2(-0.6, 1.0).normalized());
  std::vector<double> pushes;
  const auto a = pushApart({kGravity, kGravity}, {1.0 / 0.07, 1.0 / 8.5},
                           {left, right, heavy_on_light, heavy_on_slope}, &pushes);
  EXPECT_LE(a[0].norm(), 1e-12);
  EXPECT_LE(a[1].norm(), 1e-12);
  for (double push : pushes) EXPECT_GT(push, 0.0);
}

TEST(PushApart, BallsWedgedBetweenTwoWallsUnderSlantedGravityAreHeldStill) {
  // A 1000 kg ball in a box's left corner, a 1 kg ball against the right wall touching it, and
  // a 1 kg ball on both, under gravity slanted towards the right wall: all three held still.
  // Wall, ball, ball, wall is a redundant chain: rounding leaves the left wall's contact open
  // or closed by 1e-14. Pivoting decided on pushes refined against the exact equations, which
  // that rounding made -200 there: it took the contact in and let it go again until its bound
  // ran out, and the heavy ball sank into the light one at 0.11 m/s^2. (Held still to 1e-14
  // here; normals a unit in the last place different leave 4e-10, the regularization's.)
  const Vec2 slanted(0.3, -g);
  const std::vector<RestingContact> contacts{
      onImmovable(0, {0.0, 1.0}),  onImmovable(0, {1.0, 0.0}), onImmovable(1, {0.0, 1.0}),
      onImmovable(1, {-1.0, 0.0}), onBall(1, 0, {1.0, 0.0}),   onBall(2, 0, {0.5, std::sqrt(0.75)}),
      onBall(2, 1, {-0.5, std::sqrt(0.75)})};
  const auto a = pushApart({slanted, slanted, slanted}, {1e-3, 1.0, 1.0}, contacts);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_LE(a[i].norm(), 1e-9) << i;
}

TEST(PushApart, AColumnOfBallsIsHeldStillEachContactCarryingTheWeightAbove) {
  // Gauss-Seidel's error shrinks by a constant factor a sweep, the closer to 1 the taller the
  // column: alone, it would not reach rounding within its sweeps. Unit masses: the push under
  // ball k carries the n - k balls from it up, (n - k) g. Twelve balls are solved with dense
  // matrices, a hundred with sparse ones.
  for (const std::size_t n : {12, 100}) {
    std::vector<RestingContact> contacts{onImmovable(0, {0.0, 1.0})};
    for (std::size_t k = 1; k < n; ++k) contacts.push_back(onBall(k, k - 1, {0.0, 1.0}));
    std::vector<double> pushes;
    const auto a = pushApart(std::vector<Vec2>(n, kGravity), std::vector<double>(n, 1.0),
                             contacts, &pushes);
    // Rounding grows with the weight carried.
    const double taller = static_cast<double>(n) / 12.0;
    for (std::size_t k = 0; k < n; ++k) {
      EXPECT_LE(a[k].norm(), 1e-13 * taller) << n << " " << k;
      EXPECT_NEAR(pushes[k], static_cast<double>(n - k) * g, 1e-12 * taller) << n << " " << k;
    }
  }
}

TEST(PushApart, FromAnyPushesToStartWithItReachesTheSameRates) {
  // The frictionless pyramid again (its top sinks at g / 7), started from its own solution and
  // from pushes far off: warm starts change the work, not the answer.
  const std::vector<Vec2> free{kGravity, kGravity, kGravity};
  const std::vector<double> inverse_masses{1.0, 1.0, 1.0};
  const std::vector<RestingContact> pyramid{
      onImmovable(0, {0.0, 1.0}), onImmovable(1, {0.0, 1.0}), onBall(2, 0, {1.0, std::sqrt(3.0)}),
      onBall(2, 1, {-1.0, std::sqrt(3.0)})};
  std::vector<double> solved;
  const auto cold = pushApart(free, inverse_masses, pyramid, &solved);
  for (std::vector<double> start : {solved, std::vector<double>{50.0, 0.0, 0.0, 20.0}}) {
    const auto warm = pushApart(free, inverse_masses, pyramid, &start);
    for (std::size_t i = 0; i < free.size(); ++i) EXPECT_NEAR((warm[i] - cold[i]).norm(), 0.0, 1e-13);
    EXPECT_NEAR((warm[2] - Vec2(0.0, -g / 7.0)).norm(), 0.0, 1e-12);
  }
}

TEST(PushApart, AColumnSolvedForOnePullAfterAnotherFromItsLastPushesIsExactEachTime) {
  // A column of unit masses on a floor, contact k under ball k, solved for one pull after
  // another, each from the pushes last found for it (or, new, for the pull before), where
  // other contacts push, even as many (in a column Gauss-Seidel could not make up for wrong
  // pivots). One ball is pulled up at `up` g, the others fall at g. From the contact that opens
  // up, the balls rise at g; the pushes below carry the balls under it, and the one above it,
  // if any, presses the risen balls together by `above` g.
  struct Pull {
    std::size_t ball;  // n: none
    double up;
    std::size_t opens;  // n: none
    double above;
  };
  for (const std::size_t n : {60, 100}) {
    std::vector<RestingContact> column{onImmovable(0, {0.0, 1.0})};
    for (std::size_t k = 1; k < n; ++k) column.push_back(onBall(k, k - 1, {0.0, 1.0}));
    const std::vector<double> inverse_masses(n, 1.0);
    // The top ball rising alone; the two at the top rising together (as many contacts push);
    // gravity alone.
    const std::vector<Pull> pulls{Pull{n - 1, 1.0, n - 1, 0.0}, Pull{n - 2, 3.0, n - 2, 2.0},
                                  Pull{n, 0.0, n, 0.0}};
    std::vector<std::vector<double>> found(pulls.size());
    std::vector<double> last;
    const double taller = static_cast<double>(n) / 12.0;  // rounding grows with the weight
    for (const std::size_t p : {0, 1, 0, 2, 1}) {
      const Pull& pull = pulls[p];
      std::vector<Vec2> free(n, kGravity);
      if (pull.ball < n) free[pull.ball] = Vec2(0.0, pull.up * g);
      std::vector<double>& pushes = found[p];
      if (pushes.empty()) pushes = last;
      const auto a = pushApart(free, inverse_masses, column, &pushes);
      last = pushes;
      ASSERT_EQ(pushes.size(), n);
      for (std::size_t k = 0; k < n; ++k) {
        const Vec2 rate = k >= pull.opens ? Vec2(0.0, g) : Vec2::Zero();
        const double push = k < pull.opens ? static_cast<double>(pull.opens - k) * g
                                           : (k == pull.opens ? 0.0 : pull.above * g);
        EXPECT_LE((a[k] - rate).norm(), 1e-13 * taller) << n << " " << p << " " << k;
        EXPECT_NEAR(pushes[k], push, 1e-12 * taller) << n << " " << p << " " << k;
      }
    }
  }
}

TEST(PushApart, TwoColumnsOfDifferentMassesAreEachHeldStill) {
  // Two columns of n balls side by side, the second twice as heavy: two islands whose contacts
  // all push, the same ones by their place in the island, solved with one factoring workspace.
  // Solved twice, the second time warm from the first's pushes, each is held still and each
  // push carries the weight above it, (n - k) m g.
  const std::size_t n = 60;
  std::vector<RestingContact> contacts;
  std::vector<double> inverse_masses;
  for (const double mass : {1.0, 2.0}) {
    const std::size_t first = inverse_masses.size();
    contacts.push_back(onImmovable(first, {0.0, 1.0}));
    for (std::size_t k = 1; k < n; ++k)
      contacts.push_back(onBall(first + k, first + k - 1, {0.0, 1.0}));
    inverse_masses.insert(inverse_masses.end(), n, 1.0 / mass);
  }
  std::vector<double> pushes;
  const double taller = static_cast<double>(n) / 12.0;  // rounding grows with the weight
  for (int solve = 0; solve < 2; ++solve) {
    const auto a = pushApart(std::vector<Vec2>(2 * n, kGravity), inverse_masses, contacts, &pushes);
    for (std::size_t i = 0; i < 2 * n; ++i) {
      const double mass = i < n ? 1.0 : 2.0;
      EXPECT_LE(a[i].norm(), 2e-13 * taller) << solve << " " << i;
      EXPECT_NEAR(pushes[i], static_cast<double>(n - i % n) * mass * g, 2e-12 * taller)
          << solve << " " << i;
    }
  }
}

TEST(PushApart, AFloorAndAWallShareTheLoadOfABallPressedIntoTheirCorner) {
  // Pushed left at 3 into a 45-degree wall and down at g onto a floor: the ball stops, the
  // wall pushes 3 sqrt(2) (its push's horizontal part takes the 3), the floor the g - 3 left.
  const Vec2 wall = Vec2(1.0, 1.0) / std::sqrt(2.0);
  std::vector<double> pushes;
  const auto a = pushApart({Vec2(-3.0, -g)}, {1.0},
                           {onImmovable(0, {0.0, 1.0}), onImmovable(0, wall)}, &pushes);
  EXPECT_LE(a[0].norm(), 1e-14);
  EXPECT_NEAR(pushes[0], g - 3.0, 1e-14);
  EXPECT_NEAR(pushes[1], 3.0 * std::sqrt(2.0), 1e-14);
}

TEST(PushApart, RandomIslandsSolvedColdMeetComplementarity) {
  // Balls touching each other and fixed bodies along random normals, at random rates, solved
  // from no pushes: every closing contact of a ball stack or wedge flips at once; where that
  // overshoots, single pivots finish. Whatever the path, no gap closes, and a contact pushes
  // only where its gap stays shut.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), mass(0.2, 5.0);
  for (int trial = 0; trial < 500; ++trial) {
    const std::size_t balls = 2 + trial % 7;
    std::vector<Vec2> free;
    std::vector<double> inverse_masses;
    for (std::size_t i = 0; i < balls; ++i) {
      free.emplace_back(10.0 * unit(rng), 10.0 * unit(rng));
      inverse_masses.push_back(1.0 / mass(rng));
    }
    // Two balls touch at one point, along one normal; a ball may touch any number of fixed
    // bodies.
    std::vector<RestingContact> contacts;
    std::set<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t k = 0; k < 2 * balls; ++k) {
      const std::size_t ball = rng() % balls, other = rng() % balls;
      const Vec2 normal = Vec2(unit(rng), unit(rng)).normalized();
      if (other == ball)
        contacts.push_back(onImmovable(ball, normal));
      else if (pairs.insert(std::minmax(ball, other)).second)
        contacts.push_back(onBall(ball, other, normal));
    }
    std::vector<double> pushes;
    const auto a = pushApart(free, inverse_masses, contacts, &pushes);
    // Rates of up to 14, to rounding.
    const double tolerance = 1e-12;
    // The rates are what the pushes make of the free ones.
    std::vector<Vec2> pushed = free;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const RestingContact& c = contacts[k];
      pushed[c.ball] += pushes[k] * inverse_masses[c.ball] * c.normal;
      if (c.other) pushed[*c.other] -= pushes[k] * inverse_masses[*c.other] * c.normal;
    }
    for (std::size_t i = 0; i < balls; ++i)
      EXPECT_LE((a[i] - pushed[i]).norm(), tolerance) << trial << " ball " << i;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const RestingContact& c = contacts[k];
      const double opening = c.normal.dot(c.other ? Vec2(a[c.ball] - a[*c.other]) : a[c.ball]);
      EXPECT_GE(pushes[k], 0.0) << trial << " contact " << k;
      EXPECT_GE(opening, -tolerance) << trial << " contact " << k;
      const double rate = pushes[k] * (inverse_masses[c.ball] +
                                       (c.other ? inverse_masses[*c.other] : 0.0));
      if (rate > tolerance) {
        EXPECT_LE(opening, tolerance) << trial << " contact " << k;
      }
    }
  }
}

TEST(ContactIslands, AreTheContactsConnectedThroughBallsThatMove) {
  // Two stacks of two on a floor, and a resting ball (inverse mass 0) that both upper balls
  // lean on: it pushes without being pushed, so it joins nothing. A contact of a resting ball
  // is in no island.
  const std::vector<double> inverse_masses{1.0, 1.0, 1.0, 1.0, 0.0};
  const std::vector<RestingContact> contacts{
      onImmovable(0, {0.0, 1.0}), onBall(1, 0, {0.0, 1.0}), onImmovable(2, {0.0, 1.0}),
      onBall(3, 2, {0.0, 1.0}),   onBall(1, 4, {-1.0, 1.0}), onBall(3, 4, {1.0, 1.0}),
      onImmovable(4, {0.0, 1.0})};
  const auto islands = contactIslands(contacts, inverse_masses);
  ASSERT_EQ(islands.size(), 2u);
  EXPECT_EQ(islands[0], (std::vector<std::size_t>{0, 1, 4}));
  EXPECT_EQ(islands[1], (std::vector<std::size_t>{2, 3, 5}));
}

TEST(CurvedContactLifetime, IsTheTimeInWhichThePathDriftsByTheHeldDrift) {
  const double R = 0.5, v = 2.0, horizon = 1.0;
  // Sliding round a circle of radius R at speed v: the jerk is v^3 / R^2, the drift from the
  // true motion jerk t^3 / 6 (sooner than the distance leaves R, by v^4 t^4 / (8 R^3)).
  const Motion sliding{Vec2(0.0, R), Vec2(v, 0.0), Vec2(0.0, -v * v / R)};
  EXPECT_NEAR(curvedContactLifetime(sliding, horizon),
              std::cbrt(6.0 * kHeldDrift * R * R / (v * v * v)), 1e-15);
  // Setting off from rest along the circle (a pendulum at its turning point): no jerk, but the
  // distance grows by a^2 t^4 / (8 R).
  const double a = 3.0;
  EXPECT_NEAR(curvedContactLifetime({Vec2(0.0, R), Vec2::Zero(), Vec2(a, 0.0)}, horizon),
              std::pow(8.0 * R * kHeldDrift / (a * a), 0.25), 1e-9);
  // Held still: nothing drifts until the horizon.
  EXPECT_EQ(curvedContactLifetime({Vec2(0.0, R), Vec2::Zero(), Vec2::Zero()}, horizon), horizon);
}
