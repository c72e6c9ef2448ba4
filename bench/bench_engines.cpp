// The same scenes in this engine, Box2D 2.4.1 and Chipmunk 7.0.3, one run: time per step and
// the quality figures (balls escaped from the box, largest overlap as a fraction of the radius,
// energy at the end over energy at the start, balls awake at the end). Usage:
// bench_engines [N ...] [--budget S] [--steps K] [--scene pile|smooth|heaps|billiards|bullets ...]
//               [--engine ours|Box2D|Chipmunk ...]
// (N defaults to 1000, K to 600, and every scene and engine runs unless some are named). Each
// engine starts no step after S seconds of stepping (60 by default); this engine goes first in
// each scene and the peers make no more steps than it did, so a scene's figures cover the same
// stretch of sim time unless a peer ran out of time first. (`--engine ours` alone times this
// engine without its peers, as comparisons of two of its builds want.)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <box2d/box2d.h>
#include <chipmunk/chipmunk.h>

#include "ball_physics_sim/engine/broad_phase.h"
#include "ball_physics_sim/engine/world.h"

namespace {

using ball_physics_sim::engine::Vec2;
namespace engine = ball_physics_sim::engine;

constexpr int kSteps = 600;  // unless --steps says otherwise
constexpr double kStep = 1.0 / 60.0;
constexpr double kMass = 1.0;  // kg, every ball
// Box2D's own testbed settings.
constexpr int kBox2DVelocityIterations = 8;
constexpr int kBox2DPositionIterations = 3;
// The pile's grid, in diameters, and its random shift sideways (so that the columns are not
// exactly aligned stacks, which would stay balanced).
constexpr double kPileSpacing = 1.2;
constexpr double kPileJitter = 0.05;
// A heap: two columns of four, this far from the next heap (the box's floor between them).
constexpr int kHeapColumns = 2, kHeapRows = 4;
constexpr double kHeapGap = 3.6;  // m
constexpr double kBilliardsSpeed = 3.0;  // m/s, at most
constexpr double kBulletSpeed = 400.0;   // m/s

struct BallStart {
  Vec2 position;
  Vec2 velocity;
};

// A closed square box [0, width] x [0, height] and balls in it.
struct SceneSpec {
  std::string name;
  double radius = 0.5;
  double restitution = 1.0;
  double friction = 0.0;
  Vec2 gravity = Vec2::Zero();
  double width = 10.0, height = 10.0;
  bool ball_contacts = true;
  std::vector<BallStart> balls;
};

int columnsFor(int n) { return static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n)))); }

// N balls dropped from a grid 1.2 diameters apart into a box, e = 0.5, mu = 0.3, gravity.
SceneSpec pile(int n) {
  SceneSpec s;
  s.name = "pile";
  s.restitution = 0.5;
  s.friction = 0.3;
  s.gravity = Vec2(0.0, -9.81);
  const int columns = columnsFor(n), rows = (n + columns - 1) / columns;
  const double spacing = kPileSpacing * 2.0 * s.radius;
  s.width = columns * spacing + 0.2;
  s.height = rows * spacing + 2.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-kPileJitter, kPileJitter);
  for (int i = 0; i < n; ++i) {
    const Vec2 at(0.1 + spacing * (i % columns + 0.5) + jitter(rng),
                  0.2 + spacing * (i / columns + 0.5));
    s.balls.push_back({at, Vec2::Zero()});
  }
  return s;
}

// The pile without friction: every contact pushes along its normal only.
SceneSpec smooth(int n) {
  SceneSpec s = pile(n);
  s.name = "smooth";
  s.friction = 0.0;
  return s;
}

