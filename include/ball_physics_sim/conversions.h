#pragma once

#include <string>

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Vector3.h>

#include "ball_physics_sim/AddSegment.h"
#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/BallState.h"
#include "ball_physics_sim/BrickHit.h"
#include "ball_physics_sim/Contact.h"
#include "ball_physics_sim/Explode.h"
#include "ball_physics_sim/SensorEvent.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ball_physics_sim/engine/aim_request.h"
#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/contact.h"
#include "ball_physics_sim/engine/forces.h"
#include "ball_physics_sim/engine/format.h"
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
// The mode passes as it is: the engine refuses one it does not know.
engine::AimRequest toAimRequest(const Aim::Request& request);

// The names of a ball's and a launcher's tf frames, which their interactive markers share.
constexpr char kBallFramePrefix[] = "ball_";
constexpr char kLauncherFramePrefix[] = "launcher_";
std::string ballFrame(engine::BallId id);
std::string launcherFrame(const std::string& launcher);

// Numbers in service answers and errors are written as the engine writes its own.
using engine::format;

}  // namespace ball_physics_sim
