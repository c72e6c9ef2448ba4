#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

// Gauss-Seidel sweeps of a settle's friction (see settleTogether): a dense pile's contacts
// pass a push through a few balls a sweep, and the sweeps of the steps before carry on in its
// balls' velocities.
constexpr int kSettleSweeps = 64;

// The exact pushes close a gap to touching, to rounding; where pivoting gives up on them,
// Gauss-Seidel leaves gaps closing a little past it (4e-8 m/s in a pile of 140 balls, where
// other events leave gaps already closed past touching within kContactSlop). The balls slow
// down only where a gap would end closed past touching by more than this, the tolerance within
// which bodies touch: slowing them for less froze whole piles, step after step. Measured from
// the gap, not its closing, so that it never adds up from settle to settle.
constexpr double kSettleOverlap = kContactSlop;  // m
// Gaps closing faster than allowed by this fraction of the fastest ball (before or after the
// exact pushes) are rounding: pushApart's own tolerance is 1e-15 of that.
constexpr double kSettleRounding = 1e-12;

// Balls after a settle: their velocities and spins, and each contact's normal impulse as the
// sweeps leave it (and, for the caller, what it settled).
struct Settled {
  std::vector<Vec2> velocities;
  std::vector<double> spins;
  std::vector<double> pushes;
  std::vector<RestingContact> contacts;
  std::vector<double> inverse_masses;
  std::vector<std::size_t> members;  // the caller's index of each ball
};

// One perfectly inelastic impact, with Coulomb friction, of every pair of bodies that may meet
// over a stretch of time: `balls` carry the velocities they would end it with untouched (and
// their spins), `contacts` are at the level of velocities, each with its bias the rate at which
// its gap may close over the stretch, and `frictions` (one per contact) their pairs' Coulomb
// coefficients. Friction is found by projected Gauss-Seidel sweeps, normal pushes with it; the
// pushes are then made exact by pushApart, so that no gap closes by more than it may, to
// rounding, while friction is where the sweeps left it (within its cone, which the exact pushes
// only widen); where a gap would still close faster than `allowed` (one rate per contact, at
// least its bias: see kSettleOverlap), the balls slow down together by
// shareClosingNoGapTooFast. `impulses`, if given, holds each contact's normal and friction
// impulse: the sweeps start from them if it has one per contact (a pile settled a moment ago is
// mostly settled still), and it receives the sweeps' last. A ball whose inverse mass is 0 does
// not move.
Settled settleTogether(const std::vector<Ball>& balls, const std::vector<double>& inverse_masses,
                       const std::vector<RestingContact>& contacts,
                       const std::vector<double>& frictions, const std::vector<double>& allowed,
                       std::vector<std::array<double, 2>>* impulses = nullptr);

// The largest share in [0, 1] of the balls' velocities with which no contact's gap closes
// faster than `allowed` (one rate >= 0 per contact) by more than `rounding`: each gap's rate is
// linear in the share, and with none it closes by nothing (they stand still at worst).
double shareClosingNoGapTooFast(const std::vector<RestingContact>& contacts,
                                const std::vector<Vec2>& velocities,
                                const std::vector<double>& allowed, double rounding);

}  // namespace ball_physics_sim::engine
