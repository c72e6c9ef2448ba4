#include <cmath>
#include <fstream>
#include <initializer_list>
#include <iomanip>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "ball_physics_sim/engine/scene.h"

namespace ball_physics_sim::engine {

SceneError::SceneError(const std::string& file, const std::string& key, const std::string& reason)
    : std::runtime_error(file + ": " + key + ": " + reason) {}

namespace {

// Whole numbers a scene may give (kept well within an int).
constexpr double kMostHits = 1e6;    // a brick's hits_to_break
constexpr double kMostGroups = 1e6;  // a ball's group

std::string indexed(const std::string& list, std::size_t i) {
  return list + "[" + std::to_string(i) + "]";
}

std::string member(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

// Reads typed values out of one file's YAML, naming the file and key in every error.
class SceneReader {
 public:
  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw SceneError(file_, key, reason);
  }

  void requireMap(const YAML::Node& node, const std::string& path) const {
    if (!node.IsMap()) fail(path.empty() ? "(top level)" : path, "must be a mapping of keys");
  }

  // Typos must not pass silently as defaults.
  void allowOnly(const YAML::Node& map, const std::string& path,
                 std::initializer_list<const char*> keys) const {
    std::set<std::string> seen;
    for (const auto& entry : map) {
      if (!entry.first.IsScalar()) fail(path.empty() ? "(top level)" : path, "keys must be names");
      const std::string key = entry.first.as<std::string>();
      if (!seen.insert(key).second) fail(member(path, key), "given twice");
      bool known = false;
      for (const char* allowed : keys) known = known || key == allowed;
      if (!known) fail(member(path, key), "unknown key");
    }
  }

  double number(const YAML::Node& map, const std::string& path, const std::string& key,
                std::optional<double> fallback = std::nullopt) const {
    const YAML::Node node = map[key];
    if (!node) {
      if (!fallback) fail(member(path, key), "missing");
      return *fallback;
    }
    double value;
    if (!node.IsScalar() || !YAML::convert<double>::decode(node, value))
      fail(member(path, key), "must be a number");
    if (!std::isfinite(value)) fail(member(path, key), "must be finite");
    return value;
  }

  // A number that must be whole and within [low, high]; `what` says so in the error, if given.
  long wholeNumber(const YAML::Node& map, const std::string& path, const std::string& key,
                   double low, double high, std::optional<double> fallback = std::nullopt,
                   const std::string& what = "") const {
    const double value = number(map, path, key, fallback);
    if (value != std::floor(value) || value < low || value > high) {
      std::ostringstream range;
      range << std::fixed << std::setprecision(0) << "must be a whole number within [" << low
            << ", " << high << "]";
      fail(member(path, key), what.empty() ? range.str() : what);
    }
    return static_cast<long>(value);
  }

  Vec2 vector(const YAML::Node& map, const std::string& path, const std::string& key,
              std::optional<Vec2> fallback = std::nullopt) const {
    const YAML::Node node = map[key];
    if (!node) {
      if (!fallback) fail(member(path, key), "missing");
      return *fallback;
    }
    return point(node, member(path, key));
  }

  // An [x, y] at `key_path`.
  Vec2 point(const YAML::Node& node, const std::string& key_path) const {
    if (!node.IsSequence() || node.size() != 2) fail(key_path, "must be [x, y]");
    Vec2 v;
    for (std::size_t i = 0; i < 2; ++i) {
      if (!node[i].IsScalar() || !YAML::convert<double>::decode(node[i], v[i]) ||
          !std::isfinite(v[i]))
        fail(key_path, "must be [x, y] of finite numbers");
    }
    return v;
  }

  std::vector<Vec2> points(const YAML::Node& map, const std::string& path,
                           const std::string& key) const {
    const YAML::Node node = map[key];
    std::vector<Vec2> result;
    if (!node) return result;
    if (!node.IsSequence()) fail(member(path, key), "must be a list of [x, y]");
    for (std::size_t i = 0; i < node.size(); ++i)
      result.push_back(point(node[i], indexed(member(path, key), i)));
    return result;
  }

  bool flag(const YAML::Node& map, const std::string& path, const std::string& key,
            bool fallback) const {
    const YAML::Node node = map[key];
    if (!node) return fallback;
    bool value;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value))
      fail(member(path, key), "must be true or false");
    return value;
  }

  std::string text(const YAML::Node& map, const std::string& path, const std::string& key,
                   const std::string& fallback) const {
    const YAML::Node node = map[key];
    if (!node) return fallback;
    if (!node.IsScalar()) fail(member(path, key), "must be a string");
    return node.as<std::string>();
  }

  YAML::Node list(const YAML::Node& map, const std::string& key) const {
    const YAML::Node node = map[key];
    if (node && !node.IsSequence()) fail(key, "must be a list");
    return node;
  }

 private:
  std::string file_;
};

