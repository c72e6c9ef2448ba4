// World: game parts: sensors, bricks and pockets.

#include "ball_physics_sim/engine/world.h"

#include <stdexcept>
#include <string>

#include "ball_physics_sim/engine/kinematics.h"

namespace ball_physics_sim::engine {

void World::addSensor(const Sensor& sensor) {
  if (sensor.name.empty()) throw std::invalid_argument("a sensor needs a name");
  checkRegion(sensor.region, "sensor '" + sensor.name + "'");
  for (const Sensor& other : sensors_)
    if (other.name == sensor.name)
      throw std::invalid_argument("there is a sensor named '" + sensor.name + "' already");
  sensors_.push_back(sensor);
}

std::vector<SensorEvent> World::takeSensorEvents() {
  std::vector<SensorEvent> taken;
  taken.swap(sensor_events_);
  return taken;
}

std::vector<BrickHit> World::takeBrickHits() {
  std::vector<BrickHit> taken;
  taken.swap(brick_hits_);
  return taken;
}

void World::watchSensors(double from, double dt) {
  if (sensors_.empty()) return;
  const std::size_t first_new = sensor_events_.size();
  for (std::size_t i = 0; i < balls_.size(); ++i) {
    const Motion motion = motionOf(i);
    for (std::size_t s = 0; s < sensors_.size(); ++s) {
      const Region& region = sensors_[s].region;
      noteSensor(i, s, centreInside(region, motion), from);
      for (const double t : regionCrossings(region, motion, dt)) {
        const Motion then{motion.positionAt(t), motion.velocityAt(t), motion.acceleration};
        noteSensor(i, s, centreInside(region, then), from + t);
      }
    }
  }
  // In the order they happened, whichever ball they are of.
  std::stable_sort(sensor_events_.begin() + first_new, sensor_events_.end(),
                   [](const SensorEvent& a, const SensorEvent& b) { return a.time < b.time; });
}

void World::noteSensor(std::size_t ball, std::size_t s, bool inside, double time) {
  const std::pair<BallId, std::size_t> key{balls_[ball].id, s};
  if (inside == (in_sensors_.count(key) > 0)) return;
  if (inside)
    in_sensors_.insert(key);
  else
    in_sensors_.erase(key);
  sensor_events_.push_back({time, sensors_[s].name, balls_[ball].id, inside});
  if (inside && sensors_[s].pocket) pocketed_.push_back(balls_[ball].id);
}

void World::hitBrick(std::size_t segment, std::size_t ball, double time) {
  Segment& brick = segments_[segment];
  --brick.hits_to_break;
  brick_hits_.push_back({time, brick.id, balls_[ball].id, brick.hits_to_break});
  if (brick.hits_to_break == 0) broken_bricks_.push_back(brick.id);
}

void World::removeBrokenAndPocketed() {
  for (const SegmentId id : broken_bricks_) removeSegment(id);
  broken_bricks_.clear();
  for (const BallId id : pocketed_) removeBall(id);
  pocketed_.clear();
}

}  // namespace ball_physics_sim::engine
