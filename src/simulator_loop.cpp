// SimulatorNode: the loop and its timing (as flatland's simulation_manager).

#include "ball_physics_sim/simulator_node.h"

#include <malloc.h>
#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <thread>

#include <rosgraph_msgs/Clock.h>

#include "ball_physics_sim/conversions.h"

namespace ball_physics_sim {

namespace {

// How much nicer than the loop the threads that yield to it are (19 is the least priority).
constexpr int kYieldingNiceness = 10;
constexpr int kLeastPriority = 19;
// How often the loop hands the memory freed since back to the system. The steps allocate and
// free about a million blocks a second, from more than one thread: glibc's malloc keeps what
// they free in its arenas, so the node's resident memory would climb long after its live heap
// stops growing. A trim takes a few milliseconds with 1,000 balls (3 to 10): every 10 s, that
// is under a thousandth of the loop's time, and memory is back within a soak's 10 s window.
constexpr double kReturnMemoryPeriod = 10.0;  // s of wall time

}  // namespace

void yieldToTheLoop(const char* name) {
  [[maybe_unused]] static thread_local const bool lowered = [name] {
    pthread_setname_np(pthread_self(), name);
    const auto thread = static_cast<id_t>(syscall(SYS_gettid));
    errno = 0;
    const int niceness = getpriority(PRIO_PROCESS, thread);  // (the loop's, inherited)
    return errno == 0 &&
           setpriority(PRIO_PROCESS, thread,
                       std::min(niceness + kYieldingNiceness, kLeastPriority)) == 0;
  }();
}

void SimulatorNode::run() {
  // Publishing follows the wall clock, so that topics stay alive while paused.
  ros::WallTime next_states = ros::WallTime::now(), next_markers = next_states;
  ros::WallTime next_return = next_states + ros::WallDuration(kReturnMemoryPeriod);
  restartPacing();
  aim_spinner_.start();
  while (ros::ok()) {
    ros::WallTime due;
    {
      const std::lock_guard<std::mutex> lock(world_mutex_);
      ros::spinOnce();
      // Waking to publish is no reason to step: below the factor's pace, it would step faster.
      if (!paused_ && ros::WallTime::now() >= nextStepDue()) stepOnce();
      const ros::WallTime now = ros::WallTime::now();
      const ros::WallDuration state_period(1.0 / live_.publish_rate);
      const ros::WallDuration marker_period(1.0 / live_.marker_rate);
      // A rate raised by reconfigure holds from now, not from the next time the old one was due.
      next_states = std::min(next_states, now + state_period);
      next_markers = std::min(next_markers, now + marker_period);
      if (now >= next_states) {
        publishStates();
        next_states = std::max(next_states + state_period, now);
      }
      if (now >= next_markers) {
        publishMarkers();
        next_markers = std::max(next_markers + marker_period, now);
      }
      due = std::min(next_states, next_markers);
      if (!paused_) due = std::min(due, nextStepDue());
    }
    // Behind, the loop would take the lock again at once: aim gets its turn first.
    while (aim_waiting_) std::this_thread::yield();
    ros::WallTime wall_now = ros::WallTime::now();
    if (wall_now >= next_return) {
      malloc_trim(0);
      next_return = wall_now + ros::WallDuration(kReturnMemoryPeriod);
      wall_now = ros::WallTime::now();
    }
    if (due > wall_now) (due - wall_now).sleep();
  }
}

ros::WallTime SimulatorNode::nextStepDue() const {
  if (live_.real_time_factor == 0.0) return ros::WallTime();  // as fast as possible: now
  return pacing_wall_start_ +
         ros::WallDuration((scene_.world.time() - pacing_sim_start_) / live_.real_time_factor);
}

void SimulatorNode::restartPacing() {
  pacing_wall_start_ = ros::WallTime::now();
  pacing_sim_start_ = scene_.world.time();
}

void SimulatorNode::stepOnce() {
  stopStaleDrive();
  scene_.world.step(time_step_);
  predictions_stale_ = true;
  const std::vector<engine::Contact> contacts = scene_.world.takeContacts();
  unpublished_contacts_.insert(unpublished_contacts_.end(), contacts.begin(), contacts.end());
  // Rare, and what a game waits for: sent at once, not at the publish rate.
  for (const engine::SensorEvent& event : scene_.world.takeSensorEvents())
    sensor_events_pub_.publish(toMsg(event));
  for (const engine::BrickHit& hit : scene_.world.takeBrickHits()) brick_hits_pub_.publish(toMsg(hit));
  publishClock();
}

void SimulatorNode::publishClock() {
  if (!publish_clock_) return;
  rosgraph_msgs::Clock clock;
  clock.clock = ros::Time(scene_.world.time());
  clock_pub_.publish(clock);
}

void SimulatorNode::stopStaleDrive() {
  if (!driving_ || scene_.world.time() < drive_until_) return;
  scene_.world.drive(*driving_, engine::Vec2::Zero());
  driving_.reset();
}

}  // namespace ball_physics_sim
