#include "ball_physics_sim/simulator_node.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <geometry_msgs/TransformStamped.h>
#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/ContactArray.h"
#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/bank_shot.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

namespace {

std::string scenePath(const ros::NodeHandle& private_nh) {
  std::string file;
  if (private_nh.getParam("scene_file", file)) return file;
  const std::string scene = private_nh.param<std::string>("scene", "default");
  return ros::package::getPath("ball_physics_sim") + "/config/scenes/" + scene + ".yaml";
}

// Numbers in messages, in the shortest form that reads well ("9", "9.93194").
template <typename T>
std::string format(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string format(const engine::Vec2& v) { return "(" + format(v.x()) + ", " + format(v.y()) + ")"; }

// A parameter within (0, upper], or [0, upper] if zero is allowed.
double positiveParam(const ros::NodeHandle& private_nh, const std::string& name, double fallback,
                     bool zero_allowed = false,
                     double upper = std::numeric_limits<double>::infinity()) {
  const double value = private_nh.param(name, fallback);
  if (!std::isfinite(value) || value < 0.0 || (value == 0.0 && !zero_allowed) || value > upper)
    throw std::invalid_argument("~" + name + " must be " + (zero_allowed ? ">= 0" : "> 0") +
                                (std::isfinite(upper) ? " and <= " + format(upper) : "") +
                                ", got " + format(value));
  return value;
}

// A prediction runs the whole world this far ahead per launcher: a longer look costs a
// proportionally longer computation.
constexpr double kMaxPredictionHorizon = 60.0;  // s
// The most of the node's time predictions may take.
constexpr double kPredictionShare = 0.1;

// One `step` call runs this many steps at most: the node answers nothing else meanwhile.
constexpr std::uint32_t kMaxStepsPerCall = 100000;

// A parameter that counts bodies or names one: a whole number, at least one (or zero).
std::size_t countParam(const ros::NodeHandle& private_nh, const std::string& name, int fallback,
                       bool zero_allowed = false) {
  const int value = private_nh.param(name, fallback);
  if (value < (zero_allowed ? 0 : 1))
    throw std::invalid_argument("~" + name + " must be >= " + (zero_allowed ? "0" : "1") +
                                ", got " + std::to_string(value));
  return static_cast<std::size_t>(value);
}

geometry_msgs::TransformStamped frame(const std::string& parent, const std::string& child,
                                      const ros::Time& stamp, const engine::Vec2& position,
                                      double yaw) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = stamp;
  t.child_frame_id = child;
  t.transform.translation.x = position.x();
  t.transform.translation.y = position.y();
  t.transform.rotation = yawQuaternion(yaw);
  return t;
}

}  // namespace

SimulatorNode::SimulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
    : initial_scene_(engine::loadScene(scenePath(private_nh))),
      scene_(initial_scene_),
      frame_id_(private_nh.param<std::string>("frame_id", "world")),
      time_step_(positiveParam(private_nh, "time_step", 1.0 / 120.0)),
      real_time_factor_(positiveParam(private_nh, "real_time_factor", 1.0, true)),
      state_period_(1.0 / positiveParam(private_nh, "publish_rate", 60.0)),
      marker_period_(1.0 / positiveParam(private_nh, "marker_rate", 30.0)),
      show_labels_(private_nh.param("show_labels", true)),
      prediction_horizon_(positiveParam(private_nh, "prediction_horizon", 3.0, true,
                                        kMaxPredictionHorizon)),
      max_balls_(countParam(private_nh, "max_balls", 1000)),
      max_segments_(countParam(private_nh, "max_segments", 1000)),
      max_speed_(positiveParam(private_nh, "max_speed", 1000.0, false, engine::kMaxSpeed)),
      max_radius_(positiveParam(private_nh, "max_radius", 100.0, false, engine::kMaxCoordinate)),
      max_spawn_rate_(positiveParam(private_nh, "max_spawn_rate", 200.0)),
      fire_on_click_(private_nh.param("fire_on_click", false)),
      driven_ball_(static_cast<engine::BallId>(countParam(private_nh, "driven_ball", 0, true))),
      cmd_vel_timeout_(positiveParam(private_nh, "cmd_vel_timeout", 0.5)),
      publish_clock_(nh.param("/use_sim_time", false)),
      paused_(private_nh.param("start_paused", false)) {
  if (prediction_horizon_ > engine::kMaxPredictionSteps * time_step_)
    throw std::invalid_argument("~prediction_horizon must be at most " +
                                std::to_string(engine::kMaxPredictionSteps) +
                                " time steps (~time_step), got " + format(prediction_horizon_));
  balls_pub_ = nh.advertise<BallStateArray>("balls", 10);
  contacts_pub_ = nh.advertise<ContactArray>("contacts", 100);
  sensor_events_pub_ = nh.advertise<SensorEvent>("sensor_events", 100);
  brick_hits_pub_ = nh.advertise<BrickHit>("brick_hits", 100);
  markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("markers", 10);
  if (publish_clock_) clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  services_ = {nh.advertiseService("aim", &SimulatorNode::aim, this),
               nh.advertiseService("fire", &SimulatorNode::fire, this),
               nh.advertiseService("spawn_ball", &SimulatorNode::spawnBall, this),
               nh.advertiseService("remove_ball", &SimulatorNode::removeBall, this),
               nh.advertiseService("add_segment", &SimulatorNode::addSegment, this),
               nh.advertiseService("remove_segment", &SimulatorNode::removeSegment, this),
               nh.advertiseService("set_segment_motion", &SimulatorNode::setSegmentMotion, this),
               nh.advertiseService("explode", &SimulatorNode::explode, this),
               nh.advertiseService("reset", &SimulatorNode::reset, this),
               nh.advertiseService("pause", &SimulatorNode::pause, this),
               nh.advertiseService("step", &SimulatorNode::step, this)};
  clicked_point_sub_ = nh.subscribe("clicked_point", 10, &SimulatorNode::aimAtClickedPoint, this);
  cmd_vel_sub_ = nh.subscribe("cmd_vel", 10, &SimulatorNode::driveBall, this);
  ROS_INFO("sim_node: scene '%s' with %zu balls, %zu segments, %zu launchers; step %g s%s",
           scene_.name.c_str(), scene_.world.balls().size(), scene_.world.segments().size(),
           scene_.launchers.size(), time_step_, paused_ ? "; paused" : "");
}

