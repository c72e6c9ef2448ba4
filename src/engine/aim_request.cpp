#include "ball_physics_sim/engine/aim_request.h"

#include <cmath>
#include <stdexcept>

#include "ball_physics_sim/engine/bank_shot.h"
#include "ball_physics_sim/engine/format.h"
#include "ball_physics_sim/engine/prediction.h"

namespace ball_physics_sim::engine {

namespace {

// What a predicted shot strikes, for messages: "segment 3 at (x, y) after t s".
std::string describe(const PredictedImpact& hit) {
  const char* kind = hit.other_kind == ContactKind::kBall      ? "ball "
                     : hit.other_kind == ContactKind::kSegment ? "segment "
                                                               : "the end of segment ";
  return kind + format(hit.other_id) + " at " + format(hit.position) + " after " +
         format(hit.time) + " s";
}

// Why a shot cannot be predicted (its muzzle is blocked, ...).
std::string cannotPredict(const std::invalid_argument& e) {
  return std::string("cannot predict the shot: ") + e.what();
}

// One request's answer, built up by the mode that handles it.
class Aimer {
 public:
  Aimer(const World& world, const Launcher& launcher, const AimLimits& limits, AimAnswer& answer)
      : world_(world), launcher_(launcher), limits_(limits), answer_(answer) {}

  // kAngle (and kTarget under gravity, which only points): the aim along `angle`, with the
  // first impact the prediction sees (if any) as the time of flight and predicted hit, said in
  // the message (as is a blocked muzzle, which leaves them 0).
  AimSolution along(double angle) const {
    if (limits_.prediction_horizon == 0.0) return AimSolution{angle, 0.0};
    std::string error;
    const std::optional<ShotPrediction> prediction =
        predict(world_, angle, limits_.prediction_horizon, error);
    if (!prediction) {
      answer_.message += "; " + error;  // pointing needs no prediction: the aim still holds
      return AimSolution{angle, 0.0};
    }
    const std::optional<PredictedImpact>& hit = prediction->final_impact;
    if (!hit) {
      answer_.message += "; the shot hits nothing within " + format(limits_.prediction_horizon) +
                         " s (~prediction_horizon)";
      return AimSolution{angle, 0.0};
    }
    answer_.message += "; the shot first hits " + describe(*hit);
    answer_.predicted_hit = hit->position;
    return AimSolution{angle, hit->time};
  }

  // kTarget and kTargetBallistic: the aim at `request.target`, confirmed by arrivalAt.
  std::optional<AimSolution> atPoint(const AimRequest& request) const {
    const Vec2& target = request.target;
    if (!target.allFinite()) {
      answer_.message = "target must be finite";
      return std::nullopt;
    }
    if (target == launcher_.position) {
      answer_.message =
          "target " + format(target) + " is where launcher '" + launcher_.name + "' is";
      return std::nullopt;
    }
    const Vec2& gravity = world_.gravity();
    const bool ballistic = request.mode == AimMode::kTargetBallistic;
    std::optional<AimSolution> solution;
    if (ballistic && request.time_of_flight != 0.0) {
      solution = timedArc(target, request);
    } else if (ballistic) {
      solution =
          aimBallistic(launcher_.position, target, answer_.speed, gravity, request.high_arc);
      if (!solution)
        answer_.message = "target " + format(target) + " is out of reach at " +
                          format(answer_.speed) + " m/s; it needs at least " +
                          format(minimumBallisticSpeed(launcher_.position, target, gravity)) +
                          " m/s";
    } else {
      solution = aimStraight(launcher_.position, target, answer_.speed);
      if (gravity != Vec2::Zero()) {
        // A straight aim under gravity falls short of the target: say so, and where it lands.
        answer_.message = "pointed straight at the target; gravity bends the path, so use "
                          "TARGET_BALLISTIC to hit it";
        return along(solution->angle);
      }
    }
    if (!solution) return std::nullopt;
    return arrivalAt(*solution, target);
  }

