#include "ball_physics_sim/engine/broad_phase.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace ball_physics_sim::engine {

namespace {

// A box over more cells than this is kept out of the cells (a long wall, a bullet's sweep).
constexpr int kMostCellsPerBox = 64;
// The grid has at most this many cells per box, whatever the boxes' spread.
constexpr double kMostCellsPerKey = 4.0;
// Cells are this many median boxes wide: a box then spans one or two cells a side, not two or
// three. (1000 or 10,000 elastic balls, the benchmark's scene, stepped 9% and 7% faster at 2
// than at 1; at 3 and 4, slower again.)
constexpr double kMedianBoxesPerCell = 2.0;

// Where more than one box in this many has changed, update lays the cells out anew, to fit
// the boxes as they are now.
constexpr std::size_t kFewChangedShare = 4;

// Removes the first item that `is`, which must be there; the last item takes its place.
template <typename T, typename Is>
void removeFirst(std::vector<T>& items, Is is) {
  *std::find_if(items.begin(), items.end(), is) = items.back();
  items.pop_back();
}

Box grown(Box box, double by) {
  box.min -= Vec2::Constant(by);
  box.max += Vec2::Constant(by);
  return box;
}

}  // namespace

Box sweptBox(const Motion& motion, double radius, double horizon) {
  const Vec2 start = motion.position;
  const Vec2 end = motion.positionAt(horizon);
  Box box{start.cwiseMin(end), start.cwiseMax(end)};
  for (int axis = 0; axis < 2; ++axis) {
    const double a = motion.acceleration[axis];
    if (a == 0.0) continue;
    const double turn = -motion.velocity[axis] / a;  // where this coordinate stops and turns
    if (!(turn > 0.0 && turn < horizon)) continue;
    const double extreme = motion.positionAt(turn)[axis];
    box.min[axis] = std::min(box.min[axis], extreme);
    box.max[axis] = std::max(box.max[axis], extreme);
  }
  return grown(box, radius + kBoxMargin);
}

Box ballBox(const Vec2& centre, double radius) {
  return grown(Box{centre, centre}, radius + kBoxMargin);
}

Box segmentBox(const Segment& segment, double horizon) {
  Box box{segment.start.cwiseMin(segment.end), segment.start.cwiseMax(segment.end)};
  if (segment.angular_velocity != 0.0) {  // its ends may go anywhere round the pivot
    const double reach = segment.reachFromPivot();
    box = {segment.pivot - Vec2::Constant(reach), segment.pivot + Vec2::Constant(reach)};
  }
  if (segment.velocity != Vec2::Zero()) {
    const Vec2 shift = horizon * segment.velocity;
    box.min += shift.cwiseMin(Vec2::Zero());
    box.max += shift.cwiseMax(Vec2::Zero());
  }
  return grown(box, 0.5 * segment.thickness + kBoxMargin);
}

void BoxGrid::reset(const std::vector<Box>& boxes) {
  assert(boxes.size() <= std::numeric_limits<std::uint32_t>::max());  // (Entry's keys)
  pairs_found_ = false;
  boxes_ = boxes;
  ranges_.assign(boxes.size(), CellRange{});
  oversized_.clear();
  for (std::vector<Entry>& cell : cells_) cell.clear();
  if (boxes.empty()) return;
  Box bounds = boxes.front();
  std::vector<double> sizes;
  sizes.reserve(boxes.size());
  for (const Box& box : boxes) {
    bounds.min = bounds.min.cwiseMin(box.min);
    bounds.max = bounds.max.cwiseMax(box.max);
    sizes.push_back((box.max - box.min).maxCoeff());
  }
  // The median, not the mean: a few long walls or fast sweeps would make every cell too big.
  std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
  const Vec2 extent = bounds.max - bounds.min;
  const double most_cells = kMostCellsPerKey * static_cast<double>(boxes.size());
  const double cell_size = std::max({kMedianBoxesPerCell * sizes[sizes.size() / 2],
                                    std::sqrt(extent.prod() / most_cells),
                                    extent.maxCoeff() / most_cells, 1e-300});
  cells_per_metre_ = 1.0 / cell_size;
  origin_ = bounds.min;
  columns_ = static_cast<int>(std::floor(extent.x() * cells_per_metre_)) + 1;
  rows_ = static_cast<int>(std::floor(extent.y() * cells_per_metre_)) + 1;
  cells_.resize(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_));
  for (std::size_t key = 0; key < boxes.size(); ++key) {
    ranges_[key] = cellsOf(boxes[key]);
    insert(key, ranges_[key]);
  }
}