Ball readBall(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  r.requireMap(node, path);
  r.allowOnly(node, path,
              {"position", "velocity", "angular_velocity", "radius", "mass", "restitution",
               "friction", "rolling_resistance", "inertia_factor", "group"});
  Ball ball;
  ball.position = r.vector(node, path, "position");
  ball.velocity = r.vector(node, path, "velocity", Vec2::Zero());
  ball.angular_velocity = r.number(node, path, "angular_velocity", 0.0);
  ball.radius = r.number(node, path, "radius");
  ball.mass = r.number(node, path, "mass", 1.0);
  ball.restitution = r.number(node, path, "restitution", 1.0);
  ball.friction = r.number(node, path, "friction", 0.0);
  ball.rolling_resistance = r.number(node, path, "rolling_resistance", 0.0);
  ball.inertia_factor = r.number(node, path, "inertia_factor", ball.inertia_factor);
  ball.group = static_cast<int>(r.wholeNumber(node, path, "group", 0.0, kMostGroups, 0.0));
  return ball;
}

Segment readSegment(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  r.requireMap(node, path);
  r.allowOnly(node, path,
              {"start", "end", "thickness", "restitution", "friction", "rolling_resistance",
               "velocity", "angular_velocity", "pivot", "min_angle", "max_angle", "waypoints",
               "speed", "hits_to_break", "kick"});
  Segment segment;
  segment.start = r.vector(node, path, "start");
  segment.end = r.vector(node, path, "end");
  segment.thickness = r.number(node, path, "thickness", 0.0);
  segment.restitution = r.number(node, path, "restitution", 1.0);
  segment.friction = r.number(node, path, "friction", 0.0);
  segment.rolling_resistance = r.number(node, path, "rolling_resistance", 0.0);
  segment.velocity = r.vector(node, path, "velocity", Vec2::Zero());
  segment.angular_velocity = r.number(node, path, "angular_velocity", 0.0);
  segment.pivot = r.vector(node, path, "pivot", segment.start);
  segment.min_angle = r.number(node, path, "min_angle", segment.min_angle);
  segment.max_angle = r.number(node, path, "max_angle", segment.max_angle);
  segment.waypoints = r.points(node, path, "waypoints");
  if (!segment.waypoints.empty() && node["velocity"])
    r.fail(member(path, "velocity"), "not with waypoints: their speed sets it");
  segment.speed = r.number(node, path, "speed", 0.0);
  segment.kick = r.number(node, path, "kick", 0.0);
  segment.hits_to_break =
      static_cast<int>(r.wholeNumber(node, path, "hits_to_break", 0.0, kMostHits, 0.0));
  return segment;
}

Region readRegion(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  return {r.vector(node, path, "min"), r.vector(node, path, "max")};
}

Wind readWind(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  r.requireMap(node, path);
  r.allowOnly(node, path, {"min", "max", "acceleration"});
  return {readRegion(r, node, path), r.vector(node, path, "acceleration")};
}

Attractor readAttractor(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  r.requireMap(node, path);
  r.allowOnly(node, path, {"centre", "strength", "core"});
  return {r.vector(node, path, "centre"), r.number(node, path, "strength"),
          r.number(node, path, "core", 0.0)};
}

Water readWater(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  r.requireMap(node, path);
  r.allowOnly(node, path, {"min", "max", "density", "drag"});
  return {readRegion(r, node, path), r.number(node, path, "density", 1000.0),
          r.number(node, path, "drag", 0.0)};
}

Sensor readSensor(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  r.requireMap(node, path);
  r.allowOnly(node, path, {"name", "min", "max", "pocket"});
  Sensor sensor{r.text(node, path, "name", ""), readRegion(r, node, path),
                r.flag(node, path, "pocket", false)};
  if (sensor.name.empty()) r.fail(member(path, "name"), "missing");
  return sensor;
}

// A rope's ends are balls of the scene, by their number in `balls` counting from 1 (their ids).
// Its length is by default the distance between its ends: it starts taut.
Rope readRope(const SceneReader& r, const YAML::Node& node, const std::string& path,
              const World& world) {
  r.requireMap(node, path);
  r.allowOnly(node, path, {"ball", "other_ball", "anchor", "length", "restitution"});
  auto ballNumber = [&](const std::string& key) {
    const std::size_t balls = world.balls().size();
    return static_cast<BallId>(
        r.wholeNumber(node, path, key, 1.0, double(balls), std::nullopt,
                      "must be the number of a ball in balls, from 1 to " + std::to_string(balls)));
  };
  if (node["other_ball"].IsDefined() == node["anchor"].IsDefined())
    r.fail(path, "needs one of other_ball and anchor: what the ball is tied to");
  Rope rope;
  rope.ball = ballNumber("ball");
  if (node["other_ball"]) rope.other_ball = ballNumber("other_ball");
  rope.anchor = r.vector(node, path, "anchor", Vec2::Zero());
  const Vec2 far = rope.other_ball ? world.findBall(*rope.other_ball)->position : rope.anchor;
  rope.length = r.number(node, path, "length", (world.findBall(rope.ball)->position - far).norm());
  rope.restitution = r.number(node, path, "restitution", 0.0);
  return rope;
}

