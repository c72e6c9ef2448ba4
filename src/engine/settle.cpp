#include "ball_physics_sim/engine/settle.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include <Eigen/SparseCholesky>

#include "ball_physics_sim/engine/resting_contact.h"

namespace ball_physics_sim::engine {

namespace {

// A contact as the sweeps use it, its hot loop's data only (a settle's rows fit a fast cache):
// its bodies' numbers (a segment is the still body numbered after the balls), its normal
// (the tangent is perpendicular to it), and per impulse the share of its own rate a unit of it
// takes away (its effective mass) and the impulse so far.
struct Row {
  std::uint32_t a = 0, b = 0;
  double normal_x = 0.0, normal_y = 0.0;
  double bias = 0.0, friction = 0.0;
  double normal_mass = 0.0, friction_mass = 0.0;
  double normal_impulse = 0.0, friction_impulse = 0.0;
};

// Added to the diagonal of the pushing contacts' equations (pushTogether), as a share of each
// contact's own term: first next to nothing, exact; then enough to keep the pushes in bounds
// where redundant contacts (a ball on three in a packed pile) have biases that disagree, which
// make the exact equations unsolvable (a tall column then falls a little short).
constexpr double kExactRegularization = 1e-10;
constexpr double kRedundantRegularization = 1e-2;
// Pushes that grow past this many times the sweeps' largest have run away: pushes of
// redundant contacts that cancel each other out.
constexpr double kRunawayPushes = 1e3;

// The sweeps work on rows side by side (see Block), so a row waits for the rows just before it
// that changed one of its balls: a sweep puts a row off while it shares a ball with one of the
// kIndependentRows - 1 rows before it (at most kMostPutOff rows put off at once; the oldest
// goes when they are). Rows after it go ahead, a few sharing a ball with it too, so the order
// is near the one given, not it, and mostly keeps its effect (a push passes bottom-up through a
// pile in a sweep). Then four rows side by side share no ball, and seldom one with the four
// before (which they would wait for); rows kept farther apart take the order farther from the
// one given, and piles land with deeper overlaps.
constexpr std::size_t kIndependentRows = 6;
constexpr std::size_t kMostPutOff = 16;

// A contact without a push (nor friction: pushTogether may leave some where it took the push
// away) whose gap opens by more than this over the stretch, as a share of the smaller radius,
// is left out of a round's sweeps: it would take none in them (a round rarely pushes its balls
// together that much), and the round's end checks it with the others. A churned pile's settles
// end with a third of their contacts opening without a push (pairs near, not touching).
constexpr double kUnsweptOpening = 1e-2;

// A body as the sweeps change it: its velocity and spin, and its inverse mass (what a unit
// impulse does to its velocity); and, apart, what only a block copies (see blocksOf): how a unit
// impulse at its surface turns it, and its radius. (A segment's still slot, and the spare of a
// block's empty lane: nothing.) Kept small and aligned, a body is half a cache line, and the
// sweeps' gathers and scatters of velocities touch fewer lines.
struct alignas(32) Body {
  double vx = 0.0, vy = 0.0, w = 0.0;
  double inverse_mass = 0.0;
};
struct Surface {
  double turn = 0.0;  // a unit impulse at its surface turns it by 1 / (k m r) (I = k m r^2)
  double radius = 0.0;
};
struct Bodies {
  std::vector<Body> moving;
  std::vector<Surface> surfaces;
  // `count` bodies, all still and of no size (nothing).
  void reset(std::size_t count) {
    moving.assign(count, Body{});
    surfaces.assign(count, Surface{});
  }
  Body& operator[](std::size_t i) { return moving[i]; }
  const Body& operator[](std::size_t i) const { return moving[i]; }
  std::size_t size() const { return moving.size(); }
};

// A row's rates and impulses, for one row (T a double: the checks and the direct solve) or rows
// side by side (a Wide: the sweeps; passed by reference, as a function built without AVX cannot
// pass a register of four): the opening rate past the bias, from the relative velocity (dvx,
// dvy) along the normal (nx, ny); the slip (see slipSpeed; a segment's surface is still), from
// that and the spins w; and an impulse's parts in the plane, from its parts along the normal
// and along the tangent.
template <typename T>
inline void openingRate(const T& nx, const T& ny, const T& dvx, const T& dvy, const T& bias,
                        T& rate) {
  rate = nx * dvx + ny * dvy + bias;
}
template <typename T>
inline void slipRate(const T& nx, const T& ny, const T& dvx, const T& dvy, const T& a_radius,
                     const T& a_w, const T& b_radius, const T& b_w, T& rate) {
  rate = -ny * dvx + nx * dvy - a_radius * a_w - b_radius * b_w;
}
template <typename T>
inline void inPlane(const T& normal, const T& friction, const T& nx, const T& ny, T& x, T& y) {
  x = normal * nx - friction * ny;
  y = normal * ny + friction * nx;
}

inline void push(const Row& row, double normal, double friction, Bodies& bodies) {
  double x, y;
  inPlane(normal, friction, row.normal_x, row.normal_y, x, y);
  Body& a = bodies[row.a];
  a.vx += a.inverse_mass * x;
  a.vy += a.inverse_mass * y;
  a.w -= bodies.surfaces[row.a].turn * friction;
  Body& b = bodies[row.b];
  b.vx -= b.inverse_mass * x;
  b.vy -= b.inverse_mass * y;
  b.w -= bodies.surfaces[row.b].turn * friction;
}

inline double opening(const Row& row, const Bodies& bodies) {
  const Body& a = bodies[row.a];
  const Body& b = bodies[row.b];
  double rate;
  openingRate(row.normal_x, row.normal_y, a.vx - b.vx, a.vy - b.vy, row.bias, rate);
  return rate;
}

// Doubles side by side in one register: two with SSE2 (every x86-64 has it), four with AVX2.
// Rows that share no ball are swept with the instructions of one (the benchmark's 1,000-ball
// pile: 5.5 ns a row four at a time, 7.2 two at a time). Elsewhere two doubles are what the
// compiler makes of them.
template <int kLanes>
struct WideOf;
template <>
struct WideOf<2> {
  using type = double __attribute__((vector_size(16)));
};
template <>
struct WideOf<4> {
  using type = double __attribute__((vector_size(32)));
};
template <int kLanes>
using Wide = typename WideOf<kLanes>::type;
using Pair = Wide<2>;

// Rows side by side, for the sweeps: each lane one row, with what a unit impulse does to its
// bodies (a lane without one is all 0, and points at the spare body). What a sweep without
// friction reads comes first, in the block's first half, and the friction's after it.
// (Aligned to a register's width: a build without AVX aligns four doubles only to two.)
template <int kLanes>
struct alignas(sizeof(Wide<kLanes>)) Block {
  using W = Wide<kLanes>;
  std::uint32_t a[kLanes], b[kLanes];
  W normal_x, normal_y, bias, normal_mass, normal_impulse, a_inverse_mass, b_inverse_mass;
  W friction, friction_mass, friction_impulse, a_turn, b_turn, a_radius, b_radius;
  std::uint32_t rows[kLanes];  // the lanes' rows' numbers, or kNoRow
};
constexpr std::uint32_t kNoRow = std::numeric_limits<std::uint32_t>::max();

// A body's velocity (vx and vy, one after the other), read and written whole: a read of half of
// what was written whole waits for the write to reach the cache.
inline Pair velocityOf(const Body& body) {
  Pair v;
  std::memcpy(&v, &body.vx, sizeof v);
  return v;
}
inline void setVelocity(Body& body, Pair v) { std::memcpy(&body.vx, &v, sizeof v); }

// Whether two rows share a ball (the still body they may share: it does not move).
bool shareBall(const Row& r, const Row& s, std::uint32_t still) {
  return r.a == s.a || r.a == s.b || (r.b != still && (r.b == s.a || r.b == s.b));
}

// The rows numbered `swept`, kLanes by kLanes in their order: a block ends early at a row that
// would share a ball with one in it. `still` is the segments' body, the spare the one after it.
template <int kLanes>
void blocksOf(const std::vector<Row>& rows, const std::vector<std::uint32_t>& swept,
              std::uint32_t still, const Bodies& bodies, std::vector<Block<kLanes>>& blocks) {
  const std::uint32_t spare = still + 1;
  blocks.clear();  // (kept from round to round: taken afresh, its pages would fault)
  const auto fill = [&](Block<kLanes>& block, int lane, std::uint32_t j) {
    const Row& row = rows[j];
    const Body& a = bodies[row.a];
    const Body& b = bodies[row.b];
    block.rows[lane] = j;
    block.a[lane] = row.a;
    block.b[lane] = row.b;
    block.normal_x[lane] = row.normal_x;
    block.normal_y[lane] = row.normal_y;
    block.bias[lane] = row.bias;
    block.friction[lane] = row.friction;
    block.normal_mass[lane] = row.normal_mass;
    block.friction_mass[lane] = row.friction_mass;
    block.normal_impulse[lane] = row.normal_impulse;
    block.friction_impulse[lane] = row.friction_impulse;
    block.a_inverse_mass[lane] = a.inverse_mass;
    block.b_inverse_mass[lane] = b.inverse_mass;
    block.a_turn[lane] = bodies.surfaces[row.a].turn;
    block.b_turn[lane] = bodies.surfaces[row.b].turn;
    block.a_radius[lane] = bodies.surfaces[row.a].radius;
    block.b_radius[lane] = bodies.surfaces[row.b].radius;
  };
  const auto apart = [&](const Block<kLanes>& block, int lanes, const Row& row) {
    for (int lane = 0; lane < lanes; ++lane)
      if (shareBall(rows[block.rows[lane]], row, still)) return false;
    return true;
  };
  for (std::size_t i = 0; i < swept.size();) {
    Block<kLanes>& block = blocks.emplace_back();  // (all 0)
    int lanes = 0;
    for (; lanes < kLanes && i < swept.size() && apart(block, lanes, rows[swept[i]]); ++i)
      fill(block, lanes++, swept[i]);
    for (; lanes < kLanes; ++lanes) {
      block.rows[lanes] = kNoRow;
      block.a[lanes] = block.b[lanes] = spare;
    }
  }
}

// Where a block's impulses head over the sweeps (the conjugate direction), and how the last
// sweep changed them: the normal's first, apart from the friction's, which a sweep without
// friction leaves as they are (0).
template <int kLanes>
struct alignas(sizeof(Wide<kLanes>)) Heading {
  Wide<kLanes> normal, normal_change;
  Wide<kLanes> friction, friction_change;
};

// One projected Gauss-Seidel sweep, kLanes rows at a time: each row's normal push, then, if
// `kRough`, its friction within Coulomb's cone (a push along the normal leaves the slip as it
// was). Where no row swept has friction, or friction is held (not `kRough`), friction is left
// out: its impulses and the spins stay as they are (a smooth pile's impulses 0), and the sweep
// reads and writes a third less. Each heading keeps its block's change, and the squares of the
// changes are returned, summed row by row in the sweep's order: the same however many lanes a
// block has. (As std::max and std::clamp choose, lane by lane.)
template <int kLanes, bool kRough>
[[gnu::always_inline]] inline double sweep(std::vector<Block<kLanes>>& blocks,
                                           std::vector<Heading<kLanes>>& headings,
                                           Bodies& bodies) {
  using W = Wide<kLanes>;
  const W zero{};
  double squares = 0.0;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    Block<kLanes>& block = blocks[k];
    W avx, avy, aw{}, bvx, bvy, bw{};
    for (int lane = 0; lane < kLanes; ++lane) {
      const Body& a = bodies[block.a[lane]];
      const Body& b = bodies[block.b[lane]];
      const Pair va = velocityOf(a), vb = velocityOf(b);
      avx[lane] = va[0];
      avy[lane] = va[1];
      bvx[lane] = vb[0];
      bvy[lane] = vb[1];
      if constexpr (kRough) {
        aw[lane] = a.w;
        bw[lane] = b.w;
      }
    }
    const W dvx = avx - bvx, dvy = avy - bvy;
    W opening_rate;
    openingRate(block.normal_x, block.normal_y, dvx, dvy, block.bias, opening_rate);
    const W wanted = block.normal_impulse - opening_rate * block.normal_mass;
    const W pushed = zero < wanted ? wanted : zero;
    const W normal = pushed - block.normal_impulse;
    W friction = zero, x, y;
    if constexpr (kRough) {
      W slip_rate;
      slipRate(block.normal_x, block.normal_y, dvx, dvy, block.a_radius, aw, block.b_radius, bw,
               slip_rate);
      const W limit = block.friction * pushed;
      const W unclamped = block.friction_impulse - slip_rate * block.friction_mass;
      const W gripped = unclamped < -limit ? -limit : (limit < unclamped ? limit : unclamped);
      friction = gripped - block.friction_impulse;
      block.friction_impulse = gripped;
      inPlane(normal, friction, block.normal_x, block.normal_y, x, y);
    } else {
      x = normal * block.normal_x;
      y = normal * block.normal_y;
    }
    const W new_avx = avx + block.a_inverse_mass * x, new_avy = avy + block.a_inverse_mass * y;
    const W new_bvx = bvx - block.b_inverse_mass * x, new_bvy = bvy - block.b_inverse_mass * y;
    // (Spins change only with friction: without, these are not used.)
    const W new_aw = aw - block.a_turn * friction, new_bw = bw - block.b_turn * friction;
    for (int lane = 0; lane < kLanes; ++lane) {
      Body& a = bodies[block.a[lane]];
      Body& b = bodies[block.b[lane]];
      setVelocity(a, Pair{new_avx[lane], new_avy[lane]});
      setVelocity(b, Pair{new_bvx[lane], new_bvy[lane]});
      if constexpr (kRough) {
        a.w = new_aw[lane];
        b.w = new_bw[lane];
      }
    }
    block.normal_impulse = pushed;
    headings[k].normal_change = normal;
    // (Without friction its change is 0, as its heading stays: its square adds nothing.)
    if constexpr (kRough) headings[k].friction_change = friction;
    for (int lane = 0; lane < kLanes; ++lane)
      squares += kRough ? normal[lane] * normal[lane] + friction[lane] * friction[lane]
                        : normal[lane] * normal[lane];
  }
  return squares;
}

// A body's velocity and spin, or a change of them; without friction (not `kRough`: see sweep)
// its velocity alone, a third less to read and write.
template <bool kRough>
struct Rates {
  double vx = 0.0, vy = 0.0, w = 0.0;
};
template <>
struct Rates<false> {
  double vx = 0.0, vy = 0.0;
};

// The bodies' rates.
template <bool kRough>
void ratesOf(const Bodies& bodies, std::vector<Rates<kRough>>& rates) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    rates[i].vx = bodies[i].vx;
    rates[i].vy = bodies[i].vy;
    if constexpr (kRough) rates[i].w = bodies[i].w;
  }
}