void SimulatorNode::run() {
  // Publishing follows the wall clock, so that topics stay alive while paused.
  ros::WallTime next_states = ros::WallTime::now(), next_markers = next_states;
  restartPacing();
  while (ros::ok()) {
    ros::spinOnce();
    if (!paused_) stepOnce();
    const ros::WallTime now = ros::WallTime::now();
    if (now >= next_states) {
      publishStates();
      next_states = std::max(next_states + state_period_, now);
    }
    if (now >= next_markers) {
      publishMarkers();
      next_markers = std::max(next_markers + marker_period_, now);
    }
    ros::WallTime due = std::min(next_states, next_markers);
    if (!paused_ && real_time_factor_ == 0.0) continue;
    if (!paused_)
      due = std::min(due, pacing_wall_start_ + ros::WallDuration((scene_.world.time() -
                                                                  pacing_sim_start_) /
                                                                 real_time_factor_));
    const ros::WallTime wall_now = ros::WallTime::now();
    if (due > wall_now) (due - wall_now).sleep();
  }
}

void SimulatorNode::restartPacing() {
  pacing_wall_start_ = ros::WallTime::now();
  pacing_sim_start_ = scene_.world.time();
}

void SimulatorNode::stepOnce() {
  stopStaleDrive();
  scene_.world.step(time_step_);
  predictions_stale_ = true;
  const std::vector<engine::Contact> contacts = scene_.world.takeContacts();
  unpublished_contacts_.insert(unpublished_contacts_.end(), contacts.begin(), contacts.end());
  // Rare, and what a game waits for: sent at once, not at the publish rate.
  for (const engine::SensorEvent& event : scene_.world.takeSensorEvents())
    sensor_events_pub_.publish(toMsg(event));
  for (const engine::BrickHit& hit : scene_.world.takeBrickHits()) brick_hits_pub_.publish(toMsg(hit));
  publishClock();
}

void SimulatorNode::publishClock() {
  if (!publish_clock_) return;
  rosgraph_msgs::Clock clock;
  clock.clock = ros::Time(scene_.world.time());
  clock_pub_.publish(clock);
}

void SimulatorNode::publishStates() {
  const ros::Time stamp(scene_.world.time());
  BallStateArray balls;
  balls.header.stamp = stamp;
  balls.header.frame_id = frame_id_;
  std::vector<geometry_msgs::TransformStamped> frames;
  for (const engine::Ball& ball : scene_.world.balls()) {
    balls.balls.push_back(toMsg(ball));
    frames.push_back(
        frame(frame_id_, "ball_" + std::to_string(ball.id), stamp, ball.position, ball.angle));
  }
  for (const engine::Launcher& launcher : scene_.launchers)
    frames.push_back(
        frame(frame_id_, "launcher_" + launcher.name, stamp, launcher.position, launcher.angle));
  balls_pub_.publish(balls);
  // tf listeners drop a frame's data at a stamp they already hold: send it when time has moved.
  if (!last_tf_stamp_ || stamp > *last_tf_stamp_) {
    tf_broadcaster_.sendTransform(frames);
    last_tf_stamp_ = stamp;
  }

  if (unpublished_contacts_.empty()) return;
  ContactArray contacts;
  contacts.header = balls.header;
  for (const engine::Contact& contact : unpublished_contacts_)
    contacts.contacts.push_back(toMsg(contact));
  contacts_pub_.publish(contacts);
  unpublished_contacts_.clear();
}

