#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/SparseCore>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/motion.h"

namespace ball_physics_sim::engine {

// Gaps within this distance count as touching: a ball reset to its point of impact sits there
// up to rounding, on either side.
constexpr double kContactSlop = 1e-9;  // m

// A ball comes to rest on what is this close to it, and a resting ball woken wakes the resting
// balls this close to it: a settled pile's sweeps leave gaps that open and close by about a
// tenth of this a step (balls creeping at ~1e-5 m/s, whose gaps change by ~1e-8 m), which
// kContactSlop would keep awake for seconds.
constexpr double kRestingGap = 1e-7;  // m

// A held contact moves with the constant accelerations found when it was held. Against a
// curved body (ball, cap, rope) they keep the distance only at that instant: moving round it,
// the path leaves the circle. It is held again before it drifts more than this.
constexpr double kHeldDrift = kContactSlop;  // m
// Lifetimes are never shorter than this, so that a step always moves on.
constexpr double kShortestHold = 1e-9;  // s

// How long, up to `horizon`, a held contact between curved bodies (or a taut rope) keeps their
// distance within kHeldDrift of what it is now; `relative` is the motion of the ball's centre
// relative to the other centre.
double curvedContactLifetime(const Motion& relative, double horizon);

// The acceleration with which the gap between bodies touching at a curved surface opens as they
// slide round each other: |relative tangential velocity|^2 / distance between the centres.
double centripetalOpening(const Vec2& relative_velocity, const Vec2& normal, double distance);

// A ball touching another body.
struct RestingContact {
  std::size_t ball = 0;
  std::optional<std::size_t> other;    // another ball's index; none for a segment
  Vec2 normal = Vec2::Zero();          // unit, pointing toward `ball`
  // Added to the rate at which the gap opens. For accelerations against a curved body (ball,
  // cap): |relative tangential velocity|^2 / distance, the centripetal term by which sliding
  // round each other opens the gap. Zero for velocities. For positions, minus the distance
  // along the normal at which they touch.
  double bias = 0.0;
  std::size_t body = 0;  // the caller's name for what the ball touches, carried along
};

// How fast the contact's gap opens at the bodies' `rates` (velocities, accelerations), its bias
// added: below 0, it closes faster than its bias allows.
double opening(const RestingContact& c, const std::vector<Vec2>& rates);

// The indices of the contacts in each island: contacts connected through balls that move, so
// that no push in one island moves a ball of another. A contact whose ball does not move is in
// none.
std::vector<std::vector<std::size_t>> contactIslands(const std::vector<RestingContact>& contacts,
                                                     const std::vector<double>& inverse_masses);

// How fast each contact of `island` (indices into `contacts`) opens per unit push of each, a
// push as in pushApart: the entries of a symmetric matrix numbered as `island` is, nonzero only
// where two contacts share a ball that moves (duplicates, to be summed).
std::vector<Eigen::Triplet<double>> openingPerPush(const std::vector<RestingContact>& contacts,
                                                   const std::vector<double>& inverse_masses,
                                                   const std::vector<std::size_t>& island);

// Normal forces (or impulses) that keep touching bodies from closing on each other. Given
// the balls' free rates (accelerations under gravity, or velocities) and inverse masses (0 for
// a body that does not move, such as a resting ball), returns the rates after the pushes:
// each push is away from the other body, no contact's gap closes, and a push acts only where
// its gap does not open. This linear complementarity problem is solved per island of balls
// that push each other: directly (principal pivoting, on dense matrices for a small island and
// sparse ones for a large one), then polished by projected Gauss-Seidel, whose per-ball
// projection against immovable bodies is exact, to rounding. On
// velocities it is a perfectly inelastic impact of every contact at once; on accelerations,
// the normal forces of resting contact (Baraff's formulation).
// On positions it moves overlapping bodies apart until they just touch. `pushes`, if given,
// receives each contact's push, in rate per inverse mass (0 where its gap opens by itself); if
// it holds one per contact already, the solve starts from those (a problem solved before and
// changed a little is solved again in a fraction of the work).
std::vector<Vec2> pushApart(const std::vector<Vec2>& free, const std::vector<double>& inverse_masses,
                            const std::vector<RestingContact>& contacts,
                            std::vector<double>* pushes = nullptr);

}  // namespace ball_physics_sim::engine
