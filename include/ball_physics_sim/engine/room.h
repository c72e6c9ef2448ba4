#pragma once

#include <cstddef>
#include <vector>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// A room: segments that stay put, joined end to end (each shared end exactly equal, shared by
// no third segment) in a closed convex loop, as a box's walls are. Inside it a ball can reach
// a corner only through a face: where it would touch a corner, it would overlap the nearer of
// the corner's two faces by at least (1 - sin(corner / 2)) of the contact distance, so it hit
// that face (or another corner) before. A ball's searches inside a room skip its corners.
struct Room {
  std::vector<std::size_t> walls;    // segment indices, in order round the loop
  std::vector<Vec2> inward_normals;  // each wall's unit normal toward the inside
  std::vector<double> offsets;       // inward_normals[i] . x >= offsets[i] on the inside
  double shortest_wall = 0.0;        // m (the walls are all as thick)
};

// Every corner turns the loop by at least this much (its inside angle is at most 120 degrees):
// the face to overlap before it, at least 0.13 of the contact distance, is far beyond rounding.
constexpr double kMinRoomTurn = 1.0471975511965976;  // rad, pi / 3

// The rooms among `segments`, leaving out the `movable` ones (indices, ascending). A room's
// walls are all as thick; a segment is a wall of one room at most.
std::vector<Room> findRooms(const std::vector<Segment>& segments,
                            const std::vector<std::size_t>& movable);

// Whether no corner of `room` can be the first thing a ball centred at `centre` touches, at
// `contact_distance` from the walls (toi.h): the centre is inside (on every wall's inner side,
// boundary included), and every wall is at least two contact distances long, so that the face
// overlapped near a corner is there.
bool shieldsCorners(const Room& room, const Vec2& centre, double contact_distance);

}  // namespace ball_physics_sim::engine