// A body's change since it was `before`.
template <bool kRough>
Rates<kRough> changeOf(const Body& body, const Rates<kRough>& before) {
  Rates<kRough> change;
  change.vx = body.vx - before.vx;
  change.vy = body.vy - before.vy;
  if constexpr (kRough) change.w = body.w - before.w;
  return change;
}

// The sweeps' blocks of rows kLanes wide, and their headings (see sweepSideBySide).
template <int kLanes>
struct LaneScratch {
  std::vector<Block<kLanes>> blocks;
  std::vector<Heading<kLanes>> headings;
};

// The bodies' rates before a sweep, and where they head (see goOn).
template <bool kRough>
struct RateScratch {
  std::vector<Rates<kRough>> before, motions;
};

}  // namespace

// A settle's rows (with the rate past which each is swept on: see settleTogether) and bodies,
// the rows a round sweeps, and the sweeps' working copies, two or four lanes wide, with friction
// or without.
struct SettleScratch::Storage {
  std::vector<Row> rows;
  std::vector<double> least;
  Bodies bodies;
  std::vector<std::uint32_t> swept;
  LaneScratch<2> two;
  LaneScratch<4> four;
  RateScratch<true> rough;
  RateScratch<false> smooth;

  template <int kLanes>
  LaneScratch<kLanes>& lanes() {
    if constexpr (kLanes == 2)
      return two;
    else
      return four;
  }
  template <bool kRough>
  RateScratch<kRough>& rates() {
    if constexpr (kRough)
      return rough;
    else
      return smooth;
  }
};