std::vector<engine::ShotPrediction> SimulatorNode::predictShots() const {
  std::vector<engine::ShotPrediction> predictions;
  if (prediction_horizon_ == 0.0) return predictions;
  for (const engine::Launcher& launcher : scene_.launchers) {
    try {
      const int bounces = banking_launchers_.count(launcher.name) ? engine::kMaxBankBounces : 0;
      predictions.push_back(engine::predictLaunch(scene_.world, launcher, launcher.angle,
                                                  launcher.speed, time_step_,
                                                  prediction_horizon_, bounces));
    } catch (const std::invalid_argument&) {
      predictions.emplace_back();  // the muzzle is blocked: nothing to show
    }
  }
  return predictions;
}

void SimulatorNode::publishMarkers() {
  const ros::WallTime now = ros::WallTime::now();
  if (predictions_stale_ && now >= next_prediction_) {
    predictions_ = predictShots();
    predictions_stale_ = false;
    // However big the world, at most kPredictionShare of the node's time goes to predicting.
    next_prediction_ = now + (ros::WallTime::now() - now) * (1.0 / kPredictionShare);
  }
  visualization_msgs::MarkerArray markers = sceneMarkers(
      scene_, predictions_, show_labels_, frame_id_, ros::Time(scene_.world.time()));
  // The bodies drawn before and gone now are deleted from rviz; those drawn now are remembered.
  auto deleteGone = [&](const auto& bodies, std::set<std::uint32_t>& drawn, auto appendDelete) {
    std::set<std::uint32_t> now;
    for (const auto& body : bodies) now.insert(body.id);
    for (const std::uint32_t id : drawn)
      if (!now.count(id)) appendDelete(id, frame_id_, markers);
    drawn.swap(now);
  };
  deleteGone(scene_.world.balls(), drawn_balls_, appendBallDelete);
  deleteGone(scene_.world.segments(), drawn_segments_, appendSegmentDelete);
  deleteGone(scene_.world.ropes(), drawn_ropes_, appendRopeDelete);
  markers_pub_.publish(markers);
}

engine::Launcher* SimulatorNode::findLauncher(const std::string& name, std::string& error) {
  if (scene_.launchers.empty()) {
    error = "scene '" + scene_.name + "' has no launcher";
    return nullptr;
  }
  if (name.empty()) return &scene_.launchers.front();
  for (engine::Launcher& launcher : scene_.launchers)
    if (launcher.name == name) return &launcher;
  error = "no launcher named '" + name + "'; the scene has:";
  for (const engine::Launcher& launcher : scene_.launchers) error += " '" + launcher.name + "'";
  return nullptr;
}

namespace {

// What a predicted shot strikes, for messages: "segment 3 at (x, y) after t s".
std::string describe(const engine::PredictedImpact& hit) {
  const char* kind = hit.other_kind == engine::ContactKind::kBall      ? "ball "
                     : hit.other_kind == engine::ContactKind::kSegment ? "segment "
                                                                       : "the end of segment ";
  return kind + format(hit.other_id) + " at " + format(hit.position) + " after " +
         format(hit.time) + " s";
}

// Why a shot cannot be predicted (its muzzle is blocked, ...).
std::string cannotPredict(const std::invalid_argument& e) {
  return std::string("cannot predict the shot: ") + e.what();
}

// The speed a request asks for (0: the launcher's own), or none with `error` set.
std::optional<double> requestedSpeed(double speed, const engine::Launcher& launcher,
                                     double max_speed, std::string& error) {
  if (speed == 0.0) return launcher.speed;
  if (!std::isfinite(speed) || speed < 0.0 || speed > max_speed) {
    error = "speed must be finite and > 0, at most " + format(max_speed) +
            " m/s (~max_speed; or 0 for the launcher's " + format(launcher.speed) + " m/s), got " +
            format(speed);
    return std::nullopt;
  }
  return speed;
}

}  // namespace

