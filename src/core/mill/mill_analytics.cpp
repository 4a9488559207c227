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

constexpr double kBinWidth = 360.0 / kShellBins;  // deg

// The longest run of bins with counts >= half the largest count, on the circle: its first bin
// and its length (0: nothing covered; kShellBins: all of it). Ties: the first found from an
// empty bin onwards.
std::pair<int, int> main_run(std::span<const std::int64_t> counts, std::int64_t top) {
  const auto in = [&](int b) { return 2 * counts[static_cast<std::size_t>(b)] >= top; };
  if (top <= 0) return {0, 0};
  int empty = 0;
  while (empty < kShellBins && in(empty)) ++empty;
  if (empty == kShellBins) return {0, kShellBins};
  // Start the scan at a bin below the level so that no run wraps past the scan's end.
  int best_start = 0, best_len = 0;
  for (int k = 0, start = 0, len = 0; k < kShellBins; ++k) {
    const int b = (empty + k) % kShellBins;
    if (!in(b)) {
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
};

// Adds the bins a particle at `d` (frame coordinates) of radius r covers.
void cover_bins(std::vector<std::int64_t>& cover, Vec2 d, double r) {
  const double rho = norm(d);
  const double half = std::asin(std::min(1.0, r / rho)) * kDegree;
  const double phi = Frame::angle(d);
  const int b0 = bin_of(phi - half), n = static_cast<int>(std::ceil(2.0 * half / kBinWidth));
  for (int b = 0; b <= n; ++b) {
    const int bin = (b0 + b) % kShellBins;
    if (std::abs(std::remainder(bin_centre(bin) - phi, 360.0)) <= half) ++cover[bin];
  }
}

// layer: how far inside the lifters' tops (the shell without lifters) a particle's surface may
// lie and still be next to the shell.
ChargeSums charge_sums(const ParticleStore& p, const Frame& f, double shell, double layer,
                       double omega, double shell_speed, double time, Vec2 gravity) {
  const Field<double>* clock = p.last_contact();
  ChargeSums s;
  std::int64_t& airborne = s.cover[kShellBins];
  std::int64_t& corotating = s.cover[kShellBins + 1];
  s.cover[kShellBins + 2] = static_cast<std::int64_t>(p.n_owned());
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const Vec2 d = f.local(p.pos[k]);
    const double r = p.radius[k], rho = norm(d);
    s.moments[0] += p.mass[k];
    s.moments[1] += p.mass[k] * (p.pos[k].x - f.centre.x);
    s.moments[2] += p.mass[k] * (p.pos[k].y - f.centre.y);
    if (clock ? time - (*clock)[k] >= kFlightTime : !touching(p, k, gravity)) ++airborne;
    const Vec2 v_shell = omega * perp(p.pos[k] - f.centre);
    if (d.y > 0.0 && shell_speed > 0.0 && norm(p.vel[k] - v_shell) < 0.05 * shell_speed)
      ++corotating;
    if (shell - rho - r < layer && rho > r) cover_bins(s.cover, d, r);
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

ShellArc shell_arc(std::span<const std::int64_t> counts) {
  const std::int64_t top = *std::max_element(counts.begin(), counts.end());
  const auto [start, len] = main_run(counts, top);
  ShellArc a;
  if (len == 0 || len == kShellBins) {
    a.toe = a.shoulder = kNaN;
    a.arc = len * kBinWidth;
    return a;
  }
  // The half level's crossings between the run's end bins and their outer neighbours' centres.
  const double level = 0.5 * static_cast<double>(top);
  const auto at = [&](int b) {
    return static_cast<double>(counts[static_cast<std::size_t>((b + kShellBins) % kShellBins)]);
  };
  const int end = start + len - 1;
  const double in_toe = (at(start) - level) / (at(start) - at(start - 1));
  const double in_shoulder = (at(end) - level) / (at(end) - at(end + 1));
  a.toe = bin_centre(start) - in_toe * kBinWidth;
  a.arc = (len - 1 + in_toe + in_shoulder) * kBinWidth;
  if (a.toe < -180.0) a.toe += 360.0;
  a.shoulder = a.toe + a.arc;  // above 180: the charge is carried past the top
  return a;
}

ChargeShape measure_charge(const ParticleStore& p, const Walls& walls, const DrumSpec& drum,
                           const Domain& domain, double time, Vec2 gravity, bool surface) {
  const double omega = walls.drum_omega();
  const Frame f{drum.center, drum.speed < 0.0 ? -1.0 : 1.0};
  const DrumGeometry geometry(drum);
  const double shell = geometry.inner_radius();
  double r_max = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) r_max = std::max(r_max, p.radius[k]);
  r_max = domain.max(r_max);
  ChargeSums s = charge_sums(p, f, shell, geometry.tallest_lifter() + 2.0 * r_max, omega,
                             std::abs(omega) * shell, time, gravity);
  domain.sum(std::span<std::int64_t>(s.cover));
  domain.sum(std::span<double>(s.moments));
  ChargeShape c;
  const double n = static_cast<double>(std::max<std::int64_t>(1, s.cover[kShellBins + 2]));
  c.airborne_fraction = static_cast<double>(s.cover[kShellBins]) / n;
  c.corotating_fraction = static_cast<double>(s.cover[kShellBins + 1]) / n;
  c.mass = s.moments[0];
  c.com_x = s.moments[0] > 0 ? s.moments[1] / s.moments[0] : kNaN;
  c.com_y = s.moments[0] > 0 ? s.moments[2] / s.moments[0] : kNaN;
  std::vector<std::int64_t> on(kShellBins);
  for (int b = 0; b < kShellBins; ++b) {
    on[static_cast<std::size_t>(b)] = s.cover[static_cast<std::size_t>(b)] > 0;
    if (on[static_cast<std::size_t>(b)]) c.shell[b / 8] |= static_cast<std::uint8_t>(1 << (b % 8));
  }
  const ShellArc a = shell_arc(on);
  c.toe = a.toe;
  c.shoulder = a.shoulder;
  c.shell_arc = a.arc;
  c.surface_angle = kNaN;
  if (surface) c.surface_angle = measure_surface_angle(p, drum, domain, c.toe, c.shoulder, gravity);
  return c;
}

double measure_surface_angle(const ParticleStore& p, const DrumSpec& drum, const Domain& domain,
                             double toe, double shoulder, Vec2 gravity) {
  // A charge spread over more than three quarters of the shell has no free surface to speak of.
  if (!std::isfinite(toe) || !std::isfinite(shoulder) || shoulder - toe > 270.0) return kNaN;
  const Frame f{drum.center, drum.speed < 0.0 ? -1.0 : 1.0};
  double r_max = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) r_max = std::max(r_max, p.radius[k]);
  return surface_angle(p, f, domain, DrumGeometry(drum).inner_radius(), toe, shoulder,
                       domain.max(r_max), gravity);
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

void MillWindow::count(const ShellBits& bits, int sign) {
  for (int b = 0; b < kShellBins; ++b)
    if (shell_bit(bits, b)) counts_[static_cast<std::size_t>(b)] += sign;
}

void MillWindow::add(const MillSample& s) {
  samples_.push_back(s);
  count(s.shell, +1);
  const auto old = std::find_if(samples_.begin(), samples_.end(), [&](const MillSample& m) {
    return m.time >= s.time - window_ * (1.0 + 1e-9);
  });
  for (auto it = samples_.begin(); it != old; ++it) count(it->shell, -1);
  samples_.erase(samples_.begin(), old);
}

void MillWindow::set_last_shape(double toe, double shoulder, double surface_angle) {
  if (samples_.empty()) return;
  samples_.back().toe = toe;
  samples_.back().shoulder = shoulder;
  samples_.back().surface_angle = surface_angle;
}

void MillWindow::restore(std::vector<MillSample> samples) {
  samples_ = std::move(samples);
  std::fill(counts_.begin(), counts_.end(), 0);
  for (const MillSample& s : samples_) count(s.shell, +1);
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
    if (std::isfinite(s.surface_angle)) {
      w.surface_angle += s.surface_angle;
      ++n;
    }
  }
  const double m = static_cast<double>(samples_.size());
  w.airborne /= m;
  w.corotating /= m;
  w.charge_angle /= m;
  w.charge_angle_std = std::sqrt(std::max(0.0, angle2 / m - w.charge_angle * w.charge_angle));
  w.surface_angle = n > 0 ? w.surface_angle / n : kNaN;
  const ShellArc profile = arc();
  w.toe = profile.toe;
  w.shoulder = profile.shoulder;
  w.shell_arc = profile.arc;
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

double ChargeSizes::slice_thickness() const {
  if (d_min == d_max || !(mass > 0.0)) return d_max;
  return mass_diameter / mass;
}

ChargeSizes charge_sizes(const ParticleStore& p, const Domain& domain) {
  std::array<double, 3> sums{};  // area, mass, mass x diameter
  double d_min = std::numeric_limits<double>::max(), d_max = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const double r = p.radius[k];
    sums[0] += std::numbers::pi * r * r;
    sums[1] += p.mass[k];
    sums[2] += p.mass[k] * 2.0 * r;
    d_min = std::min(d_min, 2.0 * r);
    d_max = std::max(d_max, 2.0 * r);
  }
  domain.sum(std::span<double>(sums));
  ChargeSizes s{sums[0], sums[1], sums[2], -domain.max(-d_min), domain.max(d_max)};
  if (s.d_min > s.d_max) s.d_min = s.d_max;  // no particle
  return s;
}

MillNumbers mill_numbers(const Scene& scene, const ChargeSizes& sizes) {
  MillNumbers m;
  m.slice_thickness = sizes.slice_thickness();
  if (!scene.drum.present) return m;
  const double g = norm(scene.run.gravity), R = scene.drum.radius;
  m.fill_fraction = sizes.area / (std::numbers::pi * R * R);
  m.bed_filling = bed_filling(m.fill_fraction);
  m.critical_speed = critical_speed(g, R);
  m.critical_speed_with_fill = critical_speed_with_fill(g, R, m.fill_fraction);
  m.speed_fraction = std::abs(scene.drum.speed) / m.critical_speed;
  m.froude = scene.drum.speed * scene.drum.speed * R / g;
  return m;
}

}  // namespace dem2d
