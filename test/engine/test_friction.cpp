#include <cmath>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/friction.h"
#include "ball_physics_sim/engine/invariants.h"
#include "ball_physics_sim/engine/scene.h"
#include "ball_physics_sim/engine/world.h"
#include "bodies.h"

using namespace ball_physics_sim::engine;
using namespace ball_physics_sim::engine::test;

namespace {

Ball rough(Ball b, double friction, double spin = 0.0, double rolling_resistance = 0.0) {
  b.friction = friction;
  b.angular_velocity = spin;
  b.rolling_resistance = rolling_resistance;
  return b;
}

Segment rough(Segment s, double friction, double rolling_resistance = 0.0) {
  s.friction = friction;
  s.rolling_resistance = rolling_resistance;
  return s;
}

// Total angular momentum about the origin: orbital r x m v plus spin I w.
double angularMomentum(const World& world) {
  double total = 0.0;
  for (const Ball& b : world.balls())
    total += b.mass * (b.position.x() * b.velocity.y() - b.position.y() * b.velocity.x()) +
             b.inertia_factor * b.mass * b.radius * b.radius * b.angular_velocity;
  return total;
}

// A ball of radius 0.5 released at rest on a rough incline of angle theta (friction mu and
// rolling resistance c for both); after `seconds`, how far it went down the slope, its speed
// that way and its spin, and whether it rests.
struct SlopeRun {
  double distance, speed, spin;
  bool at_rest;
};
SlopeRun releaseOnIncline(double theta, double mu, double seconds, double c = 0.0) {
  World world(Vec2(0.0, -kG));
  const Vec2 down(std::cos(theta), -std::sin(theta)), up_normal(std::sin(theta), std::cos(theta));
  world.addSegment(rough(segment(Vec2::Zero(), 100.0 * down), mu, c));
  const Vec2 start = 1.0 * down + 0.5 * up_normal;
  world.addBall(rough(ball(start, Vec2::Zero()), mu, 0.0, c));
  run(world, seconds);
  const Ball& b = world.balls()[0];
  return {(b.position - start).dot(down), b.velocity.dot(down), b.angular_velocity, b.at_rest};
}


// One ball (mass 1, radius 0.5, a solid sphere) touching fixed bodies along `normals` (each
// pointing toward it), pulled by `free` and spinning at `spin`: its contacts held with
// `frictions`, from `start`.
FrictionalRates holdOneBall(const Vec2& free, const std::vector<Vec2>& normals,
                            const std::vector<ContactFriction>& frictions,
                            const std::vector<ContactForces>& start = {}, double spin = 0.0) {
  std::vector<RestingContact> contacts;
  for (const Vec2& n : normals) {
    RestingContact c;
    c.normal = n;
    contacts.push_back(c);
  }
  return holdWithFriction({free}, {rough(ball(Vec2::Zero(), Vec2::Zero()), 0.0, spin)}, {1.0},
                          contacts, frictions, start);
}

void expectForces(const ContactForces& found, double normal, double friction,
                  double torque = 0.0) {
  EXPECT_NEAR(found.normal, normal, 1e-12 * normal);
  EXPECT_NEAR(found.friction, friction, 1e-12 * normal);
  EXPECT_NEAR(found.torque, torque, 1e-12 * normal);
}

}  // namespace

TEST(Friction, CombinedCoefficientIsTheGeometricMean) {
  EXPECT_DOUBLE_EQ(combinedFriction(0.3, 0.3), 0.3);
  EXPECT_DOUBLE_EQ(combinedFriction(0.1, 0.4), 0.2);
  EXPECT_EQ(combinedFriction(0.0, 5.0), 0.0);
}

TEST(Friction, ASolidBallHittingARoughFloorLeavesItRolling) {
  // Sticking: the tangential impulse stops the slip. For a solid sphere (I = 2/5 m r^2) the
  // speed along the floor becomes 5/7 of it and the spin -v/r; the normal part bounces by e.
  World world(Vec2::Zero());
  world.addSegment(rough(segment({-10.0, 0.0}, {10.0, 0.0}), 10.0));
  world.addBall(rough(ball({0.0, 1.0}, {3.0, -4.0}, 0.5, 2.0, 0.5), 10.0));
  world.step(0.25);  // the impact at 0.125 s
  const Ball& b = world.balls()[0];
  const double vx = 3.0 * 5.0 / 7.0;
  EXPECT_NEAR(b.velocity.x(), vx, 1e-12 * vx);
  EXPECT_NEAR(b.velocity.y(), 2.0, 1e-12);
  EXPECT_NEAR(b.angular_velocity, -vx / 0.5, 1e-12 * vx / 0.5);
  EXPECT_NEAR(b.angle, -vx / 0.5 * 0.125, 1e-12);
}

TEST(Friction, ASlidingImpactTakesMuTimesTheNormalImpulse) {
  // mu = 0.1 cannot stop the slip: J_n = (1 + e) m v_n = 6 N s, J_t = 0.6 N s against it.
  World world(Vec2::Zero());
  world.addSegment(rough(segment({-10.0, 0.0}, {10.0, 0.0}), 0.1));
  world.addBall(rough(ball({0.0, 1.0}, {3.0, -4.0}, 0.5, 1.0, 0.5), 0.1));
  world.step(0.25);
  const Ball& b = world.balls()[0];
  EXPECT_NEAR(b.velocity.x(), 3.0 - 0.6, 1e-12);
  EXPECT_NEAR(b.velocity.y(), 2.0, 1e-12);
  // Torque -r J_t over I = 0.4 m r^2: -0.6 / (0.4 * 0.5).
  EXPECT_NEAR(b.angular_velocity, -3.0, 1e-12);
}

