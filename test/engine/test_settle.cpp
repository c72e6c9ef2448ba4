#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/settle.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using namespace ball_physics_sim::engine::test;

namespace {

constexpr double kH = kFrameStep;

// A contact of ball 0 with a floor below it, whose gap may close at `bias` over the settle.
RestingContact floorContact(double bias = 0.0) { return {0, std::nullopt, Vec2(0, 1), bias, 0}; }

}  // namespace

TEST(Settle, ABallOnTheFloorIsHeldUpWithTheImpulseOfItsWeightOverTheStretch) {
  std::vector<std::array<double, 2>> impulses;
  const Settled s = settleTogether({ball({0, 0.5}, {0, -kG * kH}, 0.5, 2.0)}, {0.5},
                                   {floorContact()}, {0.3}, kH, &impulses);
  EXPECT_NEAR(s.velocities[0].norm(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(s.spins[0], 0.0);
  EXPECT_NEAR(impulses[0][0], 2.0 * kG * kH, 1e-14);
  EXPECT_DOUBLE_EQ(impulses[0][1], 0.0);
}

TEST(Settle, AFallingBallClosesItsGapToTheFloorNoMore) {
  // 0.1 m above the floor at 3 m/s: over the stretch it may close 0.1 m, at 0.1 / h m/s.
  const double bias = 0.1 / kH;
  const Settled s =
      settleTogether({ball({0, 0.6}, {0, -3.0})}, {1.0}, {floorContact(bias)}, {0.0}, kH);
  EXPECT_NEAR(s.velocities[0].y(), -std::min(3.0, bias), 1e-12);
  const Settled slow =
      settleTogether({ball({0, 0.6}, {0, -1.0})}, {1.0}, {floorContact(bias)}, {0.0}, kH);
  EXPECT_DOUBLE_EQ(slow.velocities[0].y(), -1.0);  // its gap closes less: untouched
}

TEST(Settle, ASlidingBallIsSlowedAndSpunByFrictionAtTheConesEdge) {
  // Pressed by its weight over h, friction takes mu m g h of momentum from a ball sliding at
  // 1 m/s, and turns it by mu g h / (k r) (a solid ball, k = 2/5).
  const double mu = 0.3, r = 0.5;
  const Settled s =
      settleTogether({ball({0, r}, {1.0, -kG * kH}, r)}, {1.0}, {floorContact()}, {mu}, kH);
  EXPECT_NEAR(s.velocities[0].x(), 1.0 - mu * kG * kH, 1e-14);
  EXPECT_NEAR(s.velocities[0].y(), 0.0, 1e-15);
  EXPECT_NEAR(s.spins[0], -mu * kG * kH / (0.4 * r), 1e-13);
}

TEST(Settle, ASlowlySlidingBallIsGrippedIntoRolling) {
  // Within the cone, friction stops the slip: v (1 - k / (1 + k)) = v / (1 + k) rolling, spin
  // -v / ((1 + k) r).
  const double v = 1e-3, r = 0.5;
  const Settled s =
      settleTogether({ball({0, r}, {v, -kG * kH}, r)}, {1.0}, {floorContact()}, {0.3}, kH);
  EXPECT_NEAR(s.velocities[0].x(), v / 1.4, 1e-16);
  EXPECT_NEAR(s.spins[0], -v / (1.4 * r), 1e-16);
  EXPECT_NEAR(s.velocities[0].x() + r * s.spins[0], 0.0, 1e-17);  // rolling: no slip
}

TEST(Settle, TwoBallsMeetingHeadOnMoveOnTogetherWithTheirMomentum) {
  // Perfectly inelastic: (m1 v1 + m2 v2) / (m1 + m2) = (1 * 2 + 3 * -1) / 4.
  const Settled s = settleTogether({ball({0, 0}, {2, 0}), ball({1, 0}, {-1, 0}, 0.5, 3.0)},
                                   {1.0, 1.0 / 3.0}, {{0, 1, Vec2(-1, 0), 0.0, 1}}, {0.0}, kH);
  EXPECT_NEAR(s.velocities[0].x(), -0.25, 1e-15);
  EXPECT_NEAR(s.velocities[1].x(), -0.25, 1e-15);
}

TEST(Settle, AResolvedPileStartedFromItsImpulsesIsLeftStill) {
  // Three balls stacked on a floor: the floor holds up 3 m g h, the middle contact 2 m g h,
  // the top one m g h. Started from those impulses, the settle changes nothing.
  std::vector<Ball> balls;
  for (int i = 0; i < 3; ++i) balls.push_back(ball({0, 0.5 + i}, {0, -kG * kH}));
  const std::vector<RestingContact> contacts{
      floorContact(), {1, 0, Vec2(0, 1), 0.0, 1}, {2, 1, Vec2(0, 1), 0.0, 2}};
  std::vector<std::array<double, 2>> impulses{
      {3 * kG * kH, 0.0}, {2 * kG * kH, 0.0}, {kG * kH, 0.0}};
  const Settled s = settleTogether(balls, {1.0, 1.0, 1.0}, contacts, {0.3, 0.3, 0.3}, kH,
                                   &impulses);
  for (const Vec2& v : s.velocities) EXPECT_NEAR(v.norm(), 0.0, 1e-15);
  EXPECT_NEAR(impulses[0][0], 3 * kG * kH, 1e-14);
  EXPECT_NEAR(impulses[2][0], kG * kH, 1e-14);
}

TEST(Settle, EachContactHoldsUpTheWeightAboveItWhateverOrderTheSweepsTakeItIn) {
  // Two stacks of three, of 1 and 2 kg balls, their contacts given bottom up in turn: the
  // sweeps put off those sharing a ball with one just before, and each contact's push is still
  // its own, the weight above it over the stretch, n m g h. (To 1e-8: the rounds end once no gap
  // closes past its allowance, and the round that gets there leaves the pushes that near.)
  std::vector<Ball> balls;
  for (int i = 0; i < 3; ++i) {
    balls.push_back(ball({0, 0.5 + i}, {0, -kG * kH}));
    balls.push_back(ball({10, 0.5 + i}, {0, -kG * kH}, 0.5, 2.0));
  }
  std::vector<RestingContact> contacts{{0, std::nullopt, Vec2(0, 1), 0.0, 0},
                                       {1, std::nullopt, Vec2(0, 1), 0.0, 0}};
  for (std::size_t i = 2; i < 6; ++i) contacts.push_back({i, i - 2, Vec2(0, 1), 0.0, i});
  const std::vector<double> weights_above{3.0, 6.0, 2.0, 4.0, 1.0, 2.0};  // n m
  std::vector<std::array<double, 2>> impulses;
  const Settled s = settleTogether(balls, {1.0, 0.5, 1.0, 0.5, 1.0, 0.5}, contacts,
                                   std::vector<double>(6, 0.3), kH, &impulses);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    EXPECT_NEAR(s.pushes[k], weights_above[k] * kG * kH, 1e-8) << k;
    EXPECT_DOUBLE_EQ(impulses[k][0], s.pushes[k]) << k;
  }
  for (const Vec2& v : s.velocities) EXPECT_NEAR(v.norm(), 0.0, 1e-8);
}

TEST(Settle, AContactLeftOutOfARoundForOpeningFastIsSweptOnceAPushClosesIt) {
  // A 1 kg ball leaving the floor at 1 m/s: that contact opens far too fast to take a push, and
  // the first round leaves it out. A 3 kg ball coming down on it at 2 m/s takes it along at
  // (1 - 6) / 4 m/s, into the floor; the next round sweeps the floor's contact too, and both
  // stop: the floor takes the 5 N s they carried down, the balls' contact the 6 of the upper
  // (to 1e-8, as the round that gets within the allowance leaves them).
  const std::vector<RestingContact> contacts{floorContact(), {1, 0, Vec2(0, 1), 0.0, 1}};
  const Settled s = settleTogether({ball({0, 0.5}, {0, 1.0}), ball({0, 1.5}, {0, -2.0}, 0.5, 3.0)},
                                   {1.0, 1.0 / 3.0}, contacts, {0.0, 0.0}, kH);
  EXPECT_NEAR(s.velocities[0].norm(), 0.0, 1e-8);
  EXPECT_NEAR(s.velocities[1].norm(), 0.0, 1e-8);
  EXPECT_NEAR(s.pushes[0], 5.0, 1e-8);
  EXPECT_NEAR(s.pushes[1], 6.0, 1e-8);
}

TEST(Settle, AnOverlapPastWhatASettleMayLeaveOpensByAFifthOfItNoFasterThanTheMostOpeningSpeed) {
  // A gap may close entirely over the stretch; an overlap opens kOverlapRecovery of itself.
  EXPECT_DOUBLE_EQ(settleBias(0.1, kH, true), 0.1 / kH);
  EXPECT_DOUBLE_EQ(settleBias(-1e-5, kH, true), -kOverlapRecovery * 1e-5 / kH);
  EXPECT_DOUBLE_EQ(settleBias(-1.0, kH, true), -kMostOpeningSpeed);
  // Not to open, it closes no further.
  EXPECT_DOUBLE_EQ(settleBias(0.1, kH, false), 0.1 / kH);
  EXPECT_DOUBLE_EQ(settleBias(-1e-5, kH, false), 0.0);
  // A ball at rest on the floor, sunk 1e-5 m into it, is pushed out at that rate.
  const Settled s = settleTogether({ball({0, 0.5 - 1e-5}, {0, -kG * kH})}, {1.0},
                                   {floorContact(settleBias(-1e-5, kH, true))}, {0.0}, kH);
  EXPECT_NEAR(s.velocities[0].y(), kOverlapRecovery * 1e-5 / kH, 1e-15);
}

TEST(Settle, AColumnOfTenBallsOnAFloorSinksByNoMoreThanASettleMayLeave) {
  // Gauss-Seidel passes a push down a column a ball a sweep: its rounds go on until every gap
  // closes by kSettleOverlap of a radius at most.
  const double r = 0.5;
  std::vector<Ball> balls;
  std::vector<RestingContact> contacts{floorContact()};
  for (std::size_t i = 0; i < 10; ++i) {
    balls.push_back(ball({0, r + 2.0 * r * i}, {0, -kG * kH}, r));
    if (i > 0) contacts.push_back({i, i - 1, Vec2(0, 1), 0.0, i});
  }
  const Settled s = settleTogether(balls, std::vector<double>(10, 1.0), contacts,
                                   std::vector<double>(10, 0.3), kH);
  EXPECT_GE(s.velocities[0].y() * kH, -kSettleOverlap * r);
  for (std::size_t i = 1; i < 10; ++i)
    EXPECT_GE((s.velocities[i].y() - s.velocities[i - 1].y()) * kH, -kSettleOverlap * r) << i;
}

TEST(Settle, AColumnOfAHundredBallsLandingOnAFloorStopsInOneSettle) {
  // Sweeps pass the floor's push up such a column a ball a sweep, and its load down it as
  // slowly, listed from the top: far too slowly for the rounds, until the pushing contacts are
  // solved together before the last.
  const double r = 0.5;
  const std::size_t n = 100;
  std::vector<Ball> balls;
  std::vector<RestingContact> contacts;
  for (std::size_t i = 0; i < n; ++i) balls.push_back(ball({0, r + 2.0 * r * i}, {0, -1.0}, r));
  for (std::size_t i = n - 1; i > 0; --i) contacts.push_back({i, i - 1, Vec2(0, 1), 0.0, i});
  contacts.push_back(floorContact());
  const Settled s = settleTogether(balls, std::vector<double>(n, 1.0), contacts,
                                   std::vector<double>(n, 0.0), kH);
  EXPECT_GE(s.velocities[0].y() * kH, -kSettleOverlap * r);
  for (std::size_t i = 1; i < n; ++i)
    EXPECT_GE((s.velocities[i].y() - s.velocities[i - 1].y()) * kH, -kSettleOverlap * r) << i;
  // No push lifts the column either: it ends as it would closing every gap by no more.
  for (std::size_t i = 0; i < n; ++i) EXPECT_LE(s.velocities[i].y(), 1e-6) << i;
}

// A packed, jittered pile of balls of two masses, `rows` rows of 12, its contacts bottom up as
// the world gives them, each pair's friction `friction(i)` for ball i.
struct JitteredPile {
  std::vector<Ball> balls;
  std::vector<double> inverse_masses;
  std::vector<RestingContact> contacts;
  std::vector<double> frictions;
};
template <typename Friction>
JitteredPile jitteredPile(Friction friction, int rows = 16) {
  JitteredPile pile;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02), radius(0.46, 0.5);
  for (int row = 0; row < rows; ++row)
    for (int column = 0; column < 12; ++column) {
      const Vec2 at(column + 0.5 * (row % 2) + jitter(random), 0.5 + 0.87 * row + jitter(random));
      const double mass = (row + column) % 3 == 0 ? 2.0 : 1.0;
      pile.balls.push_back(
          ball(at, {jitter(random), -kG * kH + jitter(random)}, radius(random), mass));
      pile.inverse_masses.push_back(1.0 / mass);
    }
  const std::vector<Ball>& balls = pile.balls;
  const auto touching = [&](std::size_t i, std::optional<std::size_t> other, Vec2 normal,
                            double gap) {
    if (gap > 0.1) return;
    const double smaller =
        other ? std::min(balls[i].radius, balls[*other].radius) : balls[i].radius;
    pile.contacts.push_back({i, other, normal,
                             settleBias(gap + kSettleOverlap * smaller, kH, true),
                             other ? *other : balls.size()});
    pile.frictions.push_back(friction(i));
  };
  for (std::size_t i = 0; i < balls.size(); ++i) {
    touching(i, std::nullopt, Vec2(0, 1), balls[i].position.y() - balls[i].radius);
    for (std::size_t j = 0; j < i; ++j) {
      const Vec2 apart = balls[i].position - balls[j].position;
      touching(i, j, apart.normalized(), apart.norm() - balls[i].radius - balls[j].radius);
    }
  }
  return pile;
}

