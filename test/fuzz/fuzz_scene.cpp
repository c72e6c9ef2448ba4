// Fuzzes the scene loader with arbitrary text: it must load the scene or throw SceneError,
// never crash, and a scene it loads must step within the invariants.
#include <optional>

#include "ball_physics_sim/engine/scene.h"
#include "fuzz_target.h"

namespace {

// Long enough for the loaded balls to fall onto what the scene holds.
constexpr int kSteps = 60;
constexpr double kTimeStep = 1.0 / 60.0;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ball_physics_sim;
  std::optional<engine::Scene> scene;
  try {
    scene = engine::parseScene(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
  } catch (const engine::SceneError&) {
    return 0;
  }
  for (int i = 0; i < kSteps; ++i) fuzz::stepAndCheck(scene->world, kTimeStep);
  return 0;
}
