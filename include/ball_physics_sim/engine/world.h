#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/contact.h"
#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/forces.h"
#include "ball_physics_sim/engine/friction.h"
#include "ball_physics_sim/engine/held_contacts.h"
#include "ball_physics_sim/engine/motion.h"
#include "ball_physics_sim/engine/region.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/rope.h"
#include "ball_physics_sim/engine/room.h"
#include "ball_physics_sim/engine/segment.h"
#include "ball_physics_sim/engine/settle.h"
#include "ball_physics_sim/engine/toi.h"
#include "ball_physics_sim/engine/tournament_tree.h"
#include "ball_physics_sim/engine/warm_starts.h"

namespace ball_physics_sim::engine {

// Balls and segments (static or kinematic) under uniform gravity, advanced by exact continuous
// collision detection: within a step the earliest impact is found, everything moves exactly to
// it, it is resolved, and the rest of the step goes on. One thread at a time: even its const
// methods may bring a ball's state up to date. Its methods are split by concern, as Chipmunk
// splits cpSpace: world.cpp (bodies), world_step.cpp (the step's phases), world_budgets.cpp
// (a step's budgets of events, and a group out of its budget), world_events.cpp (predicting and
// resolving impacts), world_holds.cpp (resting contact), world_settle.cpp (piles settling),
// world_wakes.cpp (what wakes a resting ball a settle reaches), world_crushes.cpp (moving
// segments in settles: crushes and jams), world_settled.cpp (what a settle does to its balls:
// courses, rest, hits, energy), world_fields.cpp (fields and pushes), world_game.cpp (sensors,
// bricks, pockets).
class World {
 public:
  // Throws std::invalid_argument unless gravity is finite and at most kMaxGravity.
  explicit World(const Vec2& gravity = Vec2(0.0, -9.81));

  // Gravity from now on (on a ball already moving, from the next step); wakes every resting
  // ball, whose supports were found for the old gravity. Throws std::invalid_argument, the
  // world unchanged, as the constructor does, or for gravity not along -y while there is water.
  void setGravity(const Vec2& gravity);

  // Adds a ball (its id is assigned) or a segment and returns the id. Throws
  // std::invalid_argument naming what is wrong (non-finite values, radius or mass <= 0,
  // restitution outside [0, 1], overlap with what is already there); the world is unchanged.
  BallId addBall(Ball ball);
  SegmentId addSegment(Segment segment);

  // Sets how the segment with this id moves from now on (it stops following its waypoints)
  // and wakes the resting balls that touch it; false if there is none. Throws
  // std::invalid_argument as addSegment would; the world is unchanged.
  bool setSegmentMotion(SegmentId id, const Vec2& velocity, double angular_velocity);

  // Adds wind (forces.h) that blows from now on (on a ball already moving, from the next step),
  // and wakes the resting balls it blows on.
  // Throws std::invalid_argument naming what is wrong; the world is unchanged.
  void addWind(const Wind& wind);
  const std::vector<Wind>& winds() const { return winds_; }

  // Adds an attractor (forces.h) that pulls from now on, and wakes every resting ball. Throws
  // std::invalid_argument naming what is wrong; the world is unchanged.
  void addAttractor(const Attractor& attractor);
  const std::vector<Attractor>& attractors() const { return attractors_; }

  // Adds water (forces.h) from now on, and wakes the resting balls in it. Throws
  // std::invalid_argument naming what is wrong; the world is unchanged.
  void addWater(const Water& water);
  const std::vector<Water>& waters() const { return waters_; }

  // Adds a sensor (region.h) that watches from now on. Throws std::invalid_argument naming what
  // is wrong (a bad region, an empty name or one another sensor has); the world is unchanged.
  void addSensor(const Sensor& sensor);
  const std::vector<Sensor>& sensors() const { return sensors_; }

  // Ties a rope (rope.h) between the balls or ball and anchor it names, and returns its id
  // (assigned). Throws std::invalid_argument naming what is wrong (checkRope's cases, a ball
  // that does not exist, ends already farther apart than its length); the world is unchanged.
  RopeId addRope(Rope rope);
  // Cuts the rope with this id and wakes the resting balls it tied; false if there is none.
  bool removeRope(RopeId id);
  // A ball's ropes go with it.
  const std::vector<Rope>& ropes() const { return ropes_; }

  // Pushes the ball with this id with `acceleration` (besides gravity and wind) from now on, as
  // a motor would; zero stops. Wakes it if that changes its push. False if there is no such
  // ball. Throws std::invalid_argument, the world unchanged, for a non-finite acceleration or
  // one stronger than kMaxGravity.
  bool drive(BallId id, const Vec2& acceleration);

  // Gives every ball the blast reaches its impulse (forces.h), waking it, and returns their
  // ids. Throws std::invalid_argument, the world unchanged, for a blast checkBlast refuses or
  // one that would make a ball faster than `max_speed` (at most kMaxSpeed).
  std::vector<BallId> explode(const Blast& blast, double max_speed = kMaxSpeed);

  // Removes the ball (and its ropes) or segment with that id and wakes the resting balls that
  // touched it; false if there is none.
  bool removeBall(BallId id);
  bool removeSegment(SegmentId id);

  // Sets the position, velocity and angular velocity of the ball with this id (a teleport, a
  // kick, a stop) and wakes it, the resting balls it touched and those it touches now; false
  // if there is none. Throws std::invalid_argument naming what is wrong (checkBall's cases, an
  // overlap with what is there, a rope it would be farther from its other end than its
  // length); the world is unchanged.
  bool setBallState(BallId id, const Vec2& position, const Vec2& velocity,
                    double angular_velocity);

  // Advances the world by dt > 0 seconds.
  void step(double dt);
  // step, but only until the ball with this id first strikes another ball in an impact of its
  // own within dt: the strike is resolved as an impact (even where step would settle a pile it
  // strikes, and waking as an impact does) and the step ends there. What a search needs that
  // asks only where a shot strikes first (aimBank's scan): the rest of the step, a struck
  // pile's settle, is not worked out. The world is then one to read the strike from, not one
  // that step would have made: balls a settle took in that step keep its whole step's
  // velocities. A strike passed on at an impact's instant, one among settled balls, or an id
  // that is not there does not stop it. Returns the time the world advanced.
  double stepUntilStrike(double dt, BallId ball);

