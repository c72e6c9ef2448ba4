#include <exception>

#include <ros/ros.h>

#include "ball_physics_sim/simulator_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "sim_node");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    ball_physics_sim::SimulatorNode node(nh, private_nh);
    node.run();
  } catch (const std::exception& e) {
    ROS_FATAL("sim_node cannot start: %s", e.what());
    return 1;
  }
  return 0;
}
