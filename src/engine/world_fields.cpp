// World: fields and pushes: gravity, wind, attractors, water, drives and blasts.

#include "ball_physics_sim/engine/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

namespace {

// A float whose buoyancy's stiffness times a settle's stretch squared is this or more ((omega
// duration)^2: explicit steps of it grow from 4) is stiff: a settle takes its buoyancy's fall as
// it rises at the stretch's end (settledFreeVelocity).
constexpr double kStiffFloat = 1.0;
// Whether a float of `buoyancy` stiffness (1/s^2) is stiff over `duration`, and by how much:
// its stiffness times duration squared if it is, else 0.
double stiffness(double buoyancy, double duration) {
  const double springy = buoyancy * duration * duration;
  return springy >= kStiffFloat ? springy : 0.0;
}
// A stretch under a changing pull is shortened until the pull's rate at its middle allows it:
// each round at most halves it, so a few rounds meet the rate where it grows from nothing.
constexpr int kStretchRefinements = 8;

// Water's surface is level, the top of its region: the water weighs down.
void checkGravityForWater(const Vec2& gravity) {
  if (gravity.x() != 0.0 || gravity.y() > 0.0)
    throw std::invalid_argument("water needs gravity along -y (its surface is its region's top)");
}

}  // namespace

void World::setGravity(const Vec2& gravity) {
  if (!gravity.allFinite() || gravity.norm() > kMaxGravity)
    throw std::invalid_argument("gravity must be finite and at most " +
                                std::to_string(kMaxGravity) + " m/s^2");
  if (!waters_.empty()) checkGravityForWater(gravity);
  const Vec2 change = gravity - gravity_;
  gravity_ = gravity;
  settle_impulses_.clear();  // found for the old weights
  std::vector<std::size_t> resting;
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    if (balls_[i].at_rest) {
      resting.push_back(i);
      continue;
    }
    ballNow(i);  // (its course changes here)
    accelerations_[i] += change;  // its contacts are held anew at the next step
  }
  for (const std::size_t i : resting) wake(i);  // (takes the new gravity)
}

void World::addWind(const Wind& wind) {
  checkWind(wind);
  winds_.push_back(wind);
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (centreInside(wind.region, motionOf(i))) wake(i);
}

void World::addAttractor(const Attractor& attractor) {
  checkAttractor(attractor);
  attractors_.push_back(attractor);
  for (std::size_t i = 0; i < balls_.size(); ++i) wake(i);
}

void World::addWater(const Water& water) {
  checkWater(water);
  checkGravityForWater(gravity_);
  waters_.push_back(water);
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (centreInside(wettedRegion(water, balls_[i].radius), motionOf(i))) wake(i);
}

bool World::drive(BallId id, const Vec2& acceleration) {
  if (!acceleration.allFinite() || acceleration.norm() > kMaxGravity)
    throw std::invalid_argument("drive's acceleration must be finite and at most " +
                                std::to_string(kMaxGravity) + " m/s^2, got (" +
                                std::to_string(acceleration.x()) + ", " +
                                std::to_string(acceleration.y()) + ")");
  const std::optional<std::size_t> i = indexOf(id);
  if (!i) return false;
  if (drives_[*i] == acceleration) return true;
  const Vec2 change = acceleration - drives_[*i];
  drives_[*i] = acceleration;
  if (balls_[*i].at_rest)
    wake(*i);  // which gives it its free acceleration
  else
    accelerations_[*i] += change;  // its contacts are held anew at the next step
  return true;
}

std::vector<BallId> World::explode(const Blast& blast, double max_speed) {
  checkBlast(blast);
  max_speed = std::min(max_speed, kMaxSpeed);
  std::vector<std::pair<std::size_t, Vec2>> pushed;  // ball, its velocity after the blast
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    const Vec2 impulse = blastImpulse(blast, balls_[i].position);
    if (impulse == Vec2::Zero()) continue;
    const Vec2 velocity = motionOf(i).velocity + impulse / balls_[i].mass;
    if (!(velocity.norm() <= max_speed))
      throw std::invalid_argument("the blast would throw ball " + std::to_string(balls_[i].id) +
                                  " faster than " + std::to_string(max_speed) + " m/s");
    pushed.emplace_back(i, velocity);
  }
  std::vector<BallId> ids;
  for (const auto& [i, velocity] : pushed) {
    wake(i);
    balls_[i].velocity = velocity;
    ids.push_back(balls_[i].id);
  }
  if (!ids.empty()) retryJams();
  return ids;
}

Vec2 World::freeAcceleration(std::size_t ball) const {
  const Vec2 acceleration = gravity_ + steadyPush(ball);
  // No motion to look at: the common case, per event.
  if (attractors_.empty() && waters_.empty()) return acceleration;
  const Motion middle = middleOfStretch(ball, fieldStretchOf(ball), acceleration);
  return acceleration + fieldPull(ball, middle.position, middle.velocity);
}

