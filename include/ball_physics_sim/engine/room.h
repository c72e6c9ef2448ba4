#pragma once

#include <cstddef>
#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/resting_contact.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// A room: segments that stay put, joined end to end (each shared end exactly equal, shared by
// no third such segment) in a closed convex loop, as a box's walls are. Inside it a ball can
// reach a corner only through a face: where it would touch a corner, it would overlap the
// nearer of the corner's two faces by at least (1 - sin(corner / 2)) of the contact distance,
// so it met that face (or another corner) before. A ball's searches inside a room skip its
// corners.
struct Room {
  std::vector<std::size_t> walls;    // segment indices, in order round the loop
  std::vector<Vec2> inward_normals;  // each wall's unit normal toward the inside
  std::vector<double> offsets;       // inward_normals[i] . x >= offsets[i] on the inside
  double shortest_wall = 0.0;        // m (the walls are all as thick)
};

// Every corner turns the loop by at least this much (its inside angle is at most 120 degrees):
// the face to overlap before it, by at least 0.13 of the contact distance, is far beyond
// rounding. (A regular hexagon's turns are this, give or take an ulp: it may be either.)
constexpr double kMinRoomTurn = kPi / 3.0;  // rad
// A ball is shielded only if its centre is this share of the contact distance inside every
// wall's line, halfway from where it touches a face (1) to where it may touch a corner
// (sin 60 degrees): it starts well clear of every corner, whatever small overlap it has.
constexpr double kShieldedClearance = 0.5 * (1.0 + 0.86602540378443865);
// Nor a ball of a smaller contact distance: its margins would near the engine's absolute
// tolerances.
constexpr double kMinShieldedReach = 1000.0 * kContactSlop;  // m

// The rooms among `segments`, leaving out the `movable` ones (indices). A room's walls are all
// as thick; a segment is a wall of one room at most.
std::vector<Room> findRooms(const std::vector<Segment>& segments,
                            const std::vector<std::size_t>& movable);

// Whether no corner of `room` can be the first thing a ball centred at `centre` touches, at
// `contact_distance` from the walls (toi.h): the centre is inside, kShieldedClearance clear of
// every wall's line; every wall is at least two contact distances long (the face overlapped
// near a corner is so within one of it, with room to spare); and the contact distance is at
// least kMinShieldedReach.
bool shieldsCorners(const Room& room, const Vec2& centre, double contact_distance);

}  // namespace ball_physics_sim::engine
