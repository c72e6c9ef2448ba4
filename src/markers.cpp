#include "ball_physics_sim/markers.h"

#include <algorithm>
#include <cmath>

#include "ball_physics_sim/conversions.h"

namespace ball_physics_sim {

namespace {

// Segments of zero thickness are drawn this thick so that they can be seen.
constexpr double kMinDrawnThickness = 0.04;  // m
constexpr double kLauncherArrowLength = 0.8;  // m

std_msgs::ColorRGBA color(float r, float g, float b) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = 1.0f;
  return c;
}

visualization_msgs::Marker marker(const std::string& ns, int id, int type,
                                  const std::string& frame_id, const ros::Time& stamp) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame_id;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  return m;
}

visualization_msgs::Marker deleted(const std::string& ns, int id, const std::string& frame_id) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame_id;
  m.ns = ns;
  m.id = id;
  m.action = visualization_msgs::Marker::DELETE;
  return m;
}

}  // namespace

void appendBallDelete(engine::BallId id, const std::string& frame_id,
                      visualization_msgs::MarkerArray& array) {
  array.markers.push_back(deleted("balls", static_cast<int>(id), frame_id));
}

void appendSegmentDelete(engine::SegmentId id, const std::string& frame_id,
                         visualization_msgs::MarkerArray& array) {
  array.markers.push_back(deleted("segments", static_cast<int>(id), frame_id));
  for (int end = 0; end < 2; ++end)
    array.markers.push_back(deleted("caps", 2 * static_cast<int>(id) + end, frame_id));
}

visualization_msgs::MarkerArray sceneMarkers(const engine::Scene& scene, const std::string& frame_id,
                                             const ros::Time& stamp) {
  using visualization_msgs::Marker;
  visualization_msgs::MarkerArray array;
  for (const engine::Ball& ball : scene.world.balls()) {
    Marker m = marker("balls", static_cast<int>(ball.id), Marker::SPHERE, frame_id, stamp);
    m.pose.position = toPoint(ball.position);
    m.scale.x = m.scale.y = m.scale.z = 2.0 * ball.radius;
    m.color = ball.at_rest ? color(0.35f, 0.45f, 0.8f) : color(1.0f, 0.55f, 0.1f);
    array.markers.push_back(m);
  }
  for (const engine::Segment& segment : scene.world.segments()) {
    const double thickness = std::max(segment.thickness, kMinDrawnThickness);
    Marker body = marker("segments", static_cast<int>(segment.id), Marker::CUBE, frame_id, stamp);
    body.pose.position = toPoint(0.5 * (segment.start + segment.end));
    const engine::Vec2 d = segment.end - segment.start;
    body.pose.orientation = yawQuaternion(std::atan2(d.y(), d.x()));
    body.scale.x = segment.length();
    body.scale.y = body.scale.z = thickness;
    body.color = color(0.85f, 0.85f, 0.85f);
    array.markers.push_back(body);
    for (int end = 0; end < 2; ++end) {
      Marker cap = marker("caps", 2 * static_cast<int>(segment.id) + end, Marker::SPHERE,
                          frame_id, stamp);
      cap.pose.position = toPoint(segment.cap(end));
      cap.scale.x = cap.scale.y = cap.scale.z = thickness;
      cap.color = body.color;
      array.markers.push_back(cap);
    }
  }
  for (std::size_t i = 0; i < scene.launchers.size(); ++i) {
    const engine::Launcher& launcher = scene.launchers[i];
    Marker arrow = marker("launchers", static_cast<int>(i), Marker::ARROW, frame_id, stamp);
    arrow.pose.position = toPoint(launcher.position);
    arrow.pose.orientation = yawQuaternion(launcher.angle);
    arrow.scale.x = kLauncherArrowLength;
    arrow.scale.y = arrow.scale.z = 2.0 * launcher.projectile.radius;
    arrow.color = color(0.2f, 0.8f, 0.3f);
    array.markers.push_back(arrow);
  }
  return array;
}

}  // namespace ball_physics_sim
