#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/motion.h"
#include "ball_physics_sim/engine/segment.h"

namespace ball_physics_sim::engine {

// An axis-aligned box.
struct Box {
  Vec2 min = Vec2::Zero();
  Vec2 max = Vec2::Zero();
};

// Boxes are grown by this much so that rounding in positions (~1e-10 m within kMaxCoordinate)
// does not hide a pair that the exact tests find touching. (A near-graze that the impact
// polynomials' own cancellation reports from further away, possible only for long fast sweeps
// of tiny balls, is dropped instead.)
constexpr double kBoxMargin = 1e-6;  // m

// The box a ball of `radius` sweeps moving with `motion` over [0, horizon], grown by
// kBoxMargin: per axis the path's ends and, if it turns within the horizon, its turning point.
Box sweptBox(const Motion& motion, double radius, double horizon);

// The box of a ball of `radius` at `centre`, grown by kBoxMargin: sweptBox's for no motion,
// without the path's arithmetic (it is asked for several times an event).
Box ballBox(const Vec2& centre, double radius);

// The box a segment's capsule sweeps over [0, horizon], grown by kBoxMargin: a turning one's
// is the box of the circle its ends go round.
Box segmentBox(const Segment& segment, double horizon);

// Whether two boxes overlap or touch. (Inline, and without a branch: of the boxes in a grid
// query's cells, about as many overlap the query's as do not.)
inline bool overlap(const Box& a, const Box& b) {
  return (a.min.x() <= b.max.x()) & (b.min.x() <= a.max.x()) & (a.min.y() <= b.max.y()) &
         (b.min.y() <= a.max.y());
}

// Boxes kept in a uniform grid of cells, so that the boxes near one box are found in time about
// linear in how many there are, and a box that moves is moved alone: after an impact only the
// balls it changed are looked up again, where a sweep would sort every box anew.
class BoxGrid {
 public:
  // Lays the cells out over these boxes (cells about two median boxes wide, at most a few
  // per box) and puts each box in, keyed by its index.
  void reset(const std::vector<Box>& boxes);
  // Moves the box with this key (a key reset was given) to `box`.
  void move(std::size_t key, const Box& box);
  // Puts in these boxes, keyed by index, as reset does, but where they are as many as it holds
  // and few have changed, all within the cells laid out (a sleeping pile's stay as they were),
  // it moves those alone and keeps the cells.
  void update(const std::vector<Box>& boxes);
  // The keys of the boxes that overlap or touch `box`, each once, in no particular order: put in
  // `keys` (emptied first, its storage kept for the next query) or returned.
  void overlapping(const Box& box, std::vector<std::size_t>& keys) const;
  std::vector<std::size_t> overlapping(const Box& box) const;
  // The pairs (a, b), a < b, of keys whose boxes overlap or touch, each once: from the cells,
  // each pair in the first cell both cover, so that finding them all costs no query per box.
  // Found once until a box moves or the grid is laid out anew.
  const std::vector<std::pair<std::size_t, std::size_t>>& pairs() const;
  // The pairs (a, b), a < b, of keys whose boxes overlap or touch, of which one or both are in
  // `keys` (keys the grid was given, each once), each pair once: put in `found` (emptied
  // first). A query per key: where few of the keys matter (the balls awake beside a sleeping
  // pile), the cells of the others are not looked at.
  void pairsOf(const std::vector<std::size_t>& keys,
               std::vector<std::pair<std::size_t, std::size_t>>& found) const;

 private:
  // The cells a box covers, as column and row ranges; empty (from > to) for an oversized box.
  struct CellRange {
    int first_column = 0, last_column = -1, first_row = 0, last_row = -1;
  };
  // A key in a cell, with the first cell its box covers: a box over several cells is reported
  // by the first of them that a query covers too (the later of the two first columns, and of
  // the two first rows), without bookkeeping per query, nor a look at its range.
  struct Entry {
    std::uint32_t key;
    int first_column, first_row;
  };
  CellRange cellsOf(const Box& box) const;
  int columnOf(double x) const;
  int rowOf(double y) const;
  void insert(std::size_t key, const CellRange& cells);
  void erase(std::size_t key, const CellRange& cells);

  Vec2 origin_ = Vec2::Zero();
  double cells_per_metre_ = 1.0;
  int columns_ = 0, rows_ = 0;
  std::vector<std::vector<Entry>> cells_;  // row by row
  // Boxes over so many cells that they are kept aside and tested against every query.
  std::vector<std::size_t> oversized_;
  std::vector<Box> boxes_;
  std::vector<CellRange> ranges_;
  mutable std::vector<std::pair<std::size_t, std::size_t>> pairs_;  // as pairs() last found
  mutable bool pairs_found_ = false;
  std::vector<std::size_t> changed_;  // update's
  mutable std::vector<std::size_t> asked_in_, near_;  // pairsOf's bookkeeping
  mutable std::size_t asks_ = 0;
};

}  // namespace ball_physics_sim::engine
