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

std::string format(const engine::Vec2& v) { return "(" + format(v.x()) + ", " + format(v.y()) + ")"; }

}  // namespace ball_physics_sim