bool SimulatorNode::aim(Aim::Request& request, Aim::Response& response) {
  response.success = false;
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  response.angle = launcher->angle;
  response.speed = launcher->speed;
  std::optional<double> speed =
      requestedSpeed(request.speed, *launcher, max_speed_, response.message);
  if (!speed) return true;

  const bool angle_given =
      request.mode == Aim::Request::ANGLE || request.mode == Aim::Request::TIMED;
  if (angle_given && !std::isfinite(request.angle)) {
    response.message = "angle must be finite";
    return true;
  }
  if (request.time_of_flight != 0.0 && request.mode != Aim::Request::TARGET_BALLISTIC) {
    response.message = "time_of_flight is for TARGET_BALLISTIC only";
    return true;
  }

  std::optional<engine::AimSolution> solution;
  switch (request.mode) {
    case Aim::Request::ANGLE:
      response.message = "aimed along the given angle";
      solution = aimAlong(*launcher, engine::normalizedAngle(request.angle), *speed, response);
      break;
    case Aim::Request::TARGET:
    case Aim::Request::TARGET_BALLISTIC:
      solution = aimAtPoint(*launcher, request, *speed, response);
      break;
    case Aim::Request::LEAD_BALL:
      solution = leadBall(*launcher, *speed, request.target_ball_id, response);
      break;
    case Aim::Request::TIMED:
      solution = timeBall(*launcher, engine::normalizedAngle(request.angle), *speed,
                          request.target_ball_id, response);
      break;
    case Aim::Request::BANK:
      solution = bankBall(*launcher, *speed, request.target_ball_id, response);
      break;
    default:
      response.message = "unknown mode " + format(int(request.mode)) +
                         "; use ANGLE (0), TARGET (1), TARGET_BALLISTIC (2), LEAD_BALL (3), "
                         "TIMED (4) or BANK (5)";
      return true;
  }
  if (!solution) return true;
  launcher->angle = solution->angle;
  launcher->speed = *speed;
  if (request.mode == Aim::Request::BANK)
    banking_launchers_.insert(launcher->name);
  else
    banking_launchers_.erase(launcher->name);
  predictions_stale_ = true;
  response.success = true;
  response.angle = solution->angle;
  response.speed = *speed;
  response.time_of_flight = solution->time_of_flight;
  publishMarkers();
  return true;
}

std::optional<engine::ShotPrediction> SimulatorNode::predictAim(
    const engine::World& world, const engine::Launcher& launcher, double angle, double speed,
    double horizon, std::string& error) const {
  try {
    return engine::predictLaunch(world, launcher, angle, speed, time_step_, horizon);
  } catch (const std::invalid_argument& e) {
    error = cannotPredict(e);
    return std::nullopt;
  }
}

engine::AimSolution SimulatorNode::aimAlong(const engine::Launcher& launcher, double angle,
                                            double speed, Aim::Response& response) const {
  if (prediction_horizon_ == 0.0) return engine::AimSolution{angle, 0.0};
  std::string error;
  const std::optional<engine::ShotPrediction> prediction =
      predictAim(scene_.world, launcher, angle, speed, prediction_horizon_, error);
  if (!prediction) {
    response.message += "; " + error;  // pointing needs no prediction: the aim still holds
    return engine::AimSolution{angle, 0.0};
  }
  const std::optional<engine::PredictedImpact>& hit = prediction->final_impact;
  if (!hit) {
    response.message += "; the shot hits nothing within " + format(prediction_horizon_) +
                        " s (~prediction_horizon)";
    return engine::AimSolution{angle, 0.0};
  }
  response.message += "; the shot first hits " + describe(*hit);
  response.predicted_hit = toPoint(hit->position);
  return engine::AimSolution{angle, hit->time};
}

std::optional<engine::AimSolution> SimulatorNode::aimAtPoint(const engine::Launcher& launcher,
                                                             const Aim::Request& request,
                                                             double& speed,
                                                             Aim::Response& response) const {
  const engine::Vec2 target = toVec2(request.target);
  if (!target.allFinite()) {
    response.message = "target must be finite";
    return std::nullopt;
  }
  if (target == launcher.position) {
    response.message = "target " + format(target) + " is where launcher '" + launcher.name + "' is";
    return std::nullopt;
  }
  const engine::Vec2& gravity = scene_.world.gravity();
  const bool ballistic = request.mode == Aim::Request::TARGET_BALLISTIC;
  std::optional<engine::AimSolution> solution;
  if (ballistic && request.time_of_flight != 0.0) {
    solution = timedArc(launcher, target, request, speed, response);
  } else if (ballistic) {
    solution = engine::aimBallistic(launcher.position, target, speed, gravity, request.high_arc);
    if (!solution)
      response.message =
          "target " + format(target) + " is out of reach at " + format(speed) +
          " m/s; it needs at least " +
          format(engine::minimumBallisticSpeed(launcher.position, target, gravity)) + " m/s";
  } else {
    solution = engine::aimStraight(launcher.position, target, speed);
    if (gravity != engine::Vec2::Zero()) {
      // A straight aim under gravity falls short of the target: say so, and where it lands.
      response.message = "pointed straight at the target; gravity bends the path, so use "
                         "TARGET_BALLISTIC to hit it";
      return aimAlong(launcher, solution->angle, speed, response);
    }
  }
  if (!solution) return std::nullopt;
  return arrivalAt(launcher, *solution, speed, target, response);
}