SettleScratch::SettleScratch() = default;
SettleScratch::SettleScratch(const SettleScratch&) {}
SettleScratch& SettleScratch::operator=(const SettleScratch&) { return *this; }
SettleScratch::SettleScratch(SettleScratch&&) noexcept = default;
SettleScratch& SettleScratch::operator=(SettleScratch&&) noexcept = default;
SettleScratch::~SettleScratch() = default;

SettleScratch::Storage& SettleScratch::storage() {
  if (!storage_) storage_ = std::make_unique<Storage>();
  return *storage_;
}

namespace {

using Scratch = SettleScratch::Storage;

// Each block's impulses go on `share` of the way they head, and the heading takes in the last
// sweep's change (without friction, if not `kRough`: see sweep). Each body goes on as its
// contacts' impulses do: what the heading does to it is kept body by body (`motions`: `share` of
// the last, plus the body's change over the last sweep, from where it was `before` it), so that
// each body moves once, rather than once for each of its contacts (one that does not move
// keeps a heading of 0).
template <int kLanes, bool kRough>
[[gnu::always_inline]] inline void goOn(double share, std::vector<Block<kLanes>>& blocks,
                                        std::vector<Heading<kLanes>>& headings,
                                        const std::vector<Rates<kRough>>& before,
                                        std::vector<Rates<kRough>>& motions, Bodies& bodies) {
  using W = Wide<kLanes>;
  const W by = W{} + share;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    Block<kLanes>& block = blocks[k];
    Heading<kLanes>& heading = headings[k];
    const W normal = by * heading.normal;
    block.normal_impulse += normal;
    heading.normal = normal + heading.normal_change;
    if constexpr (kRough) {
      const W friction = by * heading.friction;
      block.friction_impulse += friction;
      heading.friction = friction + heading.friction_change;
    }
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    Body& body = bodies[i];
    Rates<kRough>& motion = motions[i];
    const Rates<kRough> change = changeOf(body, before[i]);
    const double on_x = share * motion.vx, on_y = share * motion.vy;
    motion.vx = on_x + change.vx;
    motion.vy = on_y + change.vy;
    body.vx += on_x;
    body.vy += on_y;
    if constexpr (kRough) {
      const double on_w = share * motion.w;
      motion.w = on_w + change.w;
      body.w += on_w;
    }
  }
}

