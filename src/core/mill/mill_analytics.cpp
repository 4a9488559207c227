#include "core/mill/mill_analytics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/geometry/drum_geometry.hpp"

namespace dem2d {

namespace {

constexpr double kDegree = 180.0 / std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Whether particle k felt any contact in the last force evaluation: a contact-free particle's
// accelerations are exactly gravity and zero (the force accumulators themselves are cleared
// for the next step by then).
bool touching(const ParticleStore& p, std::size_t k, Vec2 gravity) {
  return !(p.acc[k] == gravity) || p.alpha[k] != 0.0;
}

int bin_of(double angle_deg) {
  const double turn = std::fmod(angle_deg + 180.0, 360.0);
  const int b = static_cast<int>(std::floor((turn < 0 ? turn + 360.0 : turn) * kShellBins / 360.0));
  return std::clamp(b, 0, kShellBins - 1);
}
double bin_centre(int b) { return (b + 0.5) * 360.0 / kShellBins - 180.0; }

// The largest run of covered bins on the circle after bridging gaps of at most `bridge` bins:
// its first bin and its length (0: nothing covered; kShellBins: all of it).
std::pair<int, int> largest_arc(const std::vector<std::int64_t>& cover, int bridge) {
  std::vector<char> on(kShellBins);
  for (int b = 0; b < kShellBins; ++b) on[b] = cover[b] > 0;
  // Bridge short gaps (circularly): a gap is a run of empty bins between two covered ones.
  const int first = static_cast<int>(std::find(on.begin(), on.end(), 1) - on.begin());
  if (first == kShellBins) return {0, 0};
  std::vector<char> closed = on;
  for (int k = 0, gap = 0; k <= kShellBins; ++k) {
    const int b = (first + k) % kShellBins;
    if (on[b] && k > 0) {
      if (gap > 0 && gap <= bridge)
        for (int g = 1; g <= gap; ++g) closed[(b - g + kShellBins) % kShellBins] = 1;
      gap = 0;
    } else if (!on[b]) {
      ++gap;
    }
  }
  if (std::all_of(closed.begin(), closed.end(), [](char c) { return c != 0; }))
    return {0, kShellBins};
  // Start the scan at an empty bin so that no run wraps past the scan's end.
  const int empty = static_cast<int>(std::find(closed.begin(), closed.end(), 0) - closed.begin());
  int best_start = 0, best_len = 0;
  for (int k = 0, start = 0, len = 0; k < kShellBins; ++k) {
    const int b = (empty + k) % kShellBins;
    if (!closed[b]) {
      len = 0;
      continue;
    }
    if (len == 0) start = b;
    if (++len > best_len) {
      best_len = len;
      best_start = start;
    }
  }
  return {best_start, best_len};
}

// Per-particle coordinates in the frame of the angles: x mirrored for a clockwise drum.
struct Frame {
  Vec2 centre;
  double sense;  // +1 counter-clockwise (or at rest), -1 clockwise
  Vec2 local(Vec2 x) const { return {sense * (x.x - centre.x), x.y - centre.y}; }
  static double angle(Vec2 d) { return std::atan2(d.x, -d.y) * kDegree; }
};

// Sums over this rank's particles: shell cover, centre of mass, counts.
struct ChargeSums {
  std::vector<std::int64_t> cover = std::vector<std::int64_t>(kShellBins + 3, 0);
  std::array<double, 3> moments{};  // m, m x, m y
  double r_max = 0.0;
};

ChargeSums charge_sums(const ParticleStore& p, const Frame& f, double shell, double lift,
                       double omega, double shell_speed, double time, Vec2 gravity) {
  const Field<double>* clock = p.last_contact();
  ChargeSums s;
  std::int64_t& airborne = s.cover[kShellBins];
  std::int64_t& corotating = s.cover[kShellBins + 1];
  s.cover[kShellBins + 2] = static_cast<std::int64_t>(p.n_owned());
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const Vec2 d = f.local(p.pos[k]);
    const double r = p.radius[k], rho = norm(d);
    s.r_max = std::max(s.r_max, r);
    s.moments[0] += p.mass[k];
    s.moments[1] += p.mass[k] * (p.pos[k].x - f.centre.x);
    s.moments[2] += p.mass[k] * (p.pos[k].y - f.centre.y);
    if (clock ? time - (*clock)[k] >= kFlightTime : !touching(p, k, gravity)) ++airborne;
    const Vec2 v_shell = omega * perp(p.pos[k] - f.centre);
    if (d.y > 0.0 && shell_speed > 0.0 && norm(p.vel[k] - v_shell) < 0.05 * shell_speed)
      ++corotating;
    if (shell - rho - r >= r + lift || rho <= r) continue;  // not at the shell
    if (!touching(p, k, gravity)) continue;                 // flying past it
    const double half = std::asin(std::min(1.0, r / rho)) * kDegree;
    const double phi = Frame::angle(d);
    const int b0 = bin_of(phi - half),
              n = static_cast<int>(std::ceil(2.0 * half * kShellBins / 360.0));
    for (int b = 0; b <= n; ++b) {
      const int bin = (b0 + b) % kShellBins;
      if (std::abs(std::remainder(bin_centre(bin) - phi, 360.0)) <= half) ++s.cover[bin];
    }
  }
  return s;
}

// The free surface's angle (deg) between toe and shoulder: a line through the highest particle
// tops, per chord bin, across the chord's middle 60 %.
double surface_angle(const ParticleStore& p, const Frame& f, const Domain& domain, double shell,
                     double toe, double shoulder, double r_max, Vec2 gravity) {
  const auto on_shell = [&](double phi) {
    return Vec2{shell * std::sin(phi / kDegree), -shell * std::cos(phi / kDegree)};
  };
  const Vec2 t = on_shell(toe), s = on_shell(shoulder);
  const double length = norm(s - t);
  if (!(length > 0.0) || r_max <= 0.0) return kNaN;
  const Vec2 u = (1.0 / length) * (s - t), n = perp(u);  // n: away from the bed
  const int bins = std::max(5, static_cast<int>(length / (2.0 * r_max)));
  std::vector<double> top(static_cast<std::size_t>(bins), -std::numeric_limits<double>::max());
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    if (!touching(p, k, gravity)) continue;  // in flight: not the bed
    const Vec2 d = f.local(p.pos[k]) - t;
    const double along = dot(d, u) / length;
    if (along < 0.2 || along >= 0.8) continue;
    const int b = std::min(bins - 1, static_cast<int>(along * bins));
    top[static_cast<std::size_t>(b)] =
        std::max(top[static_cast<std::size_t>(b)], dot(d, n) + p.radius[k]);
  }
  domain.max(top);
  double sx = 0, sy = 0, sxx = 0, sxy = 0, count = 0;
  for (int b = 0; b < bins; ++b) {
    const double h = top[static_cast<std::size_t>(b)];
    if (h == -std::numeric_limits<double>::max()) continue;
    const double x = (b + 0.5) / bins * length;
    sx += x;
    sy += h;
    sxx += x * x;
    sxy += x * h;
    ++count;
  }
  const double det = count * sxx - sx * sx;
  if (count < 3 || !(det > 0.0)) return kNaN;
  const double slope = (count * sxy - sx * sy) / det;
  return 0.5 * (toe + shoulder) + std::atan(slope) * kDegree;
}

}  // namespace

