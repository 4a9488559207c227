// The superellipse |x/a|^n + |y/b|^n = 1: the geometry of the first non-round particle shape, as
// plain functions (the kernel's shape slot is built on them later; docs/extending.md, "A particle
// shape"). Everything here is in SI units (metres, kilograms, radians).
//
// Frames: the body frame has the curve's centre at the origin and its semi-axes a (along x) and
// b (along y); the lab frame places it at `centre`, turned counter-clockwise by `theta`:
// lab = centre + rotate(body, theta). Functions taking a pose work in the lab frame.
//
// Domain: a, b > 0 and 2 <= n <= kMaxExponent (n = 2 an ellipse, large n a rounded box). The
// implicit function is evaluated with the scaled coordinates |x|/a, |y|/b clamped at kMaxScaled
// so that their n-th powers stay finite: points farther than 10^6 semi-axes from the body give
// finite but meaningless values (nothing in a contact goes there).
//
// The 3D body a superellipse stands for (mass, inertia): the superellipsoid |x/a|^n + |y/b|^n +
// |z/c|^n <= 1 with c = min(a, b), lying in the plane with its smallest extent along the drum's
// axis. For a = b and n = 2 it is the sphere of radius a, so discs and superellipses agree.
//
// Nothing here throws or allocates; the iterative functions have a tolerance and an iteration
// cap and say how many iterations they took and whether they converged.
#pragma once

#include "core/base/vec2.hpp"
#include "core/shape/disc.hpp"

