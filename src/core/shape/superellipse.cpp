// The superellipse's geometry (core/shape/superellipse.hpp): the implicit function, support
// points, curvature, mass and inertia, and the contacts against walls and another superellipse.
#include "core/shape/superellipse.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace dem2d {

namespace {

Vec2 angle_cs(double theta) { return {std::cos(theta), std::sin(theta)}; }
// A pose's rotation: the caller's (cos, sin) if given, else taken from its angle.
Vec2 pose_rotation(const SuperPose& p) {
  return p.rot.x != 0.0 || p.rot.y != 0.0 ? p.rot : angle_cs(p.theta);
}
// A lab-frame vector in the body frame of a body turned by the rotation (cos, sin) = cs, and back.
Vec2 to_body(Vec2 v, Vec2 cs) { return rotate(v, Vec2{cs.x, -cs.y}); }
Vec2 to_lab(Vec2 v, Vec2 cs) { return rotate(v, cs); }

// One coordinate's share of F, its derivative and its second derivative: with u = |x|/a,
// u^n, sign(x) n/a u^(n-1) and n(n-1)/a^2 u^(n-2). u^(n-2) is taken once by pow: it is 1 at
// u = 0 for n = 2 (pow(0, 0) = 1) and 0 there for n > 2, finite for every n >= 2.
struct AxisTerm {
  double f, g, h;
};
// u^k for a whole k >= 0 by repeated squaring (pow's value to a few ulps, a tenth of its time).
double whole_power(double u, int k) {
  double w = 1.0;
  for (; k > 0; k >>= 1, u *= u)
    if (k & 1) w *= u;
  return w;
}
// A whole exponent up to this is taken by multiplication (n = 2: u^0 = 1, n = 4, n = 8, ...).
constexpr double kMaxWholeExponent = 16.0;
AxisTerm axis_term(double x, double a, double n) {
  const double u = std::min(std::abs(x) / a, kMaxScaled);
  const double e = n - 2.0;
  const double w = e == std::floor(e) && e <= kMaxWholeExponent
                       ? whole_power(u, static_cast<int>(e))
                       : std::pow(u, e);
  const double u1 = w * u;
  return {u1 * u, std::copysign(n / a * u1, x), n * (n - 1.0) / (a * a) * w};
}

// The cap of the curvature radius of one body: curvature_radius_cap, remembered for the last two
// shapes asked for on this thread (a pair's two bodies, or a mill of one or two shapes, hit it);
// a miss costs three Gamma functions and a cube root.
double radius_cap(const SuperEllipse& s) {
  struct Entry {
    double a = -1.0, b = -1.0, n = -1.0, cap = 0.0;
  };
  thread_local Entry memo[2];
  thread_local int older = 0;
  for (const Entry& e : memo)
    if (e.a == s.a && e.b == s.b && e.n == s.n) return e.cap;
  Entry& e = memo[older];
  older = 1 - older;
  e = {s.a, s.b, s.n, kCurvatureRadiusCap * equivalent_radius(s)};
  return e.cap;
}

// 1 / kappa capped at `cap` (kappa >= 0).
double capped_inverse(double kappa, double cap) { return kappa * cap > 1.0 ? 1.0 / kappa : cap; }

// 1 / kappa at a body-frame point of the curve, at most `cap`.
double capped_radius(const SuperEllipse& s, Vec2 p, double cap) {
  const ImplicitValue e = evaluate(s, p);
  const double g2 = norm2(e.grad);
  const double g3 = g2 * std::sqrt(g2);
  const double num = e.grad.y * e.grad.y * e.hess.x + e.grad.x * e.grad.x * e.hess.y;
  return num * cap > g3 ? g3 / num : cap;
}

// (F + 1)^(1/n) at a body-frame point: the body's own norm of p (1 on the curve, homogeneous of
// degree 1), and its gradient. Root finding along a line is nearly linear in it, whatever n.
struct NormValue {
  double value;
  Vec2 grad;
};
NormValue body_norm(const SuperEllipse& s, Vec2 p) {
  const ImplicitValue e = evaluate(s, p);
  const double f1 = e.f + 1.0;
  if (!(f1 > 0.0)) return {0.0, {}};
  const double v = std::pow(f1, 1.0 / s.n);
  return {v, (v / (s.n * f1)) * e.grad};
}

// x^(1/n) for x in [1, 2] (a support point's norm): square roots for n = 4 and 8, else pow.
double root_n(double x, double n) {
  if (n == 4.0) return std::sqrt(std::sqrt(x));
  if (n == 8.0) return std::sqrt(std::sqrt(std::sqrt(x)));
  return std::pow(x, 1.0 / n);
}
// x^q, q = 1 / (n - 1), for x in [0, 1]: the cube root for n = 4, else pow.
double root_n1(double x, double n, double q) { return n == 4.0 ? std::cbrt(x) : std::pow(x, q); }

}  // namespace

// ---- Implicit function, support, curvature ------------------------------------------------------

ImplicitValue evaluate(const SuperEllipse& s, Vec2 p) {
  const AxisTerm x = axis_term(p.x, s.a, s.n);
  const AxisTerm y = axis_term(p.y, s.b, s.n);
  return {x.f + y.f - 1.0, {x.g, y.g}, {x.h, y.h}};
}