TEST(Friction, ABackspinningBallBouncesBackward) {
  // Backspin w = +20 rad/s (counter-clockwise, moving right) on a sticking floor: the slip
  // stops at v' = (5 v - 2 r w) / 7, here (15 - 20) / 7 < 0, so it comes back.
  World world(Vec2::Zero());
  world.addSegment(rough(segment({-10.0, 0.0}, {10.0, 0.0}), 10.0));
  world.addBall(rough(ball({0.0, 1.0}, {3.0, -4.0}), 10.0, 20.0));
  world.step(0.25);
  EXPECT_NEAR(world.balls()[0].velocity.x(), (5.0 * 3.0 - 2.0 * 0.5 * 20.0) / 7.0, 1e-12);
}

TEST(Friction, AGlancingImpactBetweenRoughBallsKeepsMomentumAndStopsTheSlip) {
  World world(Vec2::Zero());
  world.addBall(rough(ball({0.0, 0.0}, {2.0, 0.0}, 0.5, 1.0), 10.0, 3.0));
  world.addBall(rough(ball({3.0, 0.6}, {-1.0, 0.0}, 0.4, 2.5), 10.0, -1.0));
  const Vec2 momentum_before = world.balls()[0].velocity + 2.5 * world.balls()[1].velocity;
  const double angular_before = angularMomentum(world);
  const double energy_before = mechanicalEnergy(world);
  world.step(1.0);
  const std::vector<Contact> contacts = world.takeContacts();
  ASSERT_EQ(contacts.size(), 1u);
  const Ball &a = world.balls()[0], &b = world.balls()[1];
  const Vec2 momentum_after = a.velocity + 2.5 * b.velocity;
  EXPECT_NEAR((momentum_after - momentum_before).norm(), 0.0, 1e-12);
  // The contact forces act along the line through the contact point, so angular momentum about
  // any point is kept too.
  EXPECT_NEAR(angularMomentum(world), angular_before, 1e-12);
  // Sticking: after the impact the surfaces do not slide at the contact point.
  const Vec2& n = contacts[0].normal;
  EXPECT_NEAR(slipSpeed(a.velocity - b.velocity, n, a.radius, a.angular_velocity,
                        b.radius * b.angular_velocity),
              0.0, 1e-12);
  EXPECT_LT(mechanicalEnergy(world), energy_before);  // friction dissipates (e = 1 here)
}

TEST(Friction, ABallRollsDownAGentleInclineAtFiveSeventhsGSinTheta) {
  // mu = 0.3 >= 2/7 tan(30 deg) = 0.165: rolling, a = 5/7 g sin(theta), w = -v / r.
  const double theta = M_PI / 6.0, t = 2.0;
  const SlopeRun slope = releaseOnIncline(theta, 0.3, t);
  const double a = 5.0 / 7.0 * kG * std::sin(theta);
  EXPECT_NEAR(slope.distance, 0.5 * a * t * t, 1e-9 * 0.5 * a * t * t);
  EXPECT_NEAR(slope.speed, a * t, 1e-9 * a * t);
  EXPECT_NEAR(slope.spin, -slope.speed / 0.5, 1e-9 * a * t / 0.5);
}

TEST(Friction, ABallSlidesDownASteepIncline) {
  // mu = 0.1 < 0.165: it slides, a = g (sin(theta) - mu cos(theta)), and friction spins it up
  // at mu g cos(theta) / (2/5 r).
  const double theta = M_PI / 6.0, t = 2.0, mu = 0.1;
  const SlopeRun slope = releaseOnIncline(theta, mu, t);
  const double a = kG * (std::sin(theta) - mu * std::cos(theta));
  EXPECT_NEAR(slope.distance, 0.5 * a * t * t, 1e-9 * 0.5 * a * t * t);
  EXPECT_NEAR(slope.speed, a * t, 1e-9 * a * t);
  const double spin = -mu * kG * std::cos(theta) / (0.4 * 0.5) * t;
  EXPECT_NEAR(slope.spin, spin, 1e-9 * std::abs(spin));
}

TEST(Friction, ASlidingBallStartsToRollWhenFrictionHasStoppedItsSlip) {
  // Pushed along a rough floor without spin: it slides, slowed by mu g and spun up, until at
  // t* = 2 v0 / (7 mu g) it rolls at 5/7 v0, and then rolls on at that speed.
  World world(Vec2(0.0, -kG));
  world.addSegment(rough(segment({-10.0, 0.0}, {100.0, 0.0}), 0.2));
  const double v0 = 4.0, mu = 0.2;
  world.addBall(rough(ball({0.0, 0.5}, {v0, 0.0}), mu));
  run(world, 2.0);
  const double rolling_at = 2.0 * v0 / (7.0 * mu * kG);
  const double x = v0 * rolling_at - 0.5 * mu * kG * rolling_at * rolling_at +
                   5.0 / 7.0 * v0 * (2.0 - rolling_at);
  const Ball& b = world.balls()[0];
  EXPECT_NEAR(b.position.x(), x, 1e-9 * x);
  EXPECT_NEAR(b.position.y(), 0.5, 1e-12);
  EXPECT_NEAR(b.velocity.x(), 5.0 / 7.0 * v0, 1e-12);
  EXPECT_NEAR(b.angular_velocity, -5.0 / 7.0 * v0 / 0.5, 1e-12);
}

TEST(Friction, RollingResistanceSlowsARollingBallToRestAtTheExactPlace) {
  // Rolling at v0 on a floor with rolling resistance c: the torque c N r against the spin and
  // the friction that keeps it rolling slow it at a = c g / (1 + 2/5) until it stops, at
  // v0^2 / 2a, and rests there.
  World world(Vec2(0.0, -kG));
  const double v0 = 2.0, c = 0.05, a = c * kG / 1.4;
  world.addSegment(rough(segment({-10.0, 0.0}, {100.0, 0.0}), 0.5, c));
  world.addBall(rough(ball({0.0, 0.5}, {v0, 0.0}), 0.5, -v0 / 0.5, c));
  run(world, 1.2 * v0 / a);
  const Ball& b = world.balls()[0];
  EXPECT_NEAR(b.position.x(), v0 * v0 / (2.0 * a), 1e-9);
  EXPECT_NEAR(b.position.y(), 0.5, 1e-12);
  EXPECT_TRUE(b.at_rest);
  EXPECT_EQ(b.angular_velocity, 0.0);
}