TEST(Settle, SweepingTwoContactsAtATimeGivesTheSameResultsToTheBitAsFour) {
  // Rough and smooth balls (sweeps with friction), and smooth ones alone (without): a processor
  // without AVX2 sweeps them two contacts at a time.
  if (!sweepsFourAtATime()) GTEST_SKIP() << "no AVX2 here: both would sweep two at a time";
  for (const double mu : {0.3, 0.0}) {
    const JitteredPile pile = jitteredPile([&](std::size_t i) { return i % 2 == 0 ? mu : 0.0; });
    ASSERT_GT(pile.contacts.size(), 400u);
    std::vector<std::array<double, 2>> four_impulses, two_impulses;
    const Settled four = settleTogether(pile.balls, pile.inverse_masses, pile.contacts,
                                        pile.frictions, kH, &four_impulses, SweepLanes::kMost);
    const Settled two = settleTogether(pile.balls, pile.inverse_masses, pile.contacts,
                                       pile.frictions, kH, &two_impulses, SweepLanes::kTwo);
    for (std::size_t i = 0; i < pile.balls.size(); ++i) {
      EXPECT_EQ(four.velocities[i], two.velocities[i]) << mu << " " << i;
      EXPECT_EQ(four.spins[i], two.spins[i]) << mu << " " << i;
    }
    EXPECT_EQ(four_impulses, two_impulses) << mu;
  }
}

