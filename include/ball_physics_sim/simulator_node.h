#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/Twist.h>
#include <interactive_markers/interactive_marker_server.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_broadcaster.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>

#include "ball_physics_sim/AddSegment.h"
#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/Explode.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/LoadScene.h"
#include "ball_physics_sim/RemoveBall.h"
#include "ball_physics_sim/RemoveSegment.h"
#include "ball_physics_sim/SetBallState.h"
#include "ball_physics_sim/SetSegmentMotion.h"
#include "ball_physics_sim/SimulatorNodeConfig.h"
#include "ball_physics_sim/SpawnBall.h"
#include "ball_physics_sim/Step.h"
#include "ball_physics_sim/engine/aim_request.h"
#include "ball_physics_sim/engine/prediction.h"
#include "ball_physics_sim/engine/scene.h"

namespace ball_physics_sim {

// The path of the scene shipped as config/scenes/NAME.yaml.
std::string shippedScenePath(const std::string& name);

// The node's settings that rqt_reconfigure may change while it runs (besides gravity, which is
// the world's).
struct LiveSettings {
  double real_time_factor;    // sim s per wall s; 0: as fast as possible
  double publish_rate;        // Hz (wall clock) of balls, contacts and tf
  double marker_rate;         // Hz (wall clock) of markers
  double prediction_horizon;  // s: how far shots are predicted; 0: not at all
  bool show_labels;
  bool fire_on_click;
};

// Throws std::invalid_argument naming the first setting out of its range, as its ~parameter,
// for steps of `time_step`: the one check of the parameters at start and of reconfigure.
void checkLiveSettings(const LiveSettings& settings, double time_step);

// Names the calling thread (at most 15 characters, as ps and top show it) and makes it 10
// nicer than the loop, once (Linux gives each thread a niceness of its own): the aims and the
// markers' shot predictions run on copies of the world for as long as they take, and on a
// small machine they would take the processor the loop needs to keep real time.
void yieldToTheLoop(const char* name);

// The ROS face of one simulated scene: owns the handles, steps the engine at a fixed time
// step, answers the services and publishes states, contacts, tf frames and markers. Split by
// role, as flatland splits its server: simulator_node.cpp (parameters and handles),
// simulator_loop.cpp (the loop and its timing), simulator_services.cpp (the world's services),
// simulator_launchers.cpp (aim, which engine::aimLauncher answers, and fire),
// simulator_publishers.cpp (topics, tf and markers), simulator_reconfigure.cpp (settings changed
// live), simulator_interaction.cpp (rviz's interactive markers).
class SimulatorNode {
 public:
  // Reads ~scene / ~scene_file and the other parameters; throws engine::SceneError for a bad
  // scene file and std::invalid_argument for a bad parameter.
  SimulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);

  // Steps and publishes until ROS shuts down.
  void run();

