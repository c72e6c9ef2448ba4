// Through ROS: rviz's interactive markers, by the feedback rviz sends on
// interactive_markers/feedback (drags as POSE_UPDATE and MOUSE_UP, menus as MENU_SELECT), their
// effects read from the node's topics and services, and bad feedback refused with a warning
// naming the problem. The node runs the default scene (6 balls, launcher `cannon` at (-5, 1)
// aiming at 0.8 rad, 9 m/s), starting paused, under /use_sim_time.
#include <cmath>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>
#include <visualization_msgs/InteractiveMarkerInit.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ball_physics_sim/markers.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::callSucceeding;
using ball_physics_sim::test::nextMessage;
using ball_physics_sim::test::spinUntil;
using visualization_msgs::InteractiveMarkerFeedback;

namespace {

constexpr std::size_t kSceneBalls = 6;
const engine::Vec2 kCannon(-5.0, 1.0);

class Interaction : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    nh_ = new ros::NodeHandle;
    balls_sub_ = nh_->subscribe("balls", 10, &Interaction::onBalls);
    markers_sub_ = nh_->subscribe("markers", 100, &Interaction::onMarkers);
    handles_sub_ = nh_->subscribe("interactive_markers/update_full", 10, &Interaction::onHandles);
    rosout_sub_ = nh_->subscribe("/rosout", 100, &Interaction::onLog);
    feedback_pub_ = nh_->advertise<InteractiveMarkerFeedback>("interactive_markers/feedback", 100);
    ASSERT_TRUE(ros::service::waitForService("step", ros::Duration(30.0)));
    ASSERT_TRUE(spinUntil([] { return feedback_pub_.getNumSubscribers() > 0; }));
  }

  // Handles left to static destruction would outlive roscpp's own state (ASan: use after free).
  static void TearDownTestSuite() {
    for (ros::Subscriber* sub : {&balls_sub_, &markers_sub_, &handles_sub_, &rosout_sub_})
      sub->shutdown();
    feedback_pub_.shutdown();
  }

  static void onBalls(const BallStateArray::ConstPtr& msg) { balls_ = *msg; }
  static void onMarkers(const visualization_msgs::MarkerArray::ConstPtr& msg) {
    for (const auto& m : msg->markers) {
      if (m.ns == "launchers" && m.id == 0)
        launcher_yaw_ = 2.0 * std::atan2(m.pose.orientation.z, m.pose.orientation.w);
      if (m.ns == "predicted_paths" && m.id == 0) path_ = m.points;
    }
  }
  static void onHandles(const visualization_msgs::InteractiveMarkerInit::ConstPtr& msg) {
    handles_ = *msg;
  }
  static void onLog(const rosgraph_msgs::Log::ConstPtr& msg) {
    if (msg->name == "/sim" && msg->level == rosgraph_msgs::Log::WARN)
      warnings_.push_back(msg->msg);
  }

  void SetUp() override {
    setPaused(true);
    std_srvs::Trigger reset;
    ASSERT_TRUE(ros::service::call("reset", reset));
    nextBalls([](const BallStateArray& b) { return b.header.stamp.toSec() == 0.0; });
    warnings_.clear();
  }

  static void setPaused(bool paused) {
    std_srvs::SetBool pause;
    pause.request.data = paused;
    callSucceeding("pause", pause);
  }

  // Sends what rviz sends for `event` on handle `name`: the pose it was dragged to, or the menu
  // entry chosen. One client throughout, as one rviz.
  static void send(const std::string& name, std::uint8_t event, double x, double y,
                   std::uint32_t entry = 0, const std::string& frame = "world") {
    InteractiveMarkerFeedback feedback;
    feedback.header.frame_id = frame;
    feedback.client_id = "/rviz/InteractiveMarkers";
    feedback.marker_name = name;
    feedback.event_type = event;
    feedback.pose.position.x = x;
    feedback.pose.position.y = y;
    feedback.pose.orientation.w = 1.0;
    feedback.menu_entry_id = entry;
    feedback_pub_.publish(feedback);
  }
  static void drop(const std::string& name, double x, double y) {
    send(name, InteractiveMarkerFeedback::POSE_UPDATE, x, y);
    send(name, InteractiveMarkerFeedback::MOUSE_UP, x, y);
  }
  static void choose(const std::string& name, std::uint32_t entry) {
    send(name, InteractiveMarkerFeedback::MENU_SELECT, 0.0, 0.0, entry);
  }

  static BallStateArray nextBalls(const std::function<bool(const BallStateArray&)>& ready) {
    return nextMessage(balls_, ready);
  }

  static const BallState* find(const BallStateArray& balls, std::uint32_t id) {
    for (const BallState& b : balls.balls)
      if (b.id == id) return &b;
    return nullptr;
  }
  static const BallState* find(BallStateArray&& balls, std::uint32_t id) = delete;

  static std::set<std::string> handleNames() {
    std::set<std::string> names;
    if (handles_)
      for (const auto& m : handles_->markers) names.insert(m.name);
    return names;
  }

  static const visualization_msgs::InteractiveMarker* handle(const std::string& name) {
    if (handles_)
      for (const auto& m : handles_->markers)
        if (m.name == name) return &m;
    return nullptr;
  }

  // Whether handle `name` comes to be at (x, y).
  static bool handleComesTo(const std::string& name, double x, double y) {
    return spinUntil([&] {
      const auto* h = handle(name);
      return h && std::abs(h->pose.position.x - x) < 1e-9 &&
             std::abs(h->pose.position.y - y) < 1e-9;
    });
  }

  // Whether the node warns with a message holding every one of `parts`.
  static bool warns(const std::vector<std::string>& parts) {
    return spinUntil([&] {
      for (const std::string& w : warnings_) {
        bool all = true;
        for (const std::string& part : parts) all = all && w.find(part) != std::string::npos;
        if (all) return true;
      }
      return false;
    });
  }

  // Whether the launcher's aim-mode submenu has this entry.
  static bool aimModeTicked(const std::string& title) {
    const auto* h = handle("launcher_cannon");
    if (h)
      for (const auto& entry : h->menu_entries)
        if (entry.title == title) return true;
    return false;
  }

  static bool yawComesTo(double yaw) {
    return spinUntil([&] { return launcher_yaw_ && std::abs(*launcher_yaw_ - yaw) < 1e-9; });
  }

  static ros::NodeHandle* nh_;
  static ros::Subscriber balls_sub_, markers_sub_, handles_sub_, rosout_sub_;
  static ros::Publisher feedback_pub_;
  static std::optional<BallStateArray> balls_;
  static std::optional<double> launcher_yaw_;
  static std::vector<geometry_msgs::Point> path_;  // the first launcher's predicted path
  static std::optional<visualization_msgs::InteractiveMarkerInit> handles_;
  static std::vector<std::string> warnings_;
};