TEST(Friction, AFrictionlessBallRestsWithTheSpinItHas) {
  // Nothing can change its spin, so it must not wait for the spin to stop before it rests; its
  // angle goes on turning.
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}, 0.0));
  world.addBall(rough(ball({0.0, 1.0}, Vec2::Zero(), 0.5, 1.0, 0.0), 0.0, 1.0));
  run(world, 2.0);
  const Ball& b = world.balls()[0];
  EXPECT_TRUE(b.at_rest);
  EXPECT_EQ(b.position.y(), 0.5);
  EXPECT_EQ(b.angular_velocity, 1.0);
  EXPECT_NEAR(b.angle, 2.0, 1e-12);  // 1 rad/s for 2 s, within (-pi, pi]
}

TEST(Friction, ARoughBallTurningSlowerThanTheHeldSeparationSpeedIsPutToRest) {
  // A rough ball resting on a smooth floor, turning in place: whose surface turns at 2e-6 m/s
  // it keeps on, awake; at 5e-7 m/s, slower than a held ball must move to rest (1e-6 m/s), it
  // rests, its spin stopped (rough balls rocked so in a pile's pockets for ever). And one
  // rolling on a rough floor at 5e-7 m/s rests too.
  for (const double surface : {2e-6, 5e-7}) {
    World world(Vec2(0.0, -kG));
    world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}, 0.0));
    world.addBall(rough(ball({0.0, 0.5}, Vec2::Zero(), 0.5, 1.0, 0.0), 0.5, surface / 0.5));
    run(world, 1.0);
    const Ball& b = world.balls()[0];
    EXPECT_EQ(b.at_rest, surface < 1e-6) << surface;
    EXPECT_EQ(b.angular_velocity, surface < 1e-6 ? 0.0 : surface / 0.5) << surface;
    EXPECT_EQ(b.position, Vec2(0.0, 0.5)) << surface;
  }
  const double v = 5e-7;
  World world(Vec2(0.0, -kG));
  world.addSegment(rough(segment({-5.0, 0.0}, {5.0, 0.0}, 0.0), 0.5));
  world.addBall(rough(ball({0.0, 0.5}, Vec2(v, 0.0), 0.5, 1.0, 0.0), 0.5, -v / 0.5));
  run(world, 1.0);
  const Ball& b = world.balls()[0];
  EXPECT_TRUE(b.at_rest);
  EXPECT_EQ(b.velocity, Vec2::Zero());
  EXPECT_EQ(b.angular_velocity, 0.0);
  EXPECT_EQ(b.position, Vec2(0.0, 0.5));
}

TEST(Friction, ARoughBallSpinningOnASmoothFloorDoesNotRestAndDrivesNoBallItTouches) {
  // Its contact cannot stop its spin, but a rough ball that comes to touch it could: it stays
  // awake, spinning at 10 rad/s where it is. At rest it would not be slowed by what it drives:
  // a rough ball set down touching it and a rough wall would spin up for ever, and the two
  // gain energy. They must not.
  World world(Vec2(0.0, -kG));
  world.addSegment(segment({-5.0, 0.0}, {5.0, 0.0}, 0.0));
  world.addSegment(rough(segment({-1.2, 0.0}, {-1.2, 5.0}, 0.0), 0.5));
  world.addBall(rough(ball({0.0, 0.5}, Vec2::Zero(), 0.5, 1.0, 0.0), 0.5, 10.0));
  run(world, 1.0);
  const Ball& spinning = world.balls()[0];
  EXPECT_FALSE(spinning.at_rest);
  EXPECT_EQ(spinning.position, Vec2(0.0, 0.5));
  EXPECT_EQ(spinning.angular_velocity, 10.0);
  // One metre from its centre, 0.5 m from the wall.
  world.addBall(
      rough(ball({-0.7, 0.5 + std::sqrt(0.51) + 1e-9}, Vec2::Zero(), 0.5, 1.0, 0.0), 0.5));
  double energy = mechanicalEnergy(world);
  for (int i = 0; i < 600; ++i) {
    world.step(kFrameStep);
    const double now = mechanicalEnergy(world);
    ASSERT_LE(now, energy + 1e-12 * std::abs(energy)) << "step " << i;
    energy = now;
  }
}

TEST(Friction, RollingResistanceHoldsABallOnASlopeNoSteeperThanItsCoefficient) {
  // At rest on a slope, friction holds the centre (mu >= tan(theta)) and rolling resistance
  // must hold the turning that friction's torque asks: tan(theta) <= c. Steeper, it rolls at
  // g (sin(theta) - c cos(theta)) / (1 + 2/5).
  const double c = 0.1, t = 2.0;
  const SlopeRun held = releaseOnIncline(std::atan(0.099), 0.5, t, c);
  EXPECT_TRUE(held.at_rest);
  EXPECT_EQ(held.distance, 0.0);
  const double theta = std::atan(0.101), a = kG * (std::sin(theta) - c * std::cos(theta)) / 1.4;
  const SlopeRun rolled = releaseOnIncline(theta, 0.5, t, c);
  EXPECT_NEAR(rolled.distance, 0.5 * a * t * t, 1e-9 * 0.5 * a * t * t);
  EXPECT_NEAR(rolled.spin, -rolled.speed / 0.5, 1e-9 * a * t / 0.5);
}