void clock_contacts(ParticleStore& p, double time, Vec2 gravity) {
  Field<double>* clock = p.last_contact();
  if (clock == nullptr) return;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    if (touching(p, k, gravity)) (*clock)[k] = time;
}

ChargeShape measure_charge(const ParticleStore& p, const Walls& walls, const DrumSpec& drum,
                           const Domain& domain, double time, Vec2 gravity) {
  const double omega = walls.drum_omega();
  const Frame f{drum.center, drum.speed < 0.0 ? -1.0 : 1.0};
  const DrumGeometry geometry(drum);
  const double shell = geometry.inner_radius();
  ChargeSums s = charge_sums(p, f, shell, geometry.tallest_lifter(), omega, std::abs(omega) * shell,
                             time, gravity);
  domain.sum(std::span<std::int64_t>(s.cover));
  domain.sum(std::span<double>(s.moments));
  const double r_max = domain.max(s.r_max);
  ChargeShape c;
  const double n = static_cast<double>(std::max<std::int64_t>(1, s.cover[kShellBins + 2]));
  c.airborne_fraction = static_cast<double>(s.cover[kShellBins]) / n;
  c.corotating_fraction = static_cast<double>(s.cover[kShellBins + 1]) / n;
  c.mass = s.moments[0];
  c.com_x = s.moments[0] > 0 ? s.moments[1] / s.moments[0] : kNaN;
  c.com_y = s.moments[0] > 0 ? s.moments[2] / s.moments[0] : kNaN;
  const int bridge =
      static_cast<int>(std::ceil(2.0 * r_max / shell * kDegree * kShellBins / 360.0));
  const auto [start, len] = largest_arc(s.cover, bridge);
  c.shell_arc = len * 360.0 / kShellBins;
  if (len == 0 || len == kShellBins) {
    c.toe = c.shoulder = c.surface_angle = kNaN;
    return c;
  }
  c.toe = bin_centre(start) - 0.5 * 360.0 / kShellBins;
  c.shoulder = c.toe + c.shell_arc;
  if (c.shoulder > 180.0) {  // the arc runs past the top: keep toe < shoulder, toe in range
    c.toe -= 360.0;
    c.shoulder -= 360.0;
  }
  // A charge spread over more than three quarters of the shell has no free surface to speak of.
  c.surface_angle = c.shell_arc > 270.0
                        ? kNaN
                        : surface_angle(p, f, domain, shell, c.toe, c.shoulder, r_max, gravity);
  return c;
}