// Maximising u . p on F(p) = 0: grad F parallel to u, so |x/a|^(n-1) = k a|u_x| and
// |y/b|^(n-1) = k b|u_y| for one k > 0: |x/a| = K sx, |y/b| = K sy with sx = |a u_x|^q,
// sy = |b u_y|^q, q = 1/(n-1), and F = 0 gives K = 1/N, N = (sx^n + sy^n)^(1/n). Both a|u_x| and
// b|u_y| are first divided by the larger (the point does not change: K absorbs it), so that sx,
// sy are in [0, 1] and nothing under- or overflows; sx^n = sx * (a|u_x|)/m since sx^(n-1) is that.
Vec2 support(const SuperEllipse& s, Vec2 u) {
  const double ax = s.a * std::abs(u.x);
  const double by = s.b * std::abs(u.y);
  const double m = std::max(ax, by);
  if (!(m > 0.0)) return {s.a, 0.0};  // no direction given: any point will do
  if (s.n == 2.0) {
    // The ellipse: (a^2 u_x, b^2 u_y) / h, h = sqrt(a^2 u_x^2 + b^2 u_y^2) the support function.
    const double h = std::sqrt(rounded(ax * ax) + rounded(by * by));
    return {std::copysign(s.a * ax / h, u.x), std::copysign(s.b * by / h, u.y)};
  }
  const double q = 1.0 / (s.n - 1.0);
  const double rx = ax / m, ry = by / m;  // one of them is 1
  const double sx = rx < 1.0 ? root_n1(rx, s.n, q) : 1.0;
  const double sy = ry < 1.0 ? root_n1(ry, s.n, q) : 1.0;
  const double inv_norm = 1.0 / root_n(rounded(sx * rx) + rounded(sy * ry), s.n);
  return {std::copysign(s.a * sx * inv_norm, u.x), std::copysign(s.b * sy * inv_norm, u.y)};
}

Vec2 support_lab(const SuperEllipse& s, Vec2 centre, double theta, Vec2 u) {
  const Vec2 cs = angle_cs(theta);
  return centre + to_lab(support(s, to_body(u, cs)), cs);
}

double curvature(const SuperEllipse& s, Vec2 p) {
  const ImplicitValue e = evaluate(s, p);
  const double g2 = norm2(e.grad);
  if (!(g2 > 0.0)) return 0.0;  // the centre: no level curve
  const double num = e.grad.y * e.grad.y * e.hess.x + e.grad.x * e.grad.x * e.hess.y;
  return num / (g2 * std::sqrt(g2));
}

double curvature_radius(const SuperEllipse& s, Vec2 p) {
  return capped_radius(s, p, radius_cap(s));
}

double curvature_radius(const SuperEllipse& s, Vec2 p, double cap) {
  return capped_radius(s, p, cap);
}

double curvature_radius_cap(const SuperEllipse& s) { return radius_cap(s); }

// support() with the curvature there, without another pow: with rx = a|u_x| / m, sx = rx^q and
// N^n = sx rx + sy ry, the scaled coordinate X = |x|/a = sx / N has X^(n-1) = rx / N^(n-1) and
// X^(n-2) = (rx / sx) N^2 / N^n (rx / sx = rx^((n-2)/(n-1)): 1 at rx = 0 for n = 2, else 0).
// The common factor n / N^(n-1) of the gradient cancels but once in kappa.
SupportCurvature support_curvature(const SuperEllipse& s, Vec2 u) {
  const double ax = s.a * std::abs(u.x);
  const double by = s.b * std::abs(u.y);
  const double m = std::max(ax, by);
  if (!(m > 0.0)) return {{s.a, 0.0}, curvature(s, {s.a, 0.0})};
  if (s.n == 2.0) {
    // The ellipse: support function h = sqrt(a^2 u_x^2 + b^2 u_y^2), point (a^2 u_x, b^2 u_y) / h,
    // curvature radius h + h'' = a^2 b^2 / h^3.
    const double h2 = rounded(ax * ax) + rounded(by * by);
    const double h = std::sqrt(h2);
    const double ab = s.a * s.b;
    return {{std::copysign(s.a * ax / h, u.x), std::copysign(s.b * by / h, u.y)},
            h2 * h / (ab * ab)};
  }
  const double q = 1.0 / (s.n - 1.0);
  const double rx = ax / m, ry = by / m;  // one of them is 1
  const double sx = rx < 1.0 ? root_n1(rx, s.n, q) : 1.0;
  const double sy = ry < 1.0 ? root_n1(ry, s.n, q) : 1.0;
  const double Nn = rounded(sx * rx) + rounded(sy * ry);
  const double N = root_n(Nn, s.n);
  const Vec2 p{std::copysign(s.a * sx / N, u.x), std::copysign(s.b * sy / N, u.y)};
  const double flat = s.n > 2.0 ? 0.0 : 1.0;
  const double wx = (sx > 0.0 ? rx / sx : flat) * N * N / Nn;  // X^(n-2)
  const double wy = (sy > 0.0 ? ry / sy : flat) * N * N / Nn;  // Y^(n-2)
  // grad F = c (rx / a, ry / b), c = n / N^(n-1) = n N / N^n; F_xx = n (n-1) / a^2 X^(n-2).
  const double c = s.n * N / Nn;
  const double gx = rx / s.a, gy = ry / s.b;
  const double g = std::sqrt(rounded(gx * gx) + rounded(gy * gy));
  const double num = s.n * (s.n - 1.0) * (gy * gy * wx / (s.a * s.a) + gx * gx * wy / (s.b * s.b));
  return {p, num / (c * g * g * g)};
}

// ---- Size, mass, inertia ------------------------------------------------------------------------

// The farthest point of the curve from its centre. max(a, b) only for n = 2: for n > 2 the
// rounded corners reach beyond it (a = b: a 2^(1/2 - 1/n)). Maximising x^2 + y^2 on the curve:
// with X = |x|/a, Y = |y|/b, X^(n-2) and Y^(n-2) are proportional to a^2 and b^2, so X = alpha^e K,
// Y = beta^e K with e = 2/(n-2), alpha = a/m, beta = b/m (m = max(a, b)) and K from X^n + Y^n = 1.
// The axes' ends are stationary too: the largest of the three.
double bounding_radius(const SuperEllipse& s) {
  const double m = std::max(s.a, s.b);
  if (!(s.n > 2.0)) return m;
  const double al = s.a / m, be = s.b / m, e = 2.0 / (s.n - 2.0);
  const double X = std::pow(al, e), Y = std::pow(be, e);
  const double K = std::pow(std::pow(X, s.n) + std::pow(Y, s.n), -1.0 / s.n);
  return std::max(m, m * K * std::hypot(al * X, be * Y));
}