ros::NodeHandle* Interaction::nh_;
ros::Subscriber Interaction::balls_sub_, Interaction::markers_sub_, Interaction::handles_sub_,
    Interaction::rosout_sub_;
ros::Publisher Interaction::feedback_pub_;
std::optional<BallStateArray> Interaction::balls_;
std::optional<double> Interaction::launcher_yaw_;
std::vector<geometry_msgs::Point> Interaction::path_;
std::optional<visualization_msgs::InteractiveMarkerInit> Interaction::handles_;
std::vector<std::string> Interaction::warnings_;

}  // namespace

TEST_F(Interaction, BallsHaveHandlesWhilePausedAndTheWorldsMenuPausesAndResumes) {
  std::set<std::string> paused = {"world", "launcher_cannon"};
  for (std::size_t id = 1; id <= kSceneBalls; ++id) paused.insert("ball_" + std::to_string(id));
  ASSERT_TRUE(spinUntil([&] { return handleNames() == paused; }));
  choose("world", kMenuResume);
  // Time runs, and the balls' handles go: they would trail every step.
  nextBalls([](const BallStateArray& b) { return b.header.stamp.toSec() > 0.1; });
  EXPECT_TRUE(spinUntil([] {
    return handleNames() == std::set<std::string>{"world", "launcher_cannon"};
  }));
  choose("world", kMenuPause);
  EXPECT_TRUE(spinUntil([&] { return handleNames() == paused; }));
  const double stopped = nextBalls([](const BallStateArray&) { return true; }).header.stamp.toSec();
  spinUntil([] { return false; }, 0.3);
  EXPECT_EQ(nextBalls([](const BallStateArray&) { return true; }).header.stamp.toSec(), stopped);
}

TEST_F(Interaction, ABallDraggedAndLetGoIsMovedThere) {
  drop("ball_1", -2.0, 1.0);
  const BallStateArray moved = nextBalls([](const BallStateArray& b) {
    const BallState* ball = find(b, 1);
    return ball && ball->position.x == -2.0;
  });
  const BallState* ball = find(moved, 1);
  ASSERT_NE(ball, nullptr);
  EXPECT_EQ(ball->position.y, 1.0);
  EXPECT_TRUE(handleComesTo("ball_1", -2.0, 1.0));
  EXPECT_TRUE(warnings_.empty()) << warnings_.front();
}

TEST_F(Interaction, BadDragsAreRefusedWithTheirReasonAndChangeNothing) {
  drop("ball_1", 3.6, 0.3);  // onto ball 2
  EXPECT_TRUE(warns({"ball_1", "refused", "overlap ball 2"}));
  send("ball_1", InteractiveMarkerFeedback::MOUSE_UP, std::nan(""), 1.0);
  EXPECT_TRUE(warns({"ball_1", "not finite"}));
  send("ball_1", InteractiveMarkerFeedback::MOUSE_UP, -2.0, 1.0, 0, "ball_1");
  EXPECT_TRUE(warns({"ball_1", "poses must be in 'world', got 'ball_1'"}));
  drop("ball_99", -2.0, 1.0);
  EXPECT_TRUE(warns({"ball_99", "there is no ball 99"}));
  drop("launcher_mortar", -2.0, 1.0);
  EXPECT_TRUE(warns({"launcher_mortar", "no launcher named 'mortar'", "'cannon'"}));
  drop("launcher_cannon", -5.0, 1.0);
  EXPECT_TRUE(warns({"launcher_cannon", "points nowhere"}));
  choose("nothing", kMenuFire);
  EXPECT_TRUE(warns({"nothing", "no such interactive marker"}));
  choose("world", kMenuFire);
  EXPECT_TRUE(warns({"world", "no menu entry 1"}));
  // Nothing moved, the handle is back on its ball, and the world steps on.
  EXPECT_TRUE(handleComesTo("ball_1", 3.0, 0.3));
  EXPECT_TRUE(yawComesTo(0.8));
  const BallStateArray after = test::ballsAt(balls_, 0.0);
  EXPECT_EQ(after.balls.size(), kSceneBalls);
  const BallState* ball = find(after, 1);
  ASSERT_NE(ball, nullptr);
  EXPECT_EQ(ball->position.x, 3.0);
  EXPECT_EQ(ball->position.y, 0.3);
  EXPECT_EQ(test::stepBy(1), test::kTimeStep);
}