TEST(Settle, ScratchKeptFromALargerSettleGivesTheSameResultsToTheBitAsStorageOfItsOwn) {
  // Storage kept from settle to settle holds the last one's rows, blocks and rates, rough and
  // smooth: a settle of a smaller pile after a larger one starts from none of them, two
  // contacts at a time or as many as the processor takes.
  const JitteredPile large = jitteredPile([](std::size_t i) { return i % 3 == 0 ? 0.0 : 0.5; });
  const JitteredPile small = jitteredPile([](std::size_t i) { return i % 2 == 0 ? 0.3 : 0.0; }, 8);
  for (const SweepLanes lanes : {SweepLanes::kMost, SweepLanes::kTwo}) {
    SettleScratch scratch;
    for (const SweepLanes before : {SweepLanes::kMost, SweepLanes::kTwo})
      settleTogether(large.balls, large.inverse_masses, large.contacts, large.frictions, kH,
                     nullptr, before, &scratch);
    std::vector<std::array<double, 2>> kept_impulses, own_impulses;
    const Settled kept = settleTogether(small.balls, small.inverse_masses, small.contacts,
                                        small.frictions, kH, &kept_impulses, lanes, &scratch);
    const Settled own = settleTogether(small.balls, small.inverse_masses, small.contacts,
                                       small.frictions, kH, &own_impulses, lanes);
    ASSERT_GT(kept.sweeps, 0);
    EXPECT_EQ(kept.sweeps, own.sweeps);
    EXPECT_EQ(kept.velocities, own.velocities);
    EXPECT_EQ(kept.spins, own.spins);
    EXPECT_EQ(kept.pushes, own.pushes);
    EXPECT_EQ(kept_impulses, own_impulses);
  }
}

