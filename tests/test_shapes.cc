#include "tests/test_shapes.h"

#include <cmath>

namespace hexbite::test {

TriSurface torus(int n, int m) {
  const double pi = std::acos(-1.0);
  TriSurface s;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * pi * i / n, v = 2 * pi * j / m;
      s.vertices.push_back(
          {(10 + 3 * std::cos(v)) * std::cos(u), (10 + 3 * std::cos(v)) * std::sin(u), 3 * std::sin(v)});
    }
  auto id = [&](int i, int j) { return (i % n) * m + (j % m); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return s;
}

}  // namespace hexbite::test