TEST_F(Interaction, DraggingALaunchersKnobAimsItLiveAndItsPathFollows) {
  send("launcher_cannon", InteractiveMarkerFeedback::POSE_UPDATE, -5.0, 3.0);
  EXPECT_TRUE(yawComesTo(M_PI / 2));
  // Straight up: the path rises above the muzzle.
  EXPECT_TRUE(spinUntil([] {
    return path_.size() >= 2 && std::abs(path_[1].x + 5.0) < 1e-9 && path_[1].y > path_[0].y;
  }));
  send("launcher_cannon", InteractiveMarkerFeedback::MOUSE_UP, -3.0, 1.0);
  EXPECT_TRUE(yawComesTo(0.0));
  // Let go, the knob sits just past the tip of the launcher's arrow, 0.95 m along the aim.
  EXPECT_TRUE(handleComesTo("launcher_cannon", -4.05, 1.0));
}

TEST_F(Interaction, ALaunchersMenuSetsHowItsKnobAimsAndFires) {
  choose("launcher_cannon", kMenuLobLow);
  EXPECT_TRUE(spinUntil([] { return aimModeTicked("[x] in a low arc to the knob"); }));
  drop("launcher_cannon", -1.0, 1.0);
  ASSERT_TRUE(spinUntil([] { return launcher_yaw_ && std::abs(*launcher_yaw_ - 0.8) > 1e-3; }));
  const double dragged_yaw = *launcher_yaw_;
  // The knob aimed as the aim service aims the same request.
  Aim aim;
  aim.request.mode = Aim::Request::TARGET_BALLISTIC;
  aim.request.target.x = -1.0;
  aim.request.target.y = 1.0;
  aim = callSucceeding("aim", aim);
  EXPECT_NEAR(dragged_yaw, aim.response.angle, 1e-12);
  choose("launcher_cannon", kMenuAimAlong);  // as the other tests expect it
  EXPECT_TRUE(spinUntil([] { return aimModeTicked("[x] along the knob"); }));

  choose("launcher_cannon", kMenuFire);
  const BallStateArray fired =
      nextBalls([](const BallStateArray& b) { return b.balls.size() == kSceneBalls + 1; });
  const BallState* ball = find(fired, kSceneBalls + 1);
  ASSERT_NE(ball, nullptr);
  EXPECT_NEAR(std::atan2(ball->velocity.y, ball->velocity.x), aim.response.angle, 1e-12);
  EXPECT_NEAR(std::hypot(ball->velocity.x, ball->velocity.y), 9.0, 1e-12);
  EXPECT_TRUE(spinUntil([] { return handle("ball_7") != nullptr; }));
}

TEST_F(Interaction, ABallsMenuHasTheFirstLauncherLeadItOrRemovesIt) {
  // A ball falling where the cannon can strike it at 9 m/s.
  const SpawnBall spawned = callSucceeding("spawn_ball", test::spawnRequest(-2.0, 2.0, 0.3, 1.0));
  const std::string name = "ball_" + std::to_string(spawned.response.ball_id);
  choose(name, kMenuLeadBall);
  ASSERT_TRUE(spinUntil([] { return launcher_yaw_ && std::abs(*launcher_yaw_ - 0.8) > 1e-3; }));
  const double led_yaw = *launcher_yaw_;
  Aim aim;
  aim.request.mode = Aim::Request::LEAD_BALL;
  aim.request.target_ball_id = spawned.response.ball_id;
  aim = callSucceeding("aim", aim);
  EXPECT_NEAR(led_yaw, aim.response.angle, 1e-12);

  choose("ball_3", kMenuRemoveBall);
  const BallStateArray removed =
      nextBalls([](const BallStateArray& b) { return b.balls.size() == kSceneBalls; });
  EXPECT_EQ(find(removed, 3), nullptr);
  EXPECT_TRUE(spinUntil([] { return handle("ball_3") == nullptr; }));
  choose("ball_3", kMenuRemoveBall);
  EXPECT_TRUE(warns({"ball_3", "there is no ball 3"}));
}

int main(int argc, char** argv) { return test::runClient(argc, argv, "test_interaction"); }