std::optional<engine::AimSolution> SimulatorNode::timedArc(const engine::Launcher& launcher,
                                                           const engine::Vec2& target,
                                                           const Aim::Request& request,
                                                           double& speed,
                                                           Aim::Response& response) const {
  const double time_of_flight = request.time_of_flight;
  if (!std::isfinite(time_of_flight) || time_of_flight < 0.0) {
    response.message = "time_of_flight must be finite and > 0 (or 0 to aim at `speed`), got " +
                       format(time_of_flight);
    return std::nullopt;
  }
  if (request.speed != 0.0) {
    response.message = "give speed or time_of_flight, not both: the time fixes the speed";
    return std::nullopt;
  }
  const engine::Vec2 velocity = engine::launchVelocityFor(launcher.position, target,
                                                          time_of_flight, scene_.world.gravity());
  const double needed = velocity.norm();
  if (!(needed > 0.0 && needed <= max_speed_)) {
    response.message = "reaching " + format(target) + " in " + format(time_of_flight) +
                       " s needs " + format(needed) + " m/s; shots go > 0 and at most " +
                       format(max_speed_) + " m/s (~max_speed)";
    return std::nullopt;
  }
  speed = needed;
  return engine::AimSolution{std::atan2(velocity.y(), velocity.x()), time_of_flight};
}

std::optional<engine::AimSolution> SimulatorNode::arrivalAt(const engine::Launcher& launcher,
                                                            const engine::AimSolution& solution,
                                                            double speed,
                                                            const engine::Vec2& target,
                                                            Aim::Response& response) const {
  response.predicted_hit = toPoint(target);
  // The node predicts no further ahead than its markers do.
  if (prediction_horizon_ == 0.0 || solution.time_of_flight > kMaxPredictionHorizon) {
    response.message = "aimed at " + format(target) + ": the shot arrives after " +
                       format(solution.time_of_flight) + " s, unchecked for obstacles (" +
                       (prediction_horizon_ == 0.0 ? "~prediction_horizon is 0)"
                                                   : "longer than " +
                                                         format(kMaxPredictionHorizon) + " s)");
    return solution;
  }
  const std::optional<engine::ShotPrediction> prediction =
      predictAim(scene_.world, launcher, solution.angle, speed,
                 solution.time_of_flight + time_step_, response.message);
  if (!prediction) return std::nullopt;
  const std::optional<engine::PredictedImpact>& hit = prediction->final_impact;
  if (!hit || hit->time >= solution.time_of_flight) {
    response.message = "aimed at " + format(target) + ": the shot arrives after " +
                       format(solution.time_of_flight) + " s";
    return solution;
  }
  // Striking what lies at the target (a ball clicked on, the wall aimed at) is arriving; a point
  // clicked on a segment drawn thicker than it is counts as on it.
  if (!engine::impactCovers(scene_.world, *hit, launcher.projectile.radius, target,
                            0.5 * kMinDrawnThickness)) {
    response.message = "target " + format(target) + " is blocked: the shot would first hit " +
                       describe(*hit);
    return std::nullopt;
  }
  response.message = "aimed at " + format(target) + ": the shot strikes " + describe(*hit) +
                     ", at the target";
  response.predicted_hit = toPoint(hit->position);
  return engine::AimSolution{solution.angle, hit->time};
}

std::optional<engine::PredictedImpact> SimulatorNode::strikeOf(
    const engine::World& world, const engine::Launcher& launcher, double angle, double speed,
    engine::BallId target, double time_of_flight, Aim::Response& response) const {
  const std::optional<engine::ShotPrediction> prediction =
      predictAim(world, launcher, angle, speed, time_of_flight + time_step_, response.message);
  if (!prediction) return std::nullopt;
  const std::optional<engine::PredictedImpact>& hit = prediction->final_impact;
  if (!hit || hit->other_kind != engine::ContactKind::kBall || hit->other_id != target) {
    response.message =
        hit ? "the shot at ball " + format(target) + " would first hit " + describe(*hit)
            : "ball " + format(target) + " changes course (it hits something) before the shot "
              "reaches it";
    return std::nullopt;
  }
  response.predicted_hit = toPoint(hit->position);
  return hit;
}