namespace dem2d {

struct SuperEllipse {
  double a = 0.0;  // semi-axis along the body's x (m)
  double b = 0.0;  // semi-axis along the body's y (m)
  double n = 2.0;  // exponent, 2 <= n <= kMaxExponent
};

inline constexpr double kMaxExponent = 50.0;
// Scaled coordinates |x|/a beyond this are clamped (kMaxScaled^kMaxExponent = 1e300 is finite).
inline constexpr double kMaxScaled = 1.0e6;
// The curvature radius is capped at this multiple of the volume-equivalent radius: the flat
// faces of a large exponent have radii growing without bound (infinite at the face's middle
// for n > 2), which a Hertz law must not see.
inline constexpr double kCurvatureRadiusCap = 10.0;

// ---- The implicit function F = |x/a|^n + |y/b|^n - 1 (body frame) -----------------------------

// F, its gradient and its Hessian at a body-frame point. The Hessian is diagonal in the body
// frame: hess = (F_xx, F_yy). One pow per coordinate.
struct ImplicitValue {
  double f = 0.0;
  Vec2 grad{};
  Vec2 hess{};
};
ImplicitValue evaluate(const SuperEllipse& s, Vec2 p);
inline double implicit(const SuperEllipse& s, Vec2 p) { return evaluate(s, p).f; }
inline Vec2 gradient(const SuperEllipse& s, Vec2 p) { return evaluate(s, p).grad; }
inline Vec2 hessian(const SuperEllipse& s, Vec2 p) { return evaluate(s, p).hess; }

// ---- Support points and curvature ---------------------------------------------------------------

// The point of the curve farthest along the body-frame unit direction u (closed form: the
// gradient of F is parallel to u there).
Vec2 support(const SuperEllipse& s, Vec2 u);
// The same in the lab frame: the body at `centre` turned by `theta`, u a lab-frame unit vector.
Vec2 support_lab(const SuperEllipse& s, Vec2 centre, double theta, Vec2 u);

// Curvature kappa = (F_y^2 F_xx + F_x^2 F_yy) / |grad F|^3 of the level curve through the
// body-frame point p (on the curve: the curve's own curvature). Uncapped: 0 at a face's middle
// for n > 2.
double curvature(const SuperEllipse& s, Vec2 p);
// 1 / kappa at a point of the curve, capped at kCurvatureRadiusCap * equivalent_radius(s).
double curvature_radius(const SuperEllipse& s, Vec2 p);

// ---- Size, mass and inertia ------------------------------------------------------------------

// Bounding radius: the smallest circle about the centre that holds the curve (max(a, b) for
// n = 2; the rounded corners reach beyond it for n > 2).
double bounding_radius(const SuperEllipse& s);
// The 2D area 4ab Gamma(1+1/n)^2 / Gamma(1+2/n).
double area(const SuperEllipse& s);
// The superellipsoid's volume 8abc Gamma(1+1/n)^3 / Gamma(1+3/n), c = min(a, b).
double volume(const SuperEllipse& s);
// The radius of the sphere of the same volume.
double equivalent_radius(const SuperEllipse& s);
double mass(const SuperEllipse& s, double density);
// Moment of inertia about the z axis through the centre (the drum's axis direction):
// rho a b c (a^2 + b^2) 8 Gamma(3/n) Gamma(1/n)^2 / (n^3 Gamma(1+5/n)).
double inertia_z(const SuperEllipse& s, double density);

// ---- Against walls -----------------------------------------------------------------------------

// A superellipse against a wall element. contact.g: overlap (> 0 in contact), the unit normal
// from the body towards the wall, the contact point on the wall. contact.arm: from the centre to
// the body's deepest point (the disc's general path takes r n, the same point). contact.r_eff:
// the curvature radius at that point (capped). iterations / converged: of the iterative ones.
struct SuperWallContact {
  WallContact contact;
  int iterations = 0;
  bool converged = true;
};

struct SolveOptions {
  double tol = 1.0e-10;  // dimensionless (see each function)
  int max_iter = 30;
};

// Against the segment [a, b] with rounded ends (Disc::segment's convention). The wall's side is
// the one away from the body's centre. The deepest point of the body beyond the segment's line
// is the support point along the normal towards the wall (closed form); when it projects onto
// the segment the contact is that face's, else the nearer end's (a point contact, below).
SuperWallContact contact_segment(const SuperEllipse& s, Vec2 centre, double theta, Vec2 a, Vec2 b,
                                 const SolveOptions& opt = {});
// Inside the circle of centre c and radius R (the drum's shell): the body's point farthest
// from c. Iterates on the direction of the body's normal (see the source); tol: on that angle
// (rad).
SuperWallContact contact_inside_circle(const SuperEllipse& s, Vec2 centre, double theta, Vec2 c,
                                       double R, const SolveOptions& opt = {});
// Against the point e (a lifter's corner, a segment's end): the body's boundary point nearest to
// e; overlap > 0 when e is inside, -distance when outside. Newton on the point and its
// multiplier; tol: on the step, relative to the bounding radius.
SuperWallContact contact_point(const SuperEllipse& s, Vec2 centre, double theta, Vec2 e,
                               const SolveOptions& opt = {});

// ---- Two superellipses: the midway-point method ------------------------------------------------

// One body's place: centre of mass and angle (lab frame).
struct SuperPose {
  Vec2 centre{};
  double theta = 0.0;
};

struct SuperPairContact {
  bool candidate = false;  // the bounding circles overlap (else nothing below is set but delta)
  bool converged = false;  // the midway point converged; false: the fallback below
  int iterations = 0;      // Newton steps of the midway point
  Vec2 midway{};           // X: grad F_i(X) + mu^2 grad F_j(X) = 0, F_i(X) = F_j(X)
  double mu = 0.0;
  Vec2 n{};                         // unit normal from i towards j (grad F_i at X, normalised)
  Vec2 p_i{}, p_j{};                // surface points of i and j on the line X + t n
  double delta = 0.0;               // (p_i - p_j) . n, > 0 in contact
  Vec2 point{};                     // contact point (p_i + p_j) / 2
  Vec2 arm_i{}, arm_j{};            // contact point minus each centre
  double rho_i = 0.0, rho_j = 0.0;  // curvature radii at p_i and p_j (capped)
};

// Two superellipses. `warm`: the midway point of an earlier step (nullptr: start from the
// point midway in the bounding circles' overlap on the line of centres). tol: on the scaled
// residual of the three equations; max_iter: Newton steps. Not converged: the normal along the
// line of centres and the overlap of the two support points along it (the separating-axis
// overlap on that axis, at least the true one), flagged converged = false.
SuperPairContact contact_pair(const SuperEllipse& si, const SuperPose& pi, const SuperEllipse& sj,
                              const SuperPose& pj, const Vec2* warm = nullptr,
                              const SolveOptions& opt = {});

}  // namespace dem2d