// `sweeps` sweeps of the rows that `scratch.swept` numbers (see blocksOf), kLanes at a time.
// Between two, the impulses go on the way the sweeps before took them, by the share that the
// last sweep's change is of the one before (Silcowitz, Niebe and Erleben's nonsmooth nonlinear
// conjugate gradient, 2010), and head afresh where the change grew: a push passes through a
// pile's chains of contacts in fewer sweeps. The last is a sweep's change, within its bounds.
// Returns how many it took: none after one that changes nothing.
// (Built into its callers, so that a caller built for AVX2 has it built so too.)
template <int kLanes, bool kRough>
[[gnu::always_inline]] inline int sweepSideBySide(Scratch& scratch, std::uint32_t still,
                                                  int sweeps) {
  std::vector<Row>& rows = scratch.rows;
  Bodies& bodies = scratch.bodies;
  std::vector<Block<kLanes>>& blocks = scratch.lanes<kLanes>().blocks;
  blocksOf<kLanes>(rows, scratch.swept, still, bodies, blocks);
  std::vector<Heading<kLanes>>& headings = scratch.lanes<kLanes>().headings;
  headings.assign(blocks.size(), Heading<kLanes>{});
  std::vector<Rates<kRough>>& before = scratch.rates<kRough>().before;
  std::vector<Rates<kRough>>& motions = scratch.rates<kRough>().motions;
  before.assign(bodies.size(), Rates<kRough>{});
  motions.assign(bodies.size(), Rates<kRough>{});
  double last_change = 0.0;
  int k = 0;
  while (k < sweeps) {
    if (k + 1 < sweeps) ratesOf<kRough>(bodies, before);  // (the last heads nowhere)
    const double change = sweep<kLanes, kRough>(blocks, headings, bodies);
    ++k;
    if (change == 0.0) break;  // (and so would every sweep after it)
    const bool heads_on = last_change > 0.0 && change <= last_change;
    const double share = heads_on ? change / last_change : 0.0;
    last_change = change;
    if (k == sweeps) break;
    if (heads_on) {
      goOn<kLanes, kRough>(share, blocks, headings, before, motions, bodies);
      continue;
    }
    // (The first sweep's change is where the impulses head; a change that grew heads nowhere.)
    for (Heading<kLanes>& heading : headings) {
      heading.normal = k == 1 ? heading.normal_change : Wide<kLanes>{};
      if constexpr (kRough) heading.friction = k == 1 ? heading.friction_change : Wide<kLanes>{};
    }
    for (std::size_t i = 0; i < bodies.size(); ++i)
      motions[i] = k == 1 ? changeOf(bodies[i], before[i]) : Rates<kRough>{};
  }
  for (const Block<kLanes>& block : blocks)
    for (int lane = 0; lane < kLanes; ++lane)
      if (block.rows[lane] != kNoRow) {
        rows[block.rows[lane]].normal_impulse = block.normal_impulse[lane];
        rows[block.rows[lane]].friction_impulse = block.friction_impulse[lane];
      }
  return k;
}

