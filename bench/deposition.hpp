// deposition.hpp: a packing of discs in a circular drum built without dynamics, by sequential
// deposition (bench/settled_drum.hpp uses it for the charges too large to settle by dynamics).
//
// Each disc is dropped at a given x from above everything and moved quasi-statically under
// gravity, with no friction and no inertia: it falls straight down until it touches a disc or
// the drum wall (the circle of radius R centred at the origin), then rolls on that support,
// downhill, until it touches a second one. It stays there if gravity lies in the cone of the two
// contact normals (both supports push, none pulls); otherwise it lets go of the support that
// would have to pull and rolls on the other. A disc that rolls past the equator of its support
// falls again. Every disc thus rests on two supports (the first one on the wall's lowest point),
// touching them at zero overlap: the packing has no voids and every disc is held, which is what
// a packing tiled from copies of a smaller one lacked (bench/settled_drum.hpp, header).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/base/vec2.hpp"

namespace bench {

class Deposition {
 public:
  // Discs of radius at most r_max in the drum of radius R.
  Deposition(double R, double r_max) : R_(R), r_max_(r_max), h_(2.0 * r_max) {
    n_ = static_cast<int>(std::ceil(2.0 * R / h_)) + 1;
    head_.assign(static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_), -1);
    top_.assign(static_cast<std::size_t>(n_), -std::numeric_limits<double>::infinity());
  }

  const std::vector<dem2d::Vec2>& positions() const { return x_; }
  const std::vector<double>& radii() const { return r_; }
  std::int64_t rolls() const { return rolls_; }  // supports rolled on, over all drops

  // The height at which a disc of radius r dropped at x would first touch something.
  double landing(double x, double r) const {
    dem2d::Vec2 c{x, std::numeric_limits<double>::infinity()};
    fall(c, r, -2);
    return c.y;
  }

  // Drop a disc of radius r at x (|x| <= R - r); `tie` breaks the one undecided case (a disc
  // landing exactly on the top of another). Returns where it rests.
  dem2d::Vec2 drop(double x, double r, bool tie) {
    const double rw = R_ - r;  // the wall's circle for this disc's centre
    if (!(std::abs(x) <= rw)) throw std::runtime_error("deposition: drop outside the drum");
    dem2d::Vec2 c{x, std::numeric_limits<double>::infinity()};
    int support = fall(c, r, -2);
    for (int move = 0;; ++move) {
      if (move > 10000) throw std::runtime_error("deposition: a disc found no rest");
      ++rolls_;
      // Roll on `support` (-1: the wall) from c, downhill, to the end of its arc.
      Arc arc{{0.0, 0.0}, rw, std::atan2(c.y, c.x), -1.0, -0.5 * std::numbers::pi};
      if (support >= 0) {
        arc.p = x_[static_cast<std::size_t>(support)];
        arc.rho = r + r_[static_cast<std::size_t>(support)];
        arc.theta0 = std::atan2(c.y - arc.p.y, c.x - arc.p.x);
        if (!(std::sin(arc.theta0) > 0.0)) {  // at or below its support's equator: falls off
          support = fall(c, r, support);
          continue;
        }
        const bool right = c.x > arc.p.x || (c.x == arc.p.x && tie);
        arc.dir = right ? -1.0 : 1.0;
        arc.theta_end = right ? 0.0 : std::numbers::pi;
      } else {
        if (!(c.y < 0.0))
          throw std::runtime_error(
              "deposition: a disc reached the drum's wall above its centre "
              "(the charge is deeper than the drum's lower half)");
        if (c.x == 0.0) break;  // the lowest point of the wall
        if (c.x < 0.0 && arc.theta0 > 0.0) arc.theta0 -= 2.0 * std::numbers::pi;
        arc.dir = c.x > 0.0 ? -1.0 : 1.0;
      }
      const auto [travel, hit] = first_obstacle(arc, r, support);
      const double theta = arc.theta0 + arc.dir * travel;
      c = arc.p + arc.rho * dem2d::Vec2{std::cos(theta), std::sin(theta)};
      if (hit == kNothing) {     // nothing on the way
        if (support < 0) break;  // the lowest point of the wall
        support = fall(c, r, support);
        continue;
      }
      // Two supports: gravity in the cone of their normals (a n_s + b n_h = up, both >= 0)?
      const dem2d::Vec2 ns = normal_from(support, c), nh = normal_from(hit, c);
      const double det = ns.x * nh.y - ns.y * nh.x;
      const double a = -nh.x / det, b = ns.x / det;
      // b < 0 (the disc met would pull) cannot happen for an obstacle met downhill; rounding
      // that says so is read as rest, never as a licence to roll through the obstacle.
      if (std::abs(det) < 1e-12 || a >= 0.0 || b < 0.0) break;
      support = hit;  // the old support would pull: roll on the one met (moving away from the
                      // old one, whose interval of contact angles is left behind)
    }
    add(c, r);
    return c;
  }

 private:
  static constexpr int kNothing = -3;  // first_obstacle: the arc is free to its end

  // The arc a rolling disc's centre follows: centre p, radius rho, from angle theta0 in the
  // direction dir (+1 counterclockwise) to theta_end.
  struct Arc {
    dem2d::Vec2 p;
    double rho, theta0, dir, theta_end;
  };

