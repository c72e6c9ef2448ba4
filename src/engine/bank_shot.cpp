#include "ball_physics_sim/engine/bank_shot.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/aiming.h"

namespace ball_physics_sim::engine {

namespace {

// The scan sees a stretch of angles that strike the target this many times (unless
// kMaxScanSamples caps the scan): off flat walls the stretch spans about
// 2 (r_shot + r_target) / path length radians; caps, being convex, narrow it.
constexpr double kSamplesPerStretch = 4.0;
// Bounds on the scan's work, in predictions: at least a sample a degree (what kEdgeBisections
// is sized for), at most what keeps a search under a second in a small scene.
constexpr int kMinScanSamples = 360;
constexpr int kMaxScanSamples = 4096;
// Halvings of a stretch's edge: from a sample's width (at most 1 degree) to below 1e-11 rad.
constexpr int kEdgeBisections = 32;
// Stretches confirmed on the whole world at most: each costs a prediction of all its balls.
constexpr int kMaxConfirmations = 8;
// The scan's predictions step this many times per horizon: impacts are found exactly whatever
// the step, so long steps only save work. The confirmation steps as the world will.
constexpr double kScanStepsPerHorizon = 16.0;

// The bodies a bank shot bounces off, in order.
using BouncePath = std::vector<std::pair<ContactKind, std::uint32_t>>;

// Its bounces, when a predicted shot strikes `target` after one bounce or more; none otherwise.
std::optional<BouncePath> bankPathOf(const ShotPrediction& prediction, BallId target) {
  const std::optional<PredictedImpact>& strike = prediction.final_impact;
  if (prediction.bounces.empty() || !strike || strike->other_kind != ContactKind::kBall ||
      strike->other_id != target)
    return std::nullopt;
  BouncePath path;
  for (const PredictedImpact& bounce : prediction.bounces)
    path.emplace_back(bounce.other_kind, bounce.other_id);
  return path;
}

// What stays fixed while the launch angle is searched.
struct ShotSearch {
  const Launcher& launcher;
  double speed;
  BallId target;
  double time_step;
  double horizon;
  int bounces;
  // The scan's: each prediction stops at the shot's strike, the rest of its step unneeded (a
  // pile struck would settle over it).
  bool until_strike;

