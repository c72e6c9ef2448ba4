#include "ball_physics_sim/engine/room.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace ball_physics_sim::engine {

namespace {

// One end of a segment: which segment, and which of its caps.
struct End {
  std::size_t segment;
  int cap;
};

// Per segment and cap, the other segment's end at exactly the same point, where there is
// exactly one: at a point three segments share, the walls would not make one loop.
using Partners = std::vector<std::array<std::optional<End>, 2>>;

Partners partnersOf(const std::vector<Segment>& segments, const std::vector<bool>& fixed) {
  auto point = [&segments](const End& e) { return segments[e.segment].cap(e.cap); };
  std::vector<End> ends;
  for (std::size_t k = 0; k < segments.size(); ++k)
    if (fixed[k]) ends.insert(ends.end(), {End{k, 0}, End{k, 1}});
  std::sort(ends.begin(), ends.end(), [&point](const End& a, const End& b) {
    const Vec2 p = point(a), q = point(b);
    return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
  });
  Partners partners(segments.size());
  for (std::size_t i = 0, j = 0; i < ends.size(); i = j) {
    while (j < ends.size() && point(ends[j]) == point(ends[i])) ++j;
    if (j - i != 2 || ends[i].segment == ends[i + 1].segment) continue;
    partners[ends[i].segment][ends[i].cap] = ends[i + 1];
    partners[ends[i + 1].segment][ends[i + 1].cap] = ends[i];
  }
  return partners;
}

// The walls met going round from `first`'s end, each with the cap it is left by, if they
// come back to `first`; each one met is marked looked at. A walk that reaches a free end, or
// a wall looked at before (a loop's walls are met from within it only), is no loop.
std::optional<std::vector<End>> loopFrom(std::size_t first, const Partners& partners,
                                         std::vector<bool>& looked_at) {
  std::vector<End> loop;
  End at{first, 1};
  do {
    looked_at[at.segment] = true;
    loop.push_back(at);
    const std::optional<End> next = partners[at.segment][at.cap];
    if (!next || (next->segment != first && looked_at[next->segment])) return std::nullopt;
    at = {next->segment, 1 - next->cap};
  } while (at.segment != first);
  return loop;
}

// A wall's unit direction as the loop goes along it.
Vec2 directionAlong(const End& left_by, const std::vector<Segment>& segments) {
  const Vec2 direction = segments[left_by.segment].direction();
  return left_by.cap == 1 ? direction : Vec2(-direction);
}

// The room a loop of walls makes, if it is convex, winds round once and turns enough at
// every corner, and its walls are all as thick.
std::optional<Room> roomOf(const std::vector<End>& loop, const std::vector<Segment>& segments) {
  const std::size_t n = loop.size();
  if (n < 3) return std::nullopt;
  std::vector<Vec2> along;
  for (const End& wall : loop) along.push_back(directionAlong(wall, segments));
  double winding = 0.0;
  Room room;
  room.shortest_wall = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& next = along[(i + 1) % n];
    const double turn = std::atan2(perpendicular(along[i]).dot(next), along[i].dot(next));
    // (A wall folding back on the last, turn +-pi, leaves no inside.)
    if (std::abs(turn) < kMinRoomTurn || std::abs(turn) >= kPi || turn * winding < 0.0)
      return std::nullopt;
    winding += turn;
    const Segment& wall = segments[loop[i].segment];
    if (wall.thickness != segments[loop[0].segment].thickness) return std::nullopt;
    room.walls.push_back(loop[i].segment);
    room.shortest_wall = std::min(room.shortest_wall, wall.length());
  }
  // Turning the same way at every corner, a loop winds round a whole number of times: once
  // is a convex polygon, more a star.
  if (std::abs(winding) > 3.0 * kPi) return std::nullopt;
  const double inward = winding > 0.0 ? 1.0 : -1.0;  // the inside is on the left going round
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 normal = inward * perpendicular(along[i]);
    room.inward_normals.push_back(normal);
    room.offsets.push_back(normal.dot(segments[loop[i].segment].cap(loop[i].cap)));
  }
  return room;
}

}  // namespace

std::vector<Room> findRooms(const std::vector<Segment>& segments,
                            const std::vector<std::size_t>& movable) {
  std::vector<bool> fixed(segments.size(), true);
  for (const std::size_t k : movable) fixed[k] = false;
  const Partners partners = partnersOf(segments, fixed);
  std::vector<bool> looked_at(segments.size(), false);
  std::vector<Room> rooms;
  for (std::size_t first = 0; first < segments.size(); ++first) {
    if (!fixed[first] || looked_at[first]) continue;
    if (const std::optional<std::vector<End>> loop = loopFrom(first, partners, looked_at))
      if (std::optional<Room> room = roomOf(*loop, segments)) rooms.push_back(std::move(*room));
  }
  return rooms;
}

bool shieldsCorners(const Room& room, const Vec2& centre, double contact_distance) {
  if (contact_distance < kMinShieldedReach || room.shortest_wall < 2.0 * contact_distance)
    return false;
  const double clearance = kShieldedClearance * contact_distance;
  for (std::size_t i = 0; i < room.walls.size(); ++i)
    if (room.inward_normals[i].dot(centre) < room.offsets[i] + clearance) return false;
  return true;
}

}  // namespace ball_physics_sim::engine
