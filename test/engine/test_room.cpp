#include "ball_physics_sim/engine/room.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "bodies.h"

namespace ball_physics_sim::engine {
namespace {

using test::segment;

// The walls of [0, 10] x [0, 10], going round counter-clockwise from the floor.
std::vector<Segment> boxWalls() {
  return {segment({0, 0}, {10, 0}), segment({10, 0}, {10, 10}), segment({10, 10}, {0, 10}),
          segment({0, 10}, {0, 0})};
}

// A closed loop through `corners`, in their order.
std::vector<Segment> loopThrough(const std::vector<Vec2>& corners) {
  std::vector<Segment> walls;
  for (std::size_t i = 0; i < corners.size(); ++i)
    walls.push_back(segment(corners[i], corners[(i + 1) % corners.size()]));
  return walls;
}

// The corners of a regular polygon of `n` sides, radius 10 about the origin.
std::vector<Vec2> regularCorners(int n, int step = 1) {
  std::vector<Vec2> corners;
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * M_PI * step * i / n;
    corners.push_back(10.0 * Vec2(std::cos(angle), std::sin(angle)));
  }
  return corners;
}

TEST(Room, TheFourWallsOfABoxMakeOneWithTheirNormalsPointingIn) {
  const std::vector<Room> rooms = findRooms(boxWalls(), {});
  ASSERT_EQ(rooms.size(), 1u);
  const Room& room = rooms[0];
  EXPECT_EQ(room.walls, (std::vector<std::size_t>{0, 1, 2, 3}));
  const std::vector<Vec2> inward = {{0, 1}, {-1, 0}, {0, -1}, {1, 0}};
  EXPECT_EQ(room.inward_normals, inward);
  EXPECT_EQ(room.offsets, (std::vector<double>{0, -10, -10, 0}));
  EXPECT_EQ(room.shortest_wall, 10.0);
}

TEST(Room, WallsGivenInAnyOrderAndEitherWayRoundMakeTheSameInside) {
  // Clockwise, out of order, one wall drawn backwards: the inside is still the box's.
  std::vector<Segment> walls = {segment({10, 10}, {10, 0}), segment({0, 0}, {0, 10}),
                                segment({0, 0}, {10, 0}), segment({10, 10}, {0, 10})};
  const std::vector<Room> rooms = findRooms(walls, {});
  ASSERT_EQ(rooms.size(), 1u);
  EXPECT_EQ(rooms[0].walls.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const Segment& wall = walls[rooms[0].walls[i]];
    const Vec2 middle = 0.5 * (wall.start + wall.end);
    // The normal points from the wall's middle to the box's centre.
    EXPECT_EQ(rooms[0].inward_normals[i], (Vec2(5, 5) - middle) / 5.0);
    EXPECT_EQ(rooms[0].inward_normals[i].dot(middle), rooms[0].offsets[i]);
  }
}

TEST(Room, TrianglesAndPentagonsAreRoomsButAnOctagonsCornersAreTooOpen) {
  // Inside angles of 60 and 108 degrees are within kMinRoomTurn; 135 is not.
  EXPECT_EQ(findRooms(loopThrough(regularCorners(3)), {}).size(), 1u);
  EXPECT_EQ(findRooms(loopThrough(regularCorners(5)), {}).size(), 1u);
  EXPECT_TRUE(findRooms(loopThrough(regularCorners(8)), {}).empty());
}

TEST(Room, AStarWindsRoundTwiceAndIsNone) {
  // A pentagram turns 144 degrees the same way at every corner, twice round in all.
  EXPECT_TRUE(findRooms(loopThrough(regularCorners(5, 2)), {}).empty());
}

TEST(Room, ANonConvexLoopIsNone) {
  // An L: five corners turn left, one right.
  EXPECT_TRUE(findRooms(loopThrough({{0, 0}, {10, 0}, {10, 5}, {5, 5}, {5, 10}, {0, 10}}), {})
                  .empty());
}

TEST(Room, AnOpenBoxAMovableWallACornerOfThreeOrUnequalThicknessesMakeNone) {
  std::vector<Segment> open = boxWalls();
  open.pop_back();
  EXPECT_TRUE(findRooms(open, {}).empty());
  EXPECT_TRUE(findRooms(boxWalls(), {2}).empty());
  std::vector<Segment> three_at_a_corner = boxWalls();
  three_at_a_corner.push_back(segment({0, 0}, {5, 5}));
  EXPECT_TRUE(findRooms(three_at_a_corner, {}).empty());
  std::vector<Segment> thick = boxWalls();
  thick[1].thickness = 0.2;
  EXPECT_TRUE(findRooms(thick, {}).empty());
  // As thick all round, they make one.
  for (Segment& wall : thick) wall.thickness = 0.2;
  EXPECT_EQ(findRooms(thick, {}).size(), 1u);
}

TEST(Room, ABoxInABoxMakesTwoAndTheSegmentsBesideThemNone) {
  std::vector<Segment> walls = boxWalls();
  walls.push_back(segment({1, 8}, {3, 8}));  // a shelf, on its own
  const std::vector<Segment> inner = loopThrough({{4, 4}, {6, 4}, {6, 6}, {4, 6}});
  walls.insert(walls.end(), inner.begin(), inner.end());
  const std::vector<Room> rooms = findRooms(walls, {});
  ASSERT_EQ(rooms.size(), 2u);
  EXPECT_EQ(rooms[0].walls, (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(rooms[1].walls, (std::vector<std::size_t>{5, 6, 7, 8}));
  EXPECT_EQ(rooms[1].shortest_wall, 2.0);
}

TEST(Room, ItShieldsTheCornersFromABallInsideThatFitsAlongEveryWall) {
  const Room room = findRooms(boxWalls(), {})[0];
  EXPECT_TRUE(shieldsCorners(room, {5, 5}, 0.5));
  EXPECT_TRUE(shieldsCorners(room, {0.5, 0.5}, 0.5));  // touching two walls at a corner
  EXPECT_TRUE(shieldsCorners(room, {0, 5}, 0.5));      // centre on a wall: still inside
  EXPECT_FALSE(shieldsCorners(room, {-0.5, 5}, 0.5));  // outside, beside a wall
  EXPECT_FALSE(shieldsCorners(room, {-0.5, -0.5}, 0.5));
  EXPECT_TRUE(shieldsCorners(room, {5, 5}, 5.0));  // walls two contact distances long
  EXPECT_FALSE(shieldsCorners(room, {5, 5}, 5.0000001));
}

}  // namespace
}  // namespace ball_physics_sim::engine