Launcher readLauncher(const SceneReader& r, const YAML::Node& node, const std::string& path) {
  r.requireMap(node, path);
  r.allowOnly(node, path,
              {"name", "position", "angle", "speed", "ball_radius", "ball_mass",
               "ball_restitution", "ball_friction", "ball_rolling_resistance", "ball_group"});
  Launcher launcher;
  launcher.name = r.text(node, path, "name", "");
  if (launcher.name.empty()) r.fail(member(path, "name"), "missing");
  launcher.position = r.vector(node, path, "position");
  launcher.angle = r.number(node, path, "angle", 0.0);
  launcher.speed = r.number(node, path, "speed", launcher.speed);
  if (launcher.speed <= 0.0) r.fail(member(path, "speed"), "must be > 0");
  launcher.projectile.radius = r.number(node, path, "ball_radius", 0.1);
  launcher.projectile.mass = r.number(node, path, "ball_mass", 1.0);
  launcher.projectile.restitution = r.number(node, path, "ball_restitution", 1.0);
  launcher.projectile.friction = r.number(node, path, "ball_friction", 0.0);
  launcher.projectile.rolling_resistance = r.number(node, path, "ball_rolling_resistance", 0.0);
  launcher.projectile.group =
      static_cast<int>(r.wholeNumber(node, path, "ball_group", 0.0, kMostGroups, 0.0));
  try {
    checkBall(launcher.launch(launcher.speed));
  } catch (const std::invalid_argument& e) {
    r.fail(path, std::string("its balls: ") + e.what());
  }
  return launcher;
}

// Calls add(item, key) for each item of the list `name`; a std::invalid_argument from the
// world becomes a SceneError naming the item.
template <typename Add>
void forEachItem(const SceneReader& r, const YAML::Node& root, const std::string& name, Add add) {
  const YAML::Node items = r.list(root, name);
  for (std::size_t i = 0; items && i < items.size(); ++i) {
    const std::string key = indexed(name, i);
    try {
      add(items[i], key);
    } catch (const std::invalid_argument& e) {
      r.fail(key, e.what());
    }
  }
}

World readWorld(const SceneReader& r, const YAML::Node& root) {
  try {
    return World(r.vector(root, "", "gravity", Vec2(0.0, -9.81)));
  } catch (const std::invalid_argument& e) {
    r.fail("gravity", e.what());
  }
}

}  // namespace

Scene loadScene(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw SceneError(path, "(file)", "cannot be opened");
  std::ostringstream text;
  text << file.rdbuf();
  return parseScene(text.str(), path);
}

Scene parseScene(const std::string& yaml, const std::string& file) {
  const SceneReader r(file);
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    r.fail("(file)", "is not valid YAML: " + e.msg + " at line " + std::to_string(e.mark.line + 1));
  }
  r.requireMap(root, "");
  r.allowOnly(root, "", {"name", "gravity", "wind", "attractors", "water", "sensors", "balls",
                         "segments", "ropes", "launchers"});

  Scene scene{r.text(root, "", "name", file), readWorld(r, root), {}};
  // Wind before the balls, which start with the acceleration it gives them.
  forEachItem(r, root, "wind", [&](const YAML::Node& node, const std::string& key) {
    scene.world.addWind(readWind(r, node, key));
  });
  forEachItem(r, root, "water", [&](const YAML::Node& node, const std::string& key) {
    scene.world.addWater(readWater(r, node, key));
  });
  forEachItem(r, root, "attractors", [&](const YAML::Node& node, const std::string& key) {
    scene.world.addAttractor(readAttractor(r, node, key));
  });
  // Segments first: a ball that overlaps one is an error of the ball's.
  forEachItem(r, root, "segments", [&](const YAML::Node& node, const std::string& key) {
    scene.world.addSegment(readSegment(r, node, key));
  });
  forEachItem(r, root, "balls", [&](const YAML::Node& node, const std::string& key) {
    scene.world.addBall(readBall(r, node, key));
  });
  forEachItem(r, root, "ropes", [&](const YAML::Node& node, const std::string& key) {
    scene.world.addRope(readRope(r, node, key, scene.world));
  });
  forEachItem(r, root, "sensors", [&](const YAML::Node& node, const std::string& key) {
    scene.world.addSensor(readSensor(r, node, key));
  });
  forEachItem(r, root, "launchers", [&](const YAML::Node& node, const std::string& key) {
    Launcher launcher = readLauncher(r, node, key);
    for (const Launcher& other : scene.launchers)
      if (other.name == launcher.name) r.fail(member(key, "name"), "'" + launcher.name + "' is used twice");
    scene.launchers.push_back(std::move(launcher));
  });
  return scene;
}

}  // namespace ball_physics_sim::engine