// Three equal balls stacked as a pyramid on a floor, one material throughout: the top ball
// presses the bottom ones apart, and each bottom ball, its two frictions turning it equal and
// opposite ways, needs f = (2 - sqrt(3)) N at the upper contact. So the pyramid stands exactly
// when mu >= 2 - sqrt(3) = 0.2679 (the floor then needs only a third of that).
double pyramidTopAfterOneSecond(double mu, double top_mass = 1.0, double floor_mu = -1.0) {
  World world(Vec2(0.0, -kG));
  world.addSegment(rough(segment({-6.0, 0.0}, {6.0, 0.0}), floor_mu < 0.0 ? mu : floor_mu));
  world.addBall(rough(ball({0.0, 0.5}, Vec2::Zero()), mu));
  world.addBall(rough(ball({1.0, 0.5}, Vec2::Zero()), mu));
  world.addBall(rough(ball({0.5, 0.5 + std::sqrt(0.75)}, Vec2::Zero(), 0.5, top_mass), mu));
  run(world, 1.0);
  return world.balls()[2].position.y();
}

TEST(Friction, APyramidOfThreeBallsStandsExactlyWhenMuReachesTwoMinusRootThree) {
  const double critical = 2.0 - std::sqrt(3.0), top = 0.5 + std::sqrt(0.75);
  EXPECT_EQ(pyramidTopAfterOneSecond(critical + 1e-3), top);
  EXPECT_LT(pyramidTopAfterOneSecond(critical - 1e-3), top - 1e-3);
}

TEST(Friction, APyramidWithAHeavyTopStandsWhenMuReachesTwoMinusRootThree) {
  // The contact under the top ball needs f = (2 - sqrt(3)) N whatever the top weighs; the
  // floor, under a top of weight M g on balls of m g, f / N = 0.134 M / (m + 0.366 M) (at most
  // 0.366), which a floor of mu 1 gives (the pair's mu is the geometric mean, over 0.5). A
  // heavy top makes the forces, and their rounding, M / m times the free rates': judged
  // against the free rates alone, the solve never looked converged and held the pyramid
  // without friction, which let a top 100 times as heavy fall; later, pivoting gave up under
  // one 1000 times as heavy. Up to the heaviest ball there may be.
  const double critical = 2.0 - std::sqrt(3.0), top = 0.5 + std::sqrt(0.75);
  for (const double top_mass : {100.0, 1000.0, kMaxMass}) {
    EXPECT_EQ(pyramidTopAfterOneSecond(critical + 1e-3, top_mass, 1.0), top) << top_mass;
    EXPECT_LT(pyramidTopAfterOneSecond(critical - 1e-3, top_mass, 1.0), top - 1e-3) << top_mass;
  }
}

TEST(Friction, ABallPushedAlongARoughFloorRollsOnceItsContactCloses) {
  // Pushed at its centre by 3 m/s^2 and pressed down by g: starting apart, its contact closes
  // and slides against its slip, then sticks, since rolling asks f = 2/7 of the push, within
  // mu g. It rolls at 5/7 of the push, its spin keeping pace (the floor's tangent is -x).
  const FrictionalRates rates =
      holdOneBall(Vec2(3.0, -kG), {Vec2(0.0, 1.0)}, {{0.3, 0.0, 0.0}});
  EXPECT_NEAR(rates.accelerations[0].x(), 15.0 / 7.0, 1e-12);
  EXPECT_NEAR(rates.accelerations[0].y(), 0.0, 1e-12);
  EXPECT_NEAR(rates.angular_accelerations[0], -30.0 / 7.0, 1e-12);
  expectForces(rates.forces[0], kG, 6.0 / 7.0);
}

TEST(Friction, ARollingBallPushedHarderThanFrictionHoldsSlidesAtMuTimesItsWeight) {
  // Rolling under a push of 12 m/s^2 asks f = 24/7 > mu g = 2.94: from its rolling forces, its
  // contact slides, at mu g against the push, which also spins it up.
  const FrictionalRates rates = holdOneBall(Vec2(12.0, -kG), {Vec2(0.0, 1.0)}, {{0.3, 0.0, 0.0}},
                                            {{kG, 6.0 / 7.0, 0.0}});
  EXPECT_NEAR(rates.accelerations[0].x(), 12.0 - 0.3 * kG, 1e-12);
  EXPECT_NEAR(rates.accelerations[0].y(), 0.0, 1e-12);
  EXPECT_NEAR(rates.angular_accelerations[0], -0.3 * kG / (0.4 * 0.5), 1e-12);
  expectForces(rates.forces[0], kG, 0.3 * kG);
}

TEST(Friction, AContactPulledOpenLetsGo) {
  const FrictionalRates rates =
      holdOneBall(Vec2(1.0, kG), {Vec2(0.0, 1.0)}, {{0.3, 0.0, 0.0}}, {{kG, 0.5, 0.0}});
  EXPECT_EQ(rates.accelerations[0], Vec2(1.0, kG));
  EXPECT_EQ(rates.angular_accelerations[0], 0.0);
  expectForces(rates.forces[0], 0.0, 0.0);
}

TEST(Friction, ARollingBallsResistanceTakesCNRAndItsFrictionKeepsItRolling) {
  // Turning at -2 rad/s on a floor (rolling towards +x), with rolling resistance c = 0.1: a
  // torque c N r = 0.05 g against the spin, and the friction that keeps it rolling,
  // f = 5/7 of torque / r (from 3.5 f = 2.5 torque / r for a solid ball of radius 0.5): it
  // slows at g / 14, its spin at g / 7.
  const FrictionalRates rates = holdOneBall(Vec2(0.0, -kG), {Vec2(0.0, 1.0)}, {{0.5, 0.1, 0.0}},
                                            {}, -2.0);
  EXPECT_NEAR(rates.accelerations[0].x(), -kG / 14.0, 1e-12);
  EXPECT_NEAR(rates.accelerations[0].y(), 0.0, 1e-12);
  EXPECT_NEAR(rates.angular_accelerations[0], kG / 7.0, 1e-12);
  expectForces(rates.forces[0], kG, kG / 14.0, 0.05 * kG);
}

