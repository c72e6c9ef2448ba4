#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <ros/time.h>
#include <visualization_msgs/InteractiveMarker.h>
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

// The menu entries of the interactive markers: rviz sends the id back as menu_entry_id.
enum HandleMenuEntry : std::uint32_t {
  kMenuFire = 1,  // a launcher's
  kMenuAimMode,   // its submenu of the four below: what dragging its knob does
  kMenuAimAlong,
  kMenuAimStraight,
  kMenuLobLow,
  kMenuLobHigh,
  kMenuRemoveBall,  // a ball's
  kMenuLeadBall,
  kMenuPause,  // the world's
  kMenuResume,
};

// The interactive markers rviz drags and clicks (names as the tf frames, and "world"), whose
// menus are the entries above: a disc under a ball, showing as a rim, dragged in the plane to
// move the ball; a knob just past the tip of a launcher's aim arrow, dragged to aim, its menu
// with `aim_mode` (one of kMenuAimAlong to kMenuLobHigh) ticked; a button above the top left of
// the scene's segments and launchers (`world_at`) with the world's menu.
constexpr char kWorldHandle[] = "world";
visualization_msgs::InteractiveMarker ballHandle(const engine::Ball& ball,
                                                 const std::string& frame_id);
visualization_msgs::InteractiveMarker launcherHandle(const engine::Launcher& launcher,
                                                     std::uint32_t aim_mode,
                                                     const std::string& frame_id);
visualization_msgs::InteractiveMarker worldHandle(const engine::Vec2& world_at,
                                                  const std::string& frame_id);
// How a knob aims, as its menu says: "along the knob", ...
std::string knobAimTitle(std::uint32_t aim_mode);
// Where the handles are (a ball's at its centre): a launcher's knob past its arrow's tip, the
// world's button; and a handle's pose there.
engine::Vec2 aimKnobPosition(const engine::Launcher& launcher);
engine::Vec2 worldHandlePosition(const engine::Scene& scene);
geometry_msgs::Pose handlePose(const engine::Vec2& position);

}  // namespace ball_physics_sim
