#include "tests/test_shapes.h"

#include <array>
#include <cmath>
#include <map>

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

TriSurface box(double a, double b, double c) {
  TriSurface s;
  const double size[3] = {a, b, c};
  std::map<std::array<long, 3>, int> ids;
  auto vertex = [&](const Vec3& p) {
    const std::array<long, 3> key{std::lround(p[0] * 1e6), std::lround(p[1] * 1e6), std::lround(p[2] * 1e6)};
    auto it = ids.find(key);
    if (it != ids.end()) return it->second;
    s.vertices.push_back(p);
    return ids[key] = int(s.vertices.size()) - 1;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          int q[4];
          const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            Vec3 p{};
            p[axis] = side * size[axis];
            p[u] = (i + du[c]) * size[u] / 2;
            p[v] = (j + dv[c]) * size[v] / 2;
            q[c] = vertex(p);
          }
          // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
          if (side == 1) {
            s.triangles.push_back({q[0], q[1], q[2]});
            s.triangles.push_back({q[0], q[2], q[3]});
          } else {
            s.triangles.push_back({q[0], q[2], q[1]});
            s.triangles.push_back({q[0], q[3], q[2]});
          }
        }
    }
  return s;
}

}  // namespace hexbite::test
