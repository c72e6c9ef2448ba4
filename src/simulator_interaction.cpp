// SimulatorNode: rviz's interactive markers. Balls are dragged and launchers aimed by their
// knobs; balls, launchers and the world have menus. Each action is the service that does the
// same, called as a client would call it.

#include "ball_physics_sim/simulator_node.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

namespace {

using Feedback = visualization_msgs::InteractiveMarkerFeedback;

constexpr double kHandlesKeepAlive = 1.0;  // s of wall time

// The id in a ball's handle name ("ball_<id>"), or nothing for any other name.
std::optional<engine::BallId> ballOfHandle(const std::string& name) {
  const std::string prefix = kBallFramePrefix;
  const std::string digits = name.substr(std::min(prefix.size(), name.size()));
  if (name.compare(0, prefix.size(), prefix) != 0 || digits.empty() ||
      digits.size() > std::numeric_limits<engine::BallId>::digits10 ||
      !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); }))
    return std::nullopt;
  return static_cast<engine::BallId>(std::stoul(digits));
}

// The launcher's name in its handle's name ("launcher_<name>"), or nothing for any other name.
std::optional<std::string> launcherOfHandle(const std::string& name) {
  const std::string prefix = kLauncherFramePrefix;
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0)
    return std::nullopt;
  return name.substr(prefix.size());
}

// What dragging the launcher's knob does (kMenuAimAlong to kMenuLobHigh).
std::uint32_t knobAimMode(const std::map<std::string, std::uint32_t>& modes,
                          const std::string& launcher) {
  const auto mode = modes.find(launcher);
  return mode == modes.end() ? kMenuAimAlong : mode->second;
}

}  // namespace

void SimulatorNode::interactionCallback(const Feedback& feedback) {
  const bool dragged =
      feedback.event_type == Feedback::POSE_UPDATE || feedback.event_type == Feedback::MOUSE_UP;
  const bool released = feedback.event_type == Feedback::MOUSE_UP;
  const std::uint32_t entry = feedback.menu_entry_id;
  // Clicks and presses change nothing.
  if (!dragged && feedback.event_type != Feedback::MENU_SELECT) return;
  const std::string& name = feedback.marker_name;
  const engine::Vec2 place = toVec2(feedback.pose.position);
  bool success = false;
  std::string message;
  const auto answer = [&](const auto& response) {
    success = response.success;
    message = response.message;
  };
  const std::optional<engine::BallId> ball = ballOfHandle(name);
  const std::optional<std::string> launcher_name = launcherOfHandle(name);
  const engine::Launcher* launcher =
      launcher_name ? findLauncher(*launcher_name, message) : nullptr;
  if (dragged && !feedback.header.frame_id.empty() && feedback.header.frame_id != frame_id_) {
    message = "poses must be in '" + frame_id_ + "', got '" + feedback.header.frame_id + "'";
  } else if (dragged && !place.allFinite()) {
    message = "the pose is not finite: " + format(place);
  } else if (name == kWorldHandle && (entry == kMenuPause || entry == kMenuResume)) {
    std_srvs::SetBool::Request request;
    std_srvs::SetBool::Response response;
    request.data = entry == kMenuPause;
    pause(request, response);
    answer(response);
  } else if (ball && !scene_.world.findBall(*ball)) {
    message = "there is no ball " + format(*ball);
  } else if (ball && released) {
    // Where it is let go, moving on as it moved: a teleport.
    SetBallState::Request request;
    SetBallState::Response response;
    const engine::Ball& moved = *scene_.world.findBall(*ball);
    request.ball_id = *ball;
    request.position = toPoint(place);
    request.velocity = toVector3(moved.velocity);
    request.angular_velocity = moved.angular_velocity;
    setBallState(request, response);
    answer(response);
  } else if (ball && feedback.event_type == Feedback::POSE_UPDATE) {
    return;  // a ball goes through others on its way: it moves where it is let go
  } else if (ball && entry == kMenuRemoveBall) {
    RemoveBall::Request request;
    RemoveBall::Response response;
    request.ball_id = *ball;
    removeBall(request, response);
    answer(response);
  } else if (ball && entry == kMenuLeadBall) {
    Aim::Request request;
    Aim::Response response;
    request.mode = Aim::Request::LEAD_BALL;
    request.target_ball_id = *ball;
    aimInLoop(request, response);
    answer(response);
  } else if (launcher_name && !launcher) {
    // findLauncher said why
  } else if (launcher && dragged) {
    Aim::Response response;
    aimAtKnob(*launcher, place, response);
    answer(response);
  } else if (launcher && entry == kMenuFire) {
    Fire::Request request;
    Fire::Response response;
    request.launcher = launcher->name;
    fire(request, response);
    answer(response);
  } else if (launcher && entry >= kMenuAimAlong && entry <= kMenuLobHigh) {
    aim_modes_[launcher->name] = entry;
    success = true;
    message = "launcher '" + launcher->name + "': its knob aims " + knobAimTitle(entry);
  } else if (ball || launcher || name == kWorldHandle) {
    message = (dragged ? "it cannot be dragged" : "it has no menu entry " + format(entry));
  } else {
    message = "there is no such interactive marker";
  }
  // A handle dragged goes where its body is, at the next markers.
  if (const auto drawn = drawn_handles_.find(name); dragged && drawn != drawn_handles_.end())
    drawn->second.at = engine::Vec2::Constant(std::nan(""));
  const char* what = dragged ? "drag" : "menu";
  if (success && (released || !dragged))
    ROS_INFO("interactive marker '%s': %s", name.c_str(), message.c_str());
  else if (!success && feedback.event_type == Feedback::POSE_UPDATE)
    // rviz sends a drag's poses at its frame rate: one refusal a second says it
    ROS_WARN_THROTTLE(1.0, "interactive marker '%s': %s refused: %s", name.c_str(), what,
                      message.c_str());
  else if (!success)
    ROS_WARN("interactive marker '%s': %s refused: %s", name.c_str(), what, message.c_str());
}