  ShotPrediction predict(const World& world, double angle) const {
    return predictLaunch(world, launcher, angle, speed, time_step, horizon, bounces,
                         until_strike);
  }
  std::optional<BouncePath> bankPath(const World& world, double angle) const {
    return bankPathOf(predict(world, angle), target);
  }
};

// Consecutive scanned angles whose shots bounce off the same bodies and strike the target.
struct Stretch {
  long first;  // sample indices, which may pass the scan's end (angleOf wraps them)
  long last;
  BouncePath path;
  double strike_time;  // at its middle sample
};

// The world the scan runs on: the segments, the target and the balls at rest it leans on, the
// other balls removed (removing a ball wakes the resting balls it touches: a target resting on
// a pile would fall in the scan). Balls in motion are left out even if they hold the target
// up: simulating them in every scanned shot is what the scan must not cost (a collapsing
// pyramid made it 40 s), and the confirmation has them.
World withTargetsCluster(const World& world, BallId target) {
  const std::vector<BallId> cluster = world.restingClusterOf(target);
  const std::set<BallId> kept(cluster.begin(), cluster.end());
  World sparse = world;
  for (const Ball& ball : world.balls())
    if (!kept.count(ball.id)) sparse.removeBall(ball.id);
  return sparse;
}

int scanSamples(const World& world, const ShotSearch& search, double target_radius) {
  // The longest path a shot can fly in the horizon, |v| + |g| t integrated.
  const double reach = search.speed * search.horizon +
                       0.5 * world.gravity().norm() * search.horizon * search.horizon;
  const double stretch = 2.0 * (search.launcher.projectile.radius + target_radius) / reach;
  const double samples = std::ceil(2.0 * kPi * kSamplesPerStretch / stretch);
  return static_cast<int>(std::clamp<double>(samples, kMinScanSamples, kMaxScanSamples));
}

// The runs of equal bank paths round the circle of samples, each with its strike time.
std::vector<Stretch> stretchesOf(const std::vector<std::optional<BouncePath>>& paths,
                                 const std::vector<double>& strike_times) {
  const long n = static_cast<long>(paths.size());
  // Start where the path changes, so no run is split at the scan's end.
  long start = 0;
  while (start < n && paths[start] == paths[(start + n - 1) % n]) ++start;
  if (start == n) {
    if (!paths[0]) return {};
    return {Stretch{0, n - 1, *paths[0], strike_times[0]}};
  }
  std::vector<Stretch> stretches;
  for (long first = start; first < start + n;) {
    long last = first;
    while (last + 1 < start + n && paths[(last + 1) % n] == paths[first % n]) ++last;
    if (paths[first % n]) {
      const long middle = (first + last) / 2;
      stretches.push_back({first, last, *paths[first % n], strike_times[middle % n]});
    }
    first = last + 1;
  }
  return stretches;
}

// Bisects between an angle in the stretch and one outside it: the edge, inside by < 1e-11 rad.
double edgeOf(const World& world, const ShotSearch& search, const BouncePath& path,
              double inside, double outside) {
  for (int i = 0; i < kEdgeBisections; ++i) {
    const double middle = 0.5 * (inside + outside);
    (search.bankPath(world, middle) == path ? inside : outside) = middle;
  }
  return inside;
}

}  // namespace

std::optional<BankShot> aimBank(const World& world, const Launcher& launcher, double speed,
                                BallId target, double time_step, double horizon,
                                int max_bounces) {
  const Ball* target_ball = world.findBall(target);
  if (!target_ball) return std::nullopt;
  const ShotSearch search{launcher, speed, target,
                          std::max(time_step, horizon / kScanStepsPerHorizon), horizon,
                          max_bounces, true};
  const ShotSearch confirmation{launcher, speed, target, time_step, horizon, max_bounces, false};
  const World sparse = withTargetsCluster(world, target);

  const int n = scanSamples(world, search, target_ball->radius);
  const double width = 2.0 * kPi / n;
  const auto angleOf = [width](long sample) { return -kPi + sample * width; };
  std::vector<std::optional<BouncePath>> paths(n);
  std::vector<double> strike_times(n, 0.0);
  for (int i = 0; i < n; ++i) {
    const ShotPrediction prediction = search.predict(sparse, angleOf(i));
    paths[i] = bankPathOf(prediction, target);
    if (paths[i]) strike_times[i] = prediction.final_impact->time;
  }

  std::vector<Stretch> stretches = stretchesOf(paths, strike_times);
  std::sort(stretches.begin(), stretches.end(), [](const Stretch& a, const Stretch& b) {
    return std::make_pair(a.path.size(), a.strike_time) <
           std::make_pair(b.path.size(), b.strike_time);
  });
  if (stretches.size() > static_cast<std::size_t>(kMaxConfirmations))
    stretches.resize(kMaxConfirmations);
  for (const Stretch& stretch : stretches) {
    double angle = angleOf((stretch.first + stretch.last) / 2);
    if (stretch.last - stretch.first + 1 < n) {
      const double lower =
          edgeOf(sparse, search, stretch.path, angleOf(stretch.first), angleOf(stretch.first - 1));
      const double upper =
          edgeOf(sparse, search, stretch.path, angleOf(stretch.last), angleOf(stretch.last + 1));
      // A stretch need not be convex: its middle sample serves when the edges' middle misses.
      if (search.bankPath(sparse, 0.5 * (lower + upper)) == stretch.path)
        angle = 0.5 * (lower + upper);
    }
    // Confirmed at the angle the launcher will hold, to the last bit.
    angle = normalizedAngle(angle);
    ShotPrediction prediction = confirmation.predict(world, angle);
    if (bankPathOf(prediction, target)) return BankShot{angle, std::move(prediction)};
  }
  return std::nullopt;
}

}  // namespace ball_physics_sim::engine
