#include "ball_physics_sim/markers.h"

#include <algorithm>
#include <cmath>

#include "ball_physics_sim/conversions.h"

namespace ball_physics_sim {

namespace {

constexpr double kLauncherArrowLength = 0.8;  // m
constexpr double kLabelHeight = 0.25;          // m, height of a capital letter
// Labels float this high above the plane, so that no ball (of a radius below it) hides them.
constexpr double kLabelElevation = 5.0;  // m
constexpr double kPredictedPathWidth = 0.03;   // m
constexpr double kRopeWidth = 0.02;            // m
constexpr double kRegionDepth = 0.01;          // m: a region's box is drawn this thin
// Handles: a ball's is a disc under it, showing as a rim wide enough to grab at the shipped
// view's 50 px/m, so that the ball's own colour (its state) stays visible.
constexpr double kRimWidth = 0.08;        // m beyond the ball's radius
constexpr double kKnobDiameter = 0.3;     // m
constexpr double kButtonSize = 0.4;       // m
constexpr double kButtonLift = 0.4;       // m above the scene's top left

// The rviz screenshot test and picture script recognise balls and segments by these colours
// (scripts/rviz_capture.py).
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

std_msgs::ColorRGBA translucent(std_msgs::ColorRGBA c, float alpha) {
  c.a = alpha;
  return c;
}

visualization_msgs::Marker label(const std::string& ns, int id, const std::string& text,
                                 const engine::Vec2& position, const std::string& frame_id,
                                 const ros::Time& stamp) {
  visualization_msgs::Marker m =
      marker(ns, id, visualization_msgs::Marker::TEXT_VIEW_FACING, frame_id, stamp);
  m.pose.position = toPoint(position);
  m.pose.position.z = kLabelElevation;
  m.scale.z = kLabelHeight;
  m.color = color(1.0f, 1.0f, 1.0f);
  m.text = text;
  return m;
}

// A region (wind, a sensor) as a thin translucent box below the plane of the balls.
visualization_msgs::Marker regionMarker(const std::string& ns, int id, const engine::Region& region,
                                        const std_msgs::ColorRGBA& colour,
                                        const std::string& frame_id, const ros::Time& stamp) {
  visualization_msgs::Marker box =
      marker(ns, id, visualization_msgs::Marker::CUBE, frame_id, stamp);
  box.pose.position = toPoint(0.5 * (region.min + region.max));
  box.pose.position.z = -kRegionDepth;
  box.scale.x = region.max.x() - region.min.x();
  box.scale.y = region.max.y() - region.min.y();
  box.scale.z = kRegionDepth;
  box.color = colour;
  return box;
}

visualization_msgs::Marker deleted(const std::string& ns, int id, const std::string& frame_id) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame_id;
  m.ns = ns;
  m.id = id;
  m.action = visualization_msgs::Marker::DELETE;
  return m;
}

// The path as a line strip and, where it ends on an impact, the ball there as a ghost.
void appendPrediction(int launcher, double radius, const engine::ShotPrediction& prediction,
                      const std::string& frame_id, const ros::Time& stamp,
                      visualization_msgs::MarkerArray& array) {
  using visualization_msgs::Marker;
  if (prediction.path.size() < 2) {
    array.markers.push_back(deleted("predicted_paths", launcher, frame_id));
  } else {
    Marker path = marker("predicted_paths", launcher, Marker::LINE_STRIP, frame_id, stamp);
    path.scale.x = kPredictedPathWidth;
    path.color = translucent(color(0.2f, 0.8f, 0.3f), 0.8f);
    for (const engine::Vec2& point : prediction.path) path.points.push_back(toPoint(point));
    array.markers.push_back(path);
  }
  if (!prediction.final_impact) {
    array.markers.push_back(deleted("predicted_hits", launcher, frame_id));
    return;
  }
  Marker ghost = marker("predicted_hits", launcher, Marker::SPHERE, frame_id, stamp);
  ghost.pose.position = toPoint(prediction.final_impact->position);
  ghost.scale.x = ghost.scale.y = ghost.scale.z = 2.0 * radius;
  ghost.color = translucent(color(0.2f, 0.8f, 0.3f), 0.4f);
  array.markers.push_back(ghost);
}

visualization_msgs::MenuEntry menuEntry(std::uint32_t id, const std::string& title,
                                        std::uint32_t parent = 0) {
  visualization_msgs::MenuEntry entry;
  entry.id = id;
  entry.parent_id = parent;
  entry.title = title;
  entry.command_type = visualization_msgs::MenuEntry::FEEDBACK;
  return entry;
}

visualization_msgs::InteractiveMarker handle(const std::string& name, const engine::Vec2& position,
                                             const std::string& frame_id) {
  visualization_msgs::InteractiveMarker m;
  m.header.frame_id = frame_id;
  m.name = name;
  m.pose = handlePose(position);
  m.scale = 1.0;
  return m;
}

// A control that shows `visual`; MOVE_PLANE moves in the plane normal to the control's x axis,
// which this orientation turns onto z: the plane of the simulation.
visualization_msgs::InteractiveMarkerControl control(std::uint8_t mode,
                                                     const visualization_msgs::Marker& visual) {
  visualization_msgs::InteractiveMarkerControl c;
  c.orientation.w = c.orientation.y = std::sqrt(0.5);
  c.interaction_mode = mode;
  c.always_visible = true;
  c.markers.push_back(visual);
  return c;
}

// A handle's shape, in the handle's own frame; yellow, which no body is drawn in.
visualization_msgs::Marker handleVisual(int type) {
  visualization_msgs::Marker m;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.color = color(1.0f, 0.85f, 0.2f);
  return m;
}

}  // namespace