void SimulatorNode::aimAtKnob(const engine::Launcher& launcher, const engine::Vec2& knob,
                              Aim::Response& response) {
  Aim::Request request;
  request.launcher = launcher.name;
  request.target = toPoint(knob);
  const std::uint32_t mode = knobAimMode(aim_modes_, launcher.name);
  switch (mode) {
    case kMenuAimStraight:
      request.mode = Aim::Request::TARGET;
      break;
    case kMenuLobLow:
    case kMenuLobHigh:
      request.mode = Aim::Request::TARGET_BALLISTIC;
      request.high_arc = mode == kMenuLobHigh;
      break;
    default: {
      const engine::Vec2 along = knob - launcher.position;
      if (along.isZero()) {
        response.message = "the knob is on the launcher: it points nowhere";
        return;
      }
      request.mode = Aim::Request::ANGLE;
      request.angle = std::atan2(along.y(), along.x());
    }
  }
  aimInLoop(request, response);
}

void SimulatorNode::syncHandles() {
  std::map<std::string, DrawnHandle> shown;
  bool changed = false;
  // A handle new or of a new shape is sent whole (built only then), one that moved its pose.
  const auto show = [&](const std::string& name, const DrawnHandle& handle, const auto& build) {
    const auto drawn = drawn_handles_.find(name);
    if (drawn == drawn_handles_.end() || drawn->second.shape != handle.shape) {
      handles_->insert(build());
      changed = true;
    } else if (drawn->second.at != handle.at) {
      handles_->setPose(name, handlePose(handle.at));
      changed = true;
    }
    shown.emplace(name, handle);
  };
  const engine::Vec2 world_at = worldHandlePosition(scene_);
  show(kWorldHandle, {world_at, 0.0}, [&] { return worldHandle(world_at, frame_id_); });
  for (const engine::Launcher& launcher : scene_.launchers) {
    const std::uint32_t aim_mode = knobAimMode(aim_modes_, launcher.name);
    show(launcherFrame(launcher.name), {aimKnobPosition(launcher), double(aim_mode)},
         [&] { return launcherHandle(launcher, aim_mode, frame_id_); });
  }
  // Balls have handles only while paused: a running world would send every ball's pose at the
  // marker rate, and its balls would slip away from the pointer.
  if (paused_)
    for (const engine::Ball& ball : scene_.world.balls())
      show(ballFrame(ball.id), {ball.position, ball.radius},
           [&] { return ballHandle(ball, frame_id_); });
  for (const auto& drawn : drawn_handles_)
    if (!shown.count(drawn.first)) {
      handles_->erase(drawn.first);
      changed = true;
    }
  drawn_handles_.swap(shown);
  // rviz shows a server's handles once an update follows the (latched) full state it read, and
  // the server's keep-alive is a ROS timer, which stands still while sim time does: one a second
  // of wall time, a pose sent again.
  const ros::WallTime now = ros::WallTime::now();
  if (!changed && now - handles_sent_ > ros::WallDuration(kHandlesKeepAlive)) {
    handles_->setPose(kWorldHandle, handlePose(world_at));
    changed = true;
  }
  if (!changed) return;
  handles_->applyChanges();
  handles_sent_ = now;
}

}  // namespace ball_physics_sim