const char* regime_name(Regime r) {
  constexpr const char* kNames[] = {
      "-",           "slumping",    "rolling", "cascading", "cascading-cataracting",
      "cataracting", "centrifuging"};
  return kNames[static_cast<int>(r)];
}

Regime classify(const WindowSummary& w, const RegimeThresholds& t) {
  if (w.regime == Regime::kUnknown && w.span <= 0.0) return Regime::kUnknown;
  if (w.corotating >= t.centrifuging_corotating) return Regime::kCentrifuging;
  if (w.airborne >= t.cataracting_airborne) return Regime::kCataracting;
  if (w.airborne >= t.mixed_airborne) return Regime::kMixed;
  if (w.charge_angle_std > t.slumping_angle_std) return Regime::kSlumping;
  const double bulge = 0.5 * (w.toe + w.shoulder) - w.surface_angle;
  if (bulge >= t.cascading_bulge) return Regime::kCascading;
  return Regime::kRolling;
}

void MillWindow::add(const MillSample& s) {
  samples_.push_back(s);
  const auto old = std::find_if(samples_.begin(), samples_.end(), [&](const MillSample& m) {
    return m.time >= s.time - window_ * (1.0 + 1e-9);
  });
  samples_.erase(samples_.begin(), old);
}

WindowSummary MillWindow::summary() const {
  WindowSummary w;
  if (samples_.size() < 2) return w;
  const MillSample &a = samples_.front(), &b = samples_.back();
  w.span = b.time - a.time;
  w.power = (b.drum_work - a.drum_work) / w.span;
  double n = 0, angle2 = 0;
  for (const MillSample& s : samples_) {
    w.airborne += s.airborne;
    w.corotating += s.corotating;
    w.charge_angle += s.charge_angle;
    angle2 += s.charge_angle * s.charge_angle;
    if (std::isfinite(s.surface_angle) && std::isfinite(s.toe)) {
      w.surface_angle += s.surface_angle;
      w.toe += s.toe;
      w.shoulder += s.shoulder;
      ++n;
    }
  }
  const double m = static_cast<double>(samples_.size());
  w.airborne /= m;
  w.corotating /= m;
  w.charge_angle /= m;
  w.charge_angle_std = std::sqrt(std::max(0.0, angle2 / m - w.charge_angle * w.charge_angle));
  if (n > 0) {
    w.surface_angle /= n;
    w.toe /= n;
    w.shoulder /= n;
  } else {
    w.surface_angle = w.toe = w.shoulder = kNaN;
  }
  // Full once samples older than the window were dropped (row times need not fall on a grid
  // of the window: dt = "auto"), or when they span it. Runs start at t = 0.
  if (a.time > 0.0 || w.span >= window_ * (1.0 - 1e-9)) w.regime = classify(w);
  return w;
}

// ---------------------------------------------------------------------------------------------
// Collision spectra

const char* contact_type_name(ContactType t) {
  constexpr const char* kNames[] = {"ball-ball",  "ball-ore",    "ore-ore",
                                    "ball-shell", "ball-lifter", "ball-wall",
                                    "ore-shell",  "ore-lifter",  "ore-wall"};
  return kNames[static_cast<int>(t)];
}

CollisionSpectra::CollisionSpectra(std::vector<double> size_edges, std::vector<bool> ore)
    : edges_(std::move(size_edges)), ore_(std::move(ore)) {
  const auto types = static_cast<std::size_t>(ContactType::kCount);
  counts_.assign(types * static_cast<std::size_t>(size_classes()) * kEnergyBins, 0);
  energies_.assign(types * static_cast<std::size_t>(size_classes()), 0.0);
}

