#pragma once

#include <string>
#include <vector>

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include "ball_physics_sim/engine/prediction.h"
#include "ball_physics_sim/engine/scene.h"

namespace ball_physics_sim {

// Segments of zero thickness are drawn this thick so that they can be seen.
constexpr double kMinDrawnThickness = 0.04;  // m

// rviz markers for the scene: namespaces "balls" (id = ball id, coloured by at_rest),
// "segments" and "caps" (id = segment id, and 2 id + end for caps; bricks red), "ropes" (a line
// from the ball to the other end, id = rope id), "wind" and
// "sensors" (translucent boxes, id = index in the world's list; with `labels`, the sensors'
// names in "sensor_labels"), "water" (translucent boxes), "attractors" (a sphere of the
// core's size at each centre), "launchers" (aim arrows,
// id = launcher index); with `labels`, "ball_labels" and "segment_labels" (the ids as text,
// id = ball or segment id); "predicted_paths" (line strips) and "predicted_hits" (the ball at
// the impact that ends the prediction), id = launcher index, for launcher i's shot in
// predictions[i] (there may be fewer predictions than launchers).
visualization_msgs::MarkerArray sceneMarkers(const engine::Scene& scene,
                                             const std::vector<engine::ShotPrediction>& predictions,
                                             bool labels, const std::string& frame_id,
                                             const ros::Time& stamp);

// A DELETEALL marker: rviz forgets every marker drawn before it (a scene replaced).
void appendDeleteAll(const std::string& frame_id, visualization_msgs::MarkerArray& array);

// DELETE markers for a removed ball, rope or segment (with its caps).
void appendBallDelete(engine::BallId id, const std::string& frame_id,
                      visualization_msgs::MarkerArray& array);
void appendRopeDelete(engine::RopeId id, const std::string& frame_id,
                      visualization_msgs::MarkerArray& array);
void appendSegmentDelete(engine::SegmentId id, const std::string& frame_id,
                         visualization_msgs::MarkerArray& array);

}  // namespace ball_physics_sim