double area(const SuperEllipse& s) {
  const double g1 = std::tgamma(1.0 + 1.0 / s.n);
  return 4.0 * s.a * s.b * g1 * g1 / std::tgamma(1.0 + 2.0 / s.n);
}

namespace {
// The volume from g1 = Gamma(1 + 1/n) and g3 = Gamma(1 + 3/n).
double volume_of(const SuperEllipse& s, double g1, double g3) {
  const double c = std::min(s.a, s.b);
  return 8.0 * s.a * s.b * c * g1 * g1 * g1 / g3;
}
double radius_of_volume(double v) { return std::cbrt(3.0 * v / (4.0 * std::numbers::pi)); }
}  // namespace

double volume(const SuperEllipse& s) {
  return volume_of(s, std::tgamma(1.0 + 1.0 / s.n), std::tgamma(1.0 + 3.0 / s.n));
}

double equivalent_radius(const SuperEllipse& s) { return radius_of_volume(volume(s)); }

double EquivalentRadii::operator()(const SuperEllipse& s) {
  if (s.n != n_) {
    n_ = s.n;
    g1_ = std::tgamma(1.0 + 1.0 / s.n);
    g3_ = std::tgamma(1.0 + 3.0 / s.n);
  }
  return radius_of_volume(volume_of(s, g1_, g3_));
}

double mass(const SuperEllipse& s, double density) { return density * volume(s); }

// The Dirichlet integral over the positive octant of the unit superellipsoid:
// int x^2 dV = Gamma(3/n) Gamma(1/n)^2 / (n^3 Gamma(1 + 5/n)); eight octants, scaled by a^3 b c
// for x^2 and a b^3 c for y^2.
double inertia_z(const SuperEllipse& s, double density) {
  const double c = std::min(s.a, s.b);
  const double n = s.n;
  const double g = std::tgamma(1.0 / n);
  const double k = 8.0 * std::tgamma(3.0 / n) * g * g / (n * n * n * std::tgamma(1.0 + 5.0 / n));
  return density * s.a * s.b * c * (s.a * s.a + s.b * s.b) * k;
}

// ---- Against walls -----------------------------------------------------------------------------

namespace {

// A wall contact from the body's deepest point p (lab), the unit normal towards the wall, the
// overlap and the point on the wall; pb is p in the body frame (for the curvature).
SuperWallContact make_wall_contact(const SuperEllipse& s, Vec2 centre, Vec2 p, Vec2 pb, Vec2 n,
                                   double delta, Vec2 wall_point) {
  SuperWallContact r;
  r.contact.g.delta = delta;
  r.contact.g.n = n;
  r.contact.g.point = wall_point;
  r.contact.arm = p - centre;
  r.contact.r_eff = curvature_radius(s, pb);
  return r;
}

// One Newton step of the nearest point p (body frame) on the curve to e, with multiplier lam:
// p - e - lam grad F(p) = 0 and F(p) = 0. The Jacobian [[1 - lam F_xx, 0, -F_x],
// [0, 1 - lam F_yy, -F_y], [F_x, F_y, 0]] is solved by elimination. A diagonal 1 - lam F_xx
// at or below 0 means e lies deeper than the curvature radius (not a shallow contact): it is
// kept at 0.1 there, which still descends.
void nearest_point_step(const SuperEllipse& s, Vec2 e, Vec2& p, double& lam, double& dp) {
  const ImplicitValue v = evaluate(s, p);
  const Vec2 r = p - e - lam * v.grad;
  const double dx = std::max(1.0 - lam * v.hess.x, 0.1);
  const double dy = std::max(1.0 - lam * v.hess.y, 0.1);
  const double den = v.grad.x * v.grad.x / dx + v.grad.y * v.grad.y / dy;
  const double dlam = (-v.f + v.grad.x * r.x / dx + v.grad.y * r.y / dy) / den;
  const Vec2 step{(-r.x + v.grad.x * dlam) / dx, (-r.y + v.grad.y * dlam) / dy};
  p += step;
  lam += dlam;
  dp = norm(step);
}

}  // namespace

SuperWallContact contact_point(const SuperEllipse& s, Vec2 centre, double theta, Vec2 e,
                               const SolveOptions& opt) {
  const Vec2 cs = angle_cs(theta);
  const Vec2 eb = to_body(e - centre, cs);
  // Start on the curve where the ray from the centre through e crosses it.
  const NormValue ne = body_norm(s, eb);
  Vec2 p = ne.value > 0.0 ? (1.0 / ne.value) * eb : Vec2{s.a, 0.0};
  Vec2 g = gradient(s, p);
  double lam = dot(p - eb, g) / norm2(g);
  const double scale = bounding_radius(s);
  int k = 0;
  bool converged = false;
  while (k < opt.max_iter && !converged) {
    double dp = 0.0;
    nearest_point_step(s, eb, p, lam, dp);
    ++k;
    converged = dp <= opt.tol * scale;
  }
  g = gradient(s, p);
  const Vec2 nb = (1.0 / norm(g)) * g;
  SuperWallContact r =
      make_wall_contact(s, centre, centre + to_lab(p, cs), p, to_lab(nb, cs), dot(p - eb, nb), e);
  r.iterations = k;
  r.converged = converged;
  return r;
}

