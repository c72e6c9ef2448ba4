// Through ROS: load_scene by a shipped scene's name, by a file's path and by YAML text; reset
// returns to the scene loaded; the old scene's markers are deleted; a bad scene is refused with
// the loader's message while the running one goes on. The node starts on the default scene
// (6 balls, 7 segments, launcher `cannon`), paused, with ~max_balls 30.
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/LoadScene.h"
#include "ball_physics_sim/engine/scene.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using namespace ball_physics_sim::test;

namespace {

// A scene without gravity: its ball drifts at 0.5 m/s above a floor.
const std::string kInlineScene =
    "name: inline\n"
    "gravity: [0.0, 0.0]\n"
    "segments:\n"
    "  - {start: [-1.0, 0.0], end: [1.0, 0.0]}\n"
    "balls:\n"
    "  - {position: [0.0, 1.0], velocity: [0.5, 0.0], radius: 0.25}\n";

std::string shipped(const std::string& name) {
  return ros::package::getPath("ball_physics_sim") + "/config/scenes/" + name + ".yaml";
}

LoadScene byName(const std::string& name) {
  LoadScene load;
  load.request.name = name;
  return load;
}

// Watches balls and markers for the whole test run.
class SceneLoading : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    nh_ = new ros::NodeHandle;
    balls_sub_ = nh_->subscribe("balls", 10, &SceneLoading::onBalls);
    markers_sub_ = nh_->subscribe("markers", 100, &SceneLoading::onMarkers);
    ASSERT_TRUE(ros::service::waitForService("load_scene", ros::Duration(30.0)));
    // Connected before the first call, so that what it publishes is not missed.
    ASSERT_TRUE(spinUntil([] { return balls_ && !marker_arrays_.empty(); }));
  }

  static void onBalls(const BallStateArray::ConstPtr& msg) { balls_ = *msg; }
  static void onMarkers(const visualization_msgs::MarkerArray::ConstPtr& msg) {
    marker_arrays_.push_back(*msg);
  }

  // The node's balls are the scene's as it starts, at sim time 0.
  static void expectStartOf(const engine::Scene& scene) {
    const BallStateArray balls = ballsAt(balls_, 0.0);
    ASSERT_EQ(balls.balls.size(), scene.world.balls().size());
    for (std::size_t i = 0; i < balls.balls.size(); ++i) {
      const engine::Ball& b = scene.world.balls()[i];
      const BallState& s = balls.balls[i];
      EXPECT_EQ(s.id, b.id);
      EXPECT_EQ(s.position.x, b.position.x()) << "ball " << b.id;
      EXPECT_EQ(s.position.y, b.position.y()) << "ball " << b.id;
      EXPECT_EQ(s.velocity.x, b.velocity.x()) << "ball " << b.id;
      EXPECT_EQ(s.velocity.y, b.velocity.y()) << "ball " << b.id;
      EXPECT_EQ(s.radius, b.radius) << "ball " << b.id;
    }
  }

  // The ids drawn in namespace `ns` by a marker array.
  static std::set<int> drawnIds(const visualization_msgs::MarkerArray& array,
                                const std::string& ns) {
    std::set<int> ids;
    for (const visualization_msgs::Marker& m : array.markers)
      if (m.ns == ns && m.action == visualization_msgs::Marker::ADD) ids.insert(m.id);
    return ids;
  }

  static ros::NodeHandle* nh_;
  static ros::Subscriber balls_sub_, markers_sub_;
  static std::optional<BallStateArray> balls_;
  static std::vector<visualization_msgs::MarkerArray> marker_arrays_;
};

ros::NodeHandle* SceneLoading::nh_;
ros::Subscriber SceneLoading::balls_sub_, SceneLoading::markers_sub_;
std::optional<BallStateArray> SceneLoading::balls_;
std::vector<visualization_msgs::MarkerArray> SceneLoading::marker_arrays_;

}  // namespace