 private:
  // Services: each validates its request and answers success: false with the reason, leaving
  // the world untouched, or changes the world through the engine.
  // aim runs on its own thread (aim_spinner_), the others on the loop's.
  bool aim(Aim::Request& request, Aim::Response& response);
  bool fire(Fire::Request& request, Fire::Response& response);
  bool spawnBall(SpawnBall::Request& request, SpawnBall::Response& response);
  bool removeBall(RemoveBall::Request& request, RemoveBall::Response& response);
  bool setBallState(SetBallState::Request& request, SetBallState::Response& response);
  bool addSegment(AddSegment::Request& request, AddSegment::Response& response);
  bool removeSegment(RemoveSegment::Request& request, RemoveSegment::Response& response);
  bool setSegmentMotion(SetSegmentMotion::Request& request, SetSegmentMotion::Response& response);
  bool explode(Explode::Request& request, Explode::Response& response);
  bool loadScene(LoadScene::Request& request, LoadScene::Response& response);
  bool reset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool pause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);
  bool step(Step::Request& request, Step::Response& response);
  void aimAtClickedPoint(const geometry_msgs::PointStamped& point);
  // aim, answered on the loop's thread (rviz's click, knob and menu), where the world is held.
  void aimInLoop(const Aim::Request& request, Aim::Response& response);
  // Puts `answer`, found `elapsed` s of sim time ago, into `response` and, if it has a
  // solution, turns the launcher to it.
  void takeAim(const Aim::Request& request, const engine::AimAnswer& answer, double elapsed,
               Aim::Response& response);
  engine::AimLimits aimLimits() const;
  // world_mutex_, taken off the loop's thread: aim_waiting_ makes the loop let go of it.
  std::unique_lock<std::mutex> lockAgainstTheLoop();
  // cmd_vel: pushes the driven ball (~driven_ball; 0: the newest) with linear.x and linear.y
  // as an acceleration, until ~cmd_vel_timeout of sim time passes without another command.
  void driveBall(const geometry_msgs::Twist& twist);
  // Ends the drive once its command has timed out.
  void stopStaleDrive();
  // rqt_reconfigure: takes the settings and gravity in `config` if all are good, or refuses them
  // all, saying why; either way leaves `config` holding what is in force.
  void reconfigureCallback(SimulatorNodeConfig& config, uint32_t level);
  SimulatorNodeConfig configInForce() const;
  // Shows the reconfigure server what is in force, after the scene (its gravity) changed.
  void publishConfigInForce();
  // rviz forgets every marker; the next markers draw the scene whole.
  void forgetDrawnMarkers();
  // rviz's interactive markers: a drag or a menu entry is answered by the service that does the
  // same (set_ball_state, aim, fire, remove_ball, pause); a refusal is logged with its reason.
  void interactionCallback(const visualization_msgs::InteractiveMarkerFeedback& feedback);
  // Aims `launcher` at its knob dragged to `knob`, as the knob's aim mode says.
  void aimAtKnob(const engine::Launcher& launcher, const engine::Vec2& knob,
                 Aim::Response& response);
  // Shows the interactive marker server what changed since the handles were last drawn.
  void syncHandles();

  // The named launcher (empty: the first), or nullptr with `error` saying why.
  engine::Launcher* findLauncher(const std::string& name, std::string& error);
  // Why `ball` may not be added (a full world, a value no ball can have, a limit of this node),
  // or nothing; refills the spawn allowance.
  std::optional<std::string> refusal(const engine::Ball& ball);
  // Why a ball may not move at a finite `velocity` (faster than ~max_speed), or nothing.
  std::optional<std::string> speedRefusal(const engine::Vec2& velocity) const;
  // Adds a ball unless refused or overlapping; the id, or 0 with `error` saying why.
  engine::BallId addBall(const engine::Ball& ball, std::string& error);
  // Starts initial_scene_ afresh at sim time 0, as reset and load_scene do.
  void restartScene();
  void stepOnce();
  void publishClock();
  // Real-time pacing counts from here: after a pause or a reset the simulation does not race
  // to catch up.
  void restartPacing();
  // When the wall clock reaches the sim time at the real-time factor's pace.
  ros::WallTime nextStepDue() const;
  void publishStates();
  // Starts predicting the launchers' shots on a copy of the world once the scene has changed,
  // and takes the prediction once it is done.
  void updatePredictions();
  void publishMarkers();

  // Where reset returns: the scene loaded at start or by load_scene.
  engine::Scene initial_scene_;
  engine::Scene scene_;
  std::string frame_id_;
  double time_step_;
  LiveSettings live_;
  // The launchers' predicted shots, computed again only once the scene has changed (every
  // change sets predictions_stale_) and not before next_prediction_, on a thread of their own
  // (prediction_job_); jobs overtaken before they were done run on alone (let_go_jobs_).
  struct PredictionJob;
  std::vector<engine::ShotPrediction> predictions_;
  bool predictions_stale_ = true;
  std::shared_ptr<PredictionJob> prediction_job_;
  std::vector<std::shared_ptr<PredictionJob>> let_go_jobs_;
  // Launchers (by name) last aimed by BANK: their predicted paths follow the bounces.
  std::set<std::string> banking_launchers_;
  ros::WallTime next_prediction_;
  // Limits that protect the node from a careless or hostile client.
  std::size_t max_balls_;
  std::size_t max_segments_;
  double max_speed_;
  double max_radius_;
  double max_spawn_rate_;  // new balls per second of wall time
  double spawn_allowance_ = 0.0;
  ros::WallTime last_spawn_;
  engine::BallId driven_ball_;  // 0: the newest ball
  double cmd_vel_timeout_;      // s of sim time
  // The ball cmd_vel drives and until when (sim time); none while no drive is on.
  std::optional<engine::BallId> driving_;
  double drive_until_ = 0.0;
  bool publish_clock_;
  bool paused_;
  ros::WallTime pacing_wall_start_;
  double pacing_sim_start_ = 0.0;

  ros::Publisher balls_pub_;
  ros::Publisher contacts_pub_;
  ros::Publisher sensor_events_pub_;
  ros::Publisher brick_hits_pub_;
  ros::Publisher markers_pub_;
  ros::Publisher clock_pub_;
  // Serves aim alone (aim_spinner_): declared before the services, which it outlives.
  ros::CallbackQueue aim_queue_;
  std::vector<ros::ServiceServer> services_;
  ros::Subscriber clicked_point_sub_;
  ros::Subscriber cmd_vel_sub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  std::vector<engine::Contact> unpublished_contacts_;
  std::optional<ros::Time> last_tf_stamp_;
  // What the last markers drew, so that removed bodies' markers are deleted.
  std::set<engine::BallId> drawn_balls_;
  std::set<engine::SegmentId> drawn_segments_;
  std::set<engine::RopeId> drawn_ropes_;
  // The handles the interactive marker server shows, by name: where, and the shape they were
  // built with (a ball's radius, a knob's aim mode), so that only changes are sent.
  struct DrawnHandle {
    engine::Vec2 at;
    double shape;
  };
  std::unique_ptr<interactive_markers::InteractiveMarkerServer> handles_;
  ros::Subscriber feedback_sub_;
  std::map<std::string, DrawnHandle> drawn_handles_;
  ros::WallTime handles_sent_;
  // Each launcher's knob aim mode (kMenuAimAlong to kMenuLobHigh), by launcher name.
  std::map<std::string, std::uint32_t> aim_modes_;
  // Set up last, once the node can answer it. Its own lock would warn at every updateConfig.
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<SimulatorNodeConfig>> reconfigure_server_;
  // Held by the loop while it steps, publishes and serves the other callbacks, and by aim while
  // it copies the world and turns the launcher.
  std::mutex world_mutex_;
  // Scenes restarted and gravity changed, counted: aim refuses an answer found before either.
  std::uint64_t worlds_changed_ = 0;
  // Set while aim waits for world_mutex_: the loop, which would take it again at once, yields.
  std::atomic<bool> aim_waiting_{false};
  // Last, so that it stops first: its thread answers aim until then.
  ros::AsyncSpinner aim_spinner_{1, &aim_queue_};
};

}  // namespace ball_physics_sim
