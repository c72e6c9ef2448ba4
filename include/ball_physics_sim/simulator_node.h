#pragma once

#include <string>
#include <vector>

#include <geometry_msgs/PointStamped.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "ball_physics_sim/Aim.h"
#include "ball_physics_sim/Fire.h"
#include "ball_physics_sim/engine/scene.h"

namespace ball_physics_sim {

// The ROS face of one simulated scene: owns the handles, steps the engine at a fixed time
// step, answers the services and publishes states, contacts, tf frames and markers.
class SimulatorNode {
 public:
  // Reads ~scene / ~scene_file and the other parameters; throws engine::SceneError for a bad
  // scene file and std::invalid_argument for a bad parameter.
  SimulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);

  // Steps and publishes until ROS shuts down.
  void run();

 private:
  bool aim(Aim::Request& request, Aim::Response& response);
  bool fire(Fire::Request& request, Fire::Response& response);
  void aimAtClickedPoint(const geometry_msgs::PointStamped& point);

  // The named launcher (empty: the first), or nullptr with `error` saying why.
  engine::Launcher* findLauncher(const std::string& name, std::string& error);
  void step();
  void publishStates();
  void publishMarkers();

  engine::Scene scene_;
  std::string frame_id_;
  double time_step_;
  double real_time_factor_;
  double state_period_;
  double marker_period_;
  bool fire_on_click_;
  bool publish_clock_;

  ros::Publisher balls_pub_;
  ros::Publisher contacts_pub_;
  ros::Publisher markers_pub_;
  ros::Publisher clock_pub_;
  ros::ServiceServer aim_service_;
  ros::ServiceServer fire_service_;
  ros::Subscriber clicked_point_sub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  std::vector<engine::Contact> unpublished_contacts_;
};

}  // namespace ball_physics_sim
