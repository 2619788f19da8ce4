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

TriSurface l_block(double arm, double width, double height) {
  const double outline[6][2] = {{0, 0}, {arm, 0}, {arm, width}, {width, width}, {width, arm}, {0, arm}};
  TriSurface s;
  for (const double z : {0.0, height})  // vertices 0-5 at the bottom, 6-11 at the top
    for (const auto& p : outline) s.vertices.push_back({p[0], p[1], z});
  for (int k = 1; k <= 4; ++k) {  // the outline is star-shaped from vertex 0: a fan
    s.triangles.push_back({0, k + 1, k});
    s.triangles.push_back({6, k + 6, k + 7});
  }
  for (int i = 0; i < 6; ++i) {
    const int j = (i + 1) % 6;
    s.triangles.push_back({i, j, j + 6});
    s.triangles.push_back({i, j + 6, i + 6});
  }
  return s;
}

TriSurface rotated(TriSurface s, const Vec3& axis, double degrees) {
  const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  const double x = axis[0] / n, y = axis[1] / n, z = axis[2] / n;
  const double c = std::cos(degrees * M_PI / 180.0), k = std::sin(degrees * M_PI / 180.0), d = 1 - c;
  const double r[3][3] = {{c + x * x * d, x * y * d - z * k, x * z * d + y * k},
                          {y * x * d + z * k, c + y * y * d, y * z * d - x * k},
                          {z * x * d - y * k, z * y * d + x * k, c + z * z * d}};
  for (Vec3& v : s.vertices) {
    const Vec3 p = v;
    for (int a = 0; a < 3; ++a) v[a] = r[a][0] * p[0] + r[a][1] * p[1] + r[a][2] * p[2];
  }
  return s;
}

}  // namespace hexbite::test