TEST(Settle, ThePilesMomentumAndSpinsChangeByTheImpulsesFound) {
  // The conjugate gradient moves each ball as it moves the impulses of its contacts: the balls'
  // momentum changes by the floor's impulses (the pushes between balls cancel out), and each
  // ball's spin by its contacts' friction, k m r dw = -(the sum of their friction impulses), to
  // rounding. Rough and smooth balls, and smooth ones alone.
  for (const double mu : {0.3, 0.0}) {
    const JitteredPile pile = jitteredPile([&](std::size_t i) { return i % 2 == 0 ? mu : 0.0; });
    std::vector<std::array<double, 2>> impulses;
    const Settled s = settleTogether(pile.balls, pile.inverse_masses, pile.contacts,
                                     pile.frictions, kH, &impulses);
    Vec2 gained = Vec2::Zero(), floor = Vec2::Zero();
    std::vector<double> gripped(pile.balls.size(), 0.0);
    for (std::size_t i = 0; i < pile.balls.size(); ++i)
      gained += (s.velocities[i] - pile.balls[i].velocity) / pile.inverse_masses[i];
    for (std::size_t k = 0; k < pile.contacts.size(); ++k) {
      const RestingContact& c = pile.contacts[k];
      gripped[c.ball] += impulses[k][1];
      if (c.other) gripped[*c.other] += impulses[k][1];
      if (!c.other)
        floor += impulses[k][0] * c.normal + impulses[k][1] * Vec2(-c.normal.y(), c.normal.x());
    }
    EXPECT_NEAR((gained - floor).norm(), 0.0, 1e-12 * floor.norm()) << mu;
    for (std::size_t i = 0; i < pile.balls.size(); ++i) {
      const Ball& b = pile.balls[i];
      const double turned =
          b.inertia_factor * b.radius / pile.inverse_masses[i] * (s.spins[i] - b.angular_velocity);
      EXPECT_NEAR(turned, -gripped[i], 1e-12 * floor.norm()) << mu << " " << i;
    }
  }
}