TEST(Friction, ABallSlidingIntoACornerIsPressedByItsFrictionUnlessThatWedgesItIn) {
  // Pushed into a wall by P and pressed down by g, sliding so that the floor's friction pushes
  // it into the wall and the wall's pushes it down: N_floor = g + mu N_wall and
  // N_wall = P + mu N_floor, so N_floor = (g + mu P) / (1 - mu^2). For mu >= 1 no forces meet
  // those conditions: the corner holds it without friction.
  const double p = 2.0;
  const Vec2 floor(0.0, 1.0), wall(-1.0, 0.0);
  // Friction is mu N against the slip along the tangent: the floor's tangent is -x, the wall's -y.
  auto corner = [&](double mu) {
    return holdOneBall(Vec2(p, -kG), {floor, wall}, {{mu, 0.0, 1e-3}, {mu, 0.0, -1e-3}});
  };
  const double mu = 0.5, floor_normal = (kG + mu * p) / (1.0 - mu * mu);
  const double wall_normal = p + mu * floor_normal;
  const FrictionalRates pressed = corner(mu);
  EXPECT_NEAR(pressed.accelerations[0].norm(), 0.0, 1e-12 * floor_normal);
  expectForces(pressed.forces[0], floor_normal, -mu * floor_normal);
  expectForces(pressed.forces[1], wall_normal, mu * wall_normal);
  EXPECT_NEAR(pressed.angular_accelerations[0], -mu * (wall_normal - floor_normal) / (0.4 * 0.5),
              1e-12 * floor_normal);

  const FrictionalRates wedged = corner(1.2);
  EXPECT_NEAR(wedged.accelerations[0].norm(), 0.0, 1e-12 * kG);
  EXPECT_EQ(wedged.angular_accelerations[0], 0.0);
  expectForces(wedged.forces[0], kG, 0.0);
  expectForces(wedged.forces[1], p, 0.0);
}

TEST(Friction, ATallRoughColumnPulledSidewaysAtItsTopMeetsEveryContactsConditions) {
  // 70 rough balls stacked on a rough floor, the top one pulled sideways at 2 m/s^2, solved
  // cold: every contact pushes and grips, 140 unknowns, past what is solved densely. Friction
  // must turn the pull into the column's rolling: each contact pushes, closed, and its
  // friction keeps its slip rate zero within the cone (or slides at its edge); the top one's
  // friction is not zero, as it would be held without friction.
  const std::size_t n = 70;
  const double mu = 0.9;
  std::vector<RestingContact> column(n);
  for (std::size_t k = 0; k < n; ++k) {
    column[k].ball = k;
    if (k > 0) column[k].other = k - 1;
    column[k].normal = Vec2(0.0, 1.0);
  }
  std::vector<Vec2> free(n, Vec2(0.0, -kG));
  free[n - 1].x() = 2.0;
  const std::vector<Ball> balls(n, rough(ball(Vec2::Zero(), Vec2::Zero()), mu));
  const FrictionalRates rates = holdWithFriction(free, balls, std::vector<double>(n, 1.0),
                                                 column, std::vector<ContactFriction>(n, {mu}));
  const double tolerance = 1e-12 * n * kG;
  for (std::size_t k = 0; k < n; ++k) {
    const ContactForces& f = rates.forces[k];
    const Vec2 below = k > 0 ? rates.accelerations[k - 1] : Vec2::Zero();
    const double below_surface = k > 0 ? 0.5 * rates.angular_accelerations[k - 1] : 0.0;
    EXPECT_GT(f.normal, 0.0) << k;
    EXPECT_NEAR((rates.accelerations[k] - below).y(), 0.0, tolerance) << k;
    EXPECT_LE(std::abs(f.friction), mu * f.normal + tolerance) << k;
    if (std::abs(f.friction) < mu * f.normal - tolerance) {
      EXPECT_NEAR(slipSpeed(rates.accelerations[k] - below, column[k].normal, 0.5,
                            rates.angular_accelerations[k], below_surface),
                  0.0, tolerance)
          << k;
    }
  }
  EXPECT_GT(std::abs(rates.forces[n - 1].friction), 0.1);
}

TEST(Friction, ForcesThatWouldRunAwayAreNotTaken) {
  // Recorded from random islands: a small ball on a rough floor, touched from above by two
  // balls that do not move, sliding on one of them, with the forces of a moment ago as start.
  // The holds that start gives have no solution; made definite, their equations were answered
  // with pushes of 4.7e12 N, whose rounding the tolerance then allowed, and every gap closed at
  // metres per second squared. Whatever the hold found, no gap may close, and no force exceed
  // the cone or the ball's weight by much.
  std::vector<Ball> balls(3, ball(Vec2::Zero(), Vec2::Zero()));
  balls[0].radius = 0.099325684389312691;
  balls[0].inertia_factor = 0.55211268782524603;
  balls[1].radius = 0.28776249925954261;
  balls[2].radius = 0.37450671539749725;
  std::vector<RestingContact> contacts(3);
  contacts[0].normal = Vec2(0.0, 1.0);
  contacts[1].other = 1;
  contacts[1].normal = Vec2(0.62127360019926714, -0.78359371723836646);
  contacts[1].bias = 0.61778977861328843;
  contacts[2].other = 2;
  contacts[2].normal = Vec2(0.51128006734886766, -0.85941415669730359);
  const std::vector<ContactFriction> frictions{
      {0.77851699130070107, 0.0, 0.0},
      {0.42495181495436912, 0.0, -1.3835030703417931e-05},
      {1.4805876010280707, 0.0, 0.0036316918591137574}};
  const FrictionalRates rates = holdWithFriction(
      {Vec2(0.0, -kG), Vec2(0.0, -kG), Vec2(-0.71890099577476541, -14.292955245969747)}, balls,
      {1.0, 0.0, 0.0}, contacts, frictions,
      {{0.0, 0.0, 0.0}, {18.288155526271296, 2.1459120340492208, 0.0},
       {12.904634493630443, 18.998826033046189, 0.0}});
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const ContactForces& f = rates.forces[k];
    EXPECT_GE(contacts[k].normal.dot(rates.accelerations[0]) + contacts[k].bias, -1e-12 * kG) << k;
    EXPECT_GE(f.normal, 0.0) << k;
    EXPECT_LE(f.normal, 2.0 * kG) << k;
    EXPECT_LE(std::abs(f.friction), frictions[k].friction * f.normal * (1.0 + 1e-12)) << k;
  }
}

