#pragma once
// Small fixed-size vectors for the interfaces between modules. Heavy linear algebra uses
// Eigen inside .cpp files; these keep Eigen out of widely included headers.
#include <array>
#include <cmath>

namespace tomorig {

struct Vec2d {
  double x = 0, y = 0;
};

struct Vec3d {
  double x = 0, y = 0, z = 0;
  Vec3d operator+(const Vec3d& o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec3d operator-(const Vec3d& o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3d operator*(double s) const { return {x * s, y * s, z * s}; }
  double dot(const Vec3d& o) const { return x * o.x + y * o.y + z * o.z; }
  double norm() const { return std::sqrt(dot(*this)); }
};

struct Vec3f {
  float x = 0, y = 0, z = 0;
};

// Row-major 3x3 matrix.
using Mat3d = std::array<double, 9>;

// A ray in world coordinates (mm): origin + s * direction, direction of unit length.
struct Ray {
  Vec3d origin;
  Vec3d direction;
};

}  // namespace tomorig
