#include "ball_physics_sim/simulator_node.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/ContactArray.h"
#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/engine/aim_request.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

namespace {

std::string scenePath(const ros::NodeHandle& private_nh) {
  std::string file;
  if (private_nh.getParam("scene_file", file)) return file;
  return shippedScenePath(private_nh.param<std::string>("scene", "default"));
}

// `value`, if within (0, upper], or [0, upper] if zero is allowed; named ~name if not.
double checkedPositive(const std::string& name, double value, bool zero_allowed = false,
                       double upper = std::numeric_limits<double>::infinity()) {
  if (!std::isfinite(value) || value < 0.0 || (value == 0.0 && !zero_allowed) || value > upper)
    throw std::invalid_argument("~" + name + " must be " + (zero_allowed ? ">= 0" : "> 0") +
                                (std::isfinite(upper) ? " and <= " + format(upper) : "") +
                                ", got " + format(value));
  return value;
}

// A parameter within (0, upper], or [0, upper] if zero is allowed.
double positiveParam(const ros::NodeHandle& private_nh, const std::string& name, double fallback,
                     bool zero_allowed = false,
                     double upper = std::numeric_limits<double>::infinity()) {
  return checkedPositive(name, private_nh.param(name, fallback), zero_allowed, upper);
}

LiveSettings liveSettingsParam(const ros::NodeHandle& private_nh, double time_step) {
  const LiveSettings settings{private_nh.param("real_time_factor", 1.0),
                              private_nh.param("publish_rate", 60.0),
                              private_nh.param("marker_rate", 30.0),
                              private_nh.param("prediction_horizon", 3.0),
                              private_nh.param("show_labels", true),
                              private_nh.param("fire_on_click", false)};
  checkLiveSettings(settings, time_step);
  return settings;
}

// A parameter that counts bodies or names one: a whole number, at least one (or zero).
std::size_t countParam(const ros::NodeHandle& private_nh, const std::string& name, int fallback,
                       bool zero_allowed = false) {
  const int value = private_nh.param(name, fallback);
  if (value < (zero_allowed ? 0 : 1))
    throw std::invalid_argument("~" + name + " must be >= " + (zero_allowed ? "0" : "1") +
                                ", got " + std::to_string(value));
  return static_cast<std::size_t>(value);
}

}  // namespace

void checkLiveSettings(const LiveSettings& settings, double time_step) {
  checkedPositive("real_time_factor", settings.real_time_factor, true);
  checkedPositive("publish_rate", settings.publish_rate);
  checkedPositive("marker_rate", settings.marker_rate);
  checkedPositive("prediction_horizon", settings.prediction_horizon, true,
                  engine::kMaxPredictionHorizon);
  if (settings.prediction_horizon > engine::kMaxPredictionSteps * time_step)
    throw std::invalid_argument("~prediction_horizon must be at most " +
                                std::to_string(engine::kMaxPredictionSteps) +
                                " time steps (~time_step), got " +
                                format(settings.prediction_horizon));
}

std::string shippedScenePath(const std::string& name) {
  return ros::package::getPath("ball_physics_sim") + "/config/scenes/" + name + ".yaml";
}

SimulatorNode::SimulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
    : initial_scene_(engine::loadScene(scenePath(private_nh))),
      scene_(initial_scene_),
      frame_id_(private_nh.param<std::string>("frame_id", "world")),
      time_step_(positiveParam(private_nh, "time_step", 1.0 / 120.0)),
      live_(liveSettingsParam(private_nh, time_step_)),
      max_balls_(countParam(private_nh, "max_balls", 1000)),
      max_segments_(countParam(private_nh, "max_segments", 1000)),
      max_speed_(positiveParam(private_nh, "max_speed", 1000.0, false, engine::kMaxSpeed)),
      max_radius_(positiveParam(private_nh, "max_radius", 100.0, false, engine::kMaxCoordinate)),
      max_spawn_rate_(positiveParam(private_nh, "max_spawn_rate", 200.0)),
      driven_ball_(static_cast<engine::BallId>(countParam(private_nh, "driven_ball", 0, true))),
      cmd_vel_timeout_(positiveParam(private_nh, "cmd_vel_timeout", 0.5)),
      publish_clock_(nh.param("/use_sim_time", false)),
      paused_(private_nh.param("start_paused", false)) {
  balls_pub_ = nh.advertise<BallStateArray>("balls", 10);
  contacts_pub_ = nh.advertise<ContactArray>("contacts", 100);
  sensor_events_pub_ = nh.advertise<SensorEvent>("sensor_events", 100);
  brick_hits_pub_ = nh.advertise<BrickHit>("brick_hits", 100);
  markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("markers", 10);
  if (publish_clock_) clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  ros::NodeHandle aim_nh(nh);
  aim_nh.setCallbackQueue(&aim_queue_);
  services_ = {aim_nh.advertiseService("aim", &SimulatorNode::aim, this),
               nh.advertiseService("fire", &SimulatorNode::fire, this),
               nh.advertiseService("spawn_ball", &SimulatorNode::spawnBall, this),
               nh.advertiseService("remove_ball", &SimulatorNode::removeBall, this),
               nh.advertiseService("set_ball_state", &SimulatorNode::setBallState, this),
               nh.advertiseService("add_segment", &SimulatorNode::addSegment, this),
               nh.advertiseService("remove_segment", &SimulatorNode::removeSegment, this),
               nh.advertiseService("set_segment_motion", &SimulatorNode::setSegmentMotion, this),
               nh.advertiseService("explode", &SimulatorNode::explode, this),
               nh.advertiseService("load_scene", &SimulatorNode::loadScene, this),
               nh.advertiseService("reset", &SimulatorNode::reset, this),
               nh.advertiseService("pause", &SimulatorNode::pause, this),
               nh.advertiseService("step", &SimulatorNode::step, this)};
  clicked_point_sub_ = nh.subscribe("clicked_point", 10, &SimulatorNode::aimAtClickedPoint, this);
  cmd_vel_sub_ = nh.subscribe("cmd_vel", 10, &SimulatorNode::driveBall, this);
  handles_ = std::make_unique<interactive_markers::InteractiveMarkerServer>("interactive_markers");
  // Read here as well as by the server, which drops feedback on markers it no longer shows and,
  // within a second of ROS time (all of the first second of sim time), from a second rviz: every
  // drag and menu entry is answered or refused with its reason.
  feedback_sub_ =
      nh.subscribe("interactive_markers/feedback", 100, &SimulatorNode::interactionCallback, this);
  // The server reads its parameters at once: it is shown what is in force (the scene's gravity)
  // before its callback is set, which calls it once with that.
  reconfigure_server_ = std::make_unique<dynamic_reconfigure::Server<SimulatorNodeConfig>>(
      reconfigure_mutex_, private_nh);
  reconfigure_server_->updateConfig(configInForce());
  reconfigure_server_->setCallback(
      [this](SimulatorNodeConfig& config, uint32_t level) { reconfigureCallback(config, level); });
  ROS_INFO("sim_node: scene '%s' with %zu balls, %zu segments, %zu launchers; step %g s%s",
           scene_.name.c_str(), scene_.world.balls().size(), scene_.world.segments().size(),
           scene_.launchers.size(), time_step_, paused_ ? "; paused" : "");
}

}  // namespace ball_physics_sim
