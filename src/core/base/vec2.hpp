// Vec2: a 2D vector of doubles with the handful of operations the physics needs.
// The scalar cross product cross(a, b) = a_x b_y - a_y b_x is the z component of a x b;
// perp(a) = z x a = (-a_y, a_x) turns a vector 90 degrees counter-clockwise.
#pragma once

#include <cmath>

namespace dem2d {

struct Vec2 {
  double x = 0.0;
  double y = 0.0;

  constexpr Vec2& operator+=(Vec2 b) {
    x += b.x;
    y += b.y;
    return *this;
  }
  constexpr Vec2& operator-=(Vec2 b) {
    x -= b.x;
    y -= b.y;
    return *this;
  }
  constexpr Vec2& operator*=(double s) {
    x *= s;
    y *= s;
    return *this;
  }
};

constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
constexpr Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
constexpr Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
constexpr Vec2 operator*(Vec2 a, double s) { return {s * a.x, s * a.y}; }
constexpr bool operator==(Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; }
constexpr double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
constexpr double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
constexpr Vec2 perp(Vec2 a) { return {-a.y, a.x}; }
constexpr double norm2(Vec2 a) { return dot(a, a); }
inline double norm(Vec2 a) { return std::sqrt(norm2(a)); }
// x as a rounded double in a register: no later addition can be fused with the product that made
// it. GCC 12's vectorizer fused the rotation below into one multiply-add-subtract despite
// -ffp-contract=off (in Walls::update), so a native build (FMA) and a portable one placed the
// lifters an ulp apart; scripts/check-fma finds any fused instruction in the program.
inline double rounded(double x) {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  asm("" : "+x"(x));
#endif
  return x;
}
// `a` turned by the rotation whose (cos, sin) is `cs`: each product rounded on its own.
inline Vec2 rotate(Vec2 a, Vec2 cs) {
  return {rounded(cs.x * a.x) - rounded(cs.y * a.y), rounded(cs.y * a.x) + rounded(cs.x * a.y)};
}
inline Vec2 rotate(Vec2 a, double angle) {
  return rotate(a, Vec2{std::cos(angle), std::sin(angle)});
}

}  // namespace dem2d