void BoxGrid::move(std::size_t key, const Box& box) {
  pairs_found_ = false;
  boxes_[key] = box;
  const CellRange cells = cellsOf(box);
  const CellRange& old = ranges_[key];
  if (cells.first_column == old.first_column && cells.last_column == old.last_column &&
      cells.first_row == old.first_row && cells.last_row == old.last_row)
    return;
  erase(key, old);
  insert(key, cells);
  ranges_[key] = cells;
}

void BoxGrid::update(const std::vector<Box>& boxes) {
  if (boxes.size() != boxes_.size()) return reset(boxes);
  changed_.clear();
  for (std::size_t key = 0; key < boxes.size(); ++key)
    if (boxes[key].min != boxes_[key].min || boxes[key].max != boxes_[key].max)
      changed_.push_back(key);
  if (kFewChangedShare * changed_.size() > boxes.size()) return reset(boxes);
  // A box gone past the cells laid out would share the edge cells with every other one there.
  const Vec2 far_corner =
      origin_ + Vec2(static_cast<double>(columns_), static_cast<double>(rows_)) / cells_per_metre_;
  for (const std::size_t key : changed_)
    if ((boxes[key].min.array() < origin_.array()).any() ||
        (boxes[key].max.array() > far_corner.array()).any())
      return reset(boxes);
  for (const std::size_t key : changed_) move(key, boxes[key]);
}

std::vector<std::size_t> BoxGrid::overlapping(const Box& box) const {
  std::vector<std::size_t> keys;
  overlapping(box, keys);
  return keys;
}

void BoxGrid::overlapping(const Box& box, std::vector<std::size_t>& keys) const {
  keys.clear();
  if (boxes_.empty()) return;  // no cells laid out
  // In one cell (a box's few walls) each key is met once, and no cell need be found: 1000
  // bullets' walls are asked so some 3,700 times a step.
  if (cells_.size() == 1) {
    for (const Entry& entry : cells_.front())
      if (overlap(box, boxes_[entry.key])) keys.push_back(entry.key);
    return;
  }
  for (std::size_t key : oversized_)
    if (overlap(box, boxes_[key])) keys.push_back(key);
  // A query box that covers too many cells is still looked up cell by cell: its neighbours
  // must be found, and there are few such boxes.
  const int first_column = columnOf(box.min.x()), last_column = columnOf(box.max.x());
  const int first_row = rowOf(box.min.y()), last_row = rowOf(box.max.y());
  // Each entry is written, and kept (counted) where it is reported: whether it is cannot be
  // foretold, and a branch on it was mispredicted about as often as not.
  std::size_t count = keys.size();
  for (int row = first_row; row <= last_row; ++row)
    for (int column = first_column; column <= last_column; ++column) {
      const std::vector<Entry>& cell = cells_[static_cast<std::size_t>(row) * columns_ + column];
      keys.resize(count + cell.size());
      for (const Entry& entry : cell) {
        keys[count] = entry.key;
        // (Met first here, as the cells are walked row by row.)
        count += (std::max(entry.first_column, first_column) == column) &
                 (std::max(entry.first_row, first_row) == row) &
                 overlap(box, boxes_[entry.key]);
      }
    }
  keys.resize(count);
}

