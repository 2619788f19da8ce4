// Disjoint sets over 0..n-1 with path halving: the connected pieces of a triangle soup, the shells of a
// surface, the bodies of a hex mesh. Hand-written: a dozen lines, where Boost's disjoint_sets needs rank and
// parent property maps for the same.
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace hexbite {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  // The representative of i's set (the smallest element that was ever a root of it).
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void unite(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::size_t> parent_;
};

}  // namespace hexbite
