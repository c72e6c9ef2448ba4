#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/scene.h"

using namespace ball_physics_sim::engine;

namespace {

std::string writeScene(const std::string& name, const std::string& yaml) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << yaml;
  return path;
}

// The message loadScene throws for `yaml`.
std::string errorFor(const std::string& yaml) {
  const std::string path = writeScene("bad.yaml", yaml);
  try {
    loadScene(path);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(SceneLoader, LoadsTheDefaultScene) {
  const Scene scene = loadScene(SCENES_DIR "/default.yaml");
  EXPECT_EQ(scene.name, "default");
  EXPECT_EQ(scene.world.gravity(), Vec2(0.0, -9.81));
  EXPECT_EQ(scene.world.segments().size(), 7u);
  EXPECT_EQ(scene.world.balls().size(), 6u);
  ASSERT_EQ(scene.launchers.size(), 1u);
  EXPECT_EQ(scene.launchers[0].name, "cannon");
  EXPECT_DOUBLE_EQ(scene.launchers[0].speed, 9.0);
  EXPECT_DOUBLE_EQ(scene.launchers[0].projectile.radius, 0.2);
}

TEST(SceneLoader, LoadsEveryShippedSceneUnderItsFileName) {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(SCENES_DIR)) {
    if (entry.path().extension() != ".yaml") continue;
    EXPECT_EQ(loadScene(entry.path().string()).name, entry.path().stem().string());
    ++scenes;
  }
  EXPECT_GE(scenes, 6);
}

TEST(SceneLoader, ReadsEveryKeyOfABall) {
  const Scene scene = loadScene(writeScene("ball.yaml", R"(
gravity: [0, 0]
balls:
  - {position: [1, 2], velocity: [3, 4], angular_velocity: 5, radius: 0.5, mass: 2,
     restitution: 0.25, friction: 0.75, rolling_resistance: 0.05, inertia_factor: 0.5,
     group: 7}
segments:
  - {start: [-5, 0], end: [5, 0], thickness: 0.1, restitution: 0.5, friction: 0.4,
     rolling_resistance: 0.02}
launchers:
  - {name: a, position: [0, 4], ball_friction: 0.3, ball_rolling_resistance: 0.01,
     ball_group: 2}
)"));
  const Ball& b = scene.world.balls().at(0);
  EXPECT_EQ(b.position, Vec2(1.0, 2.0));
  EXPECT_EQ(b.velocity, Vec2(3.0, 4.0));
  EXPECT_EQ(b.angular_velocity, 5.0);
  EXPECT_EQ(b.radius, 0.5);
  EXPECT_EQ(b.mass, 2.0);
  EXPECT_EQ(b.restitution, 0.25);
  EXPECT_EQ(b.friction, 0.75);
  EXPECT_EQ(b.rolling_resistance, 0.05);
  EXPECT_EQ(b.inertia_factor, 0.5);
  EXPECT_EQ(b.group, 7);
  const Segment& s = scene.world.segments().at(0);
  EXPECT_EQ(s.thickness, 0.1);
  EXPECT_EQ(s.restitution, 0.5);
  EXPECT_EQ(s.friction, 0.4);
  EXPECT_EQ(s.rolling_resistance, 0.02);
  EXPECT_EQ(scene.launchers.at(0).projectile.friction, 0.3);
  EXPECT_EQ(scene.launchers.at(0).projectile.rolling_resistance, 0.01);
  EXPECT_EQ(scene.launchers.at(0).projectile.group, 2);
}

TEST(SceneLoader, ReadsAKinematicSegment) {
  const Scene scene = loadScene(writeScene("kinematic.yaml", R"(
segments:
  - {start: [0, 0], end: [1, 0], angular_velocity: -2, min_angle: -0.5, max_angle: 0.25}
  - {start: [0, 2], end: [1, 2], pivot: [0.5, 2], waypoints: [[0.5, 2], [0.5, 4]], speed: 3}
  - {start: [0, 5], end: [1, 5], velocity: [1, -1]}
)"));
  const Segment& flipper = scene.world.segments().at(0);
  EXPECT_EQ(flipper.pivot, Vec2(0.0, 0.0));  // the start, unless given
  EXPECT_EQ(flipper.angular_velocity, -2.0);
  EXPECT_EQ(flipper.min_angle, -0.5);
  EXPECT_EQ(flipper.max_angle, 0.25);
  const Segment& platform = scene.world.segments().at(1);
  EXPECT_EQ(platform.pivot, Vec2(0.5, 2.0));
  ASSERT_EQ(platform.waypoints.size(), 2u);
  EXPECT_EQ(platform.waypoints[1], Vec2(0.5, 4.0));
  EXPECT_EQ(platform.velocity, Vec2(0.0, 3.0));  // on its way to the second: it is on the first
  EXPECT_EQ(scene.world.segments().at(2).velocity, Vec2(1.0, -1.0));
  const std::string file = ::testing::TempDir() + "bad.yaml";
  EXPECT_EQ(errorFor("segments:\n  - {start: [0, 0], end: [1, 0], waypoints: [[0, 0], [1]], "
                     "speed: 1}\n"),
            file + ": segments[0].waypoints[1]: must be [x, y]");
  EXPECT_EQ(errorFor("segments:\n  - {start: [0, 0], end: [1, 0], waypoints: [[0, 0], [1, 0]]}\n"),
            file + ": segments[0]: speed along waypoints must be within (0, 100000.000000] m/s");
  EXPECT_EQ(errorFor("segments:\n  - {start: [0, 0], end: [1, 0], velocity: [1, 0], "
                     "waypoints: [[0, 0], [1, 0]], speed: 1}\n"),
            file + ": segments[0].velocity: not with waypoints: their speed sets it");
}

TEST(SceneLoader, ErrorsNameTheFileTheKeyAndTheReason) {
  const std::string file = ::testing::TempDir() + "bad.yaml";
  EXPECT_EQ(errorFor("balls:\n  - {position: [0, 0], radius: -1}\n"),
            file + ": balls[0]: radius must be > 0, got -1.000000");
  EXPECT_EQ(errorFor("balls:\n  - {position: [0, 0], radius: 1, colour: red}\n"),
            file + ": balls[0].colour: unknown key");
  EXPECT_EQ(errorFor("balls:\n  - {radius: 1}\n"), file + ": balls[0].position: missing");
  EXPECT_EQ(errorFor("balls:\n  - {position: [0, 0], radius: 1, radius: 2}\n"),
            file + ": balls[0].radius: given twice");
  EXPECT_EQ(errorFor("? [a, b]\n: 1\n"), file + ": (top level): keys must be names");
  EXPECT_EQ(errorFor("gravity: [0, down]\n"), file + ": gravity: must be [x, y] of finite numbers");
  EXPECT_EQ(errorFor("segments:\n  - {start: [0, 0], end: [0, 0]}\n"),
            file + ": segments[0]: segment start and end must differ");
  EXPECT_EQ(errorFor("launchers:\n  - {name: a, position: [0, 0], speed: -2}\n"),
            file + ": launchers[0].speed: must be > 0");
  EXPECT_EQ(errorFor("segments:\n  - {start: [0, 0], end: [1, 0], friction: -0.5}\n"),
            file + ": segments[0]: friction must be finite and >= 0, got -0.500000");
  EXPECT_EQ(errorFor("balls:\n  - {position: [0, 0], radius: 1, inertia_factor: 1.5}\n"),
            file + ": balls[0]: inertia factor must be within (0, 1], got 1.500000");
  EXPECT_EQ(errorFor("launchers:\n  - {name: a, position: [0, 0], ball_mass: 0}\n"),
            file + ": launchers[0]: its balls: mass must be > 0, got 0.000000");
  EXPECT_EQ(errorFor("balls:\n  - {position: [0, 0], radius: 1}\n  - {position: [1, 0], radius: 1}\n"),
            file + ": balls[1]: ball would overlap ball 1");
  EXPECT_EQ(errorFor("balls:\n  - {position: [0, 0], radius: 1, group: -1}\n"),
            file + ": balls[0].group: must be a whole number within [0, 1000000]");
}

TEST(SceneLoader, MissingFileAndBrokenYamlAreReported) {
  try {
    loadScene("/nonexistent/scene.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/scene.yaml: (file): cannot be opened");
  }
  const std::string message = errorFor("balls: [\n");
  EXPECT_NE(message.find(": (file): is not valid YAML"), std::string::npos) << message;
}

TEST(SceneLoader, ReadsWindAndNamesWhatIsWrongWithIt) {
  const Scene scene = loadScene(writeScene("wind.yaml", R"(
wind:
  - {min: [-1, 0], max: [1, 3], acceleration: [0, 12]}
)"));
  ASSERT_EQ(scene.world.winds().size(), 1u);
  EXPECT_EQ(scene.world.winds()[0].region.min, Vec2(-1.0, 0.0));
  EXPECT_EQ(scene.world.winds()[0].region.max, Vec2(1.0, 3.0));
  EXPECT_EQ(scene.world.winds()[0].acceleration, Vec2(0.0, 12.0));
  const std::string path = ::testing::TempDir() + "bad.yaml";
  EXPECT_EQ(errorFor("wind:\n  - {min: [1, 0], max: [-1, 3], acceleration: [0, 1]}\n"),
            path + ": wind[0]: wind's min corner must be below and left of its max corner");
  EXPECT_EQ(errorFor("wind:\n  - {min: [-1, 0], max: [1, 3]}\n"),
            path + ": wind[0].acceleration: missing");
  EXPECT_EQ(errorFor("wind:\n  - {min: [-1, 0], max: [1, 3], acceleration: [0, 1], speed: 2}\n"),
            path + ": wind[0].speed: unknown key");
}

TEST(SceneLoader, ReadsSensorsAndBricksAndNamesWhatIsWrongWithThem) {
  const Scene scene = loadScene(writeScene("goals.yaml", R"(
sensors:
  - {name: goal, min: [4, 0], max: [5, 1]}
segments:
  - {start: [0, 3], end: [1, 3], hits_to_break: 3}
)"));
  ASSERT_EQ(scene.world.sensors().size(), 1u);
  EXPECT_EQ(scene.world.sensors()[0].name, "goal");
  EXPECT_EQ(scene.world.sensors()[0].region.min, Vec2(4.0, 0.0));
  EXPECT_EQ(scene.world.sensors()[0].region.max, Vec2(5.0, 1.0));
  EXPECT_EQ(scene.world.segments().at(0).hits_to_break, 3);
  const std::string path = ::testing::TempDir() + "bad.yaml";
  EXPECT_EQ(errorFor("sensors:\n  - {min: [4, 0], max: [5, 1]}\n"), path + ": sensors[0].name: missing");
  EXPECT_EQ(errorFor("sensors:\n  - {name: a, min: [4, 0], max: [5, 1]}\n  - {name: a, min: [6, 0], max: [7, 1]}\n"),
            path + ": sensors[1]: there is a sensor named 'a' already");
  EXPECT_EQ(errorFor("segments:\n  - {start: [0, 3], end: [1, 3], hits_to_break: 1.5}\n"),
            path + ": segments[0].hits_to_break: must be a whole number within [0, 1000000]");
}

TEST(SceneLoader, ReadsAttractorsAndWater) {
  const Scene scene = loadScene(writeScene("attractors.yaml", R"(
gravity: [0, 0]
attractors:
  - {centre: [1, 2], strength: 3, core: 0.5}
water:
  - {min: [-4, -2], max: [4, 0], density: 800, drag: 2}
)"));
  ASSERT_EQ(scene.world.waters().size(), 1u);
  EXPECT_EQ(scene.world.waters()[0].region.max, Vec2(4.0, 0.0));
  EXPECT_EQ(scene.world.waters()[0].density, 800.0);
  EXPECT_EQ(scene.world.waters()[0].drag, 2.0);
  ASSERT_EQ(scene.world.attractors().size(), 1u);
  EXPECT_EQ(scene.world.attractors()[0].centre, Vec2(1.0, 2.0));
  EXPECT_EQ(scene.world.attractors()[0].strength, 3.0);
  EXPECT_EQ(scene.world.attractors()[0].core, 0.5);
  EXPECT_EQ(errorFor("attractors:\n  - {centre: [1, 2], strength: -3}\n"),
            ::testing::TempDir() + "bad.yaml: attractors[0]: attractor's strength must be finite "
                                   "and >= 0, got -3.000000");
}

TEST(SceneLoader, ReadsRopesAndNamesWhatIsWrongWithThem) {
  // By default a rope is as long as its ends are apart.
  const Scene scene = loadScene(writeScene("ropes.yaml", R"(
balls:
  - {position: [0, -3], radius: 0.1}
  - {position: [0, -5], radius: 0.1}
ropes:
  - {ball: 1, anchor: [0, 1]}
  - {ball: 2, other_ball: 1, length: 2.5, restitution: 0.3}
)"));
  ASSERT_EQ(scene.world.ropes().size(), 2u);
  const Rope& hung = scene.world.ropes()[0];
  EXPECT_EQ(hung.ball, 1u);
  EXPECT_FALSE(hung.other_ball.has_value());
  EXPECT_EQ(hung.anchor, Vec2(0.0, 1.0));
  EXPECT_EQ(hung.length, 4.0);
  EXPECT_EQ(hung.restitution, 0.0);
  const Rope& tied = scene.world.ropes()[1];
  EXPECT_EQ(tied.ball, 2u);
  EXPECT_EQ(tied.other_ball, std::optional<BallId>(1u));
  EXPECT_EQ(tied.length, 2.5);
  EXPECT_EQ(tied.restitution, 0.3);
  const std::string path = ::testing::TempDir() + "bad.yaml";
  const std::string balls = "balls:\n  - {position: [0, -3], radius: 0.1}\n";
  EXPECT_EQ(errorFor(balls + "ropes:\n  - {ball: 1}\n"),
            path + ": ropes[0]: needs one of other_ball and anchor: what the ball is tied to");
  EXPECT_EQ(errorFor(balls + "ropes:\n  - {ball: 2, anchor: [0, 0]}\n"),
            path + ": ropes[0].ball: must be the number of a ball in balls, from 1 to 1");
  EXPECT_EQ(errorFor(balls + "ropes:\n  - {ball: 1, anchor: [0, 0], length: 1}\n"),
            path + ": ropes[0]: rope's length 1.000000 m is shorter than the 3.000000 m between "
                   "its ends");
  EXPECT_EQ(errorFor(balls + "ropes:\n  - {ball: 1, anchor: [0, 0], colour: red}\n"),
            path + ": ropes[0].colour: unknown key");
}