const std::vector<std::pair<std::size_t, std::size_t>>& BoxGrid::pairs() const {
  if (pairs_found_) return pairs_;
  pairs_found_ = true;
  std::vector<std::pair<std::size_t, std::size_t>>& found = pairs_;
  found.clear();
  auto report = [&](std::size_t a, std::size_t b) {
    if (overlap(boxes_[a], boxes_[b])) found.emplace_back(std::min(a, b), std::max(a, b));
  };
  for (std::size_t k = 0; k < oversized_.size(); ++k) {
    for (std::size_t m = k + 1; m < oversized_.size(); ++m) report(oversized_[k], oversized_[m]);
    for (std::size_t key = 0; key < boxes_.size(); ++key)
      if (ranges_[key].first_column <= ranges_[key].last_column) report(oversized_[k], key);
  }
  for (int row = 0; row < rows_; ++row) {
    for (int column = 0; column < columns_; ++column) {
      const std::vector<Entry>& cell = cells_[static_cast<std::size_t>(row) * columns_ + column];
      for (std::size_t k = 0; k < cell.size(); ++k) {
        const Entry& a = cell[k];
        for (std::size_t m = k + 1; m < cell.size(); ++m) {
          const Entry& b = cell[m];
          // Two boxes in this cell share the cells from the larger of their first columns and
          // rows on: the pair is theirs there only.
          if (std::max(a.first_column, b.first_column) == column &&
              std::max(a.first_row, b.first_row) == row)
            report(a.key, b.key);
        }
      }
    }
  }
  return found;
}

void BoxGrid::pairsOf(const std::vector<std::size_t>& keys,
                      std::vector<std::pair<std::size_t, std::size_t>>& found) const {
  found.clear();
  asked_in_.resize(boxes_.size(), 0);
  ++asks_;
  for (const std::size_t key : keys) {
    assert(key < boxes_.size());
    asked_in_[key] = asks_;
  }
  for (const std::size_t key : keys) {
    overlapping(boxes_[key], near_);
    for (const std::size_t other : near_)
      // (A pair of two keys asked about is the lower one's.)
      if (other != key && (asked_in_[other] != asks_ || key < other))
        found.emplace_back(std::min(key, other), std::max(key, other));
  }
}

// Boxes beyond the bounds reset saw (a ball sent off by an impact) go to the edge cells. (Once
// clamped to zero or more, truncation is the floor, without a call to floor() per query.)
int BoxGrid::columnOf(double x) const {
  return static_cast<int>(std::clamp((x - origin_.x()) * cells_per_metre_, 0.0,
                                     static_cast<double>(columns_ - 1)));
}

int BoxGrid::rowOf(double y) const {
  return static_cast<int>(std::clamp((y - origin_.y()) * cells_per_metre_, 0.0,
                                     static_cast<double>(rows_ - 1)));
}

BoxGrid::CellRange BoxGrid::cellsOf(const Box& box) const {
  const CellRange cells{columnOf(box.min.x()), columnOf(box.max.x()), rowOf(box.min.y()),
                        rowOf(box.max.y())};
  const int count = (cells.last_column - cells.first_column + 1) *
                    (cells.last_row - cells.first_row + 1);
  return count > kMostCellsPerBox ? CellRange{} : cells;
}

void BoxGrid::insert(std::size_t key, const CellRange& cells) {
  if (cells.first_column > cells.last_column) oversized_.push_back(key);
  const Entry entry{static_cast<std::uint32_t>(key), cells.first_column, cells.first_row};
  for (int row = cells.first_row; row <= cells.last_row; ++row)
    for (int column = cells.first_column; column <= cells.last_column; ++column)
      cells_[static_cast<std::size_t>(row) * columns_ + column].push_back(entry);
}

void BoxGrid::erase(std::size_t key, const CellRange& cells) {
  if (cells.first_column > cells.last_column)
    removeFirst(oversized_, [key](std::size_t other) { return other == key; });
  for (int row = cells.first_row; row <= cells.last_row; ++row)
    for (int column = cells.first_column; column <= cells.last_column; ++column)
      removeFirst(cells_[static_cast<std::size_t>(row) * columns_ + column],
                  [key](const Entry& entry) { return entry.key == key; });
}

}  // namespace ball_physics_sim::engine
