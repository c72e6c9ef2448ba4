#include "ball_physics_sim/conversions.h"

#include <cmath>

namespace ball_physics_sim {

geometry_msgs::Point toPoint(const engine::Vec2& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  return p;
}

geometry_msgs::Vector3 toVector3(const engine::Vec2& v) {
  geometry_msgs::Vector3 w;
  w.x = v.x();
  w.y = v.y();
  return w;
}

engine::Vec2 toVec2(const geometry_msgs::Point& p) { return {p.x, p.y}; }

engine::Vec2 toVec2(const geometry_msgs::Vector3& v) { return {v.x, v.y}; }

geometry_msgs::Quaternion yawQuaternion(double angle) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(0.5 * angle);
  q.w = std::cos(0.5 * angle);
  return q;
}

std::string ballFrame(engine::BallId id) { return kBallFramePrefix + std::to_string(id); }

std::string launcherFrame(const std::string& launcher) { return kLauncherFramePrefix + launcher; }

BallState toMsg(const engine::Ball& ball) {
  BallState msg;
  msg.id = ball.id;
  msg.position = toPoint(ball.position);
  msg.velocity = toVector3(ball.velocity);
  msg.angular_velocity = ball.angular_velocity;
  msg.radius = ball.radius;
  msg.mass = ball.mass;
  msg.at_rest = ball.at_rest;
  return msg;
}

namespace {

std::uint8_t toMsg(engine::ContactKind kind) {
  switch (kind) {
    case engine::ContactKind::kBall: return Contact::BALL;
    case engine::ContactKind::kSegment: return Contact::SEGMENT;
    case engine::ContactKind::kCap: return Contact::CAP;
    case engine::ContactKind::kRope: break;  // never reported
  }
  return Contact::BALL;
}

}  // namespace

Contact toMsg(const engine::Contact& contact) {
  Contact msg;
  msg.time = contact.time;
  msg.ball_id = contact.ball_id;
  msg.other_kind = toMsg(contact.other_kind);
  msg.other_id = contact.other_id;
  msg.point = toPoint(contact.point);
  msg.normal = toVector3(contact.normal);
  msg.approach_speed = contact.approach_speed;
  msg.impulse = contact.impulse;
  return msg;
}

SensorEvent toMsg(const engine::SensorEvent& event) {
  SensorEvent msg;
  msg.time = event.time;
  msg.sensor = event.sensor;
  msg.ball_id = event.ball;
  msg.entered = event.entered;
  return msg;
}

BrickHit toMsg(const engine::BrickHit& hit) {
  BrickHit msg;
  msg.time = hit.time;
  msg.segment_id = hit.segment;
  msg.ball_id = hit.ball;
  msg.hits_left = static_cast<std::uint32_t>(hit.hits_left);
  return msg;
}

engine::Ball toBall(const SpawnBall::Request& request) {
  engine::Ball ball;
  ball.position = toVec2(request.position);
  ball.velocity = toVec2(request.velocity);
  ball.angular_velocity = request.angular_velocity;
  ball.radius = request.radius;
  ball.mass = request.mass;
  ball.restitution = request.restitution;
  ball.friction = request.friction;
  ball.rolling_resistance = request.rolling_resistance;
  if (request.inertia_factor != 0.0) ball.inertia_factor = request.inertia_factor;
  return ball;
}

engine::Segment toSegment(const AddSegment::Request& request) {
  engine::Segment segment;
  segment.start = toVec2(request.start);
  segment.end = toVec2(request.end);
  segment.pivot = segment.start;  // what set_segment_motion turns it about
  segment.thickness = request.thickness;
  segment.restitution = request.restitution;
  segment.friction = request.friction;
  segment.rolling_resistance = request.rolling_resistance;
  return segment;
}

engine::Blast toBlast(const Explode::Request& request) {
  return {toVec2(request.centre), request.impulse, request.radius};
}

// The service's mode constants are the engine's modes.
static_assert(Aim::Request::ANGLE == int(engine::AimMode::kAngle) &&
              Aim::Request::TARGET == int(engine::AimMode::kTarget) &&
              Aim::Request::TARGET_BALLISTIC == int(engine::AimMode::kTargetBallistic) &&
              Aim::Request::LEAD_BALL == int(engine::AimMode::kLeadBall) &&
              Aim::Request::TIMED == int(engine::AimMode::kTimed) &&
              Aim::Request::BANK == int(engine::AimMode::kBank));

engine::AimRequest toAimRequest(const Aim::Request& request) {
  engine::AimRequest aim;
  aim.mode = static_cast<engine::AimMode>(request.mode);
  aim.angle = request.angle;
  aim.target = toVec2(request.target);
  aim.target_ball = request.target_ball_id;
  aim.speed = request.speed;
  aim.high_arc = request.high_arc;
  aim.time_of_flight = request.time_of_flight;
  return aim;
}

}  // namespace ball_physics_sim