// With friction or without (see sweep), kLanes at a time.
template <int kLanes>
[[gnu::always_inline]] inline int sweepRoughOrSmooth(Scratch& scratch, std::uint32_t still,
                                                     int sweeps, bool rough) {
  return rough ? sweepSideBySide<kLanes, true>(scratch, still, sweeps)
               : sweepSideBySide<kLanes, false>(scratch, still, sweeps);
}

#if defined(__x86_64__)
__attribute__((target("avx2"))) int sweepFourAtATime(Scratch& scratch, std::uint32_t still,
                                                     int sweeps, bool rough) {
  return sweepRoughOrSmooth<4>(scratch, still, sweeps, rough);
}
#endif

// Four at a time where the processor has AVX2 and `lanes` allows, else two: the same results
// for finite rates, rows apart being swept in the same order either way (the engine is built
// without fused multiply-adds). Friction is swept where any row swept has some, unless
// `friction_held` (it stays as it is). Returns how many sweeps it took.
int sweepRows(Scratch& scratch, std::uint32_t still, int sweeps, [[maybe_unused]] SweepLanes lanes,
              bool friction_held) {
  const std::vector<std::uint32_t>& swept = scratch.swept;
  const bool rough = !friction_held &&
                     std::any_of(swept.begin(), swept.end(),
                                 [&](std::uint32_t j) { return scratch.rows[j].friction > 0.0; });
#if defined(__x86_64__)
  if (lanes == SweepLanes::kMost && sweepsFourAtATime())
    return sweepFourAtATime(scratch, still, sweeps, rough);
#endif
  return sweepRoughOrSmooth<2>(scratch, still, sweeps, rough);
}