TEST(Settle, ASmoothPileIsSweptWithoutFrictionToTheBitsOfTheSweepsWithIt) {
  // Alone, a smooth pile (its balls spinning) is swept without friction; after a rough ball
  // lying still on the floor, with it: its contact is swept (its gap opens by nothing), so its
  // round has a row with friction, and no sweep changes it. The pile's balls end the same to the
  // bit, their spins as they were, and no contact grips. (Listed first, the rough contact keeps
  // the pile's contacts in their order.)
  JitteredPile pile = jitteredPile([](std::size_t) { return 0.0; });
  std::mt19937 random(5);
  std::uniform_real_distribution<double> spin(-3.0, 3.0);
  for (Ball& b : pile.balls) b.angular_velocity = spin(random);
  std::vector<std::array<double, 2>> smooth_impulses, beside_impulses;
  const Settled smooth = settleTogether(pile.balls, pile.inverse_masses, pile.contacts,
                                        pile.frictions, kH, &smooth_impulses);
  const std::size_t n = pile.balls.size();
  pile.balls.push_back(ball({100.0, 0.5}, {0.0, 0.0}));
  pile.inverse_masses.push_back(1.0);
  pile.contacts.insert(pile.contacts.begin(), {n, std::nullopt, Vec2(0, 1), 0.0, n});
  pile.frictions.insert(pile.frictions.begin(), 0.3);
  const Settled beside = settleTogether(pile.balls, pile.inverse_masses, pile.contacts,
                                        pile.frictions, kH, &beside_impulses);
  EXPECT_EQ(beside.velocities[n], Vec2::Zero());
  EXPECT_EQ(smooth.sweeps, beside.sweeps);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(smooth.velocities[i], beside.velocities[i]) << i;
    EXPECT_EQ(smooth.spins[i], pile.balls[i].angular_velocity) << i;
    EXPECT_EQ(beside.spins[i], pile.balls[i].angular_velocity) << i;
  }
  for (std::size_t k = 0; k < smooth_impulses.size(); ++k) {
    EXPECT_EQ(smooth.pushes[k], beside.pushes[k + 1]) << k;
    EXPECT_EQ(smooth_impulses[k][1], 0.0) << k;
  }
  for (const auto& [push, grip] : beside_impulses) EXPECT_EQ(grip, 0.0);
}