int CollisionSpectra::energy_bin(double energy) {
  if (!(energy >= kEnergyMin)) return 0;
  const int b = 1 + static_cast<int>(std::floor(std::log10(energy / kEnergyMin) * kBinsPerDecade));
  return std::min(b, kEnergyBins - 1);
}

double CollisionSpectra::energy_edge(int bin) {
  return bin == 0 ? 0.0
                  : kEnergyMin * std::pow(10.0, static_cast<double>(bin - 1) / kBinsPerDecade);
}

int CollisionSpectra::size_class(double diameter) const {
  return static_cast<int>(std::upper_bound(edges_.begin(), edges_.end(), diameter) -
                          edges_.begin());
}

std::size_t CollisionSpectra::cell(ContactType t, int size_class) const {
  return static_cast<std::size_t>(static_cast<int>(t) * size_classes() + size_class);
}

std::size_t CollisionSpectra::index(ContactType t, int size_class, int bin) const {
  return cell(t, size_class) * kEnergyBins + static_cast<std::size_t>(bin);
}

void CollisionSpectra::add(ContactType type, double diameter, double energy) {
  const int c = size_class(diameter);
  ++counts_[index(type, c, energy_bin(energy))];
  energies_[cell(type, c)] += energy;
}

void CollisionSpectra::book_ended(const ParticleStore& p, const Walls& walls,
                                  const double* committed_pairs, const double* trial_pairs,
                                  std::span<const std::int32_t> pair_i,
                                  std::span<const std::int32_t> pair_j,
                                  const double* committed_walls, const double* trial_walls,
                                  std::span<const std::int32_t> wall_particle,
                                  std::span<const std::int32_t> wall_element, std::size_t width,
                                  std::size_t peak) {
  const auto is_ore = [&](std::int32_t i) {
    const auto m = static_cast<std::size_t>(p.material[i]);
    return m < ore_.size() && ore_[m];
  };
  for (std::size_t k = 0; k < pair_i.size(); ++k) {
    const double was = committed_pairs[k * width + peak];
    if (!(was > 0.0) || trial_pairs[k * width + peak] > 0.0) continue;
    const std::int32_t i = pair_i[k], j = pair_j[k];
    if (static_cast<std::size_t>(i) >= p.n_owned()) continue;  // booked where i is owned
    const int ores = int{is_ore(i)} + int{is_ore(j)};
    const auto type = ores == 0   ? ContactType::kBallBall
                      : ores == 1 ? ContactType::kBallOre
                                  : ContactType::kOreOre;
    add(type, 2.0 * std::min(p.radius[i], p.radius[j]), was);
  }
  for (std::size_t k = 0; k < wall_particle.size(); ++k) {
    const double was = committed_walls[k * width + peak];
    if (!(was > 0.0) || trial_walls[k * width + peak] > 0.0) continue;
    const std::int32_t i = wall_particle[k];
    const WallPart part = walls.elements()[static_cast<std::size_t>(wall_element[k])].part;
    const int base = is_ore(i) ? static_cast<int>(ContactType::kOreShell)
                               : static_cast<int>(ContactType::kBallShell);
    add(static_cast<ContactType>(base + static_cast<int>(part)), 2.0 * p.radius[i], was);
  }
}

double critical_speed(double gravity, double radius) { return std::sqrt(gravity / radius); }

double critical_speed_with_fill(double gravity, double radius, double phi) {
  return std::pow(1.0 - std::min(phi, 0.99), -0.25) * critical_speed(gravity, radius);
}

double bed_filling(double phi) { return phi / kBedPacking; }

MillNumbers mill_numbers(const Scene& scene, double particle_area, double largest_radius) {
  MillNumbers m;
  m.slice_thickness = 2.0 * largest_radius;
  if (!scene.drum.present) return m;
  const double g = norm(scene.run.gravity), R = scene.drum.radius;
  m.fill_fraction = particle_area / (std::numbers::pi * R * R);
  m.bed_filling = bed_filling(m.fill_fraction);
  m.critical_speed = critical_speed(g, R);
  m.critical_speed_with_fill = critical_speed_with_fill(g, R, m.fill_fraction);
  m.speed_fraction = std::abs(scene.drum.speed) / m.critical_speed;
  m.froude = scene.drum.speed * scene.drum.speed * R / g;
  return m;
}

}  // namespace dem2d
