// sim_node's dynamic_reconfigure server, called as rqt_reconfigure calls it (the set_parameters
// service): gravity changed through the engine (a ball falls at the new g), the node's live
// settings taking effect, bad values refused with the reason logged and the old ones kept, and
// the published config showing what is in force. The node runs the default scene (6 balls,
// launcher `cannon` at (-5, 1)), starting paused, under /use_sim_time, as node `sim`.
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/PointStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <rosgraph_msgs/Log.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ros_test_support.h"

using namespace ball_physics_sim;
using ball_physics_sim::test::ballsAt;
using ball_physics_sim::test::callSucceeding;
using ball_physics_sim::test::kTimeStep;
using ball_physics_sim::test::nextMessage;
using ball_physics_sim::test::spawnRequest;
using ball_physics_sim::test::spinUntil;
using ball_physics_sim::test::stepBy;

namespace {

constexpr double kSceneGravity = -9.81;  // m/s^2 along y, the default scene's
const double kNaN = std::nan("");

using Doubles = std::vector<std::pair<std::string, double>>;
using Bools = std::vector<std::pair<std::string, bool>>;

class Reconfigure : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    nh_ = new ros::NodeHandle;
    balls_sub_ = nh_->subscribe("balls", 10, &Reconfigure::onBalls);
    markers_sub_ = nh_->subscribe("markers", 100, &Reconfigure::onMarkers);
    clock_sub_ = nh_->subscribe("/clock", 100, &Reconfigure::onClock);
    updates_sub_ = nh_->subscribe("sim/parameter_updates", 10, &Reconfigure::onUpdate);
    rosout_sub_ = nh_->subscribe("/rosout", 100, &Reconfigure::onLog);
    ASSERT_TRUE(ros::service::waitForService("sim/set_parameters", ros::Duration(30.0)));
    ASSERT_TRUE(spinUntil([] { return in_force_.has_value(); }));
  }

  // Handles left to static destruction would outlive roscpp's own state (ASan: use after free).
  static void TearDownTestSuite() {
    for (ros::Subscriber* sub : {&balls_sub_, &markers_sub_, &clock_sub_, &updates_sub_, &rosout_sub_})
      sub->shutdown();
  }

  static void onBalls(const BallStateArray::ConstPtr& msg) {
    balls_ = *msg;
    ++balls_received_;
  }
  static void onMarkers(const visualization_msgs::MarkerArray::ConstPtr& msg) { markers_ = *msg; }
  static void onClock(const rosgraph_msgs::Clock::ConstPtr& msg) { clock_ = msg->clock; }
  static void onUpdate(const dynamic_reconfigure::Config::ConstPtr& msg) { in_force_ = *msg; }
  static void onLog(const rosgraph_msgs::Log::ConstPtr& msg) { logged_.push_back(msg->msg); }

  // Calls set_parameters with these values, as rqt_reconfigure does; the config it answers.
  static dynamic_reconfigure::Config reconfigure(const Doubles& doubles, const Bools& bools = {}) {
    dynamic_reconfigure::Reconfigure srv;
    for (const auto& [name, value] : doubles) {
      dynamic_reconfigure::DoubleParameter p;
      p.name = name;
      p.value = value;
      srv.request.config.doubles.push_back(p);
    }
    for (const auto& [name, value] : bools) {
      dynamic_reconfigure::BoolParameter p;
      p.name = name;
      p.value = value;
      srv.request.config.bools.push_back(p);
    }
    EXPECT_TRUE(ros::service::call("sim/set_parameters", srv));
    // The same config goes out on parameter_updates.
    EXPECT_TRUE(spinUntil([&] { return in_force_ && *in_force_ == srv.response.config; }));
    return srv.response.config;
  }

  static std::optional<double> doubleIn(const dynamic_reconfigure::Config& config,
                                        const std::string& name) {
    for (const auto& p : config.doubles)
      if (p.name == name) return p.value;
    return std::nullopt;
  }

  static std::optional<bool> boolIn(const dynamic_reconfigure::Config& config,
                                    const std::string& name) {
    for (const auto& p : config.bools)
      if (p.name == name) return p.value;
    return std::nullopt;
  }

  static void setPaused(bool paused) {
    std_srvs::SetBool pause;
    pause.request.data = paused;
    callSucceeding("pause", pause);
  }

  static bool draws(const visualization_msgs::MarkerArray& markers, const std::string& ns) {
    for (const auto& m : markers.markers)
      if (m.ns == ns && m.action == visualization_msgs::Marker::ADD) return true;
    return false;
  }

  // Whether the next markers, after those on their way, draw namespace `ns`.
  static bool nextMarkersDraw(const std::string& ns) {
    const auto next = nextMessage<visualization_msgs::MarkerArray>(
        markers_, [](const visualization_msgs::MarkerArray& m) { return draws(m, "balls"); });
    return draws(next, ns);  // (not a DELETEALL alone)
  }

  // Ball `id` as `balls` shows it at sim time `time`.
  static std::optional<BallState> ballAt(double time, std::uint32_t id) {
    for (const BallState& ball : ballsAt(balls_, time).balls)
      if (ball.id == id) return ball;
    return std::nullopt;
  }

  static std::size_t nextBallCount() {
    return nextMessage<BallStateArray>(balls_, [](const BallStateArray&) { return true; })
        .balls.size();
  }

  static void click(const ros::Publisher& pub, double x, double y) {
    geometry_msgs::PointStamped point;
    point.header.frame_id = "world";
    point.point.x = x;
    point.point.y = y;
    pub.publish(point);
  }

  static ros::NodeHandle* nh_;
  static ros::Subscriber balls_sub_, markers_sub_, clock_sub_, updates_sub_, rosout_sub_;
  static std::optional<BallStateArray> balls_;
  static std::size_t balls_received_;
  static std::optional<visualization_msgs::MarkerArray> markers_;
  static ros::Time clock_;
  static std::optional<dynamic_reconfigure::Config> in_force_;
  static std::vector<std::string> logged_;
};