TEST(Friction, ALeaningColumnOfSlidingBallsFindsTheForcesItsFrictionPressesItWith) {
  // Four balls leaning on each other on a floor, each contact sliding a little (slips of
  // 1e-4 m/s, past kRollingSlip) with mu = 0.55. Their sliding friction presses the column
  // together nearly as hard as it pushes: the normal forces come to 35 to 98 times a ball's
  // weight. Solving normal and friction forces in turn closed in on them by a factor of about
  // 0.97 a turn, so slowly that it gave up and held the column without friction. Every contact
  // must end sliding, at mu N against its slip, with its gap neither closing nor opening.
  const double mu = 0.55;
  std::vector<Ball> balls(4, rough(ball(Vec2::Zero(), Vec2::Zero()), mu));
  const std::vector<Vec2> free(4, Vec2(0.0, -kG));
  const std::vector<double> inverse_masses(4, 1.0);
  // Ball i + 1 leans on ball i: their contact's normal points down, toward ball i.
  struct Lean {
    std::size_t ball;
    std::optional<std::size_t> other;
    Vec2 normal;
    double bias, slip;
  };
  const Lean leans[] = {{0, std::nullopt, Vec2(0.0, 1.0), 0.0, -1e-4},
                        {0, 1, Vec2(0.16, -0.99), 0.45, 1e-4},
                        {1, 2, Vec2(-0.10, -0.99), 0.22, -1e-4},
                        {2, 3, Vec2(-0.05, -1.0), 0.36, 1e-4}};
  std::vector<RestingContact> contacts;
  std::vector<ContactFriction> frictions;
  for (const Lean& l : leans) {
    RestingContact c;
    c.ball = l.ball;
    c.other = l.other;
    c.normal = l.normal.normalized();
    c.bias = l.bias;
    contacts.push_back(c);
    frictions.push_back({mu, 0.0, l.slip});
  }
  const FrictionalRates rates = holdWithFriction(free, balls, inverse_masses, contacts, frictions);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const RestingContact& c = contacts[k];
    const ContactForces& f = rates.forces[k];
    EXPECT_GT(f.normal, 10.0 * kG) << k;
    EXPECT_NEAR(f.friction, -std::copysign(mu * f.normal, leans[k].slip), 1e-12 * f.normal) << k;
    const Vec2 relative =
        rates.accelerations[c.ball] - (c.other ? rates.accelerations[*c.other] : Vec2::Zero());
    EXPECT_NEAR(c.normal.dot(relative) + c.bias, 0.0, 1e-9 * f.normal) << k;
  }
}

TEST(Friction, TheRollingSceneComesToRestWithItsPyramidStanding) {
  // Balls roll and slide down its ramps and along its floor until rolling resistance stops
  // them; its pyramid of rough balls (ids 3 to 5) stands where it was put, untouched.
  Scene scene = loadScene(SCENES_DIR "/rolling.yaml");
  const std::vector<Ball> start = scene.world.balls();
  run(scene.world, 6.0);
  for (const Ball& b : scene.world.balls()) EXPECT_TRUE(b.at_rest) << "ball " << b.id;
  for (std::size_t i = 2; i < 5; ++i)
    EXPECT_EQ(scene.world.balls()[i].position, start[i].position) << "ball " << start[i].id;
  EXPECT_EQ(brokenInvariant(scene.world, 1e-9), std::nullopt);
}

Ball recorded(Vec2 position, Vec2 velocity, double spin, double radius, double mass,
              double restitution, double friction) {
  return rough(ball(position, velocity, radius, mass, restitution), friction, spin);
}

TEST(Friction, BallsThatFrictionWedgesIntoACornerGainNoEnergy) {
  // Three balls falling into a rough corner, recorded from a random box: their friction
  // presses them into the floor, the wall and each other harder the harder they press, and
  // solving normal and friction forces in turn escalated without bound. The contacts then hold
  // without friction; taking the escalated forces gained energy (4e-11 of it per step).
  World world(Vec2(0.0, -kG));
  world.addSegment(
      rough(segment({0.0, 0.0}, {10.0, 0.0}, 0.29025859181897556), 0.81230282966777589));
  world.addSegment(
      rough(segment({0.0, 0.0}, {0.0, 10.0}, 0.32481892306804522), 0.032701483894298562));
  world.addBall(recorded({0.49661896872239975, 0.82045278124752796},
                         {-0.076966851554269564, -4.3996619087743127}, 1.265576485253971,
                         0.33357209582195868, 0.91942577027610306, 0.89233401901849341,
                         0.24140747648384228));
  world.addBall(recorded({0.44796897807460712, 1.3812668275664202},
                         {-0.61724482481195997, -3.9860251093994821}, 0.35396548507497433,
                         0.22867963515477818, 1.1354798411093521, 0.22593293875257067,
                         0.76036527118330854));
  world.addBall(recorded({0.67410805100105819, 0.25683138147706475},
                         {2.5705862557570542, -6.8629742845571897}, 2.8770168895272108,
                         0.2493922697348753, 0.5002721573240696, 0.73998715222200406,
                         0.66090831767447289));
  double energy = mechanicalEnergy(world);
  for (int i = 0; i < 30; ++i) {
    world.step(kFrameStep);
    ASSERT_EQ(brokenInvariant(world, 1e-7), std::nullopt) << "step " << i;
    const double now = mechanicalEnergy(world);
    ASSERT_LE(now, energy * (1.0 + 1e-12)) << "step " << i;
    energy = now;
  }
}