// The pile's N balls in heaps of eight side by side, each dropped as the pile is: small piles
// landing, as a game's are.
SceneSpec heaps(int n) {
  SceneSpec s = pile(n);
  s.name = "heaps";
  const double spacing = kPileSpacing * 2.0 * s.radius;
  const double heap_width = kHeapColumns * spacing + kHeapGap;
  const int heaps = (n + kHeapColumns * kHeapRows - 1) / (kHeapColumns * kHeapRows);
  s.width = heaps * heap_width;
  s.height = kHeapRows * spacing + 2.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-kPileJitter, kPileJitter);
  s.balls.clear();
  for (int i = 0; i < n; ++i) {
    const int heap = i / (kHeapColumns * kHeapRows), k = i % (kHeapColumns * kHeapRows);
    const Vec2 at(0.5 * kHeapGap + heap * heap_width + spacing * (k % kHeapColumns + 0.5) +
                      jitter(rng),
                  0.2 + spacing * (k / kHeapColumns + 0.5));
    s.balls.push_back({at, Vec2::Zero()});
  }
  return s;
}

// N balls two diameters apart, no gravity, e = 1, no friction, random velocities up to 3 m/s.
SceneSpec billiards(int n) {
  SceneSpec s;
  s.name = "billiards";
  const int columns = columnsFor(n);
  s.width = s.height = 2.0 * columns;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> speed(0.0, kBilliardsSpeed), angle(0.0, 2.0 * M_PI);
  for (int i = 0; i < n; ++i) {
    const double v = speed(rng), a = angle(rng);
    s.balls.push_back({Vec2(2.0 * (i % columns) + 1.0, 2.0 * (i / columns) + 1.0),
                       v * Vec2(std::cos(a), std::sin(a))});
  }
  return s;
}

// N balls of radius 0.1 at 400 m/s in a 10 m box, passing through each other (no ball/ball
// contact), e = 1.
SceneSpec bullets(int n) {
  SceneSpec s;
  s.name = "bullets";
  s.radius = 0.1;
  s.ball_contacts = false;
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> at(0.2, 9.8), angle(0.0, 2.0 * M_PI);
  for (int i = 0; i < n; ++i) {
    const double a = angle(rng);
    s.balls.push_back({Vec2(at(rng), at(rng)), kBulletSpeed * Vec2(std::cos(a), std::sin(a))});
  }
  return s;
}

// The scene of one of main's names, with N balls.
SceneSpec sceneNamed(const std::string& name, int n) {
  if (name == "smooth") return smooth(n);
  if (name == "heaps") return heaps(n);
  if (name == "billiards") return billiards(n);
  if (name == "bullets") return bullets(n);
  return pile(n);
}

std::vector<std::pair<Vec2, Vec2>> boxWalls(const SceneSpec& s) {
  const Vec2 a(0.0, 0.0), b(s.width, 0.0), c(s.width, s.height), d(0.0, s.height);
  return {{a, b}, {b, c}, {c, d}, {d, a}};
}

// One engine running one scene.
class Sim {
 public:
  virtual ~Sim() = default;
  virtual void step() = 0;
  virtual void read(std::vector<Vec2>& positions, std::vector<Vec2>& velocities) const = 0;
  virtual int awake() const = 0;  // balls not asleep
};

class OurSim : public Sim {
 public:
  explicit OurSim(const SceneSpec& s) : world_(s.gravity) {
    for (const auto& [from, to] : boxWalls(s)) {
      engine::Segment wall;
      wall.start = from;
      wall.end = to;
      // Restitutions multiply, frictions take the geometric mean: e and mu for every pair.
      wall.restitution = std::sqrt(s.restitution);
      wall.friction = s.friction;
      world_.addSegment(wall);
    }
    for (const BallStart& start : s.balls) {
      engine::Ball ball;
      ball.position = start.position;
      ball.velocity = start.velocity;
      ball.radius = s.radius;
      ball.mass = kMass;
      ball.restitution = std::sqrt(s.restitution);
      ball.friction = s.friction;
      if (!s.ball_contacts) ball.group = 1;  // one group passes through itself
      world_.addBall(ball);
    }
  }
  // The contacts are taken, as the node takes them to publish: left, they would pile up.
  void step() override {
    world_.step(kStep);
    world_.takeContacts();
  }
  void read(std::vector<Vec2>& positions, std::vector<Vec2>& velocities) const override {
    positions.clear();
    velocities.clear();
    for (const engine::Ball& ball : world_.balls()) {
      positions.push_back(ball.position);
      velocities.push_back(ball.velocity);
    }
  }
  int awake() const override {
    return static_cast<int>(std::count_if(world_.balls().begin(), world_.balls().end(),
                                          [](const engine::Ball& b) { return !b.at_rest; }));
  }