// The order of the sweeps: `contacts` in the order given, each put off (see kIndependentRows)
// while it shares a ball with one of the few before it, later ones going ahead.
std::vector<std::size_t> sweepOrder(const std::vector<RestingContact>& contacts,
                                    std::size_t balls) {
  std::vector<std::size_t> order;
  order.reserve(contacts.size());
  // Where each ball's last row is in the order, and the rows put off, oldest first.
  std::vector<std::size_t> last(balls, std::numeric_limits<std::size_t>::max());
  std::vector<std::size_t> put_off;
  const auto apart = [&](std::size_t ball) {
    return last[ball] == std::numeric_limits<std::size_t>::max() ||
           last[ball] + kIndependentRows <= order.size();
  };
  const auto ready = [&](std::size_t k) {
    return apart(contacts[k].ball) && (!contacts[k].other || apart(*contacts[k].other));
  };
  std::size_t next = 0;
  while (order.size() < contacts.size()) {
    // The oldest row put off that is apart now, else the next in line, putting off those that
    // are not; where none is, the oldest put off goes.
    auto taken = std::find_if(put_off.begin(), put_off.end(), ready);
    if (taken == put_off.end()) {
      while (next < contacts.size() && put_off.size() < kMostPutOff && !ready(next))
        put_off.push_back(next++);
      taken = next < contacts.size() && put_off.size() < kMostPutOff
                  ? put_off.insert(put_off.end(), next++)
                  : put_off.begin();
    }
    const std::size_t k = *taken;
    put_off.erase(taken);
    last[contacts[k].ball] = order.size();
    if (contacts[k].other) last[*contacts[k].other] = order.size();
    order.push_back(k);
  }
  return order;
}

// A round of kSettleSweeps sweeps over the rows that may push (see kUnsweptOpening), in their
// order: not one that cannot move its bodies (its own term is 0). `still` is the segments' body;
// `friction_held`: see sweepRows. Returns how many sweeps it took.
int sweepRound(Scratch& scratch, std::uint32_t still, SweepLanes lanes, bool friction_held) {
  const std::vector<Row>& rows = scratch.rows;
  std::vector<std::uint32_t>& swept = scratch.swept;
  swept.clear();
  for (std::uint32_t j = 0; j < rows.size(); ++j)
    // (least is -kSettleOverlap of the smaller radius over the stretch.)
    if (rows[j].normal_mass > 0.0 &&
        (rows[j].normal_impulse > 0.0 || rows[j].friction_impulse != 0.0 ||
         opening(rows[j], scratch.bodies) <= -kUnsweptOpening / kSettleOverlap * scratch.least[j]))
      swept.push_back(j);
  if (swept.empty()) return 0;
  return sweepRows(scratch, still, kSettleSweeps, lanes, friction_held);
}

// How far past its least opening (`least`, per row) the worst contact closes (0 if none does;
// infinite if a rate is not a number).
double worstClosing(const std::vector<Row>& rows, const std::vector<double>& least,
                    const Bodies& bodies) {
  double worst = 0.0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double past = least[k] - opening(rows[k], bodies);
    if (!(past <= worst)) worst = std::isnan(past) ? std::numeric_limits<double>::infinity() : past;
  }
  return worst;
}