void appendDeleteAll(const std::string& frame_id, visualization_msgs::MarkerArray& array) {
  visualization_msgs::Marker all = deleted("", 0, frame_id);
  all.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(all);
}

void appendBallDelete(engine::BallId id, const std::string& frame_id,
                      visualization_msgs::MarkerArray& array) {
  array.markers.push_back(deleted("balls", static_cast<int>(id), frame_id));
  array.markers.push_back(deleted("ball_labels", static_cast<int>(id), frame_id));
}

void appendRopeDelete(engine::RopeId id, const std::string& frame_id,
                      visualization_msgs::MarkerArray& array) {
  array.markers.push_back(deleted("ropes", static_cast<int>(id), frame_id));
}

void appendSegmentDelete(engine::SegmentId id, const std::string& frame_id,
                         visualization_msgs::MarkerArray& array) {
  array.markers.push_back(deleted("segments", static_cast<int>(id), frame_id));
  array.markers.push_back(deleted("segment_labels", static_cast<int>(id), frame_id));
  for (int end = 0; end < 2; ++end)
    array.markers.push_back(deleted("caps", 2 * static_cast<int>(id) + end, frame_id));
}

visualization_msgs::MarkerArray sceneMarkers(const engine::Scene& scene,
                                             const std::vector<engine::ShotPrediction>& predictions,
                                             bool labels, const std::string& frame_id,
                                             const ros::Time& stamp) {
  using visualization_msgs::Marker;
  visualization_msgs::MarkerArray array;
  for (const engine::Ball& ball : scene.world.balls()) {
    Marker m = marker("balls", static_cast<int>(ball.id), Marker::SPHERE, frame_id, stamp);
    m.pose.position = toPoint(ball.position);
    m.scale.x = m.scale.y = m.scale.z = 2.0 * ball.radius;
    m.color = ball.at_rest ? color(0.35f, 0.45f, 0.8f) : color(1.0f, 0.55f, 0.1f);
    array.markers.push_back(m);
    // Above the ball, so that the ball's own colour stays visible.
    if (labels)
      array.markers.push_back(label("ball_labels", m.id, std::to_string(ball.id),
                                    ball.position + engine::Vec2(0.0, ball.radius + kLabelHeight),
                                    frame_id, stamp));
  }
  for (const engine::Segment& segment : scene.world.segments()) {
    const double thickness = std::max(segment.thickness, kMinDrawnThickness);
    Marker body = marker("segments", static_cast<int>(segment.id), Marker::CUBE, frame_id, stamp);
    body.pose.position = toPoint(0.5 * (segment.start + segment.end));
    const engine::Vec2 d = segment.end - segment.start;
    body.pose.orientation = yawQuaternion(std::atan2(d.y(), d.x()));
    body.scale.x = segment.length();
    body.scale.y = body.scale.z = thickness;
    body.color = segment.hits_to_break > 0 ? color(0.9f, 0.3f, 0.25f) : color(0.85f, 0.85f, 0.85f);
    array.markers.push_back(body);
    for (int end = 0; end < 2; ++end) {
      Marker cap = marker("caps", 2 * static_cast<int>(segment.id) + end, Marker::SPHERE,
                          frame_id, stamp);
      cap.pose.position = toPoint(segment.cap(end));
      cap.scale.x = cap.scale.y = cap.scale.z = thickness;
      cap.color = body.color;
      array.markers.push_back(cap);
    }
    // Beside the middle, on the normal's side.
    if (labels)
      array.markers.push_back(label(
          "segment_labels", body.id, std::to_string(segment.id),
          0.5 * (segment.start + segment.end) + (0.5 * thickness + kLabelHeight) * segment.normal(),
          frame_id, stamp));
  }
  for (const engine::Rope& rope : scene.world.ropes()) {
    Marker line = marker("ropes", static_cast<int>(rope.id), Marker::LINE_STRIP, frame_id, stamp);
    line.scale.x = kRopeWidth;
    line.color = color(0.75f, 0.6f, 0.4f);
    line.points.push_back(toPoint(scene.world.findBall(rope.ball)->position));
    line.points.push_back(
        toPoint(rope.other_ball ? scene.world.findBall(*rope.other_ball)->position : rope.anchor));
    array.markers.push_back(line);
  }
  for (std::size_t i = 0; i < scene.world.winds().size(); ++i)
    array.markers.push_back(regionMarker("wind", static_cast<int>(i), scene.world.winds()[i].region,
                                         translucent(color(0.5f, 0.8f, 1.0f), 0.2f), frame_id,
                                         stamp));
  for (std::size_t i = 0; i < scene.world.waters().size(); ++i)
    array.markers.push_back(regionMarker("water", static_cast<int>(i), scene.world.waters()[i].region,
                                         translucent(color(0.1f, 0.3f, 0.8f), 0.35f), frame_id,
                                         stamp));
  for (std::size_t i = 0; i < scene.world.attractors().size(); ++i) {
    const engine::Attractor& attractor = scene.world.attractors()[i];
    Marker m = marker("attractors", static_cast<int>(i), Marker::SPHERE, frame_id, stamp);
    m.pose.position = toPoint(attractor.centre);
    m.scale.x = m.scale.y = m.scale.z = std::max(2.0 * attractor.core, kMinDrawnThickness);
    m.color = translucent(color(0.8f, 0.3f, 0.9f), 0.6f);
    array.markers.push_back(m);
  }
  for (std::size_t i = 0; i < scene.world.sensors().size(); ++i) {
    const engine::Sensor& sensor = scene.world.sensors()[i];
    array.markers.push_back(regionMarker("sensors", static_cast<int>(i), sensor.region,
                                         translucent(color(0.3f, 0.9f, 0.3f), 0.25f), frame_id,
                                         stamp));
    if (labels)
      array.markers.push_back(label("sensor_labels", static_cast<int>(i), sensor.name,
                                    engine::Vec2(0.5 * (sensor.region.min.x() + sensor.region.max.x()),
                                                 sensor.region.max.y() + kLabelHeight),
                                    frame_id, stamp));
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
  for (std::size_t i = 0; i < predictions.size(); ++i)
    appendPrediction(static_cast<int>(i), scene.launchers[i].projectile.radius, predictions[i],
                     frame_id, stamp, array);
  return array;
}

std::string knobAimTitle(std::uint32_t aim_mode) {
  switch (aim_mode) {
    case kMenuAimStraight:
      return "straight at the knob";
    case kMenuLobLow:
      return "in a low arc to the knob";
    case kMenuLobHigh:
      return "in a high arc to the knob";
    default:
      return "along the knob";
  }
}

geometry_msgs::Pose handlePose(const engine::Vec2& position) {
  geometry_msgs::Pose pose;
  pose.position = toPoint(position);
  pose.orientation.w = 1.0;
  return pose;
}

engine::Vec2 aimKnobPosition(const engine::Launcher& launcher) {
  return launcher.position + (kLauncherArrowLength + 0.5 * kKnobDiameter) * launcher.aimDirection();
}

engine::Vec2 worldHandlePosition(const engine::Scene& scene) {
  std::vector<engine::Vec2> points;
  for (const engine::Segment& segment : scene.world.segments()) {
    points.push_back(segment.start);
    points.push_back(segment.end);
  }
  for (const engine::Launcher& launcher : scene.launchers) points.push_back(launcher.position);
  if (points.empty()) return engine::Vec2(0.0, kButtonLift);
  engine::Vec2 top_left = points.front();
  for (const engine::Vec2& p : points)
    top_left = engine::Vec2(std::min(top_left.x(), p.x()), std::max(top_left.y(), p.y()));
  return top_left + engine::Vec2(0.0, kButtonLift);
}

visualization_msgs::InteractiveMarker ballHandle(const engine::Ball& ball,
                                                 const std::string& frame_id) {
  using visualization_msgs::Marker;
  Marker disc = handleVisual(Marker::CYLINDER);  // along z: flat in the plane
  disc.scale.x = disc.scale.y = 2.0 * (ball.radius + kRimWidth);
  disc.scale.z = kRegionDepth;
  disc.pose.position.z = -ball.radius - kRegionDepth;
  visualization_msgs::InteractiveMarker m = handle(ballFrame(ball.id), ball.position, frame_id);
  m.controls.push_back(control(visualization_msgs::InteractiveMarkerControl::MOVE_PLANE, disc));
  m.menu_entries = {menuEntry(kMenuRemoveBall, "Remove"),
                    menuEntry(kMenuLeadBall, "Lead this ball (first launcher)")};
  return m;
}

visualization_msgs::InteractiveMarker launcherHandle(const engine::Launcher& launcher,
                                                     std::uint32_t aim_mode,
                                                     const std::string& frame_id) {
  using visualization_msgs::Marker;
  Marker knob = handleVisual(Marker::SPHERE);
  knob.scale.x = knob.scale.y = knob.scale.z = kKnobDiameter;
  visualization_msgs::InteractiveMarker m =
      handle(launcherFrame(launcher.name), aimKnobPosition(launcher), frame_id);
  m.controls.push_back(control(visualization_msgs::InteractiveMarkerControl::MOVE_PLANE, knob));
  m.menu_entries = {menuEntry(kMenuFire, "Fire"), menuEntry(kMenuAimMode, "Aim mode")};
  for (const std::uint32_t id : {kMenuAimAlong, kMenuAimStraight, kMenuLobLow, kMenuLobHigh})
    m.menu_entries.push_back(
        menuEntry(id, (id == aim_mode ? "[x] " : "[ ] ") + knobAimTitle(id), kMenuAimMode));
  return m;
}

visualization_msgs::InteractiveMarker worldHandle(const engine::Vec2& world_at,
                                                  const std::string& frame_id) {
  using visualization_msgs::Marker;
  Marker button = handleVisual(Marker::CUBE);
  button.scale.x = button.scale.y = kButtonSize;
  button.scale.z = kRegionDepth;
  visualization_msgs::InteractiveMarker m = handle(kWorldHandle, world_at, frame_id);
  m.controls.push_back(control(visualization_msgs::InteractiveMarkerControl::MENU, button));
  m.menu_entries = {menuEntry(kMenuPause, "Pause"), menuEntry(kMenuResume, "Resume")};
  return m;
}

}  // namespace ball_physics_sim