 private:
  engine::World world_;
};

class Box2DSim : public Sim {
 public:
  explicit Box2DSim(const SceneSpec& s) : world_(b2Vec2(s.gravity.x(), s.gravity.y())) {
    b2BodyDef ground_def;
    b2Body* ground = world_.CreateBody(&ground_def);
    for (const auto& [from, to] : boxWalls(s)) {
      b2EdgeShape edge;
      edge.SetTwoSided(b2Vec2(from.x(), from.y()), b2Vec2(to.x(), to.y()));
      b2FixtureDef fixture;
      fixture.shape = &edge;
      fixture.friction = s.friction;
      // Box2D takes the larger restitution and the geometric mean of frictions: e and mu for
      // every pair.
      fixture.restitution = s.restitution;
      ground->CreateFixture(&fixture);
    }
    b2CircleShape circle;
    circle.m_radius = s.radius;
    for (const BallStart& start : s.balls) {
      b2BodyDef def;
      def.type = b2_dynamicBody;
      def.position.Set(start.position.x(), start.position.y());
      def.linearVelocity.Set(start.velocity.x(), start.velocity.y());
      b2Body* body = world_.CreateBody(&def);
      b2FixtureDef fixture;
      fixture.shape = &circle;
      fixture.density = kMass / (M_PI * s.radius * s.radius);
      fixture.friction = s.friction;
      fixture.restitution = s.restitution;
      if (!s.ball_contacts) fixture.filter.groupIndex = -1;  // a negative group never collides
      body->CreateFixture(&fixture);
      bodies_.push_back(body);
    }
  }
  void step() override { world_.Step(kStep, kBox2DVelocityIterations, kBox2DPositionIterations); }
  void read(std::vector<Vec2>& positions, std::vector<Vec2>& velocities) const override {
    positions.clear();
    velocities.clear();
    for (const b2Body* body : bodies_) {
      positions.emplace_back(body->GetPosition().x, body->GetPosition().y);
      velocities.emplace_back(body->GetLinearVelocity().x, body->GetLinearVelocity().y);
    }
  }
  int awake() const override {
    return static_cast<int>(std::count_if(bodies_.begin(), bodies_.end(),
                                          [](const b2Body* body) { return body->IsAwake(); }));
  }

 private:
  b2World world_;
  std::vector<b2Body*> bodies_;
};

