#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "ball_physics_sim/engine/launcher.h"
#include "ball_physics_sim/engine/world.h"

namespace ball_physics_sim::engine {

// A world as a scene file describes it, with its launchers.
struct Scene {
  std::string name;
  World world;
  std::vector<Launcher> launchers;
};

// A scene file that cannot be used; what() reads "FILE: KEY: REASON".
class SceneError : public std::runtime_error {
 public:
  SceneError(const std::string& file, const std::string& key, const std::string& reason);
};

// Reads a scene YAML file (format in docs/scenes.md). Throws SceneError.
Scene loadScene(const std::string& path);

// Reads a scene from YAML text; errors name `file` as where it came from. Throws SceneError.
Scene parseScene(const std::string& yaml, const std::string& file);

}  // namespace ball_physics_sim::engine