ros::NodeHandle* Reconfigure::nh_ = nullptr;
ros::Subscriber Reconfigure::balls_sub_, Reconfigure::markers_sub_, Reconfigure::clock_sub_,
    Reconfigure::updates_sub_, Reconfigure::rosout_sub_;
std::optional<BallStateArray> Reconfigure::balls_;
std::size_t Reconfigure::balls_received_ = 0;
std::optional<visualization_msgs::MarkerArray> Reconfigure::markers_;
ros::Time Reconfigure::clock_;
std::optional<dynamic_reconfigure::Config> Reconfigure::in_force_;
std::vector<std::string> Reconfigure::logged_;

}  // namespace

TEST_F(Reconfigure, TheConfigAtStartIsWhatIsInForce) {
  EXPECT_EQ(doubleIn(*in_force_, "gravity_x"), 0.0);
  EXPECT_EQ(doubleIn(*in_force_, "gravity_y"), kSceneGravity);
  EXPECT_EQ(doubleIn(*in_force_, "real_time_factor"), 1.0);
  EXPECT_EQ(doubleIn(*in_force_, "publish_rate"), 60.0);
  EXPECT_EQ(doubleIn(*in_force_, "marker_rate"), 30.0);
  EXPECT_EQ(doubleIn(*in_force_, "prediction_horizon"), 3.0);
  EXPECT_EQ(boolIn(*in_force_, "show_labels"), true);
  EXPECT_EQ(boolIn(*in_force_, "fire_on_click"), false);
}

TEST_F(Reconfigure, ABallDroppedFallsAtTheNewGravityAndResetBringsBackTheScenes) {
  const dynamic_reconfigure::Config config = reconfigure({{"gravity_x", 1.0}, {"gravity_y", -2.0}});
  EXPECT_EQ(doubleIn(config, "gravity_x"), 1.0);
  EXPECT_EQ(doubleIn(config, "gravity_y"), -2.0);
  // Far from the scene's box: nothing but gravity acts on it.
  const std::uint32_t id =
      callSucceeding("spawn_ball", spawnRequest(50.0, 50.0, 0.5, 1.0)).response.ball_id;
  const std::optional<BallState> ball = ballAt(stepBy(60), id);
  ASSERT_TRUE(ball);
  const double dt = 60 * kTimeStep;
  EXPECT_NEAR(ball->position.x, 50.0 + 0.5 * 1.0 * dt * dt, 1e-9);  // g t^2 / 2
  EXPECT_NEAR(ball->position.y, 50.0 - 0.5 * 2.0 * dt * dt, 1e-9);
  EXPECT_NEAR(ball->velocity.y, -2.0 * dt, 1e-9);
  // The scene's gravity comes back with the scene, and the config says so.
  std_srvs::Trigger reset;
  callSucceeding("reset", reset);
  EXPECT_TRUE(spinUntil([] { return doubleIn(*in_force_, "gravity_y") == kSceneGravity; }));
  EXPECT_EQ(doubleIn(*in_force_, "gravity_x"), 0.0);
}