class ChipmunkSim : public Sim {
 public:
  explicit ChipmunkSim(const SceneSpec& s) : space_(cpSpaceNew()) {
    cpSpaceSetGravity(space_, cpv(s.gravity.x(), s.gravity.y()));
    for (const auto& [from, to] : boxWalls(s)) {
      cpShape* wall = cpSpaceAddShape(
          space_, cpSegmentShapeNew(cpSpaceGetStaticBody(space_), cpv(from.x(), from.y()),
                                    cpv(to.x(), to.y()), 0.0));
      // Chipmunk multiplies the two bodies' values: e and mu for every pair.
      cpShapeSetElasticity(wall, std::sqrt(s.restitution));
      cpShapeSetFriction(wall, std::sqrt(s.friction));
    }
    for (const BallStart& start : s.balls) {
      cpBody* body = cpSpaceAddBody(
          space_, cpBodyNew(kMass, cpMomentForCircle(kMass, 0.0, s.radius, cpvzero)));
      cpBodySetPosition(body, cpv(start.position.x(), start.position.y()));
      cpBodySetVelocity(body, cpv(start.velocity.x(), start.velocity.y()));
      cpShape* shape = cpSpaceAddShape(space_, cpCircleShapeNew(body, s.radius, cpvzero));
      cpShapeSetElasticity(shape, std::sqrt(s.restitution));
      cpShapeSetFriction(shape, std::sqrt(s.friction));
      // Shapes of one non-zero group never collide with each other.
      if (!s.ball_contacts)
        cpShapeSetFilter(shape, cpShapeFilterNew(1, CP_ALL_CATEGORIES, CP_ALL_CATEGORIES));
      bodies_.push_back(body);
    }
  }
  ~ChipmunkSim() override {
    cpSpaceEachShape(space_, [](cpShape* shape, void*) { cpShapeFree(shape); }, nullptr);
    cpSpaceEachBody(space_, [](cpBody* body, void*) { cpBodyFree(body); }, nullptr);
    cpSpaceFree(space_);
  }
  void step() override { cpSpaceStep(space_, kStep); }
  void read(std::vector<Vec2>& positions, std::vector<Vec2>& velocities) const override {
    positions.clear();
    velocities.clear();
    for (cpBody* body : bodies_) {
      const cpVect p = cpBodyGetPosition(body), v = cpBodyGetVelocity(body);
      positions.emplace_back(p.x, p.y);
      velocities.emplace_back(v.x, v.y);
    }
  }
  // (Chipmunk as shipped never puts a body to sleep: its sleep time threshold is infinite.)
  int awake() const override {
    return static_cast<int>(std::count_if(bodies_.begin(), bodies_.end(),
                                          [](cpBody* b) { return !cpBodyIsSleeping(b); }));
  }

 private:
  cpSpace* space_;
  std::vector<cpBody*> bodies_;
};

// Kinetic plus potential energy of unit-mass balls.
double energy(const SceneSpec& s, const std::vector<Vec2>& p, const std::vector<Vec2>& v) {
  double e = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    e += kMass * (0.5 * v[i].squaredNorm() - s.gravity.dot(p[i]));
  return e;
}

bool inBox(const SceneSpec& s, const Vec2& c) {
  return c.x() >= 0.0 && c.x() <= s.width && c.y() >= 0.0 && c.y() <= s.height;
}

// The deepest overlap, ball on ball (pairs from the engine's broad phase) or ball into a wall
// (of the balls still in the box: those out of it count as escaped).
double largestOverlap(const SceneSpec& s, const std::vector<Vec2>& p) {
  double deepest = 0.0;
  for (const Vec2& c : p) {
    if (!inBox(s, c)) continue;
    deepest = std::max({deepest, s.radius - c.x(), s.radius - c.y(), c.x() + s.radius - s.width,
                        c.y() + s.radius - s.height});
  }
  if (!s.ball_contacts) return deepest;
  std::vector<engine::Box> boxes;
  for (const Vec2& c : p) boxes.push_back(engine::ballBox(c, s.radius));
  engine::BoxGrid grid;
  grid.reset(boxes);
  for (const auto& [a, b] : grid.pairs())
    deepest = std::max(deepest, 2.0 * s.radius - (p[a] - p[b]).norm());
  return deepest;
}

int escaped(const SceneSpec& s, const std::vector<Vec2>& p) {
  return static_cast<int>(
      std::count_if(p.begin(), p.end(), [&](const Vec2& c) { return !inBox(s, c); }));
}