Motion World::middleOfStretch(std::size_t ball, double stretch, const Vec2& steady) const {
  const Motion motion = motionOf(ball);
  const Vec2 start = steady + fieldPull(ball, motion.position, motion.velocity);
  const double half = 0.5 * stretch;
  return {motion.position + half * (motion.velocity + 0.5 * half * start),
          motion.velocity + half * start};
}

Vec2 World::steadyPush(std::size_t ball) const {
  Vec2 push = drives_[ball];
  if (winds_.empty()) return push;
  const Motion motion = motionOf(ball);
  for (const Wind& wind : winds_)
    if (centreInside(wind.region, motion)) push += wind.acceleration;
  return push;
}

Vec2 World::settlePull(std::size_t ball, double duration) const {
  const Vec2 pull = gravity_ + steadyPush(ball);
  if (attractors_.empty() && waters_.empty()) return pull;
  // At the stretch's middle, where the pull at its start takes the ball: taken where the ball
  // was, it would pump energy into a pile bobbing on water (pushing a float rising too hard,
  // one sinking too little). But a stiff float's where it is: its buoyancy's fall is taken from
  // there (settledFreeVelocity), and a middle foreseen from its start would overshoot.
  const Vec2 at = stiffFloat(ball, duration) ? ballNow(ball).position
                                             : middleOfStretch(ball, duration, pull).position;
  return pull + fieldPull(ball, at, Vec2::Zero());
}

WaterStiffness World::waterStiffnessOf(std::size_t ball) const {
  const Ball& b = ballNow(ball);
  WaterStiffness stiffness;
  for (const Water& water : waters_) {
    const WaterStiffness own = waterStiffness(water, b, b.position, gravity_.norm());
    stiffness.drag += own.drag;
    stiffness.buoyancy += own.buoyancy;
  }
  return stiffness;
}

bool World::stiffFloat(std::size_t ball, double duration) const {
  return !waters_.empty() && stiffness(waterStiffnessOf(ball).buoyancy, duration) > 0.0;
}

Vec2 World::settledFreeVelocity(std::size_t ball, double duration) const {
  const Vec2 velocity = ballNow(ball).velocity + duration * settlePull(ball, duration);
  if (waters_.empty()) return velocity;
  // Drag as it will be at the stretch's end (backward Euler): taken from its start, drag
  // stronger than 2 / duration would reverse the velocity, and grow it, at each step. So too a
  // stiff float's buoyancy's fall as it rises (omega = sqrt(stiffness)): from its start, one
  // with omega duration >= 2 would swing wider at each step. (A softer float's steps are
  // stable, and are left explicit: damped, a pile on floats in fields.yaml's pond kept churning
  // in a run where explicit steps let it sleep.)
  const WaterStiffness water = waterStiffnessOf(ball);
  const double slowed = 1.0 + water.drag * duration;
  return {velocity.x() / slowed, velocity.y() / (slowed + stiffness(water.buoyancy, duration))};
}

Vec2 World::fieldPull(std::size_t ball, const Vec2& position, const Vec2& velocity) const {
  Vec2 pull = Vec2::Zero();
  for (const Attractor& attractor : attractors_) pull += attraction(attractor, position);
  for (const Water& water : waters_)
    pull += waterAcceleration(water, ballNow(ball), position, velocity, gravity_.norm());
  return pull;
}

double World::fieldStretchOf(std::size_t ball) const {
  const Ball& b = ballNow(ball);
  const Vec2 acceleration = gravity_ + drives_[ball] + fieldPull(ball, b.position, b.velocity);
  const Motion start{b.position, b.velocity, acceleration};
  // Not into water it is not in yet: its push there starts only at the crossing.
  double stretch = step_left_;
  for (const Water& water : waters_)
    if (const auto crossing = timeToCrossRegion(wettedRegion(water, b.radius), start, stretch))
      stretch = *crossing;
  auto rateAt = [&](double t) {
    const Vec2 p = start.positionAt(t), v = start.velocityAt(t);
    Vec2 rate = Vec2::Zero();
    for (const Attractor& attractor : attractors_) rate += attractionRate(attractor, p, v);
    for (const Water& water : waters_)
      rate += waterAccelerationRate(water, b, p, v, acceleration, gravity_.norm());
    return rate;
  };
  // The pull's rate where the stretch starts and where its middle is: a ball at rest or
  // turning back has none at the start, but gathers it on the way.
  stretch = std::min(stretch, fieldStretch(rateAt(0.0)));
  for (int refinement = 0; refinement < kStretchRefinements; ++refinement)
    stretch = std::min(stretch, fieldStretch(rateAt(0.5 * stretch)));
  return std::max(stretch, kShortestHold);
}

bool World::pushedSideways(std::size_t ball) const { return freeAcceleration(ball) != gravity_; }

}  // namespace ball_physics_sim::engine