TEST_F(SceneLoading, AShippedSceneByNameReplacesTheWorldAndItsMarkersAndResetReturnsToIt) {
  callSucceeding("load_scene", byName("default"));
  stepBy(3);
  spinUntil([] { return false; }, kInTransit);
  marker_arrays_.clear();
  const LoadScene loaded = callSucceeding("load_scene", byName("throw"));
  EXPECT_EQ(loaded.response.message,
            "loaded scene 'throw': 1 balls, 3 segments, 0 launchers; sim time 0");
  const engine::Scene scene = engine::loadScene(shipped("throw"));
  expectStartOf(scene);

  // rviz is told to forget everything, then draws the new scene alone: the default scene's
  // balls 2 to 6, segments 4 to 7 and cannon are gone with no DELETE of their own.
  std::size_t forget = 0;
  ASSERT_TRUE(spinUntil([&] {
    for (forget = 0; forget < marker_arrays_.size(); ++forget) {
      const auto& markers = marker_arrays_[forget].markers;
      if (!markers.empty() && markers[0].action == visualization_msgs::Marker::DELETEALL) break;
    }
    return forget + 1 < marker_arrays_.size();
  })) << "no DELETEALL followed by markers";
  const visualization_msgs::MarkerArray& drawn = marker_arrays_[forget + 1];
  EXPECT_EQ(drawnIds(drawn, "balls"), std::set<int>({1}));
  EXPECT_EQ(drawnIds(drawn, "segments"), std::set<int>({1, 2, 3}));
  EXPECT_TRUE(drawnIds(drawn, "launchers").empty());

  stepBy(60);
  std_srvs::Trigger reset;
  reset = callSucceeding("reset", reset);
  EXPECT_EQ(reset.response.message, "scene 'throw' is back at its initial state, sim time 0");
  expectStartOf(scene);
}

TEST_F(SceneLoading, ASceneFileByPathAndASceneAsYamlTextLoadToo) {
  LoadScene by_file;
  by_file.request.file = shipped("resting");
  stepBy(3);
  by_file = callSucceeding("load_scene", by_file);
  EXPECT_EQ(by_file.response.message,
            "loaded scene 'resting': 7 balls, 4 segments, 0 launchers; sim time 0");
  expectStartOf(engine::loadScene(shipped("resting")));

  LoadScene by_text;
  by_text.request.yaml = kInlineScene;
  stepBy(3);
  by_text = callSucceeding("load_scene", by_text);
  EXPECT_EQ(by_text.response.message,
            "loaded scene 'inline': 1 balls, 1 segments, 0 launchers; sim time 0");
  expectStartOf(engine::parseScene(kInlineScene, "yaml"));
  // Its gravity too: none, so the ball drifts straight on.
  const BallStateArray later = ballsAt(balls_, stepBy(12));
  ASSERT_EQ(later.balls.size(), 1u);
  EXPECT_NEAR(later.balls[0].position.x, 0.5 * 12 * kTimeStep, 1e-12);
  EXPECT_EQ(later.balls[0].position.y, 1.0);
}

TEST_F(SceneLoading, ABadSceneIsRefusedWithTheLoadersMessageAndTheRunningSceneGoesOn) {
  callSucceeding("load_scene", byName("default"));
  const double running = stepBy(5);
  const BallStateArray before = ballsAt(balls_, running);
  expectRefused<LoadScene>("load_scene", byName("throw"), {
      {"no scene", [](LoadScene& l) { l.request.name.clear(); },
       "give exactly one of name, file and yaml; got 0"},
      {"two scenes", [](LoadScene& l) { l.request.yaml = kInlineScene; },
       "give exactly one of name, file and yaml; got 2"},
      {"unknown name", [](LoadScene& l) { l.request.name = "no_such_scene"; },
       "cannot load the scene: " + shipped("no_such_scene") + ": (file): cannot be opened"},
      {"missing file", [](LoadScene& l) { l.request.name.clear(); l.request.file = "/no/such.yaml"; },
       "cannot load the scene: /no/such.yaml: (file): cannot be opened"},
      {"not YAML", [](LoadScene& l) { l.request.name.clear(); l.request.yaml = "balls: [{"; },
       "cannot load the scene: yaml: (file): is not valid YAML"},
      {"bad radius", [](LoadScene& l) {
         l.request.name.clear();
         l.request.yaml = "balls:\n  - {position: [0, 0], radius: -1}\n";
       }, "cannot load the scene: yaml: balls[0]: radius must be > 0, got -1.000000"},
      {"overlap", [](LoadScene& l) {
         l.request.name.clear();
         l.request.yaml = "balls:\n  - {position: [0, 0], radius: 1}\n  - {position: [1, 0], radius: 1}\n";
       }, "cannot load the scene: yaml: balls[1]: ball would overlap ball 1"},
      {"too many balls", [](LoadScene& l) { l.request.name = "billiards"; },
       "cannot load the scene: it has 40, more than 30 balls (~max_balls)"},
  });
  // Untouched: the same balls at the same sim time, and it steps on from there.
  const BallStateArray after = ballsAt(balls_, running);
  ASSERT_EQ(after.balls.size(), before.balls.size());
  for (std::size_t i = 0; i < after.balls.size(); ++i) {
    EXPECT_EQ(after.balls[i].id, before.balls[i].id);
    EXPECT_EQ(after.balls[i].position.x, before.balls[i].position.x);
    EXPECT_EQ(after.balls[i].position.y, before.balls[i].position.y);
  }
  EXPECT_NEAR(stepBy(1), running + kTimeStep, 1e-12);
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_load_scene");
}
