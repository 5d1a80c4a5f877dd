// A plain 3-vector of doubles for the solver's per-contact and per-particle loops. Eigen's
// SSE packets of two do not fit three components: the shuffles cost more than the arithmetic
// in these short expressions. Every operation is written out in the order YADE's (unvectorised)
// Eigen evaluates it, so that our contacts round as YADE's do: a dot product or squared norm
// sums x + (y + z) (Eigen's scalar unroller splits a reduction in halves; seen on the shared
// clump case, where the other order moved penetrations by an ulp); cross products as cross3.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace gs::solver {

struct V3 {
  double x = 0, y = 0, z = 0;
  V3() = default;
  constexpr V3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
  explicit V3(const Eigen::Vector3d& v) : x(v[0]), y(v[1]), z(v[2]) {}
  void store(Eigen::Vector3d& v) const { v = Eigen::Vector3d(x, y, z); }
  Eigen::Vector3d eigen() const { return {x, y, z}; }
};

inline V3 operator+(const V3& a, const V3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline V3 operator-(const V3& a, const V3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline V3 operator-(const V3& a) {
  return {-a.x, -a.y, -a.z};
}
inline V3 operator*(double s, const V3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline V3 operator*(const V3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline V3 operator/(const V3& a, double s) {
  return {a.x / s, a.y / s, a.z / s};
}
inline V3& operator+=(V3& a, const V3& b) {
  return a = a + b;
}
inline V3& operator-=(V3& a, const V3& b) {
  return a = a - b;
}
/// Component-wise c ? a : b (branch-free in vectorised loops).
inline V3 select(bool c, const V3& a, const V3& b) {
  return {c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z};
}
inline V3 abs(const V3& a) {
  return {std::abs(a.x), std::abs(a.y), std::abs(a.z)};
}
/// dst += v, component by component (as Eigen's +=).
inline void add_to(Eigen::Vector3d& dst, const V3& v) {
  dst[0] += v.x;
  dst[1] += v.y;
  dst[2] += v.z;
}
inline double dot(const V3& a, const V3& b) {
  return a.x * b.x + (a.y * b.y + a.z * b.z);
}
inline double squared_norm(const V3& a) {
  return dot(a, a);
}
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

}  // namespace gs::solver
