// SimulatorNode: settings changed live through dynamic_reconfigure (cfg/SimulatorNode.cfg).

#include "ball_physics_sim/simulator_node.h"

#include <stdexcept>

namespace ball_physics_sim {

void SimulatorNode::reconfigureCallback(SimulatorNodeConfig& config, uint32_t) {
  const LiveSettings wanted{config.real_time_factor, config.publish_rate, config.marker_rate,
                            config.prediction_horizon, config.show_labels, config.fire_on_click};
  const engine::Vec2 gravity(config.gravity_x, config.gravity_y);
  const bool gravity_changed = gravity != scene_.world.gravity();
  try {
    // Both checked before either changes: a refusal leaves everything as it was.
    checkLiveSettings(wanted, time_step_);
    if (gravity_changed) {
      scene_.world.setGravity(gravity);
      ++worlds_changed_;
    }
  } catch (const std::invalid_argument& e) {
    ROS_WARN("sim_node: reconfigure refused, nothing changed: %s", e.what());
    config = configInForce();
    return;
  }
  if (wanted.real_time_factor != live_.real_time_factor)
    restartPacing();  // the new pace counts from now: no race to catch up, no stall
  if (gravity_changed || wanted.prediction_horizon != live_.prediction_horizon) {
    predictions_stale_ = true;
    next_prediction_ = ros::WallTime();  // now, not when the last one's share of time is up
  }
  // Labels or predicted paths switched off would stay drawn in rviz.
  const bool redraw = wanted.show_labels != live_.show_labels ||
                      wanted.prediction_horizon != live_.prediction_horizon;
  live_ = wanted;
  if (redraw) forgetDrawnMarkers();
  config = configInForce();
}

SimulatorNodeConfig SimulatorNode::configInForce() const {
  SimulatorNodeConfig config = SimulatorNodeConfig::__getDefault__();
  config.gravity_x = scene_.world.gravity().x();
  config.gravity_y = scene_.world.gravity().y();
  config.real_time_factor = live_.real_time_factor;
  config.publish_rate = live_.publish_rate;
  config.marker_rate = live_.marker_rate;
  config.prediction_horizon = live_.prediction_horizon;
  config.show_labels = live_.show_labels;
  config.fire_on_click = live_.fire_on_click;
  return config;
}

void SimulatorNode::publishConfigInForce() {
  if (reconfigure_server_) reconfigure_server_->updateConfig(configInForce());
}

}  // namespace ball_physics_sim