  double time() const { return time_; }
  const Vec2& gravity() const { return gravity_; }
  const std::vector<Ball>& balls() const { return balls_; }
  const std::vector<Segment>& segments() const { return segments_; }

  // The ball with this id; null if there is none.
  const Ball* findBall(BallId id) const;
  // The ids of the ball with this id and of the balls at rest that touch it (within
  // kRestingGap), or touch those, and so on: what rests together with it. Empty if there is no
  // such ball.
  std::vector<BallId> restingClusterOf(BallId id) const;

  // The impacts resolved since the last call, in the order they happened. The world keeps them
  // until they are taken: a caller that never takes them keeps every one.
  std::vector<Contact> takeContacts();
  // The balls that went in or out of a sensor since the last call, in the order they did. (A
  // ball in a sensor's region when it is added, or when the sensor is, goes in at the next
  // step's start.) Kept until taken, as contacts are.
  std::vector<SensorEvent> takeSensorEvents();
  // The hits on bricks since the last call, in the order they happened. Kept until taken, as
  // contacts are.
  std::vector<BrickHit> takeBrickHits();

  // How the ball with this id moves until the next event: its position, velocity and
  // acceleration (gravity plus the forces of the contacts holding it; none at rest). None if
  // there is no such ball.
  std::optional<Motion> motionOfBall(BallId id) const;

 private:
  struct Impact {
    double time;
    std::size_t ball;
    ContactKind kind;
    std::size_t other;  // ball, segment or rope index
    int cap;            // which end, for kCap
  };

  // Ball indices, gone through in the order they were put in: the work of going through them is
  // in their balls, not in every ball of the world.
  struct BallSet {
    explicit BallSet(std::size_t balls) : has(balls, false) {}
    static BallSet every(std::size_t balls);
    // Empty, for a world of this many balls: unsetting only its members, it costs what it held.
    void reset(std::size_t balls);
    void insert(std::size_t ball);
    // Takes out the balls `other` holds (the work is in this set's balls).
    void remove(const BallSet& other);
    bool contains(std::size_t ball) const { return has[ball]; }
    std::vector<bool> has;
    std::vector<std::size_t> list;
    // Whether it held every ball that moves when made (every, awakeOrHeld; insert keeps it,
    // taking one out does not): a search from it may take all their pairs at once.
    bool every_moving = false;
  };

  // A step under way (see step): its groups of balls, the budgets of events each group has
  // (see world_budgets.cpp) and what it has spent of them, and how far the step has gone.
  struct Stepping {
    explicit Stepping(std::size_t balls)
        : events_of(balls, 0), unsettled(balls), groups(balls), spent(balls) {}
    // What a group has spent of its budgets, and whether its struggle waits.
    struct Spent {
      std::size_t balls = 1, impacts = 0, passed = 0, renewals = 0;
      bool waits = false;
    };
    std::size_t group(std::size_t ball) { return groups.find(ball); }
    // Puts the two balls' groups in one, which spends what both had spent.
    void join(std::size_t a, std::size_t b);
    // Counts an impact, or a renewal of held contacts, against the ball's group.
    void countImpact(std::size_t ball);
    void countRenewal(std::size_t ball);
    // A group's budgets: of impacts met one after another, and of events in all.
    std::size_t sequential(std::size_t group) const;
    std::size_t most(std::size_t group) const;
    // The groups past their budget of impacts met one after another, and those out of budget,
    // each named once by its ball.
    std::vector<std::size_t> pastSequential();
    std::vector<std::size_t> outOfBudget();
    // The balls of the groups `named` (each by the ball naming it, as the two above give them).
    BallSet ballsOf(const std::vector<std::size_t>& named);
    // Of the groups `named` (as above), those with a ball the last event changed (unsettled).
    std::vector<std::size_t> changedGroups(const std::vector<std::size_t>& named);
    // The budgets of the groups out of budget start again: their struggle was settled, held
    // still or freed.
    void freshBudget();
    double dt = 0.0;  // (cut short where a strike stops it: see stepUntilStrike)
    double elapsed = 0.0;
    std::vector<std::size_t> events_of;  // the impacts and hold ends each ball met
    // The balls whose islands are held anew: after an impact, those it changed; after a
    // renewal, those whose holds ended (at a segment's event, those near a movable segment);
    // at the step's start, every ball that moves (awakeOrHeld); where segments stop against a
    // struggle, every ball.
    BallSet unsettled;
    // False where the last impact's balls move freely away from everything they touch.
    bool hold_needed = true;
    // The balls that may meet in the step, in groups joined as they meet (see beginStep), and
    // what each group (by the ball that names it) has spent: a struggle spends its own group's
    // budgets, and what it meets falls on its own group's balls.
    DisjointSets groups;
    std::vector<Spent> spent;
    // Balls of the groups that went past a budget, as they went (a group may be named twice).
    std::vector<std::size_t> went_past_sequential, went_out;

   private:
    // Notes the group in went_past_sequential or went_out if it is past that budget.
    void noteBudgets(std::size_t group);
  };
  // What comes next in a step, `remaining` of it left: the first hold's end, a segment's next
  // event, how long the holds last (at most the rest of the step), and the first impact
  // within that, if any.
  struct Lookahead {
    double remaining = 0.0, hold_end = 0.0, segment_event = 0.0, held_for = 0.0;
    bool holds_end = true;  // false where a segment's event comes first
    std::optional<Impact> impact;
  };
  // The phases of a step: checks dt, groups its balls and sets their budgets and the queues
  // up; holds anew the balls the last event changed and looks ahead to the next event; meets
  // it: the struggle's, where a group's budget ran out, else the ends of holds or an impact
  // (each whether the step goes on); and brings every ball to the step's end.
  Stepping beginStep(double dt);
  // The balls that move, and the resting ones that still have a contact held: what a step's
  // start holds anew (a resting ball holds nothing itself, so a world asleep costs little).
  BallSet awakeOrHeld() const;
  // Joins in one of the step's groups the balls whose boxes over it overlap, or overlap the box
  // of one segment that may move or break, and those a rope ties.
  void groupMeetingBalls(Stepping& stepping);
  Lookahead holdAndLookAhead(Stepping& stepping);
  // Holds anew the balls the last event changed (stepping.unsettled, and every ball of a group
  // past its budget of impacts in a row, whose approaches stop inelastically), or moves them
  // freely where they need no hold.
  void holdAnew(Stepping& stepping);
  bool meetTheStruggle(Stepping& stepping, const Lookahead& next);
  bool renewEndedHolds(Stepping& stepping, const Lookahead& next);
  bool meetImpact(Stepping& stepping, const Impact& impact);
  void endStep(double dt);