TEST(Settle, AColumnListedFromTheTopSettlesWithin128Sweeps) {
  // Forty balls at rest in a column on a floor, pulled down by gravity over the stretch, their
  // contacts listed from the top: Gauss-Seidel sweeps pass the floor's push up the column a ball
  // a sweep, and alone run every round (1,024 sweeps) and the direct solves. Sped by the
  // conjugate gradient, they settle it within 128: every gap closes by kSettleOverlap of
  // a radius at most, and no push lifts a ball.
  const double r = 0.5;
  const std::size_t n = 40;
  std::vector<Ball> balls;
  std::vector<RestingContact> contacts;
  for (std::size_t i = 0; i < n; ++i) balls.push_back(ball({0, r + 2.0 * r * i}, {0, -kG * kH}, r));
  for (std::size_t i = n - 1; i > 0; --i) contacts.push_back({i, i - 1, Vec2(0, 1), 0.0, i});
  contacts.push_back(floorContact());
  const Settled s = settleTogether(balls, std::vector<double>(n, 1.0), contacts,
                                   std::vector<double>(n, 0.0), kH);
  EXPECT_LE(s.sweeps, 128);
  EXPECT_GE(s.velocities[0].y() * kH, -kSettleOverlap * r);
  for (std::size_t i = 1; i < n; ++i)
    EXPECT_GE((s.velocities[i].y() - s.velocities[i - 1].y()) * kH, -kSettleOverlap * r) << i;
  for (std::size_t i = 0; i < n; ++i) EXPECT_LE(s.velocities[i].y(), 1e-6) << i;
  // The last iterate is a sweep's: no contact pulls. The floor's push is the momentum the
  // column ends with, over what it started with: the gradient's steps move balls as they push.
  for (std::size_t k = 0; k < n; ++k) EXPECT_GE(s.pushes[k], 0.0) << k;
  double gained = 0.0;
  for (std::size_t i = 0; i < n; ++i) gained += s.velocities[i].y() + kG * kH;
  EXPECT_NEAR(s.pushes.back(), gained, 1e-12);
}

TEST(Settle, ARoughPileLandingWhoseFrictionSweepsCycleSettlesWithFrictionHeld) {
  // The jittered pile, rough (mu 0.6), its balls landing at up to 6 m/s every way and spinning:
  // sweeps with friction leave a few contacts closing a little too fast round after round, and
  // alone would run every round and the direct solves (1,024 sweeps). Once a round brings the
  // worst gap no nearer its bias, friction is held as the sweeps left it and the pushes
  // converge before the direct solves (within kSettleRounds - 1 rounds): every gap closes by
  // kSettleOverlap of the smaller radius past its bias at most, and friction grips.
  const double mu = 0.6, speed = 6.0;
  JitteredPile pile = jitteredPile([&](std::size_t) { return mu; });
  std::mt19937 random(51);
  std::uniform_real_distribution<double> share(0.0, 1.0);
  for (Ball& b : pile.balls) {
    b.velocity.y() -= speed * share(random);
    b.velocity.x() += speed * (share(random) - 0.5);
    b.angular_velocity = 10.0 * speed * (share(random) - 0.5);
  }
  std::vector<std::array<double, 2>> impulses;
  const Settled s = settleTogether(pile.balls, pile.inverse_masses, pile.contacts,
                                   pile.frictions, kH, &impulses);
  EXPECT_LE(s.sweeps, (kSettleRounds - 1) * kSettleSweeps);
  EXPECT_TRUE(std::any_of(impulses.begin(), impulses.end(),
                          [](const std::array<double, 2>& k) { return k[1] != 0.0; }));
  for (std::size_t k = 0; k < pile.contacts.size(); ++k) {
    const RestingContact& c = pile.contacts[k];
    const Vec2 apart = s.velocities[c.ball] - (c.other ? s.velocities[*c.other] : Vec2::Zero());
    const double smaller = c.other ? std::min(pile.balls[c.ball].radius,
                                              pile.balls[*c.other].radius)
                                   : pile.balls[c.ball].radius;
    EXPECT_GE((c.normal.dot(apart) + c.bias) * kH, -kSettleOverlap * smaller) << k;
  }
}
