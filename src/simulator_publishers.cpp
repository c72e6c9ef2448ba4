// SimulatorNode: what it publishes: ball states, contacts, events, tf frames and markers.

#include "ball_physics_sim/simulator_node.h"

#include <chrono>
#include <future>

#include <geometry_msgs/TransformStamped.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/ContactArray.h"
#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/bank_shot.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

namespace {

// The most of a core's time predictions may take.
constexpr double kPredictionShare = 0.1;

// Where each launcher's next shot at its default speed will go, following the bounces of those
// in `banking`.
std::vector<engine::ShotPrediction> predictShots(const engine::World& world,
                                                 const std::vector<engine::Launcher>& launchers,
                                                 const std::set<std::string>& banking,
                                                 double time_step, double horizon) {
  std::vector<engine::ShotPrediction> predictions;
  for (const engine::Launcher& launcher : launchers) {
    try {
      const int bounces = banking.count(launcher.name) ? engine::kMaxBankBounces : 0;
      predictions.push_back(engine::predictLaunch(world, launcher, launcher.angle, launcher.speed,
                                                  time_step, horizon, bounces));
    } catch (const std::invalid_argument&) {
      predictions.emplace_back();  // the muzzle is blocked: nothing to show
    }
  }
  return predictions;
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

void SimulatorNode::publishStates() {
  const ros::Time stamp(scene_.world.time());
  BallStateArray balls;
  balls.header.stamp = stamp;
  balls.header.frame_id = frame_id_;
  std::vector<geometry_msgs::TransformStamped> frames;
  for (const engine::Ball& ball : scene_.world.balls()) {
    balls.balls.push_back(toMsg(ball));
    frames.push_back(frame(frame_id_, ballFrame(ball.id), stamp, ball.position, ball.angle));
  }
  for (const engine::Launcher& launcher : scene_.launchers)
    frames.push_back(
        frame(frame_id_, launcherFrame(launcher.name), stamp, launcher.position, launcher.angle));
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

void SimulatorNode::updatePredictions() {
  const ros::WallTime now = ros::WallTime::now();
  if (live_.prediction_horizon == 0.0) {
    predictions_.clear();
    return;
  }
  // A finished prediction is taken, unless the scene restarted or the horizon changed since it
  // started. With none drawn (a new scene or horizon), the markers wait for it.
  const bool none_drawn = predictions_.size() != scene_.launchers.size();
  if (pending_predictions_.valid() &&
      (none_drawn || pending_predictions_.wait_for(std::chrono::seconds(0)) ==
                         std::future_status::ready)) {
    std::vector<engine::ShotPrediction> predicted = pending_predictions_.get();
    if (pending_for_ == std::pair(worlds_changed_, live_.prediction_horizon) &&
        predicted.size() == scene_.launchers.size()) {
      predictions_.swap(predicted);
      // However big the world, at most kPredictionShare of a core goes to predicting.
      const ros::WallTime done = ros::WallTime::now();
      next_prediction_ = done + (done - prediction_started_) * (1.0 / kPredictionShare - 1.0);
    }
  }
  if (pending_predictions_.valid() || !predictions_stale_ || now < next_prediction_) return;
  // Worked out on copies, off the loop's thread: a big world's prediction would stall the loop.
  std::set<std::string> banking;
  for (const engine::Launcher& launcher : scene_.launchers)
    if (banking_launchers_.count(launcher.name)) banking.insert(launcher.name);
  pending_predictions_ = std::async(
      std::launch::async, predictShots, scene_.world, scene_.launchers, std::move(banking),
      time_step_, live_.prediction_horizon);
  pending_for_ = {worlds_changed_, live_.prediction_horizon};
  prediction_started_ = now;
  predictions_stale_ = false;
  if (none_drawn) updatePredictions();
}

void SimulatorNode::publishMarkers() {
  updatePredictions();
  visualization_msgs::MarkerArray markers = sceneMarkers(
      scene_, predictions_, live_.show_labels, frame_id_, ros::Time(scene_.world.time()));
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
  syncHandles();
}

void SimulatorNode::forgetDrawnMarkers() {
  visualization_msgs::MarkerArray forget;
  appendDeleteAll(frame_id_, forget);
  markers_pub_.publish(forget);
  drawn_balls_.clear();
  drawn_segments_.clear();
  drawn_ropes_.clear();
}

}  // namespace ball_physics_sim
