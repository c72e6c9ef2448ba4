// SimulatorNode: what it publishes: ball states, contacts, events, tf frames and markers.

#include "ball_physics_sim/simulator_node.h"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

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
// Jobs let go that may still run before another starts: resets in a row start no more.
constexpr std::size_t kMostLetGoJobs = 2;

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

// A prediction worked out on a thread of its own, on copies of the world and launchers, for a
// scene (worlds_changed_) and horizon. Its thread fills in what it found and when, under
// `mutex`, and signals `done`.
struct SimulatorNode::PredictionJob {
  std::uint64_t world = 0;
  double horizon = 0.0;
  ros::WallTime started;
  std::mutex mutex;
  std::condition_variable done;
  std::optional<std::vector<engine::ShotPrediction>> predicted;
  ros::WallTime finished;

  bool isDone() {
    const std::lock_guard<std::mutex> lock(mutex);
    return predicted.has_value();
  }
};

void SimulatorNode::updatePredictions() {
  if (live_.prediction_horizon == 0.0) {
    predictions_.clear();
    return;
  }
  // A job overtaken by reset, load_scene or a horizon change is let go: its thread ends alone,
  // and nothing waits for it.
  let_go_jobs_.erase(std::remove_if(let_go_jobs_.begin(), let_go_jobs_.end(),
                                    [](const auto& job) { return job->isDone(); }),
                     let_go_jobs_.end());
  if (prediction_job_ && std::pair(prediction_job_->world, prediction_job_->horizon) !=
                             std::pair(worlds_changed_, live_.prediction_horizon))
    let_go_jobs_.push_back(std::move(prediction_job_));
  // With none drawn (at start, after load_scene, with the horizon turned on), the markers wait
  // for the job; otherwise they draw the last one done.
  const bool none_drawn = predictions_.size() != scene_.launchers.size();
  if (prediction_job_) {
    PredictionJob& job = *prediction_job_;
    std::unique_lock<std::mutex> lock(job.mutex);
    if (none_drawn) job.done.wait(lock, [&job] { return job.predicted.has_value(); });
    if (!job.predicted) return;
    if (job.predicted->size() == scene_.launchers.size()) predictions_.swap(*job.predicted);
    // However big the world, at most kPredictionShare of a core goes to predicting.
    next_prediction_ = job.finished + (job.finished - job.started) * (1.0 / kPredictionShare - 1.0);
    lock.unlock();
    prediction_job_.reset();
  }
  const ros::WallTime now = ros::WallTime::now();
  if (!predictions_stale_ || let_go_jobs_.size() >= kMostLetGoJobs ||
      (!none_drawn && now < next_prediction_))
    return;
  std::set<std::string> banking;
  for (const engine::Launcher& launcher : scene_.launchers)
    if (banking_launchers_.count(launcher.name)) banking.insert(launcher.name);
  auto job = std::make_shared<PredictionJob>();
  job->world = worlds_changed_;
  job->horizon = live_.prediction_horizon;
  job->started = now;
  // Copies, made here under world_mutex_: the thread owns them, and the job, to its end.
  // (One the loop waits for keeps its priority.)
  std::thread([job, world = scene_.world, launchers = scene_.launchers,
               banking = std::move(banking), time_step = time_step_, waited = none_drawn] {
    if (!waited) yieldToTheLoop("sim_predict");
    std::vector<engine::ShotPrediction> predicted =
        predictShots(world, launchers, banking, time_step, job->horizon);
    const std::lock_guard<std::mutex> lock(job->mutex);
    job->predicted = std::move(predicted);
    job->finished = ros::WallTime::now();
    job->done.notify_all();
  }).detach();
  prediction_job_ = std::move(job);
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
