#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

// Gauss-Seidel sweeps of a round of a settle (see settleTogether): a dense pile's contacts
// pass a push through a few balls a sweep, and the sweeps of the steps before carry on in its
// balls' velocities. A round's end checks every contact, to end the settle or hold its friction:
// rounds half as long sweep a third fewer rows in rough piles landing, a sixth fewer in smooth
// ones on average (more at a few seeds), for a check a round that costs about one sweep.
constexpr int kSettleSweeps = 32;
// Rounds of kSettleSweeps at most (see settleTogether): 1,024 sweeps.
constexpr int kSettleRounds = 32;

// How far past touching a settle may close a gap, as a share of the smaller radius: a tenth of
// kMostSettledOverlap, leaving room for what the sweeps fall short by.
constexpr double kSettleOverlap = 1e-4;
// What the tests and fuzzers accept of a settling pile's overlaps, as a share of the smaller
// radius: a few kSettleOverlap where the rounds converge, more where they run out (a deep pile
// landing), which later settles open.
constexpr double kMostSettledOverlap = 10.0 * kSettleOverlap;
// The share of an overlap past kSettleOverlap that a settle opens over its stretch
// (Baumgarte's position correction): all at once would launch its balls.
constexpr double kOverlapRecovery = 0.2;
// The fastest such an overlap opens, whatever the stretch: a short one would launch its balls.
constexpr double kMostOpeningSpeed = 0.01;  // m/s

// Balls after a settle: their velocities and spins, and each contact's normal impulse as the
// sweeps leave it (and, for the caller, what it settled).
struct Settled {
  std::vector<Vec2> velocities;
  std::vector<double> spins;
  std::vector<double> pushes;
  std::vector<RestingContact> contacts;
  std::vector<double> inverse_masses;
  std::vector<std::size_t> members;  // the caller's index of each ball
  int sweeps = 0;                     // how many sweeps it took
  bool converged = false;  // by its sweeps: no gap closes past its bias by more than allowed
  double work = 0.0;                  // J, that moving segments did on the balls (the caller
                                      // finds it: see World::takeBackSurfaces)
  bool crushed = false;  // a moving segment that pushes still closes on a ball past what a
                         // settle may leave
  bool opens = false;    // a contact asks to open: an overlap past the allowance, or a strike
                         // (the caller's: see World::settleIsland)
};

// How many contacts a settle's sweeps take side by side. The results are the same to the bit
// either way for finite rates (the engine is built without fused multiply-adds).
enum class SweepLanes {
  kMost,  // as many as the processor can: four with AVX2, else two
  kTwo,   // two, as a processor without AVX2 does: for the tests of the path it takes
};
// Whether this processor's sweeps take four contacts side by side (it has AVX2).
bool sweepsFourAtATime();

// What settles work in (their rows, blocks of rows, bodies and rates), kept from one settle to
// the next: a pile settles every step, and storage taken afresh each time comes as pages new to
// the process, each a fault for the system to fill. Taken at the first settle; it holds nothing
// between settles, so copying copies none of it.
class SettleScratch {
 public:
  struct Storage;  // (settle.cpp's)
  SettleScratch();
  SettleScratch(const SettleScratch&);
  SettleScratch& operator=(const SettleScratch&);
  SettleScratch(SettleScratch&&) noexcept;
  SettleScratch& operator=(SettleScratch&&) noexcept;
  ~SettleScratch();
  Storage& storage();

 private:
  std::unique_ptr<Storage> storage_;
};

// One perfectly inelastic impact, with Coulomb friction, of every pair of bodies that may meet over
// a stretch of time: `balls` carry the velocities they would end it with untouched (and their
// spins), `contacts` are at the level of velocities, each with its bias the rate at which its gap
// may close over the stretch (negative: the rate at which an overlap must open; see settleBias),
// and `frictions` (one per contact) their pairs' Coulomb coefficients. Normal and friction impulses
// are found together by projected Gauss-Seidel sweeps sped by a conjugate gradient (see
// sweepSideBySide), in rounds of kSettleSweeps until no gap closes past its bias by more than
// kSettleOverlap over the stretch (`duration`), or kSettleRounds have run: bounded work. A round
// sweeps the contacts that may push in it, not one whose gap opens fast; its end checks them all.
// Once a round brings the worst gap no nearer its bias (sweeps with friction may cycle), the
// rounds after it hold friction as it is and sweep the pushes alone: a push they make smaller
// may end with friction past its cone, which the next settle's start clamps.
// Where the rounds have not converged by the last, the pushing contacts' pushes are solved together
// directly before it, and again after it where it does not converge either, friction held as it is
// (a sparse factorization), and kept if the worst gap closes no worse: what the sweeps pass down a
// tall column or a deep pile a ball a sweep (fewer with the gradient), it passes at once. Where the
// sweeps fall short, a gap closes a little past its bias, and the next settle's bias opens it
// again. They sweep the contacts near the order given, several side by side (to the same results
// however many): one is put off while it shares a ball with one of the few before it, and a few
// after it go ahead. `impulses`, if given, holds each contact's normal and friction impulse: the
// sweeps start from them if it has one per contact (a pile settled a moment ago is mostly settled
// still), and it receives the last impulses found. A ball whose inverse mass is 0 does not move.
// `lanes`: see SweepLanes. `scratch`, if given, is worked in (else storage of its own).
Settled settleTogether(const std::vector<Ball>& balls, const std::vector<double>& inverse_masses,
                       const std::vector<RestingContact>& contacts,
                       const std::vector<double>& frictions, double duration,
                       std::vector<std::array<double, 2>>* impulses = nullptr,
                       SweepLanes lanes = SweepLanes::kMost, SettleScratch* scratch = nullptr,
                       int rounds = kSettleRounds);

// A contact's bias over a settle of `duration`, from the gap it may close (the gap plus the
// overlap it may end with): all of it may close (a speculative contact, as in Box2D); past it,
// if it is to `open`, kOverlapRecovery of the overlap opens, no faster than kMostOpeningSpeed,
// and otherwise it closes no further.
double settleBias(double gap, double duration, bool open);

}  // namespace ball_physics_sim::engine