TEST(Friction, RoughBallsInARandomBoxNeverGainEnergyNorOverlap) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Balls of random sizes, masses, restitutions, frictions, rolling resistances and spins
  // thrown about a closed 10 m box whose walls have their own; they bounce, slide, roll and
  // pile up in corners.
  for (int scene = 0; scene < 6; ++scene) {
    World world(Vec2(0.0, -kG));
    const double mu = unit(random);
    for (const auto& [from, to] : {std::pair{Vec2(0, 0), Vec2(10, 0)}, {Vec2(0, 0), Vec2(0, 10)},
                                   {Vec2(10, 0), Vec2(10, 10)}, {Vec2(0, 10), Vec2(10, 10)}}) {
      const double restitution = unit(random), friction = unit(random);
      world.addSegment(rough(segment(from, to, restitution), friction, 0.05 * unit(random)));
    }
    for (int i = 0; i < 12; ++i) {
      // One draw per statement: the order in which arguments are evaluated is unspecified.
      Ball b;
      b.position.x() = 0.5 + 9.0 * unit(random);
      b.position.y() = 0.5 + 9.0 * unit(random);
      b.velocity.x() = 10.0 * unit(random) - 5.0;
      b.velocity.y() = 10.0 * unit(random) - 5.0;
      b.radius = 0.2 + 0.2 * unit(random);
      b.mass = 0.5 + unit(random);
      b.restitution = unit(random);
      b.friction = mu * unit(random);
      b.angular_velocity = 40.0 * unit(random) - 20.0;
      b.rolling_resistance = 0.05 * unit(random);
      try {
        world.addBall(b);
      } catch (const std::invalid_argument&) {  // overlaps one placed before: left out
      }
    }
    double energy = mechanicalEnergy(world);
    for (int i = 0; i < 120; ++i) {
      world.step(kFrameStep);
      // (Four or more piled up settle together: their gaps may close as a settle's may.)
      ASSERT_EQ(brokenInvariant(world, mostSettledOverlap(world)), std::nullopt)
          << "scene " << scene;
      const double now = mechanicalEnergy(world);
      ASSERT_LE(now, energy + 1e-9 * std::abs(energy)) << "scene " << scene << " step " << i;
      energy = now;
    }
  }
}

namespace {

// Contacts of one ball with fixed bodies along `normals`, and their frictions `mu` with the
// ball's slips now.
std::pair<std::vector<RestingContact>, std::vector<ContactFriction>> touchingFixedBodies(
    const Ball& b, const std::vector<Vec2>& normals, double mu) {
  std::vector<RestingContact> contacts;
  std::vector<ContactFriction> frictions;
  for (const Vec2& n : normals) {
    RestingContact c;
    c.normal = n;
    contacts.push_back(c);
    frictions.push_back({mu, 0.0, slipSpeed(b.velocity, n, b.radius, b.angular_velocity, 0.0)});
  }
  return {contacts, frictions};
}

double kineticEnergy(const Ball& b) {
  return 0.5 * b.mass *
         (b.velocity.squaredNorm() +
          b.inertia_factor * b.radius * b.radius * b.angular_velocity * b.angular_velocity);
}

}  // namespace

TEST(SlowImpact, ABallSpinningSlowlyInARoughCornerStopsDead) {
  // Rolling on the floor, a ball runs into the wall or leaves it; rolling on the wall, it
  // leaves the floor or presses into it: both its slips stop only with the ball still. Stopped
  // one contact at a time, the floor's grip alone would roll it into the wall at r w / 3.5.
  const Ball b = rough(ball(Vec2::Zero(), Vec2::Zero()), 0.3, 1e-6);  // 5e-7 m/s at its surface
  const auto [contacts, frictions] = touchingFixedBodies(b, {{0.0, 1.0}, {1.0, 0.0}}, 0.3);
  const FrictionalRates after = stopSlowMotion({b}, {1.0}, contacts, frictions);
  EXPECT_LE(after.accelerations[0].norm(), 1e-20);
  EXPECT_LE(std::abs(after.angular_accelerations[0]), 1e-20);
}

TEST(SlowImpact, ABallRollingDownARoughWallOntoAFloorKeepsItsSpinButWhatStopsARollingSlip) {
  // It lands at u, rolling on the wall. The floor stops it, and the wall, which it does not
  // push, can stop its spin only with the impulse that stops kRollingSlip, 1e-6 / 3.5 for a
  // unit mass: the spin keeps all but 1e-6 / (3.5 * 0.4 r) of its -u / r, and the floor pushes
  // that much more than m u.
  const double u = 5e-4, r = 0.5;
  const Ball b = rough(ball(Vec2::Zero(), Vec2(0.0, -u)), 0.3, -u / r);
  const auto [contacts, frictions] = touchingFixedBodies(b, {{0.0, 1.0}, {1.0, 0.0}}, 0.3);
  const FrictionalRates after = stopSlowMotion({b}, {1.0}, contacts, frictions);
  const double allowance = kRollingSlip / 3.5;
  EXPECT_NEAR(after.accelerations[0].norm(), 0.0, 1e-18);
  EXPECT_NEAR(after.angular_accelerations[0], (-u + allowance / 0.4) / r, 1e-15 * u / r);
  EXPECT_NEAR(after.forces[1].friction, -allowance, 1e-15 * u);
  EXPECT_NEAR(after.forces[1].normal, 0.0, 1e-18);
  EXPECT_NEAR(after.forces[0].normal, u + allowance, 1e-15 * u);
}

