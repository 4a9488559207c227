// The superellipse's geometry (core/shape/superellipse.hpp): the implicit function, support
// points, curvature, mass and inertia, and the contacts against walls and another superellipse.
#include "core/shape/superellipse.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dem2d {

namespace {

Vec2 angle_cs(double theta) { return {std::cos(theta), std::sin(theta)}; }
// A lab-frame vector in the body frame of a body turned by the rotation (cos, sin) = cs, and back.
Vec2 to_body(Vec2 v, Vec2 cs) { return rotate(v, Vec2{cs.x, -cs.y}); }
Vec2 to_lab(Vec2 v, Vec2 cs) { return rotate(v, cs); }

// One coordinate's share of F, its derivative and its second derivative: with u = |x|/a,
// u^n, sign(x) n/a u^(n-1) and n(n-1)/a^2 u^(n-2). u^(n-2) is taken once by pow: it is 1 at
// u = 0 for n = 2 (pow(0, 0) = 1) and 0 there for n > 2, finite for every n >= 2.
struct AxisTerm {
  double f, g, h;
};
AxisTerm axis_term(double x, double a, double n) {
  const double u = std::min(std::abs(x) / a, kMaxScaled);
  const double w = std::pow(u, n - 2.0);
  const double u1 = w * u;
  return {u1 * u, std::copysign(n / a * u1, x), n * (n - 1.0) / (a * a) * w};
}

// The cap of the curvature radius of one body.
double radius_cap(const SuperEllipse& s) { return kCurvatureRadiusCap * equivalent_radius(s); }

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
  const double q = 1.0 / (s.n - 1.0);
  const double sx = std::pow(ax / m, q);
  const double sy = std::pow(by / m, q);
  const double inv_norm = 1.0 / std::pow(sx * (ax / m) + sy * (by / m), 1.0 / s.n);
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

double volume(const SuperEllipse& s) {
  const double c = std::min(s.a, s.b);
  const double g1 = std::tgamma(1.0 + 1.0 / s.n);
  return 8.0 * s.a * s.b * c * g1 * g1 * g1 / std::tgamma(1.0 + 3.0 / s.n);
}

double equivalent_radius(const SuperEllipse& s) {
  return std::cbrt(3.0 * volume(s) / (4.0 * std::numbers::pi));
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
  if (along < 0.0 || along > len) return contact_point(s, centre, theta, along < 0.0 ? a : b, opt);
  const double h = dot(p - a, m);  // < 0 beyond the line
  return make_wall_contact(s, centre, p, pb, -m, -h, p - h * m);
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
    pb = support(s, to_body(u, cs));
    w = d + to_lab(pb, cs);  // p - c
    const double step = std::atan2(cross(u, w), dot(u, w));
    const double ks = curvature(s, pb) * norm(w);  // |p - c| / rho
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

// One body of a pair: its shape, centre and rotation (cos, sin).
struct Body {
  const SuperEllipse* s;
  Vec2 c;
  Vec2 cs;
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

// The root t of (F + 1)^(1/n) = 1 along x + t n nearest to t = 0 (Newton on the body's norm,
// nearly linear along a line; at most 12 steps, to 1e-15 of the bounding radius).
double surface_along(const Body& b, Vec2 x, Vec2 n) {
  const Vec2 xb = to_body(x - b.c, b.cs);
  const Vec2 nb = to_body(n, b.cs);
  const double stop = 1.0e-15 * bounding_radius(*b.s);
  double t = 0.0;
  for (int k = 0; k < 12; ++k) {
    const NormValue v = body_norm(*b.s, xb + t * nb);
    const double slope = dot(v.grad, nb);
    if (!(std::abs(slope) > 0.0)) break;
    const double dt = (1.0 - v.value) / slope;
    t += dt;
    if (std::abs(dt) <= stop) break;
  }
  return t;
}

// The contact's points, overlap, arms and radii from the normal n and the surface points.
void finish_pair(const SuperEllipse& si, const SuperEllipse& sj, const Body& bi, const Body& bj,
                 SuperPairContact& r) {
  r.delta = dot(r.p_i - r.p_j, r.n);
  r.point = 0.5 * (r.p_i + r.p_j);
  r.arm_i = r.point - bi.c;
  r.arm_j = r.point - bj.c;
  r.rho_i = curvature_radius(si, to_body(r.p_i - bi.c, bi.cs));
  r.rho_j = curvature_radius(sj, to_body(r.p_j - bj.c, bj.cs));
}

// A cold start: midway between the two support points (i's along u, j's against u) on the
// direction u of least overlap among the line of centres and kColdDirections directions evenly
// about it (a coarse separating-axis search). The line of centres alone can start deep inside
// one elongated body, where the merit has stationary points other than the solution.
constexpr int kColdDirections = 16;
Vec2 cold_start(const SuperEllipse& si, const SuperPose& pi, const SuperEllipse& sj,
                const SuperPose& pj, Vec2 dn) {
  Vec2 best{};
  double least = 0.0;
  for (int k = 0; k < kColdDirections; ++k) {
    const double ang = 2.0 * std::numbers::pi * k / kColdDirections;
    const Vec2 u = rotate(dn, ang);
    const Vec2 a = support_lab(si, pi.centre, pi.theta, u);
    const Vec2 b = support_lab(sj, pj.centre, pj.theta, -u);
    const double overlap = dot(a - b, u);
    if (k == 0 || overlap < least) least = overlap, best = 0.5 * (a + b);
  }
  return best;
}

}  // namespace

SuperPairContact contact_pair(const SuperEllipse& si, const SuperPose& pi, const SuperEllipse& sj,
                              const SuperPose& pj, const Vec2* warm, const SolveOptions& opt) {
  SuperPairContact r;
  const Vec2 d = pj.centre - pi.centre;
  const double dist = norm(d);
  const double Ri = bounding_radius(si), Rj = bounding_radius(sj);
  r.delta = Ri + Rj - dist;
  if (r.delta <= 0.0) return r;  // the bounding circles are apart
  r.candidate = true;
  const Body bi{&si, pi.centre, angle_cs(pi.theta)};
  const Body bj{&sj, pj.centre, angle_cs(pj.theta)};
  const Vec2 dn = dist > 0.0 ? (1.0 / dist) * d : Vec2{1.0, 0.0};
  const double L = 0.5 * (Ri + Rj);
  // Start: the warm point, else the cold start below; mu^2 balances the gradients' lengths.
  const Vec2 x0 = warm ? *warm : cold_start(si, pi, sj, pj, dn);
  Midway m = midway_at(bi, bj, x0, 1.0, L);
  const double gi2 = norm2(m.vi.g), gj2 = norm2(m.vj.g);
  m = midway_at(bi, bj, x0, gj2 > 0.0 && gi2 > 0.0 ? std::sqrt(gi2 / gj2) : 1.0, L);
  const double tol2 = opt.tol * opt.tol;
  // Steps of at most a quarter of the smallest semi-axis: a longer one can leap into a body's
  // middle, where its gradient vanishes and the merit has a false minimum.
  const double reach = 0.25 * std::min(std::min(si.a, si.b), std::min(sj.a, sj.b));
  while (!(m.merit <= tol2) && r.iterations < opt.max_iter && damped_step(bi, bj, L, reach, m))
    ++r.iterations;
  r.converged = m.merit <= tol2;
  if (r.converged) {
    r.midway = m.x;
    r.mu = std::sqrt(m.lam);
    r.n = (1.0 / norm(m.vi.g)) * m.vi.g;
    r.p_i = m.x + surface_along(bi, m.x, r.n) * r.n;
    r.p_j = m.x + surface_along(bj, m.x, r.n) * r.n;
  } else {  // the line of centres and the support points along it
    r.n = dn;
    r.p_i = support_lab(si, pi.centre, pi.theta, dn);
    r.p_j = support_lab(sj, pj.centre, pj.theta, -dn);
    r.midway = 0.5 * (r.p_i + r.p_j);
  }
  finish_pair(si, sj, bi, bj, r);
  return r;
}

}  // namespace dem2d
