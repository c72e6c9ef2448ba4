#pragma once

#include <sstream>
#include <string>

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Vector3.h>

#include "ball_physics_sim/AddSegment.h"
#include "ball_physics_sim/BallState.h"
#include "ball_physics_sim/BrickHit.h"
#include "ball_physics_sim/Contact.h"
#include "ball_physics_sim/Explode.h"
#include "ball_physics_sim/SensorEvent.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/contact.h"
#include "ball_physics_sim/engine/forces.h"
#include "ball_physics_sim/engine/region.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim {

// Engine types <-> messages; the plane of the simulation is z = 0.
geometry_msgs::Point toPoint(const engine::Vec2& v);
geometry_msgs::Vector3 toVector3(const engine::Vec2& v);
engine::Vec2 toVec2(const geometry_msgs::Point& p);
engine::Vec2 toVec2(const geometry_msgs::Vector3& v);
// A rotation by `angle` (rad) about z.
geometry_msgs::Quaternion yawQuaternion(double angle);
BallState toMsg(const engine::Ball& ball);
Contact toMsg(const engine::Contact& contact);
SensorEvent toMsg(const engine::SensorEvent& event);
BrickHit toMsg(const engine::BrickHit& hit);
engine::Ball toBall(const SpawnBall::Request& request);
engine::Segment toSegment(const AddSegment::Request& request);
engine::Blast toBlast(const Explode::Request& request);

// Numbers in service answers and errors, in the shortest form that reads well ("9", "9.93194").
template <typename T>
std::string format(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}
// A point or vector as "(x, y)".
std::string format(const engine::Vec2& v);

}  // namespace ball_physics_sim