  std::optional<std::size_t> indexOf(BallId id) const;
  // Within a step a ball is moved on only when looked at: the ball with this index brought to
  // the present (now_) along its course. An event's work is then in the balls it touches, not in
  // every ball of the world. Only the second form can change a ball, so only it notes the ball
  // as looked at (see predictChanged), even where a non-const member calls it just to read;
  // the first leaves the ball on its course. A step changes a ball, or its accelerations, only
  // after taking it so.
  const Ball& ballNow(std::size_t ball) const;
  Ball& ballNow(std::size_t ball);
  // Finds rope_ends_ anew, after balls are removed.
  void indexRopeEnds();
  // The name of the body `key` names among the settles' warm starts (see WarmStarts).
  std::uint64_t warmStartName(std::size_t key) const;
  // How long until a segment's motion changes (a waypoint, a turning limit); infinity if never.
  double timeToSegmentEvent() const;
  Motion motionOf(std::size_t ball) const;
  // Gravity, the wind blowing on the ball, its drive, and the pull of attractors and water at
  // the middle of its stretch: its acceleration but for contacts.
  Vec2 freeAcceleration(std::size_t ball) const;
  // Its drive and the wind blowing on it: the pushes on it that neither its place within a
  // region nor its speed change.
  Vec2 steadyPush(std::size_t ball) const;
  // Where the ball would be at the middle of a stretch of `stretch`, and how fast, under its
  // pull where it starts: `steady` (gravity and its steadyPush, which the caller has) and the
  // fields' pull.
  Motion middleOfStretch(std::size_t ball, double stretch, const Vec2& steady) const;
  // The pull a settle of `duration` takes as uniform over it: gravity, the steady push, and the
  // pull of attractors and water at the stretch's middle, drag aside.
  Vec2 settlePull(std::size_t ball, double duration) const;
  // The stiffness of the water's push on the ball where it is, summed over the waters.
  WaterStiffness waterStiffnessOf(std::size_t ball) const;
  // Whether the ball floats stiffly for a settle of `duration` (kStiffFloat).
  bool stiffFloat(std::size_t ball, double duration) const;
  // The velocity the ball would end a settle's stretch of `duration` with, untouched: its pull
  // over the stretch, with water's drag (and a stiff float's buoyancy) taken at its end.
  Vec2 settledFreeVelocity(std::size_t ball, double duration) const;
  // The pull of attractors and water on the ball were it at `position` moving at `velocity`.
  Vec2 fieldPull(std::size_t ball, const Vec2& position, const Vec2& velocity) const;
  // How long the ball may move on with that pull at the middle of that time (at most what is
  // left of the step, at least kShortestHold).
  double fieldStretchOf(std::size_t ball) const;
  double inverseMassOf(std::size_t ball) const;  // 0 for a ball at rest
  // A body a ball may touch, keyed as in held_: another ball's index, the number of balls plus a
  // segment's index, or the number of balls and segments plus a rope's index. (Defined here:
  // the settles and event searches ask them of every pair.)
  std::optional<std::size_t> ballOf(std::size_t key) const {
    return key < balls_.size() ? std::optional<std::size_t>(key) : std::nullopt;
  }
  std::optional<std::size_t> segmentOf(std::size_t key) const {
    const std::size_t n = balls_.size();
    return key >= n && key < n + segments_.size() ? std::optional<std::size_t>(key - n)
                                                  : std::nullopt;
  }
  std::optional<std::size_t> ropeOf(std::size_t key) const {
    const std::size_t first = balls_.size() + segments_.size();
    return key >= first ? std::optional<std::size_t>(key - first) : std::nullopt;
  }
  std::size_t keyOf(const Impact& impact) const;
  // Whether a ball can touch the body `key` names: not itself, nor a ball it passes through.
  bool meets(std::size_t ball, std::size_t key) const;
  // Whether a ball at rest and the body `key` names keep still together: another ball at rest,
  // or a segment that stays put (never a rope).
  bool stillTogether(std::size_t ball, std::size_t key) const;
  // The pairs of keys in the grid (a < b) of which one may move in the step (a ball awake, a
  // movable segment), and possibly others: where many may move, every pair the grid has (the
  // caller passes over the rest); where few, only theirs, so that no pair of a sleeping pile is
  // looked at. Good until the next call.
  const std::vector<std::pair<std::size_t, std::size_t>>& pairsNearMoving() const;
  // The keys of the bodies the ball meets whose boxes in the grid overlap `box`, in storage kept
  // from query to query (so good until the next query). Where no two balls meet (all of one
  // group), only the segments', not the grid full of balls.
  const std::vector<std::size_t>& keysMet(std::size_t ball, const Box& box) const;
  // keysMet for the box of the ball's place now: all that may touch it.
  const std::vector<std::size_t>& keysNear(std::size_t ball) const;
  // The ball that `ball`'s contact with the body `key` names pushes or pulls back: that body if
  // it is a ball, a rope's other end if that is one; none for a segment or an anchor.
  std::optional<std::size_t> otherBallOf(std::size_t ball, std::size_t key) const;
  // The motion of the centre of the circle that `ball` touches through the ball or rope `key`
  // names: the other ball's, or a rope's anchor, still.
  Motion farEndOf(std::size_t ball, std::size_t key) const;
  // How a ball meets the body `key` names: where it is relative to it (for a rope, the normal
  // points along it, toward its other end), how far it is from touching (from pulling a rope
  // taut), how fast it moves relative to it (and a segment's point there moves), and whether
  // the body is curved there.
  struct Touch {
    Separation separation;
    double gap;
    Vec2 relative_velocity;
    Vec2 surface_velocity;  // zero for another ball, whose velocity the contact solve has
    bool curved;            // a cap, another ball, or a rope
  };
  Touch touch(std::size_t ball, std::size_t key) const;
  enum class ContactLevel { kPosition, kVelocity, kAcceleration };
  using KeyPairs = std::vector<std::pair<std::size_t, std::size_t>>;
  // The (ball, key) pairs that touch or nearly do (within kBoxMargin) among the balls that
  // touch one of `from`, through touching balls that move, or are one: each once, from its
  // awake ball, in a fixed order (by that ball, its segments first), the Gauss-Seidel sweeps'.
  // The work is in those balls, not in every ball of the world.
  KeyPairs touchingPairs(const BallSet& from) const;
  std::vector<RestingContact> touchingContacts(const KeyPairs& pairs, double slowest_approach,
                                               double fastest_separation,
                                               ContactLevel level) const;
  // The friction of a ball's contact with the body `key` names: the pair's coefficients and
  // how fast the ball's surface slides over that body's where they touch (see slipSpeed).
  ContactFriction frictionOf(std::size_t ball, std::size_t key) const;
  // Its Coulomb coefficient alone (a settle's contacts need no more).
  double coulombFrictionOf(std::size_t ball, std::size_t key) const;
  // On a segment with rolling resistance, stops a ball whose surface turns slower than
  // kRollingSlip.
  void stopSlowSpin(std::size_t ball, std::size_t key);
  // When, under the accelerations found when the contact was held, its friction stops the
  // slip (the ball rolls from then on) or its rolling resistance stops the ball's spin. None
  // if neither happens.
  std::optional<double> timeFrictionChanges(std::size_t ball, std::size_t key) const;
  // Whether the contact of `ball` with the body `key` names is held by a resting force, and its
  // forces if so (their signs as seen from whichever body keys it: the same seen from either).
  bool held(std::size_t ball, std::size_t key) const;
  const ContactForces* heldForces(std::size_t ball, std::size_t key) const;
  // Holds anew the islands (balls touching, through balls that move) that hold an `unsettled`
  // ball, and returns their balls; the others keep their accelerations and held contacts.
  BallSet holdRestingBalls(double inelastic_below, BallSet unsettled);
  // What a hold comes to for balls that touch nothing they stay against: each under its free
  // acceleration, its held contacts let go.
  void moveFreely(const BallSet& balls);
  // Forgets the held contacts that involve these balls, before they are held anew.
  void letGoHeldContacts(const BallSet& balls);
  // Wakes the resting balls that a ball being held anew (`unsettled`) touches while a push other
  // than gravity (wind, a drive, an attractor, water) acts on it: their supports were found
  // for gravity alone, and holding them still would turn the push into a wall. Whether it woke
  // any.
  bool wakePushedSideways(const KeyPairs& pairs, const BallSet& unsettled);
  // A taut rope swings its ball round a circle as long as it lasts: pulled as at the hold's
  // start, the ball would gain or lose energy every hold, by the work of a pull across its
  // path. So each rope contact among `contacts` (held with `accelerations`), and the contact of
  // two tied balls that touch, is set to act as at the middle of its island's hold, along the
  // line between the centres there and with the centripetal pull there; the hold lasts as long
  // as each of the island's swings from the start stays within kHeldDrift, and no longer than
  // a segment's motion (rope_swings_). Whether any was set.
  // (The contacts' ball indices are positions in `balls`, as are the accelerations'.)
  bool pullFromMiddleOfSwing(std::vector<RestingContact>& contacts,
                             const std::vector<std::size_t>& balls,
                             const std::vector<Vec2>& accelerations,
                             const std::vector<double>& inverse_masses);
  // Whether the hold has nothing to do for a touching pair: the ball and what it touches are
  // smooth, and farther apart than kContactSlop or separating faster than kHeldSeparationSpeed
  // (overlapping by rounding, they soon are not), as their touch `t` reads.
  bool separatesFreely(std::size_t ball, std::size_t key, const Touch& t) const;
  // Whether a push other than gravity acts on the ball.
  bool pushedSideways(std::size_t ball) const;
  // Which balls touch one of `balls`, through touching balls that move, or are one: `balls`,
  // grown.
  BallSet touchingTogether(const KeyPairs& pairs, BallSet balls) const;
  // How long, up to `horizon`, a held contact's constant accelerations stay true: until the
  // ball slides from a segment's face onto a cap or back, drifts off a curved body or a turning
  // segment, or friction turns its sliding into rolling or stops its rolling.
  double heldContactLifetime(std::size_t ball, std::size_t key, double horizon) const;
  // The hold ends of the balls held anew (see hold_ends_), `elapsed` into the step with
  // `remaining` of it left: their held contacts' lifetimes, when they go in or out of wind or
  // water, and the ends of their stretches under attractors and in water.
  void recordHoldEnds(const BallSet& held_anew, double elapsed, double remaining);
  // Records the balls that go in or out of a sensor while everything moves on for `dt` from
  // sim time `from` as it moves now: one already across a side at `from` (added there, or
  // exactly at the end of the last stretch), then at each crossing within. Sensors only
  // watch: the motion is not cut at their crossings.
  void watchSensors(double from, double dt);
  // Records a ball's going in or out of sensor `s` at `time`, if `inside` says it did.
  void noteSensor(std::size_t ball, std::size_t s, bool inside, double time);
  // Counts a hit by ball `ball` on brick `segment` at `time`.
  void hitBrick(std::size_t segment, std::size_t ball, double time);
  // Removes the bricks that broke in the step and the balls that fell into a pocket.
  void removeBrokenAndPocketed();
  // Undoes the drift of the held contacts that involve these balls.
  void closeHeldContacts(const BallSet& balls);
  // Takes the normal speed out of the contact of ball i with the body `key` names, and with
  // `gap_too` its gap, shared between the two by their inverse masses.
  void closeContact(std::size_t i, std::size_t key, bool gap_too);
  // Impact prediction, kept from one event to the next. At the step's start every ball's box
  // swept to the step's end goes into the grid and its earliest impact with what its box meets
  // is predicted (but for the balls settling on from the last step: see unpredicted_); after
  // each event only what the event changed is predicted anew.
  void predictAll(double horizon);
  // Finds rooms_ and room_of_ anew where the segments or the movable ones have changed.
  void updateRooms();
  void predictChanged(double elapsed, double remaining);
  // A ball's swept box, the keys it meets and its earliest impact with them, `elapsed` into the
  // step with `remaining` of it left.
  void predictBall(std::size_t ball, double elapsed, double remaining);
  // Keeps `earliest` (its time counted from `elapsed` into the step) as the ball's next impact,
  // and the ball as awaiting what the impact involves.
  void expectImpact(std::size_t ball, std::optional<Impact> earliest, double elapsed);
  Box keyBox(std::size_t key, double remaining) const;
  // The earliest impact predicted, if it comes within `horizon`; its time counted from now.
  std::optional<Impact> earliestImpact(double elapsed, double horizon) const;
  void considerImpact(std::size_t ball, std::size_t key, double horizon,
                      std::optional<Impact>& earliest) const;
  // What predictions assume of each body: a ball's motion and spin from `time` into the step
  // on and whether it rests or is settled, a segment's place and motion. A ball moves along its
  // course when looked at; predictChanged() finds the balls that left theirs.
  struct Course {
    double time;
    Vec2 position, velocity, acceleration;
    double angle, angular_velocity, angular_acceleration;
    bool at_rest, settled;
  };
  struct SegmentCourse {
    Vec2 start, end, velocity;
    double angular_velocity;
    bool operator==(const SegmentCourse& other) const;
  };
  Course courseOf(std::size_t ball) const;  // from now on, as it moves now
  static SegmentCourse courseOf(const Segment& segment);
  // Sets the ball's motion and spin to where its course has them at `time` into the step.
  static void moveAlong(const Course& course, double time, Ball& ball);
  // Whether the ball, looked at now, is still where its course has it, moving as it says.
  bool onCourse(std::size_t ball) const;
  // Replays the ball's place in impact_queue_ after its next impact was predicted; sets its hold
  // end and its place in hold_end_queue_.
  void queueImpact(std::size_t ball);
  void queueHoldEnd(std::size_t ball, double end);
  // Whether the impact is with the body `key` names (or, through a rope, with that ball).
  bool impactInvolves(const Impact& impact, std::size_t key) const;
  // Whether ball a's next impact comes before ball b's (one with none comes last).
  bool impactComesFirst(std::size_t a, std::size_t b) const;
  bool holdEndComesFirst(std::size_t a, std::size_t b) const;
  // Impacts at the same time are taken in one fixed order (by ball, then what it hits: balls
  // by index, then segments, faces before caps), whatever order the broad phase finds them in.
  bool comesBefore(const Impact& a, const Impact& b) const;
  // Moves everything on by dt, from `elapsed` into the step (sensors watching).
  void advance(double elapsed, double dt);
  void resolve(const Impact& impact, double time);
  // An impact changes two bodies' velocities, and a ball touching one of them (within
  // kContactSlop) that now approaches it is hit at that same instant. As events, those hits
  // would come one by one, zero time apart, each after a hold and a prediction of the world: a
  // hit on a column of balls passes down it as hundreds of them. They are resolved here
  // instead, as they arise, until no touching pair approaches faster than kRestingSpeed (the
  // next hold stops slower approaches) or `passed`, counting them, reaches `budget`. Sets
  // `changed` (emptied first, its storage kept) to the balls whose velocities the impact and
  // they changed. Returns whether they need holding: not if no hit was passed on, no rope or
  // moving segment is in the world, none of them rests, and each body near them is a segment
  // or the impact's other ball that they leave freely (as a bounce leaves a wall), or a ball
  // beyond kBoxMargin: the touches it reads tell that without the hold's search.
  bool passThroughTouching(const Impact& impact, double time, std::size_t& passed,
                           std::size_t budget, BallSet& changed);
  void resolveBallImpact(const Impact& impact, double time);
  void resolveSegmentImpact(const Impact& impact, double time);
  void resolveRopeImpact(const Impact& impact);
  // The ball and the resting balls it touches, or touches through resting balls, with at most
  // `hops` touches between (every one by default): restingClusterOf's, as indices. With
  // `above`, past the balls touching `ball` only those that press on the one they touch, and
  // those hanging by a rope: what the ball and its neighbours hold up. With `ahead` not zero,
  // only balls within 60 degrees of it from the ball they touch: what a push along it presses
  // on (a row ahead of a driven ball, not the floor's balls beside it).
  std::vector<std::size_t> restingClusterIndices(
      std::size_t ball, std::size_t hops = std::numeric_limits<std::size_t>::max(),
      bool above = false, const Vec2& ahead = Vec2::Zero()) const;
  // Whether `ball`'s own pull (gravity, fields, drive) pushes it into `other`: it rests on it.
  bool pressesOn(std::size_t ball, std::size_t other) const;
  // A step out of its budget (world_budgets.cpp).
  // The moving balls, not settled, met by `least` events or more in the step (`events_of`).
  BallSet strugglingBalls(const std::vector<std::size_t>& events_of, std::size_t least) const;
  // Out of its step's budget: the struggle (the moving balls met by kSequentialImpactsPerBall
  // events or more in the step, `events_of`) and the balls touching them wait (held still, as
  // if at rest) for the rest of the step, so that the others go on. False, and none waits, if
  // that would be every moving ball or a moving segment touches one of them.
  bool holdStillTheStruggle(const std::vector<std::size_t>& events_of);
  // Out of its step's budget: the balls that may meet the struggle (or, where there is none,
  // the balls met by any event) settle for the rest of the step; false if they cannot.
  bool settleTheStruggle(const std::vector<std::size_t>& events_of, double remaining);
  // Out of its step's budget: the moving segments that touch the struggle, or a moving ball
  // touching it, stop for the rest of the step, as a game engine's elevator stops on what it
  // would crush; whether any did.
  bool stopSegmentsPressingTheStruggle(const std::vector<std::size_t>& events_of);
  // Segments stopped and jammed (world_crushes.cpp).
  // The segment numbered `k` stops for the rest of the step (haltSegment), its jam noted
  // (noteJammed), and every ball is held anew at the next event: one held on it moved with it.
  void stopSegment(std::size_t k);
  // The segment numbered `k` stands still until the step's end (see stopped_segments_).
  void haltSegment(std::size_t k);
  // At a step's start, before its paths are foreseen: the segments that stopped on a ball
  // within kJammedRetry stand still for the step (haltSegment); jams past kJammedTime and
  // kJammedRetry are forgotten.
  void haltJammedSegments();
  // Every jammed segment tries to move again at the next step (something that held it may be
  // gone).
  void retryJams();
  // At a step's end: the stopped segments move on as they were moving.
  void restartStoppedSegments();
  // Settles (world_settle.cpp; wakes: world_wakes.cpp; moving segments: world_crushes.cpp).
  // The balls that may meet one of `seeds` in the rest of the step (`remaining`), or meet one that
  // may, and so on, move on to its end in settles (settleTogether), one an island (islandsOf), at
  // the velocities they give them, in straight lines. Along straight paths the distance between two
  // balls, or between a ball and a standing segment, is convex, so it never falls below its tangent
  // at the start, gap + n . v t: a contact that keeps that tangent from closing more than the gap
  // (and kSettleOverlap past it) by the end keeps them so throughout (against a turning segment,
  // only when its motion changes or at the end: see carriedSeparationOf). A resting ball struck
  // (see wakeStruck) wakes and settles with them. Straight paths are semi-implicit Euler, which
  // can gain energy where a support pushes a ball up: an island's velocities are scaled down, if
  // need be, until its balls end with no more energy than they have now, or than they would end
  // with on the straight paths an earlier settle of the step gave them (scaled, they close no
  // gap further).
  // The settled balls (settled_) meet nothing outside the island to the step's end unless an event
  // takes a ball there, and that ball then settles with them. Still islands are put to rest; the
  // settled balls still awake settle again at the next step's start (settling_). Each island that
  // settles moves on so; false where one cannot, its pairs meeting a body a settle does not take
  // (settleTakes), or its settle taking balls farther than they were sought within, onto bodies
  // they were not paired with (meetUnpaired), time after time: then nothing changes for its
  // balls.
  bool settleRestOfStep(double remaining, const BallSet& seeds);
  // At a step's start (`dt` long): no ball is settled yet, and those settling (settling_) settle
  // for the whole step, where they can. Stale warm starts are forgotten (WarmStarts).
  void settleAtStart(double dt);
  // Adds to `seeds` the moving balls of each pile at a step's start (`dt` long): kPileBalls or
  // more joined by lasting contacts, each touching (within kRestingGap) and neither coming
  // together nor parting faster than gravity would over the step. A pile settles from its
  // first touch, not by events and holds at every contact until the step's budget runs out.
  void seedLastingContacts(double dt, BallSet& seeds) const;
  // Whether the impact, met by a settled ball (or by a resting one whose waking would wake a
  // settled one, or, where piles form, a pile's worth of resting balls), was settled
  // instead: its balls and the settled ones that may meet them settle together for the rest of
  // the step.
  bool settlesOnImpact(const Impact& impact, double remaining);
  // Whether the ball is among settled_ (none is outside a step).
  bool isSettled(std::size_t ball) const;
  // Whether a settle takes the body `key` names as it is: a ball no rope ties (whatever pulls
  // it: see settlePull), or a segment that neither breaks nor kicks (it stands still,
  // slides or turns: settleTogether knows no more). An island with one that is not is left to
  // events.
  bool settleTakes(std::size_t key) const;
  // Whether the settle's contact `c` (its `k`th) is with a moving segment that pushes.
  bool pushesAsItMoves(const Settled& settled, const RestingContact& c, std::size_t k) const;
  // The moving segments that push on the settle's balls stop (stopSegment), their keys into
  // `stopped`.
  void stopSegmentsPressing(const Settled& settled, std::vector<std::size_t>& stopped);
  // The settled balls near the segments numbered `segments` (whose motion changed) settle again
  // for the `remaining` stretch, or, where they cannot, are no longer settled and go into
  // `unsettled` to be held, with the other balls near them.
  void settleAgainNear(const std::vector<std::size_t>& segments, double remaining,
                       BallSet& unsettled);
  // Notes the segment numbered `k` stopped now (jammed_segments_), its jam beginning now unless
  // one began within kJammedTime; whether its jam began within kJammedTime.
  void noteJammed(std::size_t k);
  bool jammedLately(std::size_t k) const;
  // Whether the segment numbered `k` is stopped for the rest of the step (haltSegment).
  bool stoppedInStep(std::size_t k) const;
  // The pairs (moving ball, key) whose bodies may meet over `duration`, each ball on its way
  // (at `free` at its end, if untouched) or within `reach` of its straight path, that join
  // balls to one of `seeds` (through balls, resting ones too); and, in `members`, their balls.
  // An island of them with a body a settle does not take (settleTakes) is left out
  // (`left_out`). In the order a sweep over their boxes' left sides meets them.
  KeyPairs settlingPairs(const std::vector<Vec2>& free, const std::vector<double>& reach,
                         double duration, const BallSet& seeds, BallSet& members,
                         bool& left_out) const;
  // Wakes the resting balls that a ball of `pairs` comes at faster than lasting contact does
  // (lastingApproach), near enough to strike in `duration`, and the resting balls within
  // kStruckHops touches of them, or that a moving segment of `pairs` reaches in it, or an island
  // of moving balls that a steady push the resting ball does not feel drives toward it
  // (steadyLoadsOf), and every resting ball touching those (all added to `woken`, with their
  // `free` velocities); whether any woke.
  bool wakeStruck(const KeyPairs& pairs, std::vector<Vec2>& free, double duration,
                  std::vector<std::size_t>& woken);
  // The islands of the moving balls of `pairs`, joined by their pairs (`joined`'s roots), each
  // with the steady pushes its balls feel (steadyPush) as one force on it and the mass it
  // moves, and the push of one of its balls and whether another's differs; no forces where none
  // of them feels one.
  struct SteadyLoads {
    DisjointSets joined;
    std::vector<Vec2> force;
    std::vector<double> mass;
    std::vector<Vec2> push;
    std::vector<bool> mixed;
  };
  SteadyLoads steadyLoadsOf(const KeyPairs& pairs) const;
  // Whether balls in lasting contact pile up and settle: not without gravity.
  bool pilesForm() const;
  // The fastest two bodies approach in lasting contact over `duration`: as fast as gravity
  // brings them together (or kRestingSpeed); faster, they strike.
  double lastingApproach(double duration) const;
  // Whether bodies `gap` apart, coming together at `approach`, strike within `duration`: faster
  // than lasting contact, and near enough to meet along straight paths.
  bool strikesWithin(double approach, double gap, double duration) const;
  // The restitution of a ball's contact with the (ball or segment) body `key` names.
  double restitutionOf(std::size_t ball, std::size_t key) const;
  // An island of a settle: its pairs, their balls (resting ones too) and, once settled, how
  // they end and the farthest it takes one from its untouched path.
  struct SettledIsland {
    KeyPairs pairs;
    std::vector<std::size_t> members;
    Settled settled;
    double farthest = 0.0;
    std::vector<std::size_t> beyond;  // its moving balls (as members numbers them) taken
                                      // farther from their untouched paths than their reach
  };
  // Per island, whether a ball it took beyond its reach (SettledIsland::beyond) may meet a
  // body that its pairs do not pair it with, on its settled path over `duration`: then it is
  // sought again. Its search's boxes (searchBox, in settle_grid_) are grown to hold such paths.
  std::vector<bool> meetUnpaired(const std::vector<SettledIsland>& islands,
                                 const std::vector<Vec2>& free, const std::vector<double>& reach,
                                 double duration) const;
  // The box in which a settle's search looks for what the ball `i` may meet over `duration`:
  // on its way, or within `reach` of its straight path to `free` (a resting ball's, where it
  // is).
  Box searchBox(std::size_t i, const Vec2& free, double reach, double duration) const;
  // The islands of `pairs`, joined through the balls that move: each settles on its own, so
  // that nothing one does changes a ball outside it.
  std::vector<SettledIsland> islandsOf(const KeyPairs& pairs) const;
  // settleMembers for the island, and again with no overlap opening if opening them would
  // take more energy than its balls have (see energyKeepingShare).
  Settled settleIsland(const SettledIsland& island, const std::vector<Vec2>& free,
                       double duration, const std::vector<std::size_t>& woken);
  // settleTogether for `pairs` over `duration`, its balls numbered in the order of `members`,
  // its contacts swept from the bottom up; overlaps past kSettleOverlap `open` or stay, and
  // strikes on the balls `woken` from rest for it bounce.
  Settled settleMembers(KeyPairs pairs, const std::vector<std::size_t>& members,
                        const std::vector<Vec2>& free, double duration, bool open,
                        const std::vector<std::size_t>& woken);
  // settleTogether for settleMembers: its first `balls` balls, then the surfaces of moving
  // segments (see takeBackSurfaces). With a moving segment jammed lately (jammedLately), it
  // runs kJammedRounds first, and goes on only where no such segment crushes a ball.
  Settled settleWithSegments(const std::vector<Ball>& settling,
                             const std::vector<double>& inverse_masses,
                             std::vector<RestingContact>& contacts,
                             const std::vector<double>& frictions, double duration,
                             std::vector<std::array<double, 2>>& impulses, std::size_t balls);
  // The contact `t` of `ball` with the segment `key`, carried with the segment for `time`
  // (carriedSeparation): the ball's separation from it then, standing still. Along that normal
  // the gap then is linear in the ball's velocity (a face's exactly, a cap's from below).
  Separation carriedSeparationOf(std::size_t ball, std::size_t key, const Touch& t,
                                 double time) const;
  // A settle of `balls` balls and, after them, the surfaces of moving segments in `settling`
  // (one for each of their `contacts`, which the settle does not move), back to its balls: the
  // contacts become the segments' again, and the settle learns the work they did (from its
  // `impulses`) and whether one crushes a ball (see Settled).
  void takeBackSurfaces(Settled& settled, std::size_t balls, std::vector<RestingContact>& contacts,
                        const std::vector<Ball>& settling,
                        const std::vector<std::array<double, 2>>& impulses,
                        double duration) const;
  // Reports the settle's hits, puts its still islands to rest, and gives the other members
  // their settled velocities (scaled to keep energy from growing) and straight courses. (Their
  // held contacts are let go first, by the caller.)
  void moveOnSettled(Settled& settled, double duration);
  // The settle's balls (as it numbers them) that rest: each island of pushing contacts among
  // still balls (slower than kSettledRestSpeed before and after the settle, `duration` long,
  // or than kSleepSpeed for kTimeToSleep unless a drive or wind pushes it (steadyPush), its
  // surface too if rough; touching what pushes it, pushed by no moving ball) that a segment or
  // a resting ball holds up. None without gravity.
  std::vector<std::size_t> stillIslands(const Settled& settled, double duration) const;
  // Into unheld_: each resting ball that leans on (pressesOn) a ball the settle moves away from
  // it, touching it now and apart by more than kMostSettledOverlap of the smaller radius at the
  // stretch's end (a ball a strike woke under it, rolling off).
  void recordUnheld(const Settled& settled, double duration);
  // At the step's end, the unheld_ balls wake, with the resting balls touching them and what
  // those hold up (restingClusterIndices with `above`): resting on nothing, they would hang in
  // the air.
  void wakeUnheld();
  // Reports as contacts the settle's pairs that come at each other faster than kRestingSpeed
  // and push, in order of the time their gaps would close at that speed.
  void reportSettledImpacts(const Settled& settled, double duration);
  // The largest share, up to 1, of a settle's velocities with which its moving balls end the
  // stretch (`duration`) with no more energy than now (those settled earlier in the step: than
  // at the end of their straight paths), each under its settlePull (what drag takes is lost).
  double energyKeepingShare(const Settled& settled, double duration) const;
  void wake(std::size_t ball);
  // Wakes the ball, the resting balls touching it and what those hold up
  // (restingClusterIndices with `above`); the resting balls beside and below sleep on.
  void wakeWhatItHoldsUp(std::size_t ball);
  // A ball stops where it is, still and unpulled, at rest (or, with its velocity kept aside,
  // waiting) until it is woken.
  void comeToRest(std::size_t ball);
  // A ball at rest or waiting moves again, a waiting one (woken, or at the step's end) with the
  // velocity it had, under its free acceleration until it is held.
  void leaveRest(std::size_t ball);
  void wakeTouching(const Segment& segment);