// Steps `sim` up to `most_steps` times, starting none after `budget` seconds of stepping, prints
// its row and returns the steps made.
int run(const std::string& engine_name, const SceneSpec& s, std::unique_ptr<Sim> sim,
        int most_steps, double budget) {
  std::vector<Vec2> p, v;
  sim->read(p, v);
  const double e0 = energy(s, p, v);
  double deepest = largestOverlap(s, p), stepping = 0.0;
  int steps = 0;
  while (steps < most_steps && stepping < budget) {
    const auto start = std::chrono::steady_clock::now();
    sim->step();
    stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++steps;
    sim->read(p, v);
    deepest = std::max(deepest, largestOverlap(s, p));
  }
  std::printf("| %-9s | %6zu | %-8s | %10.3f | %5d | %7d | %10.2e | %12.9f | %6d |\n",
              s.name.c_str(), s.balls.size(), engine_name.c_str(), 1e3 * stepping / steps, steps,
              escaped(s, p), deepest / s.radius, energy(s, p, v) / e0, sim->awake());
  std::fflush(stdout);
  return steps;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> scene_names = {"pile", "smooth", "heaps", "billiards",
                                                "bullets"};
  const std::vector<std::string> engine_names = {"ours", "Box2D", "Chipmunk"};
  const char* usage =
      "usage: bench_engines [N ...] [--budget seconds > 0] [--steps K > 0]\n"
      "                     [--scene pile|smooth|heaps|billiards|bullets ...]\n"
      "                     [--engine ours|Box2D|Chipmunk ...]\n";
  std::vector<int> sizes;
  std::vector<std::string> chosen, engines;
  double budget = 60.0;
  int most_steps = kSteps;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const std::string value = i + 1 < argc ? argv[i + 1] : "";
    if (arg == "--budget" && std::atof(value.c_str()) > 0.0) {
      budget = std::atof(value.c_str());
      ++i;
    } else if (arg == "--steps" && std::atoi(value.c_str()) > 0) {
      most_steps = std::atoi(value.c_str());
      ++i;
    } else if (arg == "--scene" && std::count(scene_names.begin(), scene_names.end(), value)) {
      chosen.push_back(value);
      ++i;
    } else if (arg == "--engine" &&
               std::count(engine_names.begin(), engine_names.end(), value)) {
      engines.push_back(value);
      ++i;
    } else if (arg == "--budget" || arg == "--steps" || arg == "--scene" || arg == "--engine") {
      std::fprintf(stderr, "bench_engines: bad value '%s' for %s\n%s", value.c_str(),
                   arg.c_str(), usage);
      return 2;
    } else if (std::atoi(arg.c_str()) > 0) {
      sizes.push_back(std::atoi(arg.c_str()));
    } else {
      std::fprintf(stderr, "bench_engines: bad argument '%s'\n%s", arg.c_str(), usage);
      return 2;
    }
  }
  if (chosen.empty()) chosen = scene_names;
  if (engines.empty()) engines = engine_names;
  const auto runs = [&](const std::string& engine) {
    return std::count(engines.begin(), engines.end(), engine) > 0;
  };
  if (sizes.empty()) sizes.push_back(1000);
  std::printf("| scene     |      N | engine   |    ms/step | steps | escaped |  overlap/r |"
              "   E_end/E_0  |  awake |\n");
  std::printf("|-----------|--------|----------|------------|-------|---------|------------|"
              "--------------|--------|\n");
  for (const int n : sizes) {
    for (const std::string& name : scene_names) {
      if (!std::count(chosen.begin(), chosen.end(), name)) continue;
      const SceneSpec s = sceneNamed(name, n);
      // The peers make no more steps than ours did, so that a scene's rows cover the same sim
      // time unless a peer's budget ran out first.
      int steps = most_steps;
      if (runs("ours")) steps = run("ours", s, std::make_unique<OurSim>(s), most_steps, budget);
      if (runs("Box2D")) run("Box2D", s, std::make_unique<Box2DSim>(s), steps, budget);
      if (runs("Chipmunk")) run("Chipmunk", s, std::make_unique<ChipmunkSim>(s), steps, budget);
    }
  }
}
