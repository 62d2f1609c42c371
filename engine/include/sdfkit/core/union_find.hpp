#pragma once
// Disjoint sets over 0..n-1 with path halving: connected components of meshes and graphs.

#include <cstdint>
#include <numeric>
#include <vector>

namespace sdfkit {

class UnionFind {
public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }

  // The representative of x's set.
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }

  // Joins the sets of a and b; false when they were already one set.
  bool unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    parent_[a] = b;
    return true;
  }

private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace sdfkit
