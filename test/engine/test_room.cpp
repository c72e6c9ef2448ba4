#include "ball_physics_sim/engine/room.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "ball_physics_sim/engine/toi.h"
#include "bodies.h"

namespace ball_physics_sim::engine {
namespace {

using test::segment;

// A closed loop through `corners`, in their order.
std::vector<Segment> loopThrough(const std::vector<Vec2>& corners) {
  std::vector<Segment> walls;
  for (std::size_t i = 0; i < corners.size(); ++i)
    walls.push_back(segment(corners[i], corners[(i + 1) % corners.size()]));
  return walls;
}

// The walls of [0, 10] x [0, 10], going round counter-clockwise from the floor.
std::vector<Segment> boxWalls() { return loopThrough({{0, 0}, {10, 0}, {10, 10}, {0, 10}}); }

// The corners of a regular polygon of `n` sides, radius 10 about the origin.
std::vector<Vec2> regularCorners(int n, int step = 1) {
  std::vector<Vec2> corners;
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * kPi * step * i / n;
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
  // Round from the first: down the right wall to (10, 0), the floor, up the left, the top.
  EXPECT_EQ(rooms[0].walls, (std::vector<std::size_t>{0, 2, 1, 3}));
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
  std::vector<Segment> split = boxWalls();  // the floor in two: a corner that does not turn
  split[0].end = {5, 0};
  split.push_back(segment({5, 0}, {10, 0}));
  EXPECT_TRUE(findRooms(split, {}).empty());
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

TEST(Room, AnOpenChainListedBackwardsIsNoneAndTheBoxAfterItStillOne) {
  // Each segment of the chain walks on into those listed before it, looked at already.
  std::vector<Segment> walls;
  auto zigzag = [](int k) { return Vec2(20.0 + k, k % 2); };
  for (int k = 5; k > 0; --k) walls.push_back(segment(zigzag(k - 1), zigzag(k)));
  const std::vector<Segment> box = boxWalls();
  walls.insert(walls.end(), box.begin(), box.end());
  const std::vector<Room> rooms = findRooms(walls, {});
  ASSERT_EQ(rooms.size(), 1u);
  EXPECT_EQ(rooms[0].walls, (std::vector<std::size_t>{5, 6, 7, 8}));
}

TEST(Room, ItShieldsTheCornersFromABallInsideThatFitsAlongEveryWall) {
  const Room room = findRooms(boxWalls(), {})[0];
  EXPECT_TRUE(shieldsCorners(room, {5, 5}, 0.5));
  EXPECT_TRUE(shieldsCorners(room, {0.5, 0.5}, 0.5));  // touching two walls at a corner
  // Overlapping a wall by up to what kShieldedClearance leaves, 0.0335 of 0.5, it still is.
  EXPECT_TRUE(shieldsCorners(room, {0.47, 5}, 0.5));
  EXPECT_FALSE(shieldsCorners(room, {0.46, 5}, 0.5));
  EXPECT_FALSE(shieldsCorners(room, {-0.5, 5}, 0.5));  // outside, beside a wall
  EXPECT_FALSE(shieldsCorners(room, {-0.5, -0.5}, 0.5));
  EXPECT_TRUE(shieldsCorners(room, {5, 5}, 5.0));  // walls two contact distances long
  EXPECT_FALSE(shieldsCorners(room, {5, 5}, 5.0000001));
  EXPECT_TRUE(shieldsCorners(room, {5, 5}, kMinShieldedReach));
  EXPECT_FALSE(shieldsCorners(room, {5, 5}, 0.5 * kMinShieldedReach));  // near the slop
}

TEST(Room, AtTheMostOpenCornerABallHeadingIntoItMeetsBothFacesBeforeTheCorner) {
  // Walls from the corner at the origin, 120 degrees apart about the -x axis, and a ball coming
  // down the bisector from x = -5 at 1 m/s: it touches the faces where d / sin 60 from the
  // corner, the cap (were it to go on) where d from it.
  const double d = 0.5;
  const Vec2 a(-10.0 * std::cos(kPi / 3.0), 10.0 * std::sin(kPi / 3.0));
  const Vec2 b(a.x(), -a.y());
  const Motion ball{{-5.0, 0.0}, {1.0, 0.0}, Vec2::Zero()};
  const double face_time = 5.0 - d / std::sin(kPi / 3.0);
  for (const Segment& wall : {segment(a, Vec2::Zero()), segment(Vec2::Zero(), b)}) {
    const std::optional<double> face = faceTimeOfImpact(ball, d, wall, 10.0);
    ASSERT_TRUE(face);
    EXPECT_NEAR(*face, face_time, 1e-12);
  }
  const std::optional<double> cap = capTimeOfImpact(ball, d, segment(a, Vec2::Zero()), 1, 10.0);
  ASSERT_TRUE(cap);
  EXPECT_NEAR(*cap, 5.0 - d, 1e-12);
  EXPECT_GT(*cap - face_time, 0.07);  // d (1 / sin 60 - 1) = 0.077 later
}

}  // namespace
}  // namespace ball_physics_sim::engine