std::optional<engine::Motion> SimulatorNode::motionOfTarget(engine::BallId target,
                                                           Aim::Response& response) const {
  const std::optional<engine::Motion> motion = scene_.world.motionOfBall(target);
  if (!motion) response.message = "there is no ball " + format(target);
  return motion;
}

std::optional<engine::AimSolution> SimulatorNode::leadBall(const engine::Launcher& launcher,
                                                           double speed, engine::BallId target,
                                                           Aim::Response& response) const {
  const std::optional<engine::Motion> motion = motionOfTarget(target, response);
  if (!motion) return std::nullopt;
  const std::optional<engine::AimSolution> solution =
      engine::aimLeading(launcher.position, speed, *motion, scene_.world.gravity());
  if (!solution) {
    response.message = "ball " + format(target) + " cannot be caught at " + format(speed) +
                       " m/s from launcher '" + launcher.name + "'";
    return std::nullopt;
  }
  const auto hit = strikeOf(scene_.world, launcher, solution->angle, speed, target,
                            solution->time_of_flight, response);
  if (!hit) return std::nullopt;
  response.message = "leading ball " + format(target) + ": it is struck after " +
                     format(hit->time) + " s";
  return engine::AimSolution{solution->angle, hit->time};
}

std::optional<engine::AimSolution> SimulatorNode::timeBall(const engine::Launcher& launcher,
                                                           double angle, double speed,
                                                           engine::BallId target,
                                                           Aim::Response& response) const {
  const std::optional<engine::Motion> motion = motionOfTarget(target, response);
  if (!motion) return std::nullopt;
  const std::optional<engine::TimedShot> shot =
      engine::timeShot(launcher.position, angle, speed, *motion, scene_.world.gravity());
  if (!shot) {
    response.message = "ball " + format(target) + " never crosses the path of launcher '" +
                       launcher.name + "' at " + format(angle) + " rad and " + format(speed) +
                       " m/s";
    return std::nullopt;
  }
  // The node fires between steps: the delay becomes whole steps, and the shot's prediction
  // starts from the world those steps make.
  if ((shot->delay + shot->time_of_flight) / time_step_ > engine::kMaxPredictionSteps) {
    response.message = "ball " + format(target) + " crosses the path only after " +
                       format(shot->delay) + " s, too far ahead to predict";
    return std::nullopt;
  }
  const long steps = std::lround(shot->delay / time_step_);
  engine::World later = scene_.world;
  for (long i = 0; i < steps; ++i) later.step(time_step_);
  const auto hit =
      strikeOf(later, launcher, angle, speed, target, shot->time_of_flight, response);
  if (!hit) return std::nullopt;
  response.fire_after = steps * time_step_;
  response.message = "fire after " + format(steps) + " steps (" + format(response.fire_after) +
                     " s; exactly " + format(shot->delay) + " s): ball " + format(target) +
                     " is struck " + format(hit->time) + " s later";
  return engine::AimSolution{angle, hit->time};
}

std::optional<engine::AimSolution> SimulatorNode::bankBall(const engine::Launcher& launcher,
                                                           double speed, engine::BallId target,
                                                           Aim::Response& response) const {
  if (!motionOfTarget(target, response)) return std::nullopt;
  if (prediction_horizon_ == 0.0) {
    response.message = "BANK searches shots with the prediction: it needs ~prediction_horizon > 0";
    return std::nullopt;
  }
  std::optional<engine::BankShot> shot;
  try {
    shot = engine::aimBank(scene_.world, launcher, speed, target, time_step_, prediction_horizon_);
  } catch (const std::invalid_argument& e) {
    response.message = cannotPredict(e);
    return std::nullopt;
  }
  if (!shot) {
    response.message = "found no shot at " + format(speed) + " m/s from launcher '" +
                       launcher.name + "' that strikes ball " + format(target) + " after 1 to " +
                       format(engine::kMaxBankBounces) + " bounces within " +
                       format(prediction_horizon_) + " s (~prediction_horizon)";
    return std::nullopt;
  }
  const engine::PredictedImpact& strike = *shot->prediction.final_impact;
  response.message = "bank shot:";
  for (const engine::PredictedImpact& bounce : shot->prediction.bounces)
    response.message += " off " + describe(bounce) + ", then";
  response.message += " strikes " + describe(strike);
  response.predicted_hit = toPoint(strike.position);
  return engine::AimSolution{shot->angle, strike.time};
}