  // kLeadBall: the aim that strikes ball `target` earliest (aimLeading), with the predicted
  // time of flight.
  std::optional<AimSolution> leadBall(BallId target) const {
    const std::optional<Motion> motion = motionOf(target);
    if (!motion) return std::nullopt;
    const std::optional<AimSolution> solution =
        aimLeading(launcher_.position, answer_.speed, *motion, world_.gravity());
    if (!solution) {
      answer_.message = "ball " + format(target) + " cannot be caught at " +
                        format(answer_.speed) + " m/s from launcher '" + launcher_.name + "'";
      return std::nullopt;
    }
    const auto hit = strikeOf(world_, solution->angle, target, solution->time_of_flight);
    if (!hit) return std::nullopt;
    answer_.message = "leading ball " + format(target) + ": it is struck after " +
                      format(hit->time) + " s";
    return AimSolution{solution->angle, hit->time};
  }

  // kTimed: along `angle`, the whole number of steps to wait before firing (timeShot), in
  // fire_after; the aim is `angle`, with the predicted time of flight.
  std::optional<AimSolution> timeBall(double angle, BallId target) const {
    const std::optional<Motion> motion = motionOf(target);
    if (!motion) return std::nullopt;
    const double speed = answer_.speed;
    const std::optional<TimedShot> shot =
        timeShot(launcher_.position, angle, speed, *motion, world_.gravity());
    if (!shot) {
      answer_.message = "ball " + format(target) + " never crosses the path of launcher '" +
                        launcher_.name + "' at " + format(angle) + " rad and " + format(speed) +
                        " m/s";
      return std::nullopt;
    }
    // The caller fires between steps: the delay becomes whole steps, and the shot's prediction
    // starts from the world those steps make.
    // Bounded as every confirmation is: the wait and the flight are simulated on the whole world.
    if (const double strike = shot->delay + shot->time_of_flight; strike > kMaxPredictionHorizon) {
      answer_.message = "ball " + format(target) + " is struck only " + format(strike) +
                        " s from now, too far ahead to predict (more than " +
                        format(kMaxPredictionHorizon) + " s)";
      return std::nullopt;
    }
    const double time_step = limits_.time_step;
    const long steps = std::lround(shot->delay / time_step);
    World later = world_;
    for (long i = 0; i < steps; ++i) {
      later.step(time_step);
      later.takeContacts();  // (kept, a minute of a pile's contacts runs to megabytes)
    }
    const auto hit = strikeOf(later, angle, target, shot->time_of_flight);
    if (!hit) return std::nullopt;
    answer_.fire_after = steps * time_step;
    answer_.message = "fire after " + format(steps) + " steps (" + format(answer_.fire_after) +
                      " s; exactly " + format(shot->delay) + " s): ball " + format(target) +
                      " is struck " + format(hit->time) + " s later";
    return AimSolution{angle, hit->time};
  }

  // kBank: the aim that strikes ball `target` after bounces (aimBank), searched within the
  // prediction horizon, with the predicted time of flight.
  std::optional<AimSolution> bankBall(BallId target) const {
    if (!motionOf(target)) return std::nullopt;
    const double horizon = limits_.prediction_horizon;
    if (horizon == 0.0) {
      answer_.message =
          "BANK searches shots with the prediction: it needs ~prediction_horizon > 0";
      return std::nullopt;
    }
    std::optional<BankShot> shot;
    try {
      shot = aimBank(world_, launcher_, answer_.speed, target, limits_.time_step, horizon);
    } catch (const std::invalid_argument& e) {
      answer_.message = cannotPredict(e);
      return std::nullopt;
    }
    if (!shot) {
      answer_.message = "found no shot at " + format(answer_.speed) + " m/s from launcher '" +
                        launcher_.name + "' that strikes ball " + format(target) +
                        " after 1 to " + format(kMaxBankBounces) + " bounces within " +
                        format(horizon) + " s (~prediction_horizon)";
      return std::nullopt;
    }
    const PredictedImpact& strike = *shot->prediction.final_impact;
    answer_.message = "bank shot:";
    for (const PredictedImpact& bounce : shot->prediction.bounces)
      answer_.message += " off " + describe(bounce) + ", then";
    answer_.message += " strikes " + describe(strike);
    answer_.predicted_hit = strike.position;
    return AimSolution{shot->angle, strike.time};
  }