// Whether the contacts `pushing` outnumber the ways their balls can move (two each, in the
// plane): then some are redundant.
bool surelyRedundant(const std::vector<Row>& rows, const std::vector<std::size_t>& pushing,
                     const Bodies& bodies) {
  std::vector<bool> moved(bodies.size(), false);
  for (const std::size_t k : pushing) {
    if (bodies[rows[k].a].inverse_mass > 0.0) moved[rows[k].a] = true;
    if (bodies[rows[k].b].inverse_mass > 0.0) moved[rows[k].b] = true;
  }
  const auto balls = static_cast<std::size_t>(std::count(moved.begin(), moved.end(), true));
  return pushing.size() > 2 * balls;
}

// The contacts that push, their pushes found together so that each closes at just its bias
// (friction held as it is), directly: sweeps pass a change of load through a pile a ball a sweep,
// and a landing pile's load changes from top to bottom. Where pushes would turn to pulls they
// stop at none, and the sweeps go on from there. Kept if the worst gap closes no worse and no
// push runs away; friction past its cone with a push made smaller waits for the next sweep with
// friction (where friction is held, or after the last round, for the next settle's start, which
// clamps it).
void pushTogether(const std::vector<RestingContact>& contacts,
                  const std::vector<std::size_t>& order,
                  const std::vector<double>& inverse_masses, const std::vector<double>& least,
                  std::vector<Row>& rows, Bodies& bodies) {
  std::vector<std::size_t> pushing, pushing_contacts;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k].normal_impulse > 0.0 && rows[k].normal_mass > 0.0) {
      pushing.push_back(k);
      pushing_contacts.push_back(order[k]);
    }
  if (pushing.empty()) return;
  const std::vector<Eigen::Triplet<double>> entries =
      openingPerPush(contacts, inverse_masses, pushing_contacts);
  const int m = static_cast<int>(pushing.size());
  // (Every contact's own term is an entry: the diagonal added keeps the pattern.)
  Eigen::SparseMatrix<double> equations(m, m), own(m, m);
  equations.setFromTriplets(entries.begin(), entries.end());
  own = equations.diagonal().asDiagonal();
  Eigen::VectorXd closing(m);
  for (int c = 0; c < m; ++c) closing[c] = -opening(rows[pushing[c]], bodies);
  const double before = worstClosing(rows, least, bodies);
  const Bodies kept = bodies;
  std::vector<double> kept_pushes(m);
  for (int c = 0; c < m; ++c) kept_pushes[c] = rows[pushing[c]].normal_impulse;
  const double largest = *std::max_element(kept_pushes.begin(), kept_pushes.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factors;
  factors.analyzePattern(equations);  // (the order that keeps the factors sparse, found once)
  auto solved = [&](double regularization) {
    factors.factorize(equations + regularization * own);
    if (factors.info() != Eigen::Success) return false;
    const Eigen::VectorXd change = factors.solve(closing);
    for (int c = 0; c < m; ++c) {
      Row& row = rows[pushing[c]];
      const double pushed = std::max(0.0, kept_pushes[c] + change[c]);
      push(row, pushed - row.normal_impulse, 0.0, bodies);
      row.normal_impulse = pushed;
    }
    if (change.allFinite() && change.maxCoeff() <= kRunawayPushes * largest &&
        worstClosing(rows, least, bodies) <= before)
      return true;
    bodies = kept;
    for (int c = 0; c < m; ++c) rows[pushing[c]].normal_impulse = kept_pushes[c];
    return false;
  };
  // Redundant, the exact equations are not worth a try.
  if (!surelyRedundant(rows, pushing, bodies) && solved(kExactRegularization)) return;
  solved(kRedundantRegularization);
}

}  // namespace

bool sweepsFourAtATime() {
#if defined(__x86_64__)
  static const bool four = __builtin_cpu_supports("avx2");
  return four;
#else
  return false;
#endif
}

