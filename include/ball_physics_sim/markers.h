#pragma once

#include <string>

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/engine/scene.h"

namespace ball_physics_sim {

// rviz markers for the scene: namespace "balls" (id = ball id, coloured by at_rest),
// "segments" and "caps" (id = segment id, and 2 id + end for caps), "launchers" (aim arrows,
// id = launcher index).
visualization_msgs::MarkerArray sceneMarkers(const engine::Scene& scene, const std::string& frame_id,
                                             const ros::Time& stamp);

// DELETE markers for a removed ball or segment (with its caps).
void appendBallDelete(engine::BallId id, const std::string& frame_id,
                      visualization_msgs::MarkerArray& array);
void appendSegmentDelete(engine::SegmentId id, const std::string& frame_id,
                         visualization_msgs::MarkerArray& array);

}  // namespace ball_physics_sim