 private:
  // The prediction of the shot along `angle` fired in `world`, `horizon` s ahead; none, with
  // the reason in `error`, if the muzzle is blocked.
  std::optional<ShotPrediction> predict(const World& world, double angle, double horizon,
                                        std::string& error) const {
    try {
      return predictLaunch(world, launcher_, angle, answer_.speed, limits_.time_step, horizon);
    } catch (const std::invalid_argument& e) {
      error = cannotPredict(e);
      return std::nullopt;
    }
  }

  // kTargetBallistic with a time of flight: the launch (launchVelocityFor), whose speed must
  // be one the caller fires, becomes the answer's speed.
  std::optional<AimSolution> timedArc(const Vec2& target, const AimRequest& request) const {
    const double time_of_flight = request.time_of_flight;
    if (!std::isfinite(time_of_flight) || time_of_flight < 0.0) {
      answer_.message =
          "time_of_flight must be finite and > 0 (or 0 to aim at `speed`), got " +
          format(time_of_flight);
      return std::nullopt;
    }
    if (request.speed != 0.0) {
      answer_.message = "give speed or time_of_flight, not both: the time fixes the speed";
      return std::nullopt;
    }
    const Vec2 velocity =
        launchVelocityFor(launcher_.position, target, time_of_flight, world_.gravity());
    const double needed = velocity.norm();
    if (!(needed > 0.0 && needed <= limits_.max_speed)) {
      answer_.message = "reaching " + format(target) + " in " + format(time_of_flight) +
                        " s needs " + format(needed) + " m/s; shots go > 0 and at most " +
                        format(limits_.max_speed) + " m/s (~max_speed)";
      return std::nullopt;
    }
    answer_.speed = needed;
    return AimSolution{std::atan2(velocity.y(), velocity.x()), time_of_flight};
  }

  // Whether the shot of `solution` reaches `target`: by the prediction it strikes nothing on
  // the way, or only what lies at the target. Otherwise names what blocks it. Unchecked (and
  // said so) when predictions are off or the flight is longer than kMaxPredictionHorizon.
  std::optional<AimSolution> arrivalAt(const AimSolution& solution, const Vec2& target) const {
    answer_.predicted_hit = target;
    const double horizon = limits_.prediction_horizon;
    if (horizon == 0.0 || solution.time_of_flight > kMaxPredictionHorizon) {
      answer_.message = "aimed at " + format(target) + ": the shot arrives after " +
                        format(solution.time_of_flight) + " s, unchecked for obstacles (" +
                        (horizon == 0.0 ? "~prediction_horizon is 0)"
                                        : "longer than " + format(kMaxPredictionHorizon) + " s)");
      return solution;
    }
    const std::optional<ShotPrediction> prediction =
        predict(world_, solution.angle, solution.time_of_flight + limits_.time_step,
                answer_.message);
    if (!prediction) return std::nullopt;
    const std::optional<PredictedImpact>& hit = prediction->final_impact;
    if (!hit || hit->time >= solution.time_of_flight) {
      answer_.message = "aimed at " + format(target) + ": the shot arrives after " +
                        format(solution.time_of_flight) + " s";
      return solution;
    }
    // Striking what lies at the target (a ball clicked on, the wall aimed at) is arriving.
    if (!impactCovers(world_, *hit, launcher_.projectile.radius, target,
                      limits_.target_tolerance)) {
      answer_.message = "target " + format(target) + " is blocked: the shot would first hit " +
                        describe(*hit);
      return std::nullopt;
    }
    answer_.message = "aimed at " + format(target) + ": the shot strikes " + describe(*hit) +
                      ", at the target";
    answer_.predicted_hit = hit->position;
    return AimSolution{solution.angle, hit->time};
  }