Settled settleTogether(const std::vector<Ball>& balls, const std::vector<double>& inverse_masses,
                       const std::vector<RestingContact>& contacts,
                       const std::vector<double>& frictions, double duration,
                       std::vector<std::array<double, 2>>* impulses, SweepLanes lanes,
                       SettleScratch* scratch, int rounds) {
  std::optional<SettleScratch> own;
  Scratch& work = (scratch ? *scratch : own.emplace()).storage();
  const std::size_t still = balls.size();  // a segment's number
  Bodies& bodies = work.bodies;
  bodies.reset(still + 2);  // (the balls, a segment's, and a spare for the sweeps)
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Ball& ball = balls[i];
    Body& body = bodies[i];
    body.vx = ball.velocity.x();
    body.vy = ball.velocity.y();
    body.w = ball.angular_velocity;
    body.inverse_mass = inverse_masses[i];
    bodies.surfaces[i] = {body.inverse_mass / (ball.inertia_factor * ball.radius), ball.radius};
  }
  // What a unit impulse at a ball's surface changes of a contact's rates: along the normal, its
  // inverse mass; across it, that and the turn, r / I = 1 / (k m r) times r.
  const auto perNormal = [&](std::size_t i) { return bodies[i].inverse_mass; };
  const auto perFriction = [&](std::size_t i) {
    return bodies[i].inverse_mass * (1.0 + 1.0 / balls[i].inertia_factor);
  };
  // Row j is contact order[j].
  const std::vector<std::size_t> order = sweepOrder(contacts, balls.size());
  std::vector<Row>& rows = work.rows;
  rows.assign(contacts.size(), Row{});
  std::vector<double>& least = work.least;  // the rate past which the sweeps go on
  least.assign(contacts.size(), 0.0);
  for (std::size_t j = 0; j < rows.size(); ++j) {
    const std::size_t k = order[j];
    const RestingContact& c = contacts[k];
    Row& row = rows[j];
    row.a = static_cast<std::uint32_t>(c.ball);
    row.b = static_cast<std::uint32_t>(c.other.value_or(still));
    row.normal_x = c.normal.x();
    row.normal_y = c.normal.y();
    double per_normal = perNormal(c.ball), per_friction = perFriction(c.ball);
    double smaller = balls[c.ball].radius;
    if (c.other) {
      per_normal += perNormal(*c.other);
      per_friction += perFriction(*c.other);
      smaller = std::min(smaller, balls[*c.other].radius);
    }
    row.bias = c.bias;
    row.friction = frictions[k];
    if (per_normal > 0.0) {
      row.normal_mass = 1.0 / per_normal;
      row.friction_mass = 1.0 / per_friction;
    }
    least[j] = -kSettleOverlap * smaller / duration;
  }
  // The impulses given start the sweeps.
  if (impulses && impulses->size() == contacts.size())
    for (std::size_t j = 0; j < rows.size(); ++j) {
      Row& row = rows[j];
      const std::array<double, 2>& given = (*impulses)[order[j]];
      row.normal_impulse = given[0];
      const double limit = row.friction * row.normal_impulse;
      row.friction_impulse = std::clamp(given[1], -limit, limit);
      push(row, row.normal_impulse, row.friction_impulse, bodies);
    }
  // Rounds of sweeps until no gap closes past its bias by more than kSettleOverlap of the
  // smaller radius over the stretch, or the rounds run out: the next settle's bias opens what
  // they leave. Rounds that have not converged by the last have a load the sweeps pass too
  // slowly (a tall column, a deep pile landing): the pushing contacts are solved together, and
  // again after the last round, from the pushes the sweeps since have found (they may have
  // changed which contacts push). Sweeps with friction may cycle (Coulomb's law is no
  // gradient's), a few contacts closing too fast round after round: once a round brings the
  // worst gap no nearer its bias, friction is held as it is, and the pushes alone converge.
  Settled s;
  bool friction_held = false;
  double worst = std::numeric_limits<double>::infinity();
  for (int round = 0; round < rounds; ++round) {
    s.sweeps += sweepRound(work, static_cast<std::uint32_t>(still), lanes, friction_held);
    const double last_worst = std::exchange(worst, worstClosing(rows, least, bodies));
    s.converged = worst == 0.0;
    if (s.converged) break;
    friction_held = friction_held || worst >= last_worst;
    if (round + 2 >= rounds)
      pushTogether(contacts, order, inverse_masses, least, rows, bodies);
  }
  if (impulses) impulses->resize(rows.size());
  s.velocities.reserve(balls.size());
  s.spins.reserve(balls.size());
  for (std::size_t i = 0; i < balls.size(); ++i) {
    s.velocities.emplace_back(bodies[i].vx, bodies[i].vy);
    s.spins.push_back(bodies[i].w);
  }
  s.pushes.resize(rows.size());
  for (std::size_t j = 0; j < rows.size(); ++j) {
    s.pushes[order[j]] = rows[j].normal_impulse;
    if (impulses) (*impulses)[order[j]] = {rows[j].normal_impulse, rows[j].friction_impulse};
  }
  return s;
}

double settleBias(double gap, double duration, bool open) {
  if (gap >= 0.0 || !open) return std::max(gap, 0.0) / duration;
  return -std::min(kOverlapRecovery * -gap / duration, kMostOpeningSpeed);
}

}  // namespace ball_physics_sim::engine