std::optional<std::string> SimulatorNode::refusal(const engine::Ball& ball) {
  if (scene_.world.balls().size() >= max_balls_)
    return "the world is full: " + format(max_balls_) + " balls (~max_balls)";
  try {
    engine::checkBall(ball);  // what no ball can be (NaN, ...) before what this node allows
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  if (ball.radius > max_radius_)
    return "radius must be at most " + format(max_radius_) + " m (~max_radius), got " +
           format(ball.radius);
  if (ball.velocity.norm() > max_speed_)
    return "speed must be at most " + format(max_speed_) + " m/s (~max_speed), got " +
           format(ball.velocity.norm());
  // A token bucket: up to a second's worth of balls at once, then ~max_spawn_rate per second.
  const ros::WallTime now = ros::WallTime::now();
  spawn_allowance_ = std::min(std::max(max_spawn_rate_, 1.0),
                              spawn_allowance_ + (now - last_spawn_).toSec() * max_spawn_rate_);
  last_spawn_ = now;
  if (spawn_allowance_ < 1.0)
    return "too many new balls: at most " + format(max_spawn_rate_) +
           " per second (~max_spawn_rate)";
  return std::nullopt;
}

engine::BallId SimulatorNode::addBall(const engine::Ball& ball, std::string& error) {
  if (const std::optional<std::string> why = refusal(ball)) {
    error = *why;
    return 0;
  }
  try {
    const engine::BallId id = scene_.world.addBall(ball);
    predictions_stale_ = true;
    spawn_allowance_ -= 1.0;
    return id;
  } catch (const std::invalid_argument& e) {
    error = e.what();
    return 0;
  }
}

bool SimulatorNode::fire(Fire::Request& request, Fire::Response& response) {
  response.success = false;
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  const std::optional<double> speed =
      requestedSpeed(request.speed, *launcher, max_speed_, response.message);
  if (!speed) return true;
  std::string error;
  response.ball_id = addBall(launcher->launch(*speed), error);
  if (response.ball_id == 0) {
    response.message = "launcher '" + launcher->name + "' cannot fire: " + error;
    return true;
  }
  response.success = true;
  response.message = "fired ball " + format(response.ball_id) + " from '" + launcher->name +
                     "' at " + format(*speed) + " m/s";
  return true;
}

bool SimulatorNode::spawnBall(SpawnBall::Request& request, SpawnBall::Response& response) {
  std::string error;
  response.ball_id = addBall(toBall(request), error);
  response.success = response.ball_id != 0;
  response.message = response.success ? "spawned ball " + format(response.ball_id)
                                      : "cannot spawn the ball: " + error;
  return true;
}

bool SimulatorNode::removeBall(RemoveBall::Request& request, RemoveBall::Response& response) {
  response.success = scene_.world.removeBall(request.ball_id);
  predictions_stale_ = true;
  response.message = (response.success ? "removed ball " : "there is no ball ") +
                     format(request.ball_id);
  return true;
}

bool SimulatorNode::explode(Explode::Request& request, Explode::Response& response) {
  response.success = false;
  try {
    response.ball_ids = scene_.world.explode(toBlast(request), max_speed_);
  } catch (const std::invalid_argument& e) {
    response.message = std::string("cannot explode: ") + e.what();
    return true;
  }
  predictions_stale_ = true;
  response.success = true;
  response.message = "the blast pushed " + format(response.ball_ids.size()) + " balls";
  return true;
}

void SimulatorNode::driveBall(const geometry_msgs::Twist& twist) {
  const std::vector<engine::Ball>& balls = scene_.world.balls();
  if (driven_ball_ == 0 && balls.empty()) {
    ROS_WARN_THROTTLE(1.0, "cmd_vel ignored: there is no ball to drive");
    return;
  }
  const engine::BallId id = driven_ball_ != 0 ? driven_ball_ : balls.back().id;
  // A command refused leaves the drive on as it was, and its timeout with it.
  try {
    if (!scene_.world.drive(id, engine::Vec2(twist.linear.x, twist.linear.y))) {
      ROS_WARN_THROTTLE(1.0, "cmd_vel ignored: there is no ball %u to drive (~driven_ball)", id);
      return;
    }
  } catch (const std::invalid_argument& e) {
    ROS_WARN_THROTTLE(1.0, "cmd_vel ignored: %s", e.what());
    return;
  }
  if (driving_ && *driving_ != id) scene_.world.drive(*driving_, engine::Vec2::Zero());
  predictions_stale_ = true;
  driving_ = id;
  drive_until_ = scene_.world.time() + cmd_vel_timeout_;
}

void SimulatorNode::stopStaleDrive() {
  if (!driving_ || scene_.world.time() < drive_until_) return;
  scene_.world.drive(*driving_, engine::Vec2::Zero());
  driving_.reset();
}

bool SimulatorNode::addSegment(AddSegment::Request& request, AddSegment::Response& response) {
  response.success = false;
  if (scene_.world.segments().size() >= max_segments_) {
    response.message = "cannot add the segment: the world has its most segments, " +
                       format(max_segments_) + " (~max_segments)";
    return true;
  }
  try {
    response.segment_id = scene_.world.addSegment(toSegment(request));
    predictions_stale_ = true;
  } catch (const std::invalid_argument& e) {
    response.message = std::string("cannot add the segment: ") + e.what();
    return true;
  }
  response.success = true;
  response.message = "added segment " + format(response.segment_id);
  return true;
}

bool SimulatorNode::removeSegment(RemoveSegment::Request& request,
                                  RemoveSegment::Response& response) {
  response.success = scene_.world.removeSegment(request.segment_id);
  predictions_stale_ = true;
  response.message = (response.success ? "removed segment " : "there is no segment ") +
                     format(request.segment_id);
  return true;
}

bool SimulatorNode::setSegmentMotion(SetSegmentMotion::Request& request,
                                     SetSegmentMotion::Response& response) {
  response.success = false;
  try {
    if (!scene_.world.setSegmentMotion(request.segment_id, toVec2(request.velocity),
                                       request.angular_velocity)) {
      response.message = "there is no segment " + format(request.segment_id);
      return true;
    }
  } catch (const std::invalid_argument& e) {
    response.message = std::string("cannot move the segment: ") + e.what();
    return true;
  }
  predictions_stale_ = true;
  response.success = true;
  response.message = "segment " + format(request.segment_id) + " moves at (" +
                     format(request.velocity.x) + ", " + format(request.velocity.y) + ") m/s, " +
                     format(request.angular_velocity) + " rad/s";
  return true;
}

bool SimulatorNode::reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  scene_ = initial_scene_;
  banking_launchers_.clear();
  driving_.reset();
  predictions_stale_ = true;
  unpublished_contacts_.clear();
  restartPacing();
  // Time jumps back: /clock says so (tf listeners clear their buffers) and tf starts again.
  publishClock();
  last_tf_stamp_.reset();
  response.success = true;
  response.message = "scene '" + scene_.name + "' is back at its initial state, sim time 0";
  return true;
}

