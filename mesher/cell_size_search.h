// The cell size for a wanted number of hexes: secant steps on log(count) against log(h), shared by the grid
// mesher's core (mesher/grid_mesher.cc) and the swept core (mesher/swept_core.cc), whose counts fall with
// the cell size like h^-1 to h^-3.
//
// Input: the target count, the slope assumed until two trials give one, and the largest fitted slope that is
// trusted (a flatter one would make a huge step). Output: per trial (h, count) the next h; a trial with no
// hexes halves h. Cost: O(1) per step.
#pragma once

#include <cmath>

namespace hexbite {

class CellSizeSearch {
 public:
  CellSizeSearch(double target, double first_slope, double max_fitted_slope)
      : target_(target), first_slope_(first_slope), max_fitted_slope_(max_fitted_slope) {}

  double next(double h, double total) {
    double slope = first_slope_;
    if (prev_total_ > 0 && total > 0 && prev_h_ != h) {
      const double fitted = std::log(total / prev_total_) / std::log(h / prev_h_);
      if (fitted < max_fitted_slope_ && fitted > -4.0) slope = fitted;
    }
    prev_h_ = h;
    prev_total_ = total;
    return h * (total > 0 ? std::pow(target_ / total, 1.0 / slope) : 0.5);
  }

 private:
  double target_, first_slope_, max_fitted_slope_;
  double prev_h_ = 0, prev_total_ = 0;
};

}  // namespace hexbite