  // What the shot along `angle`, fired in `world`, strikes first, predicted up to just past
  // `time_of_flight`: it must be ball `target`, whose strike sets the predicted hit.
  std::optional<PredictedImpact> strikeOf(const World& world, double angle, BallId target,
                                          double time_of_flight) const {
    const std::optional<ShotPrediction> prediction =
        predict(world, angle, time_of_flight + limits_.time_step, answer_.message);
    if (!prediction) return std::nullopt;
    const std::optional<PredictedImpact>& hit = prediction->final_impact;
    if (!hit || hit->other_kind != ContactKind::kBall || hit->other_id != target) {
      answer_.message =
          hit ? "the shot at ball " + format(target) + " would first hit " + describe(*hit)
              : "ball " + format(target) + " changes course (it hits something) before the "
                "shot reaches it";
      return std::nullopt;
    }
    answer_.predicted_hit = hit->position;
    return hit;
  }

  // How ball `target` moves now; none, with the reason in the message, if there is none.
  std::optional<Motion> motionOf(BallId target) const {
    const std::optional<Motion> motion = world_.motionOfBall(target);
    if (!motion) answer_.message = "there is no ball " + format(target);
    return motion;
  }

  const World& world_;
  const Launcher& launcher_;
  const AimLimits& limits_;
  AimAnswer& answer_;
};

}  // namespace

std::optional<double> shotSpeed(double requested, const Launcher& launcher, double max_speed,
                                std::string& error) {
  if (requested == 0.0) return launcher.speed;
  if (!std::isfinite(requested) || requested < 0.0 || requested > max_speed) {
    error = "speed must be finite and > 0, at most " + format(max_speed) +
            " m/s (~max_speed; or 0 for the launcher's " + format(launcher.speed) +
            " m/s), got " + format(requested);
    return std::nullopt;
  }
  return requested;
}

AimAnswer aimLauncher(const World& world, const Launcher& launcher, const AimRequest& request,
                      const AimLimits& limits) {
  AimAnswer answer;
  const std::optional<double> speed =
      shotSpeed(request.speed, launcher, limits.max_speed, answer.message);
  if (!speed) return answer;
  answer.speed = *speed;
  const bool angle_given = request.mode == AimMode::kAngle || request.mode == AimMode::kTimed;
  if (angle_given && !std::isfinite(request.angle)) {
    answer.message = "angle must be finite";
    return answer;
  }
  if (request.time_of_flight != 0.0 && request.mode != AimMode::kTargetBallistic) {
    answer.message = "time_of_flight is for TARGET_BALLISTIC only";
    return answer;
  }
  const Aimer aimer(world, launcher, limits, answer);
  switch (request.mode) {
    case AimMode::kAngle:
      answer.message = "aimed along the given angle";
      answer.solution = aimer.along(normalizedAngle(request.angle));
      break;
    case AimMode::kTarget:
    case AimMode::kTargetBallistic:
      answer.solution = aimer.atPoint(request);
      break;
    case AimMode::kLeadBall:
      answer.solution = aimer.leadBall(request.target_ball);
      break;
    case AimMode::kTimed:
      answer.solution = aimer.timeBall(normalizedAngle(request.angle), request.target_ball);
      break;
    case AimMode::kBank:
      answer.solution = aimer.bankBall(request.target_ball);
      break;
    default:
      answer.message = "unknown mode " + format(int(request.mode)) +
                       "; use ANGLE (0), TARGET (1), TARGET_BALLISTIC (2), LEAD_BALL (3), "
                       "TIMED (4) or BANK (5)";
  }
  return answer;
}

}  // namespace ball_physics_sim::engine
