#include "ball_physics_sim/engine/resting_contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <utility>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "ball_physics_sim/engine/disjoint_sets.h"
#include "ball_physics_sim/engine/toi.h"

namespace ball_physics_sim::engine {

namespace {

// Gauss-Seidel converges geometrically; stop when a sweep changes no rate by more than this
// fraction of the largest free rate, or after the bound on sweeps.
constexpr double kRelativeConvergence = 1e-15;
constexpr int kMaxSweeps = 1000;
// A contact whose gap rate is within this fraction of the largest free rate is closed.
constexpr double kClosedContact = 1e-12;
// Islands of up to this many contacts are solved with dense matrices, larger ones with sparse.
constexpr std::size_t kDenselySolvedContacts = 64;
// A dense solve's arrays have room for the largest, so that its pivots allocate none: a
// settling pile makes thousands of these solves a step.
constexpr int kDenseSize = static_cast<int>(kDenselySolvedContacts);
using DenseVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kDenseSize, 1>;
using DenseMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kDenseSize, kDenseSize>;
// Added, relative to the largest diagonal term, to the diagonal of a direct solve's matrix:
// redundant contacts (a ball wedged by three) make it singular, and pivoting needs it definite.
constexpr double kRegularization = 1e-12;
// Block pivots taken since the fewest contacts yet broke complementarity, before single ones.
constexpr int kBlockTries = 3;
// The rounding of a rate's margin, relative to the rate's size.
constexpr double kMarginRounding = 1e-14;

// How far x is inside (positive) or outside the half-plane n . x + bias >= 0 of a contact.
// For a contact with a fixed body solved per ball, x is the ball's own rate: a body that does
// not move has rate zero (a resting ball), or is a segment.
double margin(const RestingContact& c, const Vec2& x) { return c.normal.dot(x) + c.bias; }

// The point of {x : n_k . x + b_k >= 0 for every k} nearest to `x`. In 2D it is `x` itself, its
// projection onto one boundary line, or the corner of two: the nearest such candidate that is
// inside all. Exact, however nearly opposite the normals (a ball wedged between two others).
Vec2 projectOntoHalfPlanes(const Vec2& x, const std::vector<const RestingContact*>& planes,
                           double tolerance) {
  // A candidate's margins carry the rounding of x's size, which pushes may make far larger
  // than the free rates the tolerance is measured against.
  const double slack = std::max(tolerance, kMarginRounding * x.norm());
  auto inside = [&](const Vec2& p) {
    return std::all_of(planes.begin(), planes.end(),
                       [&](const RestingContact* c) { return margin(*c, p) >= -slack; });
  };
  if (inside(x)) return x;
  Vec2 best = x;
  double best_distance = std::numeric_limits<double>::infinity();
  auto consider = [&](const Vec2& p) {
    const double distance = (p - x).squaredNorm();
    if (distance < best_distance && inside(p)) {
      best = p;
      best_distance = distance;
    }
  };
  for (std::size_t k = 0; k < planes.size(); ++k) {
    const RestingContact& a = *planes[k];
    consider(x - margin(a, x) * a.normal);
    for (std::size_t l = k + 1; l < planes.size(); ++l) {
      const RestingContact& b = *planes[l];
      const double det = a.normal.x() * b.normal.y() - a.normal.y() * b.normal.x();
      if (det == 0.0) continue;  // parallel lines have no corner
      // n_a . p = -b_a and n_b . p = -b_b, by Cramer's rule.
      consider(Vec2((-a.bias * b.normal.y() + b.bias * a.normal.y()) / det,
                    (-b.bias * a.normal.x() + a.bias * b.normal.x()) / det));
    }
  }
  return best;
}

}  // namespace

std::vector<std::vector<std::size_t>> contactIslands(const std::vector<RestingContact>& contacts,
                                                     const std::vector<double>& inverse_masses) {
  // Union-find over the balls the contacts move. (The balls are the solve's own, the members of
  // a hold, not every ball of the world.)
  const std::size_t balls = inverse_masses.size();
  DisjointSets groups(balls);
  for (const RestingContact& c : contacts)
    if (inverse_masses[c.ball] != 0.0 && c.other && inverse_masses[*c.other] != 0.0)
      groups.join(c.ball, *c.other);
  // The islands in the order of their roots, each sized before it is filled: a settling pile
  // finds them at every event.
  std::vector<std::size_t> contacts_of(balls, 0);
  for (const RestingContact& c : contacts)
    if (inverse_masses[c.ball] != 0.0) ++contacts_of[groups.find(c.ball)];
  std::vector<std::size_t> island_of(balls);
  std::vector<std::vector<std::size_t>> islands;
  for (std::size_t r = 0; r < balls; ++r)
    if (contacts_of[r] != 0) {
      island_of[r] = islands.size();
      islands.emplace_back().reserve(contacts_of[r]);
    }
  for (std::size_t k = 0; k < contacts.size(); ++k)
    if (inverse_masses[contacts[k].ball] != 0.0)
      islands[island_of[groups.find(contacts[k].ball)]].push_back(k);
  return islands;
}

double opening(const RestingContact& c, const std::vector<Vec2>& rates) {
  return margin(c, c.other ? Vec2(rates[c.ball] - rates[*c.other]) : rates[c.ball]);
}

namespace {

// The contribution of a contact's push to the rates of its two balls, per unit push, as
// (ball, change) pairs; a body that does not move gets none. Held in place, not on the heap:
// the solves take it for every contact at every pivot and sweep.
struct PushEffect {
  std::array<std::pair<std::size_t, Vec2>, 2> on;
  std::size_t count = 0;
  const std::pair<std::size_t, Vec2>* begin() const { return on.data(); }
  const std::pair<std::size_t, Vec2>* end() const { return on.data() + count; }
};

PushEffect pushEffect(const RestingContact& c, const std::vector<double>& inverse_masses) {
  PushEffect effect;
  effect.on[effect.count++] = {c.ball, inverse_masses[c.ball] * c.normal};
  if (c.other && inverse_masses[*c.other] != 0.0)
    effect.on[effect.count++] = {*c.other, -inverse_masses[*c.other] * c.normal};
  return effect;
}

// A direct solve's matrix, its active contacts' part and that part's factors. Dense for a small
// island, with room for the largest so that pivots allocate none, and on the heap, once a
// solve, not on the stack of a caller's thread, which may be small (99 kB: under glibc's
// initial mmap threshold, 128 kB, which a program may fix, making each larger block an mmap);
// sparse for a large one, whose contacts each share balls with a few others.
struct DenseEquations {
  using Vector = DenseVector;
  static int mostPivots(int contacts) { return 10 * contacts * contacts + 10; }
  DenseMatrix response, sub;
  Eigen::LDLT<DenseMatrix> factors;
};
// The factors of a large island's active part, its rows taken in the order that keeps the
// whole island's factors sparse (approximate minimum degree), found once a solve: found anew
// for each pivot's part, the ordering took most of a large island's time.
class OrderedFactors {
 public:
  using Sparse = Eigen::SparseMatrix<double>;
  void orderIsland(const Sparse& response) {
    Permutation inverse;
    Eigen::AMDOrdering<int>()(response, inverse);
    const Permutation order = inverse.inverse();
    rank_.assign(order.indices().data(), order.indices().data() + order.size());
  }
  // The active part's contacts, `set`, in the island's order.
  void orderActive(const std::vector<int>& set) {
    const int m = static_cast<int>(set.size());
    std::vector<int> by_rank(m);
    for (int i = 0; i < m; ++i) by_rank[i] = i;
    std::sort(by_rank.begin(), by_rank.end(),
              [&](int a, int b) { return rank_[set[a]] < rank_[set[b]]; });
    order_.resize(m);
    for (int j = 0; j < m; ++j) order_.indices()[by_rank[j]] = j;
  }
  void compute(const Sparse& sub) {
    Sparse ordered(sub.rows(), sub.cols());
    ordered.selfadjointView<Eigen::Lower>() = sub.selfadjointView<Eigen::Lower>().twistedBy(order_);
    factors_.compute(ordered);
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const {
    return order_.transpose() * factors_.solve(order_ * rhs);
  }

 private:
  using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;
  std::vector<int> rank_;  // each contact's place in the island's order
  Permutation order_;      // the active part's rows to their places in the island's order
  Eigen::SimplicialLDLT<Sparse, Eigen::Lower, Eigen::NaturalOrdering<int>> factors_;
};
struct SparseEquations {
  using Vector = Eigen::VectorXd;
  // Warm, a large island needs a few pivots; cold, a few per contact (each a factorization).
  static int mostPivots(int contacts) { return 4 * contacts + 32; }
  Eigen::SparseMatrix<double> response, sub;
  OrderedFactors factors;
};

void setResponse(const std::vector<Eigen::Triplet<double>>& entries, int n,
                 DenseEquations& equations) {
  equations.response.setZero(n, n);
  for (const Eigen::Triplet<double>& e : entries)
    equations.response(e.row(), e.col()) += e.value();
}
void setResponse(const std::vector<Eigen::Triplet<double>>& entries, int n,
                 SparseEquations& equations) {
  equations.response.resize(n, n);
  equations.response.setFromTriplets(entries.begin(), entries.end());  // duplicates summed
  equations.factors.orderIsland(equations.response);
}

// The rows and columns of the active contacts (`set`) in `sub`.
void copyActive(const std::vector<int>& set, DenseEquations& equations) {
  const int m = static_cast<int>(set.size());
  equations.sub.resize(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) equations.sub(i, j) = equations.response(set[i], set[j]);
}
void copyActive(const std::vector<int>& set, SparseEquations& equations) {
  std::vector<int> place(equations.response.rows(), -1);
  for (std::size_t i = 0; i < set.size(); ++i) place[set[i]] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t j = 0; j < set.size(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator e(equations.response, set[j]); e; ++e)
      if (place[e.row()] >= 0) entries.emplace_back(place[e.row()], static_cast<int>(j), e.value());
  const int m = static_cast<int>(set.size());
  equations.sub.resize(m, m);
  equations.sub.setFromTriplets(entries.begin(), entries.end());
  equations.factors.orderActive(set);
}

// The active contacts' equations in `sub`, and their factors with `regularization` added to
// the diagonal (which is then set back: `sub` stays exact, for refining).
template <class Equations>
void factorActive(const std::vector<int>& set, double regularization, Equations& equations) {
  copyActive(set, equations);
  const int m = static_cast<int>(set.size());
  for (int i = 0; i < m; ++i) equations.sub.coeffRef(i, i) += regularization;
  equations.factors.compute(equations.sub);
  for (int i = 0; i < m; ++i)
    equations.sub.coeffRef(i, i) = equations.response.coeff(set[i], set[i]);
}

// The least-push solution of the active equations, for where rounding makes redundant contacts'
// exact equations slightly inconsistent; whether it was sought. Only for a small island: on a
// large one its dense decomposition would cost seconds, and Gauss-Seidel polishes the definite
// pushes instead.
bool leastPushes(const DenseEquations& equations, const DenseVector& rhs, DenseVector& solved) {
  // (Rare: its own arrays on the heap, not a DenseMatrix's 35 kB on every solve's stack.)
  solved = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(equations.sub).solve(rhs);
  return true;
}
bool leastPushes(const SparseEquations&, const Eigen::VectorXd&, Eigen::VectorXd&) {
  return false;
}

// Solves an island's complementarity problem directly, by principal pivoting (block pivots,
// then Murty's least-index rule, which ends for the positive definite matrix of pushes to
// openings), to rounding: Gauss-Seidel then has nothing left but the rounding. Pivoting starts
// from the contacts that push already, whose pushes are taken back first: a problem solved
// before and changed little needs one pivot or none. If pivoting does not end within its
// bound, or rounding makes it undo a pivot, the pushes are left as they were.
template <class Equations>
void solveDirectly(const std::vector<RestingContact>& contacts,
                   const std::vector<double>& inverse_masses, const std::vector<std::size_t>& island,
                   double tolerance, std::vector<Vec2>& rates, std::vector<double>& push) {
  using Vector = typename Equations::Vector;
  const int n = static_cast<int>(island.size());
  std::vector<PushEffect> effects;
  effects.reserve(island.size());
  for (const std::size_t k : island) effects.push_back(pushEffect(contacts[k], inverse_masses));
  auto applyPushes = [&](const Vector& pushes, double sign) {
    for (int k = 0; k < n; ++k)
      for (const auto& [ball, change] : effects[k]) rates[ball] += sign * pushes[k] * change;
  };
  Vector previous(n);
  for (int k = 0; k < n; ++k) previous[k] = push[island[k]];
  applyPushes(previous, -1.0);
  Vector free_opening(n);
  for (int k = 0; k < n; ++k) free_opening[k] = opening(contacts[island[k]], rates);
  const std::vector<Eigen::Triplet<double>> entries =
      openingPerPush(contacts, inverse_masses, island);
  // (Default-initialized: make_unique would zero a dense one's arrays first.)
  const std::unique_ptr<Equations> equations(new Equations);
  setResponse(entries, n, *equations);
  const auto& response = equations->response;
  const auto& sub = equations->sub;
  const auto& factors = equations->factors;
  double largest_diagonal = 0.0;
  for (int k = 0; k < n; ++k) largest_diagonal = std::max(largest_diagonal, response.coeff(k, k));
  const double regularization = kRegularization * largest_diagonal;
  // The contacts, in index order, whose push or opening breaks complementarity, into `broken`
  // (sized once: pivots allocate none).
  std::vector<int> broken;
  broken.reserve(n);
  auto findViolations = [&](const std::vector<bool>& active, const Vector& pushes) {
    const Vector openings = response * pushes + free_opening;
    broken.clear();
    for (int k = 0; k < n; ++k)
      if ((active[k] && pushes[k] < 0.0) || (!active[k] && openings[k] < -tolerance))
        broken.push_back(k);
    return broken.empty() ? -1 : broken.front();
  };
  std::vector<bool> active(n);
  for (int k = 0; k < n; ++k) active[k] = previous[k] > 0.0;
  // Block pivoting (Judice and Pires): every broken contact flips at once, for up to
  // kBlockTries pivots after the fewest broke; then Murty's rule, one at a time, which ends
  // (and a new fewest allows block pivots again, at most n times). A cold island whose
  // approaching contacts all close needs one pivot, not one each.
  std::size_t fewest_broken = n + 1;
  int block_tries = 0;
  std::vector<int> set;  // the active contacts
  set.reserve(n);
  int last_flipped = -1;  // the contact a pivot flipped alone
  for (int pivots = 0; pivots < Equations::mostPivots(n); ++pivots) {
    // The equations that close the active contacts.
    set.clear();
    for (int k = 0; k < n; ++k)
      if (active[k]) set.push_back(k);
    Vector rhs(set.size());
    for (std::size_t i = 0; i < set.size(); ++i) rhs[i] = -free_opening[set[i]];
    auto scattered = [&](const Vector& solved) {
      Vector pushes = Vector::Zero(n);
      for (std::size_t i = 0; i < set.size(); ++i) pushes[set[i]] = solved[i];
      return pushes;
    };
    // Pivoting decides on the pushes of the equations made definite, and so ends.
    factorActive(set, regularization, *equations);
    const Vector definite = factors.solve(rhs);
    const int violated = findViolations(active, scattered(definite));
    // A pivot makes its contact's push or opening right, in exact arithmetic; undone at once, it
    // is rounding (redundant contacts' tiny pushes and openings) that would flip it back and
    // forth to the bound: Gauss-Seidel takes the island from where it was instead.
    if (violated >= 0 && violated == last_flipped) break;
    if (broken.size() < fewest_broken) {
      fewest_broken = broken.size();
      block_tries = kBlockTries;
    }
    if (!broken.empty() && block_tries-- > 0) {
      for (const int k : broken) active[k] = !active[k];
      last_flipped = broken.size() == 1 ? violated : -1;
      continue;
    }
    if (violated >= 0) {
      active[violated] = !active[violated];
      last_flipped = violated;
      continue;
    }
    // The exact equations' pushes where they keep complementarity: the definite ones refined
    // once by their own factorization, or, where those fail (on redundant contacts rounding
    // makes the exact equations slightly inconsistent, and refined pushes far off), the
    // least-push solution.
    Vector pushes = scattered(definite + factors.solve(rhs - sub * definite));
    if (Vector least; findViolations(active, pushes) >= 0 && leastPushes(*equations, rhs, least))
      pushes = scattered(least);
    if (findViolations(active, pushes) >= 0) pushes = scattered(definite);
    for (int k = 0; k < n; ++k) push[island[k]] = pushes[k];
    applyPushes(pushes, 1.0);
    return;
  }
  applyPushes(previous, 1.0);
}

// A ball's correction by the fixed bodies whose contacts are shut, as nonnegative parts along
// their normals: the projection onto their half-planes ends on one boundary line or at the
// corner of two, so one normal or two make it up. (Along their normals alone if none does, to
// rounding.) Into `parts`, one per shut contact.
void correctionAlongNormals(const Vec2& correction, const std::vector<const RestingContact*>& shut,
                            std::vector<double>& parts) {
  parts.assign(shut.size(), 0.0);
  const double rounding = kMarginRounding * correction.norm();
  for (std::size_t k = 0; k < shut.size(); ++k) {
    const double along = shut[k]->normal.dot(correction);
    if (along >= 0.0 && (correction - along * shut[k]->normal).norm() <= rounding) {
      parts[k] = along;
      return;
    }
  }
  for (std::size_t k = 0; k < shut.size(); ++k)
    for (std::size_t l = k + 1; l < shut.size(); ++l) {
      const Vec2 &a = shut[k]->normal, &b = shut[l]->normal;
      const double det = a.x() * b.y() - a.y() * b.x();
      if (det == 0.0) continue;
      // p a + q b = correction, by Cramer's rule.
      const double p = (correction.x() * b.y() - correction.y() * b.x()) / det;
      const double q = (a.x() * correction.y() - a.y() * correction.x()) / det;
      if (p >= 0.0 && q >= 0.0) {
        parts[k] = p;
        parts[l] = q;
        return;
      }
    }
  for (std::size_t k = 0; k < shut.size(); ++k)
    parts[k] = std::max(0.0, shut[k]->normal.dot(correction));
}

// Solves an island's complementarity problem by projected Gauss-Seidel, from the pushes
// already in `push` and their rates `a`, until a sweep changes nothing or its sweeps run out.
void solveIteratively(const std::vector<RestingContact>& contacts,
                      const std::vector<double>& inverse_masses,
                      const std::vector<std::size_t>& island, double scale, double tolerance,
                      std::vector<Vec2>& a, std::vector<double>& push) {
  // Unbiased contacts of a moving ball with bodies that do not move (a cone of allowed rates)
  // are solved per ball, exactly: Gauss-Seidel crawls where a ball is wedged between nearly
  // opposite normals. The others, one push at a time: with a bias, the corner of two nearly
  // opposite lines lies far away, and a push bounded by the bias is the safe step.
  struct FixedPlanes {
    std::vector<const RestingContact*> planes;
    Vec2 without_fixed = Vec2::Zero();  // the ball's rate less what fixed bodies push
  };
  std::map<std::size_t, FixedPlanes> fixed;  // by ball
  auto movable = [&](std::optional<std::size_t> ball) {
    return ball && inverse_masses[*ball] != 0.0;
  };
  auto pushedAlone = [&](const RestingContact& c) { return movable(c.other) || c.bias != 0.0; };
  for (std::size_t k : island)
    if (!pushedAlone(contacts[k])) fixed[contacts[k].ball].planes.push_back(&contacts[k]);
  for (auto& [ball, f] : fixed) {
    f.without_fixed = a[ball];
    for (const RestingContact* c : f.planes)
      f.without_fixed -= push[c - contacts.data()] * inverse_masses[ball] * c->normal;
  }
  // The contacts pushed one at a time, each with the fixed planes of its balls (none if they
  // have none), looked up once rather than in every sweep.
  struct PushedContact {
    std::size_t contact;
    FixedPlanes* ball_planes;
    FixedPlanes* other_planes;
  };
  auto planesOf = [&](std::optional<std::size_t> ball) -> FixedPlanes* {
    const auto f = ball ? fixed.find(*ball) : fixed.end();
    return f != fixed.end() ? &f->second : nullptr;
  };
  std::vector<PushedContact> one_by_one;
  for (std::size_t k : island)
    if (pushedAlone(contacts[k]))
      one_by_one.push_back({k, planesOf(contacts[k].ball), planesOf(contacts[k].other)});
  auto move = [&](std::size_t ball, FixedPlanes* planes, const Vec2& change) {
    a[ball] += change;
    if (planes) planes->without_fixed += change;
  };

  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    double largest_change = 0.0;
    for (auto& [ball, f] : fixed) {
      const Vec2 projected = projectOntoHalfPlanes(f.without_fixed, f.planes, tolerance);
      largest_change = std::max(largest_change, (projected - a[ball]).norm());
      a[ball] = projected;
    }
    for (const auto& [k, ball_planes, other_planes] : one_by_one) {
      const RestingContact& c = contacts[k];
      const double im_a = inverse_masses[c.ball], im_b = movable(c.other) ? inverse_masses[*c.other] : 0.0;
      const double pushed = std::max(0.0, push[k] - opening(c, a) / (im_a + im_b));
      const double change = pushed - push[k];
      if (change == 0.0) continue;
      push[k] = pushed;
      move(c.ball, ball_planes, change * im_a * c.normal);
      if (im_b != 0.0) move(*c.other, other_planes, -change * im_b * c.normal);
      largest_change = std::max(largest_change, std::abs(change) * (im_a + im_b));
    }
    if (largest_change <= tolerance) break;
  }
  // Fixed bodies push where their contacts are closed at the solution: the ball's correction
  // in parts along their normals.
  const double closed = kClosedContact * std::max(scale, 1.0);
  std::vector<const RestingContact*> shut;  // (kept from ball to ball: allocated once a solve)
  std::vector<double> parts;
  for (const auto& [ball, f] : fixed) {
    shut.clear();
    for (const RestingContact* c : f.planes) {
      push[c - contacts.data()] = 0.0;
      if (margin(*c, a[ball]) <= closed) shut.push_back(c);
    }
    correctionAlongNormals(a[ball] - f.without_fixed, shut, parts);
    for (std::size_t k = 0; k < shut.size(); ++k)
      push[shut[k] - contacts.data()] = parts[k] / inverse_masses[ball];
  }
}

}  // namespace

std::vector<Eigen::Triplet<double>> openingPerPush(const std::vector<RestingContact>& contacts,
                                                   const std::vector<double>& inverse_masses,
                                                   const std::vector<std::size_t>& island) {
  // Found from the contacts of each ball a push moves, not from every pair.
  const int n = static_cast<int>(island.size());
  std::vector<std::pair<std::size_t, int>> contacts_by_ball;
  contacts_by_ball.reserve(2 * island.size());
  for (int k = 0; k < n; ++k) {
    const RestingContact& ck = contacts[island[k]];
    contacts_by_ball.emplace_back(ck.ball, k);
    if (ck.other && inverse_masses[*ck.other] != 0.0) contacts_by_ball.emplace_back(*ck.other, k);
  }
  std::sort(contacts_by_ball.begin(), contacts_by_ball.end());
  std::vector<Eigen::Triplet<double>> entries;
  for (int l = 0; l < n; ++l)
    for (const auto& [ball, change] : pushEffect(contacts[island[l]], inverse_masses))
      for (auto at = std::lower_bound(contacts_by_ball.begin(), contacts_by_ball.end(),
                                      std::make_pair(ball, 0));
           at != contacts_by_ball.end() && at->first == ball; ++at) {
        const int k = at->second;
        const RestingContact& ck = contacts[island[k]];
        if (ball == ck.ball) entries.emplace_back(k, l, ck.normal.dot(change));
        if (ck.other && ball == *ck.other) entries.emplace_back(k, l, -ck.normal.dot(change));
      }
  return entries;
}

std::vector<Vec2> pushApart(const std::vector<Vec2>& free, const std::vector<double>& inverse_masses,
                            const std::vector<RestingContact>& contacts,
                            std::vector<double>* pushes) {
  if (contacts.empty()) {  // the common case between impacts, answered cheaply
    if (pushes) pushes->clear();
    return free;
  }
  double largest_squared = 0.0;  // one square root, not one per ball
  for (const Vec2& f : free) largest_squared = std::max(largest_squared, f.squaredNorm());
  const double scale = std::sqrt(largest_squared);
  const double tolerance = kRelativeConvergence * scale;
  const bool warm = pushes && pushes->size() == contacts.size();
  std::vector<Vec2> a = free;
  std::vector<double> push(contacts.size(), 0.0);
  for (const std::vector<std::size_t>& island : contactIslands(contacts, inverse_masses)) {
    if (warm)
      for (const std::size_t k : island) {
        push[k] = (*pushes)[k];
        for (const auto& [ball, change] : pushEffect(contacts[k], inverse_masses))
          a[ball] += push[k] * change;
      }
    // Nothing pushes and no gap closes: the rates are free, exactly (three islands in five of a
    // landing pile's position and velocity passes).
    if (std::all_of(island.begin(), island.end(), [&](std::size_t k) {
          return push[k] == 0.0 && opening(contacts[k], a) >= 0.0;
        }))
      continue;
    // Gauss-Seidel crawls down a stack (its error shrinks by a constant factor a sweep, the
    // closer to 1 the taller the stack): every island is solved directly, and Gauss-Seidel
    // only polishes that (or, where pivoting gives up, solves it).
    if (island.size() <= kDenselySolvedContacts)
      solveDirectly<DenseEquations>(contacts, inverse_masses, island, tolerance, a, push);
    else
      solveDirectly<SparseEquations>(contacts, inverse_masses, island, tolerance, a, push);
    solveIteratively(contacts, inverse_masses, island, scale, tolerance, a, push);
  }
  if (pushes) *pushes = push;
  return a;
}

double centripetalOpening(const Vec2& relative_velocity, const Vec2& normal, double distance) {
  return (relative_velocity - relative_velocity.dot(normal) * normal).squaredNorm() / distance;
}

double curvedContactLifetime(const Motion& relative, double horizon) {
  const double distance = relative.position.norm();
  if (distance == 0.0) return horizon;
  const Vec2 n = relative.position / distance;
  const double tangential_speed = (relative.velocity - relative.velocity.dot(n) * n).norm();
  const double tangential_acceleration =
      (relative.acceleration - relative.acceleration.dot(n) * n).norm();
  // The path leaves the true motion round the circle by jerk t^3 / 6: the jerk of motion on a
  // circle of radius R is v^3 / R^2 from the turning, 3 v a_t / R from the change of speed.
  const double jerk = tangential_speed *
                      (tangential_speed * tangential_speed / distance + 3.0 * tangential_acceleration) /
                      distance;
  double lifetime = jerk == 0.0 ? horizon : std::min(horizon, std::cbrt(6.0 * kHeldDrift / jerk));
  // And it leaves the circle itself: the distance stays within kHeldDrift of what it is now
  // while its square stays within 2 distance kHeldDrift of the square now (to first order in
  // the drift). From rest there is no jerk, but setting off along the circle (a pendulum at its
  // turning point) the path still leaves it, by a^2 t^4 / (8 distance).
  const Polynomial beyond = squaredDistanceBeyond(relative, distance);
  Polynomial above = beyond, below = beyond;
  for (double& c : above.c) c = -c;
  above.c[0] += 2.0 * distance * kHeldDrift;
  below.c[0] += 2.0 * distance * kHeldDrift;
  for (const Polynomial& band : {above, below})
    if (const auto out = firstDownCrossing(band, 0.0, lifetime)) lifetime = *out;
  return std::max(lifetime, std::min(kShortestHold, horizon));
}

}  // namespace ball_physics_sim::engine
