#pragma once
// Arithmetic on fleet::Vec3, the project's one point type (mission frame: x east, y north,
// z up, metres). The operators live in eamos::fleet so argument-dependent lookup finds them
// from every namespace that uses the type.
#include <cmath>

#include "fleet/fleet.h"

namespace eamos::fleet {

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(Vec3 a, double k) { return {a.x * k, a.y * k, a.z * k}; }
inline bool operator==(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

inline double norm(Vec3 a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }
/// Length of the horizontal (x, y) part.
inline double horizontal_norm(Vec3 a) { return std::hypot(a.x, a.y); }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

}  // namespace eamos::fleet
