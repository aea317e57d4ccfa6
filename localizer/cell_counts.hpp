#pragma once
// The marked cells of a grid, counted over any rectangle in O(1): a summed-area table. APS asks "is the
// map under this cell of S at every offset of the window?" once per cell, over a rectangle of offsets.
#include <cstddef>
#include <vector>

namespace lidarloop {

class CellCounts {
 public:
  CellCounts() = default;
  // marked(c, r): whether cell (c, r) counts.
  template <class Marked>
  CellCounts(int cols, int rows, Marked marked)
      : cols_(cols), rows_(rows), sums_(size_t(cols + 1) * size_t(rows + 1), 0) {
    for (int r = 0; r < rows; ++r) {
      int in_row = 0;
      for (int c = 0; c < cols; ++c) {
        in_row += marked(c, r) ? 1 : 0;
        sums_[index(c + 1, r + 1)] = sums_[index(c + 1, r)] + in_row;
      }
    }
  }
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  // Marked cells in columns [c0, c0 + cols) and rows [r0, r0 + rows), all inside the grid.
  int in(int c0, int r0, int cols, int rows) const {
    return sums_[index(c0 + cols, r0 + rows)] - sums_[index(c0, r0 + rows)] - sums_[index(c0 + cols, r0)] +
           sums_[index(c0, r0)];
  }

 private:
  size_t index(int c, int r) const { return size_t(r) * size_t(cols_ + 1) + size_t(c); }
  int cols_ = 0, rows_ = 0;
  std::vector<int> sums_;  // (cols + 1) x (rows + 1): the marked cells above and left of each corner
};

}  // namespace lidarloop
