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
// 1 / kappa at a point of the curve, capped at kCurvatureRadiusCap * equivalent_radius(s). The cap
// (three Gamma functions) is remembered for the last two shapes asked for on the calling thread.
double curvature_radius(const SuperEllipse& s, Vec2 p);
// The same with the cap given (curvature_radius_cap(s), kept with the shape by the caller).
double curvature_radius(const SuperEllipse& s, Vec2 p, double cap);
// kCurvatureRadiusCap * equivalent_radius(s).
double curvature_radius_cap(const SuperEllipse& s);

// support(s, u) and the curve's curvature there (the same as curvature(s, support(s, u)), without
// the extra pow).
struct SupportCurvature {
  Vec2 p{};
  double kappa = 0.0;
};
SupportCurvature support_curvature(const SuperEllipse& s, Vec2 u);

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
// equivalent_radius with the Gamma functions of the last exponent kept: the same bits, without
// two Gamma functions per call while the exponent repeats (an ore charge's fragments share their
// parent's exponent).
class EquivalentRadii {
 public:
  double operator()(const SuperEllipse& s);

 private:
  double n_ = 0.0, g1_ = 0.0, g3_ = 0.0;  // the exponent, Gamma(1 + 1/n), Gamma(1 + 3/n)
};
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
// the one away from the body's centre. The overlap is the penetration depth of the body and the
// segment (the minimum translation separating them; the side towards the centre left out): the
// face's when the body's deepest point beyond the segment's line (the support point along the
// normal towards the wall, closed form) projects onto the segment (iterations = 0); past an end,
// the body's overlap with that end minimised over the normal's angle from the face's normal (as
// for a pair, below; tol on the angle), kept while the normal stays on the end's side, else the
// face's overlap acting at the end. A thin body tilted across the segment near its end so keeps
// its overlap, where the end's nearest point (contact_point) would read as no contact.
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

// ---- Two superellipses: the penetration depth -------------------------------------------------

// The contact of two superellipses is their penetration depth (the minimum translation distance of
// two convex bodies): delta = min over unit u of h_i(u) + h_j(-u) - u . (x_j - x_i), h the support
// functions (support()), u at the minimum the normal n and the support points p_i (of i along n)
// and p_j (of j along -n) where the curves' normals are +-n. Bodies apart (within the bounding
// circles) give -distance. It is solved as a 1D minimisation over the angle of u (Newton on the
// derivative inside a bracket, closed-form support points and curvatures, near a flat face in a
// variable that straightens it), started from the midway point's normal (warm) or the best of 16
// directions (cold). The contact point (p_i + p_j) / 2 is ill-conditioned where two flat faces
// meet near-parallel: the support points slide along a face for a tiny turn of the normal.
//
// The midway point X (F_i(X) = F_j(X), grad F_i(X) + mu^2 grad F_j(X) = 0: where the level sets
// F_i = F_j = c first touch as c grows) is solved as well by contact_pair, as a warm start a caller
// can carry from step to step (cold: from the depth's support points); the force kernel carries
// the depth's own normal instead (contact_depth, below), which needs no midway solve. The
// midway point's normal grad F_i(X) and the overlap along it are not the contact's: the level sets
// F = c are not parallel to the curve, so they differ from the penetration depth's at first order
// in the overlap (over the test's poses, overlaps 0.1-5 % of the size: median 3e-4 rad and 4e-4 of
// the overlap, up to 6e-2 rad and 5e-2).

// One body's place: centre of mass and angle (lab frame). rot: (cos theta, sin theta) when the
// caller has them (the force kernel takes them once per body and evaluation), else zero: taken
// here from theta (the same functions of the same angle, so the same bits either way).
struct SuperPose {
  Vec2 centre{};
  double theta = 0.0;
  Vec2 rot{};
};

struct SuperPairContact {
  bool candidate = false;  // the bounding circles overlap (else nothing below is set but delta)
  bool converged = false;  // the penetration depth converged (below)
  int iterations = 0;      // Newton steps of the midway point
  Vec2 midway{};           // X: grad F_i(X) + mu^2 grad F_j(X) = 0, F_i(X) = F_j(X)
  double mu = 0.0;
  Vec2 n{};                         // unit normal from i towards j: the penetration depth's
  Vec2 p_i{}, p_j{};                // support points of i along n and of j along -n
  double delta = 0.0;               // (p_i - p_j) . n: the penetration depth, > 0 in contact
  Vec2 point{};                     // contact point (p_i + p_j) / 2
  Vec2 arm_i{}, arm_j{};            // contact point minus each centre
  double rho_i = 0.0, rho_j = 0.0;  // curvature radii at p_i and p_j (capped)
  bool midway_converged = false;    // the midway point converged (else midway: its last iterate)
  int depth_iterations = 0;         // evaluations of the penetration depth's 1D minimisation
  double angle = 0.0;               // the normal's lab angle: n = (cos, sin) of it
};

// Two superellipses. `warm`: the midway point of an earlier step (nullptr: a cold start). tol: on
// the midway point's scaled residual and on the normal's angle (rad); max_iter: Newton steps of
// each. Not converged (converged = false): the last iterate of the depth's minimisation, an overlap
// along a direction near the normal (at least the true depth).
SuperPairContact contact_pair(const SuperEllipse& si, const SuperPose& pi, const SuperEllipse& sj,
                              const SuperPose& pj, const Vec2* warm = nullptr,
                              const SolveOptions& opt = {});

// The penetration depth alone, without the midway point: the force kernel's solve. `start.warm`:
// start from the lab angle start.phi (the normal of a nearby pose, such as the same contact's
// last step: 2-3 evaluations), else from the coarse search of the cold start (contact_pair's
// directions, taken from the line of centres outwards). start.bound_i, bound_j: the bounding
// radii if known (0: computed here). The search stops at the first separating axis it meets
// (for n > 2 the face normals facing the other body, then a few steps of the minimisation from
// the line of centres, then the coarse directions, then the minimisation's iterates):
// apart, with delta < 0 the gap along that axis (not the distance) and n along it, converged.
// Overlapping bodies get contact_pair's contact (to the tolerance: its start may differ by
// rounding). The midway fields are left unset.
// start.axis (cold starts of two ellipses only; zero: none): a lab-frame unit vector that separated
// the two bodies at an earlier step (the force kernel remembers the `n` of pairs found apart). It
// is tried before everything else, by the same test as the search's directions; when it separates
// them the pair is apart (delta: the gap along it, n: it, angle left 0), else the solve goes on
// exactly as without it. It proves the bodies apart and nothing more. Not for n > 2: there the
// solve below can end at a small positive overlap (up to 2.2e-6 m seen, for bodies of bounding
// radius 0.1 m) on two near-parallel flat faces of bodies that an earlier step's axis still shows
// apart (the minimisation's false convergence next to a face's middle, docs/performance.md), so the
// axis would turn such contacts into pairs apart and change the results.
struct DepthStart {
  bool warm = false;
  double phi = 0.0;
  double bound_i = 0.0, bound_j = 0.0;
  Vec2 axis{};
};
SuperPairContact contact_depth(const SuperEllipse& si, const SuperPose& pi, const SuperEllipse& sj,
                               const SuperPose& pj, const DepthStart& start = {},
                               const SolveOptions& opt = {});

}  // namespace dem2d