// The body's point p farthest from c: there the body's normal u points along p - c. Parametrise
// the curve by the angle phi of its normal u (p = support point along u) and turn u onto p - c:
// that angle map has slope rho / |p - c| (rho the curvature radius at p), below 1 at a maximum
// of |p - c| (the body is more curved than the shell) and above 1 at a minimum (the middle of a
// flat face), so the plain iteration converges to the maxima only, linearly at rate rho / |p - c|.
// Where that rate is below 1/2 the Newton step of the same map (step / (1 - rate)) is taken
// instead: quadratic, and safe there.
SuperWallContact contact_inside_circle(const SuperEllipse& s, Vec2 centre, double theta, Vec2 c,
                                       double R, const SolveOptions& opt) {
  const Vec2 cs = angle_cs(theta);
  const Vec2 d = centre - c;
  double phi = norm2(d) > 0.0 ? std::atan2(d.y, d.x) : 0.0;
  Vec2 pb{}, w{};
  int k = 0;
  bool converged = false;
  while (k < opt.max_iter && !converged) {
    const Vec2 u{std::cos(phi), std::sin(phi)};
    const SupportCurvature sc = support_curvature(s, to_body(u, cs));
    pb = sc.p;
    w = d + to_lab(pb, cs);  // p - c
    const double step = std::atan2(cross(u, w), dot(u, w));
    const double ks = sc.kappa * norm(w);  // |p - c| / rho
    phi += ks > 2.0 ? step * ks / (ks - 1.0) : step;
    ++k;
    converged = std::abs(step) <= opt.tol;
  }
  const double dist = norm(w);
  const Vec2 n = (1.0 / dist) * w;
  SuperWallContact r = make_wall_contact(s, centre, c + w, pb, n, dist - R, c + R * n);
  r.iterations = k;
  r.converged = converged;
  return r;
}

// ---- Two superellipses
// ---------------------------------------------------------------------------