TEST(SlowImpact, ASlipFasterThanRollingKeepsOnAsTheApproachStops) {
  // Sliding at 1 mm/s as it settles on a floor at 0.1 mm/s: the approach stops, and the slip is
  // left to friction's force.
  const Ball b = rough(ball(Vec2::Zero(), Vec2(1e-3, -1e-4)), 0.3);
  const auto [contacts, frictions] = touchingFixedBodies(b, {{0.0, 1.0}}, 0.3);
  const FrictionalRates after = stopSlowMotion({b}, {1.0}, contacts, frictions);
  EXPECT_EQ(after.accelerations[0], Vec2(1e-3, 0.0));
  EXPECT_EQ(after.angular_accelerations[0], 0.0);
  EXPECT_DOUBLE_EQ(after.forces[0].normal, 1e-4);
  EXPECT_EQ(after.forces[0].friction, 0.0);
}

TEST(SlowImpact, RandomIslandsStopApproachesAndSlowSlipsWithinTheirLimitsWithoutGainingEnergy) {
  // Balls touching each other and fixed bodies along random normals, moving and turning at
  // about the fastest slip that is stopped, so that some slips are slow and some are not; a
  // slow one's friction grips, or gives at mu N plus the impulse that stops kRollingSlip.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), mass(0.2, 5.0);
  const double tolerance = 1e-12;  // m/s, the solve's, on velocities below 1 m/s
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = 2 + trial % 7;
    std::vector<Ball> balls;
    std::vector<double> inverse_masses;
    for (std::size_t i = 0; i < n; ++i) {
      Ball b = ball(Vec2::Zero(), Vec2::Zero(), 0.5, mass(rng));
      b.velocity.x() = 2e-6 * unit(rng);
      b.velocity.y() = 2e-6 * unit(rng);
      b.angular_velocity = 4e-6 * unit(rng);
      balls.push_back(b);
      inverse_masses.push_back(1.0 / b.mass);
    }
    auto slip = [&](const RestingContact& c, const std::vector<Ball>& at) {
      const Vec2 relative = at[c.ball].velocity - (c.other ? at[*c.other].velocity : Vec2::Zero());
      const double other_surface =
          c.other ? at[*c.other].radius * at[*c.other].angular_velocity : 0.0;
      return slipSpeed(relative, c.normal, at[c.ball].radius, at[c.ball].angular_velocity,
                       other_surface);
    };
    std::vector<RestingContact> contacts;
    std::vector<ContactFriction> frictions;
    std::set<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t k = 0; k < 2 * n; ++k) {
      RestingContact c;
      c.ball = rng() % n;
      const std::size_t other = rng() % n;
      c.normal = Vec2(unit(rng), unit(rng)).normalized();
      if (other != c.ball) {
        if (!pairs.insert(std::minmax(c.ball, other)).second) continue;
        c.other = other;
      }
      contacts.push_back(c);
      frictions.push_back({k % 4 == 0 ? 0.0 : 0.3, 0.0, slip(c, balls)});
    }
    const FrictionalRates after = stopSlowMotion(balls, inverse_masses, contacts, frictions);
    // The velocities and spins are what the impulses make of those before.
    std::vector<Ball> pushed = balls;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const RestingContact& c = contacts[k];
      const ContactForces& j = after.forces[k];
      pushed[c.ball].velocity += j.normal / balls[c.ball].mass * c.normal;
      pushSurface(pushed[c.ball], c.normal, j.friction);
      if (!c.other) continue;
      pushed[*c.other].velocity -= j.normal / balls[*c.other].mass * c.normal;
      pushSurface(pushed[*c.other], -c.normal, j.friction);
    }
    double energy_before = 0.0, energy_after = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_LE((after.accelerations[i] - pushed[i].velocity).norm(), tolerance) << trial;
      EXPECT_NEAR(after.angular_accelerations[i], pushed[i].angular_velocity, tolerance) << trial;
      pushed[i].velocity = after.accelerations[i];
      pushed[i].angular_velocity = after.angular_accelerations[i];
      energy_before += kineticEnergy(balls[i]);
      energy_after += kineticEnergy(pushed[i]);
    }
    EXPECT_LE(energy_after, energy_before * (1.0 + 1e-9)) << trial;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const RestingContact& c = contacts[k];
      const Vec2 relative =
          pushed[c.ball].velocity - (c.other ? pushed[*c.other].velocity : Vec2::Zero());
      const double opening = c.normal.dot(relative);
      EXPECT_GE(after.forces[k].normal, 0.0) << trial << " contact " << k;
      EXPECT_GE(opening, -tolerance) << trial << " contact " << k;
      if (after.forces[k].normal > tolerance * balls[c.ball].mass) {
        EXPECT_LE(opening, tolerance) << trial << " contact " << k;
      }
      if (frictions[k].friction > 0.0 && std::abs(frictions[k].slip) <= kRollingSlip) {
        const double per_impulse = tangentialInverseMass(balls[c.ball]) +
                                   (c.other ? tangentialInverseMass(balls[*c.other]) : 0.0);
        const double limit =
            frictions[k].friction * after.forces[k].normal + kRollingSlip / per_impulse;
        const double impulse = after.forces[k].friction, slipping = slip(c, pushed);
        EXPECT_LE(std::abs(impulse), limit + tolerance / per_impulse) << trial << " contact " << k;
        if (std::abs(slipping) > tolerance) {
          EXPECT_GE(std::abs(impulse), limit - tolerance / per_impulse)
              << trial << " contact " << k;
          EXPECT_LE(impulse * slipping, 0.0) << trial << " contact " << k;
        }
      } else {
        EXPECT_EQ(after.forces[k].friction, 0.0) << trial << " contact " << k;
      }
    }
  }
}