TEST_F(Reconfigure, BadValuesAreRefusedWithTheReasonAndTheOldValuesKept) {
  const dynamic_reconfigure::Config before = *in_force_;
  const std::vector<std::pair<Doubles, std::string>> cases = {
      {{{"gravity_y", -2e4}}, "gravity must be finite and at most"},
      {{{"gravity_x", kNaN}}, "gravity must be finite"},
      {{{"real_time_factor", -1.0}}, "~real_time_factor must be >= 0, got -1"},
      {{{"publish_rate", 0.0}}, "~publish_rate must be > 0, got 0"},
      {{{"marker_rate", -5.0}}, "~marker_rate must be > 0, got -5"},
      {{{"prediction_horizon", 61.0}}, "~prediction_horizon must be >= 0 and <= 60, got 61"},
      {{{"prediction_horizon", kNaN}}, "~prediction_horizon must be >= 0"},
      // With a good value beside it: nothing of the call is taken.
      {{{"publish_rate", 10.0}, {"gravity_y", INFINITY}}, "gravity must be finite"},
      {{{"gravity_y", -1.0}, {"marker_rate", 0.0}}, "~marker_rate must be > 0"},
  };
  for (const auto& [doubles, reason] : cases) {
    logged_.clear();
    EXPECT_EQ(reconfigure(doubles), before) << reason;
    EXPECT_EQ(*in_force_, before) << reason;
    EXPECT_TRUE(spinUntil([&] {
      for (const std::string& line : logged_)
        if (line.find("reconfigure refused") != std::string::npos &&
            line.find(reason) != std::string::npos)
          return true;
      return false;
    })) << "no warning saying: " << reason;
  }
  // Still running, at the scene's gravity: a ball dropped falls at g.
  const std::uint32_t id =
      callSucceeding("spawn_ball", spawnRequest(-50.0, 50.0, 0.5, 1.0)).response.ball_id;
  const std::optional<BallState> ball = ballAt(stepBy(12), id);
  ASSERT_TRUE(ball);
  EXPECT_NEAR(ball->velocity.y, kSceneGravity * 12 * kTimeStep, 1e-9);
}

TEST_F(Reconfigure, LabelsAndPredictedPathsAreDrawnOrNotAsSet) {
  EXPECT_TRUE(nextMarkersDraw("ball_labels"));
  reconfigure({}, {{"show_labels", false}});
  EXPECT_FALSE(nextMarkersDraw("ball_labels"));
  EXPECT_TRUE(nextMarkersDraw("predicted_paths"));
  reconfigure({{"prediction_horizon", 0.0}});
  EXPECT_FALSE(nextMarkersDraw("predicted_paths"));
  reconfigure({{"prediction_horizon", 2.0}}, {{"show_labels", true}});
  EXPECT_TRUE(nextMarkersDraw("predicted_paths"));
  EXPECT_TRUE(nextMarkersDraw("ball_labels"));
}

TEST_F(Reconfigure, AClickFiresOnlyOnceFireOnClickIsSet) {
  // (Local: a publisher kept to the exit would outlive roscpp's own state.)
  const ros::Publisher pub = nh_->advertise<geometry_msgs::PointStamped>("clicked_point", 1);
  ASSERT_TRUE(spinUntil([&] { return pub.getNumSubscribers() > 0; }));
  const std::size_t balls = nextBallCount();
  click(pub, 1.0, 1.5);
  EXPECT_FALSE(spinUntil([&] { return balls_->balls.size() > balls; }, 1.0));
  reconfigure({}, {{"fire_on_click", true}});
  click(pub, 1.0, 1.5);
  EXPECT_TRUE(spinUntil([&] { return balls_->balls.size() == balls + 1; }));
  reconfigure({}, {{"fire_on_click", false}});
}

TEST_F(Reconfigure, ThePublishRateAndTheRealTimeFactorTakeEffect) {
  // Wall-clock rates: bounds wide enough for a busy machine, narrow enough to tell 4 Hz from 60.
  reconfigure({{"publish_rate", 4.0}});
  spinUntil([] { return false; }, 0.5);
  std::size_t before = balls_received_;
  spinUntil([] { return false; }, 2.0);
  EXPECT_GE(balls_received_ - before, 5u);
  EXPECT_LE(balls_received_ - before, 10u);
  reconfigure({{"publish_rate", 60.0}});
  spinUntil([] { return false; }, 0.5);
  before = balls_received_;
  spinUntil([] { return false; }, 1.0);
  EXPECT_GE(balls_received_ - before, 30u);

  reconfigure({{"real_time_factor", 0.5}});
  setPaused(false);
  spinUntil([] { return false; }, 0.5);
  const double sim_start = clock_.toSec();
  const ros::WallTime wall_start = ros::WallTime::now();
  spinUntil([] { return false; }, 3.0);
  const double factor = (clock_.toSec() - sim_start) / (ros::WallTime::now() - wall_start).toSec();
  setPaused(true);
  EXPECT_GT(factor, 0.4);  // (stepping whenever it woke to publish, it ran at 0.75)
  EXPECT_LT(factor, 0.6);
}

int main(int argc, char** argv) {
  return ball_physics_sim::test::runClient(argc, argv, "test_reconfigure");
}