namespace {

// One body of a pair: its shape, centre, rotation (cos, sin) and angle.
struct Body {
  const SuperEllipse* s;
  Vec2 c;
  Vec2 cs;
  double th = 0.0;
};

// F, its gradient and its Hessian (xx, xy, yy) at a lab-frame point.
struct LabValue {
  double f;
  Vec2 g;
  double hxx, hxy, hyy;
};
LabValue lab_value(const Body& b, Vec2 x) {
  const ImplicitValue e = evaluate(*b.s, to_body(x - b.c, b.cs));
  const double c = b.cs.x, s = b.cs.y;
  return {e.f, to_lab(e.grad, b.cs), c * c * e.hess.x + s * s * e.hess.y,
          c * s * (e.hess.x - e.hess.y), s * s * e.hess.x + c * c * e.hess.y};
}

// The midway point's unknowns, its two bodies' values there and the merit
// L^2 |grad F_i + lam grad F_j|^2 + (F_i - F_j)^2 (L a length of the pair: dimensionless).
struct Midway {
  Vec2 x;
  double lam;  // mu^2
  LabValue vi, vj;
  double merit;
};
Midway midway_at(const Body& bi, const Body& bj, Vec2 x, double lam, double L) {
  Midway m{x, lam, lab_value(bi, x), lab_value(bj, x), 0.0};
  const Vec2 r = m.vi.g + lam * m.vj.g;
  const double rf = m.vi.f - m.vj.f;
  m.merit = L * L * norm2(r) + rf * rf;
  return m;
}

double det3(const double m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// The Newton step (dx, dy, dlam) of grad F_i + lam grad F_j = 0, F_i - F_j = 0 by Cramer's rule.
// Jacobian [[H_i + lam H_j, grad F_j], [(grad F_i - grad F_j)^T, 0]]. False if it is singular.
bool newton_step(const Midway& m, double out[3]) {
  const LabValue& a = m.vi;
  const LabValue& b = m.vj;
  const double l = m.lam;
  const double J[3][3] = {{a.hxx + l * b.hxx, a.hxy + l * b.hxy, b.g.x},
                          {a.hxy + l * b.hxy, a.hyy + l * b.hyy, b.g.y},
                          {a.g.x - b.g.x, a.g.y - b.g.y, 0.0}};
  const double rhs[3] = {-(a.g.x + l * b.g.x), -(a.g.y + l * b.g.y), -(a.f - b.f)};
  const double det = det3(J);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
  for (int k = 0; k < 3; ++k) {
    double Jk[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) Jk[r][c] = c == k ? rhs[r] : J[r][c];
    out[k] = det3(Jk) / det;
  }
  return true;
}

// A damped Newton step: the full step shortened to at most `reach`, then halved until the merit
// falls and lam stays positive (at most 30 halvings). False if no such step exists.
bool damped_step(const Body& bi, const Body& bj, double L, double reach, Midway& m) {
  double d[3];
  if (!newton_step(m, d)) return false;
  const double len = std::hypot(d[0], d[1]);
  double alpha = len > reach ? reach / len : 1.0;
  for (int h = 0; h < 30; ++h, alpha *= 0.5) {
    const double lam = m.lam + alpha * d[2];
    if (!(lam > 0.0)) continue;
    const Midway t = midway_at(bi, bj, m.x + alpha * Vec2{d[0], d[1]}, lam, L);
    if (t.merit < m.merit) {
      m = t;
      return true;
    }
  }
  return false;
}

// The overlap of the two bodies' support points along the lab direction u(phi) (i's along u, j's
// along -u): g = u . (p_i - p_j) = h_i(u) + h_j(-u) - u . (x_j - x_i), its derivative
// g' = u_perp . (p_i - p_j) (the support points move along the curves, normal to u) and
// g'' = rho_i + rho_j - g (they move at the curvature radius per radian). Its minimum over phi
// is the penetration depth.
// Within this angle (rad) of a body's axis direction its flat face's Newton variable is used.
constexpr double kFlatReach = 0.1;

struct DepthEval {
  double phi;
  Vec2 u, pi, pj;
  double kappa_i, kappa_j;
  double g, dg, ddg;
};
DepthEval depth_at(const Body& bi, const Body& bj, double phi) {
  DepthEval e{phi, {std::cos(phi), std::sin(phi)}, {}, {}, 0.0, 0.0, 0.0, 0.0, 0.0};
  const SupportCurvature si = support_curvature(*bi.s, to_body(e.u, bi.cs));
  // A body without a shape is a point (a segment's end): its own support, no radius.
  const SupportCurvature sj = bj.s ? support_curvature(*bj.s, to_body(-e.u, bj.cs))
                                   : SupportCurvature{{}, std::numeric_limits<double>::infinity()};
  e.pi = bi.c + to_lab(si.p, bi.cs);
  e.pj = bj.c + to_lab(sj.p, bj.cs);
  e.kappa_i = si.kappa;
  e.kappa_j = sj.kappa;
  const Vec2 w = e.pi - e.pj;
  e.g = dot(e.u, w);
  e.dg = dot(perp(e.u), w);
  e.ddg = 1.0 / si.kappa + 1.0 / sj.kappa - e.g;  // +inf on a flat face's middle
  return e;
}

// Newton's next angle for g' = 0 from e. Near a body's axis direction phi_a (of the body with the
// larger curvature radius there, exponent n > 2), its support point moves as sign(d) |d|^(1/(n-1))
// with d = phi - phi_a (a flat face's middle sweeps by in a tiny angle), so g' is taken as a
// function of s = sign(d) |d|^(1/(n-1)), nearly linear in it, instead of phi. g'' <= 0: a step of
// `reach` downhill; infinite (exactly on an axis, where s is flat): a tiny step off it, downhill.
double newton_angle(const Body& bi, const Body& bj, const DepthEval& e, double reach) {
  if (!(e.ddg > 0.0)) return e.phi - std::copysign(reach, e.dg);
  if (!std::isfinite(e.ddg)) return e.phi - std::copysign(1e-3 * kFlatReach * reach, e.dg);
  const Body& b = e.kappa_i <= e.kappa_j ? bi : bj;
  const double p = b.s->n - 1.0;
  const double quarter = 0.5 * std::numbers::pi;
  const double th = b.th;
  const double phi_a = th + std::round((e.phi - th) / quarter) * quarter;
  const double d = e.phi - phi_a;
  const double plain = e.phi + std::clamp(-e.dg / e.ddg, -reach, reach);
  if (!(p > 1.0) || d == 0.0 || std::abs(d) > kFlatReach) return plain;
  const double sd = std::copysign(std::pow(std::abs(d), 1.0 / p), d);
  const double s1 = sd - e.dg / (e.ddg * p * d / sd);
  const double back = p == std::floor(p) && p <= kMaxWholeExponent
                          ? whole_power(std::abs(s1), static_cast<int>(p))
                          : std::pow(std::abs(s1), p);
  return phi_a + std::copysign(std::min(back, reach), s1);
}

// The penetration depth: the minimum of g over phi from phi0, by Newton on g' = 0 (newton_angle)
// kept inside a bracket [lo, hi] (g' < 0 at lo, > 0 at hi) once one is known; before that steps
// of at most `reach`. A step leaving the bracket, or not halving the previous one, bisects it
// instead. Converged: a Newton step of at most tol (rad), which is not taken.
struct DepthSolve {
  DepthEval e;
  int iterations;
  bool converged;
};
DepthSolve solve_depth(const Body& bi, const Body& bj, double phi0, double reach,
                       const SolveOptions& opt, bool stop_apart = false) {
  DepthSolve r{depth_at(bi, bj, phi0), 1, false};
  double lo = 0.0, hi = 0.0, last = 2.0 * reach;
  bool has_lo = false, has_hi = false;
  while (r.iterations < opt.max_iter) {
    const DepthEval& e = r.e;
    if (stop_apart && e.g < 0.0) {  // a separating axis: apart, the gap along it
      r.converged = true;
      break;
    }
    if (e.dg < 0.0) lo = e.phi, has_lo = true;
    if (e.dg > 0.0) hi = e.phi, has_hi = true;
    double next = newton_angle(bi, bj, e, reach);
    const double step = std::abs(next - e.phi);
    if (e.dg == 0.0 || (step <= opt.tol && std::isfinite(e.ddg))) {
      r.converged = true;
      break;
    }
    if (has_lo && has_hi && (!((next - lo) * (next - hi) < 0.0) || step > 0.5 * last))
      next = 0.5 * (lo + hi);
    last = std::abs(next - e.phi);
    r.e = depth_at(bi, bj, next);
    ++r.iterations;
  }
  return r;
}

// A cold start: the direction of least overlap of the support points among the line of centres
// and kColdDirections directions evenly about it (a coarse separating-axis search: it lands in
// the penetration depth's basin where a start on the line of centres alone can miss it for
// elongated bodies).
constexpr int kColdDirections = 16;
// The directions are dn turned by 2 pi k / kColdDirections, each from the last by one rotation
// (rounding accumulates to a few ulps: the search only picks the start).
double cold_direction(const Body& bi, const Body& bj, Vec2 dn) {
  const double phi_dn = std::atan2(dn.y, dn.x);
  const double turn = 2.0 * std::numbers::pi / kColdDirections;
  const Vec2 step{std::cos(turn), std::sin(turn)};
  double best = phi_dn, least = 0.0;
  Vec2 u = dn;
  for (int k = 0; k < kColdDirections; ++k, u = rotate(u, step)) {
    const double phi = phi_dn + turn * k;
    const Vec2 a = bi.c + to_lab(support(*bi.s, to_body(u, bi.cs)), bi.cs);
    const Vec2 b = bj.c + to_lab(support(*bj.s, to_body(-u, bj.cs)), bj.cs);
    const double overlap = dot(a - b, u);
    if (k == 0 || overlap < least) least = overlap, best = phi;
  }
  return best;
}

// The kernel's cold start: cold_direction's directions taken from dn outwards (k = 0, 1, -1, 2,
// -2, ..., 8), stopping at the first along which the bodies are apart (a separating axis: most
// pairs of a charge whose bounding circles overlap do not touch). For n > 2 the support
// functions' bound |a u_x| + |b u_y| (no pow) is tried first along each. Apart: the gap along
// that axis (negative); else the least overlap's direction (ties to the smaller |k|, then k > 0).
// For n > 2 the two face normals facing the other body are tried before those directions
// (`faces`); `search` false: the face normals alone (not apart: phi_dn, not a start).
struct ColdStart {
  bool apart;
  double phi;
  Vec2 u;
  double overlap;
};
// Whether the lab unit vector u separates the two bodies, with gap: the gap along it (< 0:
// apart), or the overlap of their support points along it. For n > 2 the support functions'
// bound |a u_x| + |b u_y| (no pow) first: a negative gap there is already a separating axis
// (then `gap` is the bound's).
bool apart_along(const Body& bi, const Body& bj, Vec2 u, double& gap) {
  const auto bound = [](const SuperEllipse& s, Vec2 v) {
    return std::abs(s.a * v.x) + std::abs(s.b * v.y);
  };
  const Vec2 ui = to_body(u, bi.cs), uj = to_body(-u, bj.cs);
  const double along = dot(u, bj.c - bi.c);
  if (!(bi.s->n == 2.0 && bj.s->n == 2.0)) {
    gap = bound(*bi.s, ui) + bound(*bj.s, uj) - along;
    if (gap < 0.0) return true;
  }
  gap = dot(support(*bi.s, ui), ui) + dot(support(*bj.s, uj), uj) - along;
  return gap < 0.0;
}
ColdStart separating_or_cold(const Body& bi, const Body& bj, Vec2 dn, double phi_dn, bool faces,
                             bool search) {
  const double turn = 2.0 * std::numbers::pi / kColdDirections;
  const Vec2 step{std::cos(turn), std::sin(turn)}, back{step.x, -step.y};
  const bool ellipses = bi.s->n == 2.0 && bj.s->n == 2.0;
  // The face normals facing the other body: for flat-sided bodies (n > 2) the likeliest
  // separating axes (the separating axis of two rectangles is one of their face normals).
  if (faces && !ellipses)
    for (const Body* b : {&bi, &bj}) {
      const Vec2 toward = b == &bi ? dn : -dn;
      const Vec2 e = b->cs, f = perp(b->cs);
      const double ce = dot(e, toward), cf = dot(f, toward);
      // The axis of the body's angle + quarter turns (0: e, 1: f, 2: -e, 3: -f), from i to j.
      int quarter = std::abs(ce) >= std::abs(cf) ? (ce >= 0.0 ? 0 : 2) : (cf >= 0.0 ? 1 : 3);
      Vec2 u = quarter == 0 ? e : quarter == 1 ? f : quarter == 2 ? -e : -f;
      if (b == &bj) u = -u, quarter += 2;
      double gap = 0.0;
      if (apart_along(bi, bj, u, gap))
        return {true, b->th + 0.5 * std::numbers::pi * quarter, u, gap};
    }
  ColdStart best{false, phi_dn, dn, 0.0};
  Vec2 fwd = dn, bwd = dn;
  for (int m = 0; search && m < kColdDirections; ++m) {
    int k = 0;
    Vec2 u = dn;
    if (m % 2 == 1) {
      fwd = rotate(fwd, step);
      k = (m + 1) / 2;
      u = fwd;
    } else if (m > 0) {
      bwd = rotate(bwd, back);
      k = -m / 2;
      u = bwd;
    }
    const double phi = phi_dn + turn * k;
    double overlap = 0.0;
    if (apart_along(bi, bj, u, overlap)) return {true, phi, u, overlap};
    if (m == 0 || overlap < best.overlap) best = {false, phi, u, overlap};
  }
  return best;
}

// The midway point from x0: damped Newton (at most opt.max_iter steps), mu^2 first balancing the
// gradients' lengths. Steps of at most a quarter of the smallest semi-axis: a longer one can leap
// into a body's middle, where its gradient vanishes and the merit has a false minimum.
Midway solve_midway(const Body& bi, const Body& bj, Vec2 x0, double L, const SolveOptions& opt,
                    int& iterations) {
  Midway m = midway_at(bi, bj, x0, 1.0, L);
  const double gi2 = norm2(m.vi.g), gj2 = norm2(m.vj.g);
  m = midway_at(bi, bj, x0, gj2 > 0.0 && gi2 > 0.0 ? std::sqrt(gi2 / gj2) : 1.0, L);
  const double tol2 = opt.tol * opt.tol;
  const SuperEllipse &si = *bi.s, &sj = *bj.s;
  const double reach = 0.25 * std::min(std::min(si.a, si.b), std::min(sj.a, sj.b));
  iterations = 0;
  while (!(m.merit <= tol2) && iterations < opt.max_iter && damped_step(bi, bj, L, reach, m))
    ++iterations;
  return m;
}

// The contact from the penetration depth's solution: normal, support points, overlap, point,
// arms and the capped curvature radii at the support points.
void finish_pair(const Body& bi, const Body& bj, const DepthEval& e, SuperPairContact& r) {
  r.n = e.u;
  r.p_i = e.pi;
  r.p_j = e.pj;
  r.delta = e.g;
  r.point = 0.5 * (r.p_i + r.p_j);
  r.arm_i = r.point - bi.c;
  r.arm_j = r.point - bj.c;
  r.rho_i = capped_inverse(e.kappa_i, radius_cap(*bi.s));
  r.rho_j = capped_inverse(e.kappa_j, radius_cap(*bj.s));
}

}  // namespace

// Warm: the midway point from the earlier one, then the depth from its normal. Cold: the depth
// from the coarse search, then the midway point from the middle of the support points (near it:
// the midway point lies within the overlap).
SuperPairContact contact_pair(const SuperEllipse& si, const SuperPose& pi, const SuperEllipse& sj,
                              const SuperPose& pj, const Vec2* warm, const SolveOptions& opt) {
  SuperPairContact r;
  const Vec2 d = pj.centre - pi.centre;
  const double dist = norm(d);
  const double Ri = bounding_radius(si), Rj = bounding_radius(sj);
  r.delta = Ri + Rj - dist;
  if (r.delta <= 0.0) return r;  // the bounding circles are apart
  r.candidate = true;
  const Body bi{&si, pi.centre, angle_cs(pi.theta), pi.theta};
  const Body bj{&sj, pj.centre, angle_cs(pj.theta), pj.theta};
  const Vec2 dn = dist > 0.0 ? (1.0 / dist) * d : Vec2{1.0, 0.0};
  const double L = 0.5 * (Ri + Rj);
  const double tol2 = opt.tol * opt.tol;
  const double reach = std::numbers::pi / kColdDirections;
  Midway m{};
  DepthSolve depth{};
  if (warm) {
    m = solve_midway(bi, bj, *warm, L, opt, r.iterations);
    const bool ok = m.merit <= tol2 && norm2(m.vi.g) > 0.0;
    const double phi0 = ok ? std::atan2(m.vi.g.y, m.vi.g.x) : cold_direction(bi, bj, dn);
    depth = solve_depth(bi, bj, phi0, reach, opt);
  } else {
    depth = solve_depth(bi, bj, cold_direction(bi, bj, dn), reach, opt);
    m = solve_midway(bi, bj, 0.5 * (depth.e.pi + depth.e.pj), L, opt, r.iterations);
  }
  r.midway_converged = m.merit <= tol2;
  r.midway = m.x;
  r.mu = std::sqrt(m.lam);
  r.depth_iterations = depth.iterations;
  r.converged = depth.converged;
  finish_pair(bi, bj, depth.e, r);
  return r;
}

// Warm: the depth from the given angle. Cold: the face normals (n > 2), kApartProbe steps of the
// minimisation from the line of centres, then the coarse search from the line of centres
// outwards; each ends at the first separating axis (apart), else the search starts the depth's
// minimisation.
constexpr int kApartProbe = 4;
namespace {

// A deep overlap (beyond kDeepOverlap of the thinner body's smallest semi-axis: fragments born
// inside each other, never a contact of a mill's charge) can have several local minima of the
// overlap over the normal's angle; a solve started near one stays in it, and when that minimum
// vanishes the overlap jumps. There the smallest of all local minima is taken: those of
// kDeepDirections evenly spaced directions, each refined, the lowest kept (with `depth`, the
// solve's own). The global minimum moves continuously with the bodies.
constexpr double kDeepOverlap = 0.25;
constexpr int kDeepDirections = 64;

// A pair found apart by the separating axis u (lab angle phi): the gap along it, converged.
const SuperPairContact& apart(SuperPairContact& r, double gap, Vec2 u, double phi) {
  r.delta = gap;
  r.n = u;
  r.angle = phi;
  r.converged = true;
  return r;
}

void deepest_minimum(const Body& bi, const Body& bj, const SolveOptions& opt, DepthSolve& depth) {
  std::array<double, kDeepDirections> g{};
  for (int k = 0; k < kDeepDirections; ++k)
    g[static_cast<std::size_t>(k)] =
        depth_at(bi, bj, 2.0 * std::numbers::pi * k / kDeepDirections).g;
  for (int k = 0; k < kDeepDirections; ++k) {
    const double here = g[static_cast<std::size_t>(k)];
    const double before = g[static_cast<std::size_t>((k + kDeepDirections - 1) % kDeepDirections)];
    const double after = g[static_cast<std::size_t>((k + 1) % kDeepDirections)];
    if (!(here <= before && here <= after)) continue;
    const DepthSolve local = solve_depth(bi, bj, 2.0 * std::numbers::pi * k / kDeepDirections,
                                         std::numbers::pi / kDeepDirections, opt, false);
    if (local.e.g < depth.e.g) {
      const int spent = depth.iterations;
      depth = local;
      depth.iterations += spent;
    }
  }
}

}  // namespace

SuperPairContact contact_depth(const SuperEllipse& si, const SuperPose& pi, const SuperEllipse& sj,
                               const SuperPose& pj, const DepthStart& start,
                               const SolveOptions& opt) {
  SuperPairContact r;
  const Vec2 d = pj.centre - pi.centre;
  const double dist = std::sqrt(rounded(d.x * d.x) + rounded(d.y * d.y));
  const double Ri = start.bound_i > 0.0 ? start.bound_i : bounding_radius(si);
  const double Rj = start.bound_j > 0.0 ? start.bound_j : bounding_radius(sj);
  r.delta = Ri + Rj - dist;
  if (r.delta <= 0.0) return r;  // the bounding circles are apart
  r.candidate = true;
  const Body bi{&si, pi.centre, pose_rotation(pi), pi.theta};
  const Body bj{&sj, pj.centre, pose_rotation(pj), pj.theta};
  const Vec2 dn = dist > 0.0 ? (1.0 / dist) * d : Vec2{1.0, 0.0};
  double phi0 = start.phi;
  if (!start.warm) {
    double gap = 0.0;
    const bool ellipses = si.n == 2.0 && sj.n == 2.0;
    if (ellipses && (start.axis.x != 0.0 || start.axis.y != 0.0) &&
        apart_along(bi, bj, start.axis, gap))
      return apart(r, gap, start.axis, 0.0);
    const double phi_dn = std::atan2(dn.y, dn.x);
    const ColdStart faces = separating_or_cold(bi, bj, dn, phi_dn, true, false);
    if (faces.apart) return apart(r, faces.overlap, faces.u, faces.phi);
    // A few steps of the minimisation from the line of centres first: most pairs apart show a
    // negative overlap within them (the overlap falls towards the direction of closest approach).
    SolveOptions few = opt;
    few.max_iter = std::min(opt.max_iter, kApartProbe);
    const DepthSolve probe = solve_depth(bi, bj, phi_dn, std::numbers::pi / kColdDirections, few,
                                         /*stop_apart=*/true);
    if (probe.e.g < 0.0) return apart(r, probe.e.g, probe.e.u, probe.e.phi);
    const ColdStart cold = separating_or_cold(bi, bj, dn, phi_dn, false, true);
    if (cold.apart) return apart(r, cold.overlap, cold.u, cold.phi);
    phi0 = cold.phi;
  }
  DepthSolve depth =
      solve_depth(bi, bj, phi0, std::numbers::pi / kColdDirections, opt, /*stop_apart=*/true);
  const double thinnest = std::min(std::min(si.a, si.b), std::min(sj.a, sj.b));
  if (depth.e.g > kDeepOverlap * thinnest) deepest_minimum(bi, bj, opt, depth);
  r.depth_iterations = depth.iterations;
  r.converged = depth.converged;
  r.angle = depth.e.phi;
  finish_pair(bi, bj, depth.e, r);
  return r;
}

// ---- A segment (after the pair: its ends use the pair's 1D minimisation) ----------------------

namespace {

// Past the segment's end e (t_out: along the segment, out of it at e): the body against the end
// alone, o_e(u) = h(u) - u . e minimised over the angle of u from the face's normal -m, downhill
// (away from t_out: the deepest point lies past e), by the pair's 1D minimisation with e as a
// body of no size. Kept if its normal stays on e's side (u . t_out <= 0), else `face`.
SuperWallContact past_an_end(const SuperEllipse& s, Vec2 centre, double theta, Vec2 e, Vec2 m,
                             Vec2 t_out, const SuperWallContact& face, const SolveOptions& opt) {
  const Body body{&s, centre, angle_cs(theta), theta};
  const Body end{nullptr, e, {1.0, 0.0}, 0.0};
  const double reach = 0.125 * std::numbers::pi;
  const DepthSolve d = solve_depth(body, end, std::atan2(-m.y, -m.x), reach, opt);
  if (!(dot(d.e.u, t_out) <= 0.0) || !(d.e.g < face.contact.g.delta)) {
    SuperWallContact r = face;
    r.iterations = d.iterations;
    r.converged = d.converged;
    return r;
  }
  SuperWallContact r;
  r.contact.g = {d.e.g, d.e.u, e};
  r.contact.arm = d.e.pi - centre;
  r.contact.r_eff = capped_inverse(d.e.kappa_i, radius_cap(s));
  r.iterations = d.iterations;
  r.converged = d.converged;
  return r;
}

}  // namespace

// The penetration depth of the body and the segment: the minimum over directions u (from the body
// to the wall) of max(o_a(u), o_b(u)), o_e(u) = h(u) - u . e the body's overlap with the end e
// along u (h its support function). o_a - o_b = u . (b - a): o_b is the larger where u . t <= 0 (t
// from a to b), o_a where u . t >= 0, and they meet at u = -m, where both are the face's overlap -h
// (the wall's side is the one away from the body's centre: u = +m is left out). When the deepest
// point along -m projects onto the segment, -m is a local minimum: the face's contact (the disc's
// case). Past an end e the overlap falls from -m into e's half: its minimum there (past_an_end). A
// thin tilted body crossing the segment near its end this way has a positive overlap though the
// end's own point contact (nearest point) can read as no contact.
SuperWallContact contact_segment(const SuperEllipse& s, Vec2 centre, double theta, Vec2 a, Vec2 b,
                                 const SolveOptions& opt) {
  const Vec2 ab = b - a;
  const double len2 = norm2(ab);
  if (!(len2 > 0.0)) return contact_point(s, centre, theta, a, opt);
  const double len = std::sqrt(len2);
  const Vec2 t = (1.0 / len) * ab;
  Vec2 m = perp(t);  // the line's unit normal on the body's side
  if (dot(m, centre - a) < 0.0) m = -m;
  // The deepest point beyond the line: the support point along -m (towards the wall).
  const Vec2 cs = angle_cs(theta);
  const Vec2 pb = support(s, to_body(-m, cs));
  const Vec2 p = centre + to_lab(pb, cs);
  const double along = dot(p - a, t);
  const double h = dot(p - a, m);  // < 0 beyond the line
  if (along >= 0.0 && along <= len) return make_wall_contact(s, centre, p, pb, -m, -h, p - h * m);
  // Past an end: the face's candidate acts at that end (its point on the wall), at the depth -h.
  const Vec2 e = along < 0.0 ? a : b;
  SuperWallContact face = make_wall_contact(s, centre, p, pb, -m, -h, e);
  face.contact.arm = e + h * m - centre;  // the wall point + delta n
  return past_an_end(s, centre, theta, e, m, along < 0.0 ? -t : t, face, opt);
}

}  // namespace dem2d