bool SimulatorNode::pause(std_srvs::SetBool::Request& request,
                          std_srvs::SetBool::Response& response) {
  paused_ = request.data;
  restartPacing();
  response.success = true;
  response.message = (paused_ ? "paused at sim time " : "running from sim time ") +
                     format(scene_.world.time());
  return true;
}

bool SimulatorNode::step(Step::Request& request, Step::Response& response) {
  response.success = false;
  response.time = scene_.world.time();
  if (!paused_) {
    response.message = "the simulation is running; pause it first (pause: true)";
    return true;
  }
  if (request.steps == 0 || request.steps > kMaxStepsPerCall) {
    response.message = "steps must be within [1, " + format(kMaxStepsPerCall) + "], got " +
                       format(request.steps);
    return true;
  }
  for (std::uint32_t i = 0; i < request.steps; ++i) stepOnce();
  response.success = true;
  response.time = scene_.world.time();
  response.message = "stepped " + format(request.steps) + " x " + format(time_step_) +
                     " s to sim time " + format(response.time);
  return true;
}

void SimulatorNode::aimAtClickedPoint(const geometry_msgs::PointStamped& point) {
  if (!point.header.frame_id.empty() && point.header.frame_id != frame_id_) {
    ROS_WARN("clicked_point in frame '%s' ignored: points must be in '%s'",
             point.header.frame_id.c_str(), frame_id_.c_str());
    return;
  }
  Aim::Request aim_request;
  Aim::Response aim_response;
  aim_request.mode = Aim::Request::TARGET_BALLISTIC;
  aim_request.target = point.point;
  aim(aim_request, aim_response);
  ROS_INFO("clicked_point: %s", aim_response.message.c_str());
  if (!aim_response.success || !fire_on_click_) return;
  Fire::Request fire_request;
  Fire::Response fire_response;
  fire(fire_request, fire_response);
  ROS_INFO("clicked_point: %s", fire_response.message.c_str());
}

}  // namespace ball_physics_sim