  // The first obstacle on the arc of a disc of radius r rolling on `support`: the angle travelled
  // to it and what it is (a disc, -1: the wall, kNothing: none up to theta_end).
  std::pair<double, int> first_obstacle(const Arc& arc, double r, int support) const {
    double best = std::abs(arc.theta_end - arc.theta0);
    int hit = kNothing;
    // The arc's points on one side of a circle form an interval of angles about `centre`
    // (half-width `half`); the arc enters it at its near end.
    auto enter = [&](double centre, double half, int who) {
      const double entry = centre - arc.dir * half;
      double travel = std::remainder(arc.dir * (entry - arc.theta0), 2.0 * std::numbers::pi);
      if (travel < 0.0)  // behind: unless touching it already and moving into it
        travel = travel > -1e-9 ? 0.0 : travel + 2.0 * std::numbers::pi;
      if (travel < best) {
        best = travel;
        hit = who;
      }
    };
    // Disc k: centres closer than r + r_k to its centre (law of cosines in the triangle p, q, c).
    auto disc = [&](int k) {
      const dem2d::Vec2 d = x_[static_cast<std::size_t>(k)] - arc.p;
      const double dist = dem2d::norm(d), reach = r + r_[static_cast<std::size_t>(k)];
      if (dist == 0.0) return;
      const double cosa =
          (arc.rho * arc.rho + dist * dist - reach * reach) / (2.0 * arc.rho * dist);
      if (cosa > -1.0 && cosa < 1.0) enter(std::atan2(d.y, d.x), std::acos(cosa), k);
    };
    if (support >= 0) {
      // The wall: centres farther than R - r from the origin, about the direction of p.
      const double rw = R_ - r, dist = dem2d::norm(arc.p);
      if (dist > 0.0) {
        const double cosb = (rw * rw - dist * dist - arc.rho * arc.rho) / (2.0 * arc.rho * dist);
        if (cosb > -1.0 && cosb < 1.0) enter(std::atan2(arc.p.y, arc.p.x), std::acos(cosb), -1);
      }
      near(arc.p, arc.rho + r + r_max_, [&](int k) {
        if (k != support) disc(k);
      });
    } else {
      for (int k : at_wall_) disc(k);
    }
    return {best, hit};
  }

  // Unit normal at the disc's centre c from support k (-1: the wall pushes towards the centre).
  dem2d::Vec2 normal_from(int k, dem2d::Vec2 c) const {
    const dem2d::Vec2 d = k >= 0 ? c - x_[static_cast<std::size_t>(k)] : -c;
    return (1.0 / dem2d::norm(d)) * d;
  }

  int cell_of(double v) const { return std::clamp(static_cast<int>((v + R_) / h_), 0, n_ - 1); }

  // Visit the discs whose centres lie in the cells within `reach` of q.
  template <class F>
  void near(dem2d::Vec2 q, double reach, F&& f) const {
    const int x0 = cell_of(q.x - reach), x1 = cell_of(q.x + reach);
    const int y0 = cell_of(q.y - reach), y1 = cell_of(q.y + reach);
    for (int cy = y0; cy <= y1; ++cy)
      for (int cx = x0; cx <= x1; ++cx)
        for (int k = head_[static_cast<std::size_t>(cy) * static_cast<std::size_t>(n_) +
                           static_cast<std::size_t>(cx)];
             k >= 0; k = next_[static_cast<std::size_t>(k)])
          f(k);
  }

  // Fall straight down from c (to the first disc or the wall below); returns the support.
  int fall(dem2d::Vec2& c, double r, int exclude) const {
    const double rw = R_ - r;
    double best = -std::sqrt(std::max(0.0, rw * rw - c.x * c.x));
    int support = -1;
    const int x0 = cell_of(c.x - r - r_max_), x1 = cell_of(c.x + r + r_max_);
    double start = -std::numeric_limits<double>::infinity();
    for (int cx = x0; cx <= x1; ++cx) start = std::max(start, top_[static_cast<std::size_t>(cx)]);
    start = std::min(start, c.y);
    if (start == -std::numeric_limits<double>::infinity()) {
      c.y = best;
      return support;
    }
    for (int cy = cell_of(start); cy >= 0; --cy) {
      // Discs in lower rows touch below this row's top edge + r + r_max.
      if (-R_ + (cy + 1) * h_ + r + r_max_ < best) break;
      for (int cx = x0; cx <= x1; ++cx)
        for (int k = head_[static_cast<std::size_t>(cy) * static_cast<std::size_t>(n_) +
                           static_cast<std::size_t>(cx)];
             k >= 0; k = next_[static_cast<std::size_t>(k)]) {
          if (k == exclude) continue;
          const dem2d::Vec2 q = x_[static_cast<std::size_t>(k)];
          const double reach = r + r_[static_cast<std::size_t>(k)], dx = c.x - q.x;
          if (std::abs(dx) >= reach) continue;
          const double y = q.y + std::sqrt(reach * reach - dx * dx);
          if (y <= c.y && y > best) {
            best = y;
            support = k;
          }
        }
    }
    c.y = best;
    return support;
  }

  void add(dem2d::Vec2 c, double r) {
    const int k = static_cast<int>(x_.size());
    x_.push_back(c);
    r_.push_back(r);
    const std::size_t cell = static_cast<std::size_t>(cell_of(c.y)) * static_cast<std::size_t>(n_) +
                             static_cast<std::size_t>(cell_of(c.x));
    next_.push_back(head_[cell]);
    head_[cell] = k;
    double& t = top_[static_cast<std::size_t>(cell_of(c.x))];
    t = std::max(t, c.y);
    // Discs that a disc rolling on the wall could touch: centre within 2 r_max + r of the wall.
    if (dem2d::norm(c) >= R_ - 2.0 * r_max_ - r) at_wall_.push_back(k);
  }

  double R_, r_max_, h_;
  int n_;
  std::vector<int> head_, next_;
  std::vector<double> top_;  // per column of cells: the highest centre in it
  std::vector<dem2d::Vec2> x_;
  std::vector<double> r_;
  std::vector<int> at_wall_;
  std::int64_t rolls_ = 0;
};

}  // namespace bench