  Vec2 gravity_;
  double time_ = 0.0;
  // Each ball as of clocks_ (time into the step); outside a step, as of now. Looking at a ball
  // brings it to now_ (ballNow), which a const reader may do: the ball is where it was, only
  // known at a later time.
  mutable std::vector<Ball> balls_;
  mutable std::vector<double> clocks_;
  double now_ = 0.0;  // time into the step being taken
  // The balls looked at to be changed since the last prediction, as a list and per ball.
  std::vector<std::size_t> looked_at_;
  std::vector<bool> is_looked_at_;
  // Each ball's acceleration until the next impact: its free acceleration plus resting
  // contacts' forces.
  std::vector<Vec2> accelerations_;
  // Each ball's drive (see drive()).
  std::vector<Vec2> drives_;
  std::vector<Wind> winds_;
  std::vector<Attractor> attractors_;
  std::vector<Water> waters_;
  double step_left_ = 0.0;  // of the step being taken, from the event being handled
  std::vector<Sensor> sensors_;
  // The (ball id, sensor index) of each ball in a sensor's region, as last seen.
  std::set<std::pair<BallId, std::size_t>> in_sensors_;
  std::vector<SensorEvent> sensor_events_;
  std::vector<BrickHit> brick_hits_;
  std::vector<SegmentId> broken_bricks_;  // in this step, removed at its end
  std::vector<BallId> pocketed_;          // likewise
  // And its angular acceleration, from the friction of its resting contacts.
  std::vector<double> angular_accelerations_;
  // Resting contacts under load until the next event, as (ball, other ball),
  // (ball, number of balls + segment index) or (ball, number of balls and segments + rope
  // index), with their forces. Their gaps stay closed by the normal forces, so impact
  // detection leaves them alone.
  HeldContacts held_;
  // Per ball, when (time into the step) the accelerations found for its island when it was last
  // held stop being exact: the earliest lifetime of its held contacts, or its going in or out of
  // wind; infinity if none.
  std::vector<double> hold_ends_;
  // Per rope held taut, how long its hold lasts (see pullFromMiddleOfSwing).
  std::vector<double> rope_swings_;
  // Per ball, in a step that ran out of budget, the velocity a waiting ball takes up again.
  std::vector<std::optional<Vec2>> waiting_velocities_;
  // Per ball, how it settles (see settleRestOfStep): whether it settles at the next step's
  // start (it was settled, and is awake; without gravity, moving), how fast its island's last
  // settle took a ball off its untouched path (from which the next one's search reaches), and
  // since when (world time) its settles have left it slower than kSleepSpeed.
  struct Settling {
    bool goes_on = false;
    double off_path = 0.0;  // m/s
    double slow_since = std::numeric_limits<double>::infinity();
  };
  std::vector<Settling> settling_;
  // Resting balls a settle left leaning on nothing (see recordUnheld), by index.
  std::vector<std::size_t> unheld_;
  // The segments stopped in the step being taken (see haltSegment), with the motion each takes
  // up again at its end.
  struct StoppedSegment {
    std::size_t segment;
    Vec2 velocity;
    double angular_velocity;
    std::vector<Vec2> waypoints;
  };
  std::vector<StoppedSegment> stopped_segments_;
  // The segments stopped lately (jammed: a lift on a pile), by id, with when their jam began
  // (for kJammedTime after, a settle with one moving runs kJammedRounds first: see
  // settleWithSegments) and when they last stopped (for kJammedRetry after, they stand still:
  // see haltJammedSegments).
  struct Jam {
    SegmentId segment;
    double began;    // s, world time
    double stopped;  // s, world time
  };
  std::vector<Jam> jammed_segments_;
  bool holds_stale_ = false;  // a segment stopped since the last event held balls anew
  // The ball whose first strike on another ball ends the step being taken (stepUntilStrike).
  std::optional<std::size_t> strike_stop_;
  // The balls settled in the step being taken, on their straight paths: impacts among them and
  // with segments, and holds, leave them alone.
  BallSet settled_{0};
  // Each pair's impulses in its latest settle (see settleRestOfStep), the next one's start.
  WarmStarts settle_impulses_;
  std::vector<Segment> segments_;
  std::vector<Rope> ropes_;
  // Each rope's ends as ball indices: its ball, and its other ball if any.
  std::vector<std::pair<std::size_t, std::optional<std::size_t>>> rope_ends_;
  std::vector<Contact> contacts_;
  // The broad phase over balls and segments (keyed as in held_), each box swept to the step's
  // end; per ball, the earliest impact with the keys its box met when last predicted (its time
  // counted from the step's start). Of two balls whose boxes meet, the one predicted later
  // looked at the other: every pair that can touch was. Empty where no two balls meet and no
  // segment can move in the step (balls_in_grid_).
  BoxGrid grid_;
  BoxGrid segment_grid_;    // the segments' boxes alone, keyed by segment index
  bool balls_meet_ = true;  // whether any two balls can meet, as of the step's start
  bool balls_in_grid_ = true;
  // The segments that move or head for waypoints, or stand jammed (haltJammedSegments), as of
  // the step's start: the others stay put until it ends (only calls between steps set a segment
  // moving), so events pass them by.
  std::vector<std::size_t> movable_segments_;
  // The rooms the others make, as of the step's start, and each segment's room if any; and
  // the segments (their ids, in order) and movable ones (as above) they were found among.
  std::vector<Room> rooms_;
  std::vector<std::optional<std::size_t>> room_of_;
  std::vector<SegmentId> rooms_segments_;
  std::vector<std::size_t> rooms_movable_;
  std::vector<std::optional<Impact>> next_impacts_;
  mutable std::vector<std::size_t> keys_met_;  // keysMet's
  mutable BoxGrid settle_grid_;                // settlingPairs'
  std::vector<std::size_t> settle_place_;      // settleMembers' number of each member
  SettleScratch settle_scratch_;               // what settleMembers' settles work in
  // Kept from search to search, which would otherwise allocate them at every event: the balls
  // touchingPairs reached and has still to look from, and those passThroughTouching has still
  // to look from, with its marks of them (all false between passes).
  mutable BallSet touching_reached_{0};
  mutable std::vector<std::size_t> touching_pending_;
  mutable std::vector<std::size_t> moving_keys_;  // pairsNearMoving's
  mutable std::vector<std::pair<std::size_t, std::size_t>> moving_pairs_;
  std::vector<std::size_t> struck_pending_;
  std::vector<bool> struck_queued_;
  BallSet changed_{0};  // predictChanged's balls to predict anew
  // The balls settling on from the last step, whose impacts predictAll leaves for the step's
  // first predictChanged: the settle at the step's start takes them off their paths (or leaves
  // them to events, and the hold sets their accelerations), and their impacts would be
  // predicted twice (a churned pile's every ball).
  BallSet unpredicted_{0};
  // Per key (as in held_), the balls whose next impact was predicted with it, some perhaps no
  // longer: those to predict anew when it changes.
  std::vector<std::vector<std::size_t>> awaiting_;
  // The earliest of next_impacts_ and of hold_ends_.
  TournamentTree impact_queue_;
  TournamentTree hold_end_queue_;
  std::vector<Course> courses_;
  std::vector<SegmentCourse> segment_courses_;
  // The contacts held or let go since the last prediction, in order, each with whether it was
  // held before that change: a map of every held contact compared after each event would cost
  // a pass over them all.
  std::vector<std::pair<std::pair<std::size_t, std::size_t>, bool>> held_changes_;
  BallId next_ball_id_ = 1;
  SegmentId next_segment_id_ = 1;
  RopeId next_rope_id_ = 1;
};

}  // namespace ball_physics_sim::engine
