// Mill analytics: what a mill engineer reads off a run (docs/output.md, "Mill analytics").
//
//   ChargeShape      the charge at one moment: toe and shoulder, bed surface angle, centre of
//                    mass, the fraction in free flight, the fraction turning with the drum
//                    above its axis (measure_charge; collective);
//   MillWindow       the last `window` seconds of those samples: the drive's average power over
//                    the window (exact: the drum's work over the window / its length) and the
//                    regime by the criterion below;
//   CollisionSpectra every contact that ended, binned by contact type, size class and its peak
//                    normal strain energy (the energy the breakage model tests).
//
// Angles (degrees) are measured at the drum's centre from the downward vertical, positive in
// the drum's sense of rotation: the charge is lifted on the positive side, so the shoulder is
// positive and the toe negative. A counter-clockwise drum (speed > 0) lifts its charge on the
// right.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/base/scene.hpp"
#include "core/geometry/walls.hpp"
#include "core/shape/particles.hpp"
#include "core/step/domain.hpp"

namespace dem2d {

// Angular resolution of the shell profile (the shell is cut into this many bins).
inline constexpr int kShellBins = 720;  // 0.5 degree

// The shell layer at one moment: bit b (byte b / 8, bit b % 8) set when a particle in contact
// lying next to the shell covers bin b (bin 0 starts at -180 degrees).
using ShellBits = std::array<std::uint8_t, kShellBins / 8>;
inline bool shell_bit(const ShellBits& bits, int b) { return (bits[b / 8] >> (b % 8)) & 1; }

// Where the charge meets the shell (toe) and leaves it (shoulder), from a profile of the shell
// layer's occupancy (counts per bin out of some number of moments): the bins whose count is at
// least half of the largest form runs; the longest run is the charge's main body, and toe and
// shoulder are where the profile crosses that half level on either side of it (interpolated
// linearly between bin centres). toe and shoulder NaN when the run is the whole circle (arc 360)
// or nothing is covered (arc 0). toe in [-180, 180), shoulder = toe + arc: above 180 when the
// charge is carried past the top.
struct ShellArc {
  double toe = 0.0, shoulder = 0.0, arc = 0.0;  // deg
};
ShellArc shell_arc(std::span<const std::int64_t> counts);

struct ChargeShape {
  // The shell layer now: the particles whose surface lies within one largest diameter of the
  // tallest lifter's top (of the shell without lifters), in contact or not (the balls landing
  // at the toe and leaving the lifters at the shoulder are the charge's ends), each covering
  // the bins its own angular width spans.
  ShellBits shell{};
  // Toe, shoulder and arc of this moment's layer alone (shell_arc of its bits: the largest
  // covered arc, broken wherever a gap between lifters is empty now). The series and the
  // window report the time-averaged profile's instead (MillWindow).
  double toe = 0.0, shoulder = 0.0;  // deg
  double shell_arc = 0.0;            // deg, 360 when the particles line the whole shell
  // The free surface: the angle from the horizontal of a straight line fitted to the highest
  // particle tops across the middle 60 % of the toe-shoulder chord, in the frame above
  // (positive: rising towards the shoulder). NaN when the arc exceeds 270 degrees.
  double surface_angle = 0.0;       // deg
  double com_x = 0.0, com_y = 0.0;  // m, centre of mass relative to the drum centre (lab axes)
  double mass = 0.0;                // kg
  // Particles in free flight (no contact for kFlightTime or more, as seen at the series rows:
  // dense beds make many short hops that are not flight) / all particles.
  double airborne_fraction = 0.0;
  // Particles above the drum's axis moving with the shell (|v - Omega z x (x - c)| below 5 % of
  // the shell's speed) / all particles: 1/2 when the whole charge lines the shell.
  double corotating_fraction = 0.0;
};

// A ball thrown off the shoulder flies 0.2-0.8 s; hops in a dense bed last up to about 0.1 s
// (tests/core/test_system.cpp measured both on the thesis scenes).
inline constexpr double kFlightTime = 0.15;  // s

// The particles in contact now (their accelerations are not gravity's alone) get `time` as
// their last contact (p.last_contact()).
void clock_contacts(ParticleStore& p, double time, Vec2 gravity);

// The charge of a scene with a drum at `time` (collective: every rank returns the same shape).
// Without `surface` the surface angle is left NaN (measure_surface_angle gives it for a chord).
ChargeShape measure_charge(const ParticleStore& p, const Walls& walls, const DrumSpec& drum,
                           const Domain& domain, double time, Vec2 gravity, bool surface = true);
// The free surface's angle (ChargeShape::surface_angle) across the chord from `toe` to
// `shoulder` (collective; NaN when either is NaN or the arc exceeds 270 degrees).
double measure_surface_angle(const ParticleStore& p, const DrumSpec& drum, const Domain& domain,
                             double toe, double shoulder, Vec2 gravity);

enum class Regime {
  kUnknown,
  kSlumping,
  kRolling,
  kCascading,
  kMixed,  // cascading-cataracting
  kCataracting,
  kCentrifuging
};
const char* regime_name(Regime r);

// The criterion (docs/models.md, "Regimes"), on averages over the window, in this order:
//   centrifuging           corotating_fraction >= 0.15: a layer of particles rides the shell
//                          over the top (a charge lining the whole shell has half of it above
//                          the axis; lifters carry 5-8 % of a cataracting charge there);
//   cataracting            airborne_fraction >= 0.05: a curtain of particles thrown from the
//                          shoulder;
//   cascading-cataracting  airborne_fraction >= 0.015: some are thrown, the rest rolls down;
//   slumping               the charge swings: the direction of its centre of mass varies with
//                          a standard deviation above 2 degrees (avalanches, or the bed
//                          rocking and sliding on the shell);
//   cascading              the charge is carried above its free surface: the chord between
//                          the window's toe and shoulder stands at least 5 degrees steeper
//                          than the surface (the kidney shape);
//   rolling                a steady, flat surface.
struct RegimeThresholds {
  double centrifuging_corotating = 0.15;
  double cataracting_airborne = 0.05;
  double mixed_airborne = 0.015;
  double slumping_angle_std = 2.0;  // deg
  double cascading_bulge = 5.0;     // deg
};

// One series row's analytics, kept for the window.
struct MillSample {
  double time = 0.0;
  double drum_work = 0.0;  // J, the drum's drive work since the start (all ranks)
  // toe and shoulder: the window's profile's at this row (MillWindow::arc after adding it);
  // surface_angle across their chord.
  double airborne = 0.0, corotating = 0.0, surface_angle = 0.0, toe = 0.0, shoulder = 0.0;
  double charge_angle = 0.0;  // deg, the centre of mass's direction (same convention)
  ShellBits shell{};          // the shell layer at this row (ChargeShape::shell)
};

// Averages over the window and the regime they give.
struct WindowSummary {
  double span = 0.0;   // s covered by the samples
  double power = 0.0;  // W: the drum's work over the span / span
  double airborne = 0.0, corotating = 0.0;
  double surface_angle = 0.0;  // deg, the rows' mean
  // The time-averaged shell profile's toe, shoulder and covered arc (MillWindow::arc).
  double toe = 0.0, shoulder = 0.0, shell_arc = 0.0;  // deg
  double charge_angle = 0.0, charge_angle_std = 0.0;  // deg
  Regime regime = Regime::kUnknown;
};

Regime classify(const WindowSummary& w, const RegimeThresholds& t = {});

// The samples of the last `window` seconds of rows, and the shell profile they make: per bin,
// the number of samples whose shell layer covers it (exact integer sums, the same on any rank
// count: each sample's bits are decided on the counts summed over ranks).
class MillWindow {
 public:
  explicit MillWindow(double window = 1.0)
      : window_(window), counts_(static_cast<std::size_t>(kShellBins), 0) {}
  // Adds a sample (times increasing) and forgets those older than its time - window.
  void add(const MillSample& s);
  // The newest sample's toe, shoulder and surface angle (measured from arc() after add()).
  void set_last_shape(double toe, double shoulder, double surface_angle);
  // The time-averaged profile's toe and shoulder over the samples held (shell_arc).
  ShellArc arc() const { return shell_arc(counts_); }
  // The averages over the samples held; regime kUnknown until the run is a window old.
  WindowSummary summary() const;
  double window() const { return window_; }
  const std::vector<MillSample>& samples() const { return samples_; }
  const std::vector<std::int64_t>& profile() const { return counts_; }
  void restore(std::vector<MillSample> samples);

 private:
  void count(const ShellBits& bits, int sign);

  double window_;
  std::vector<MillSample> samples_;
  std::vector<std::int64_t> counts_;  // per shell bin
};

// What a contact touched.
enum class ContactType : int {
  kBallBall,
  kBallOre,
  kOreOre,
  kBallShell,
  kBallLifter,
  kBallWall,
  kOreShell,
  kOreLifter,
  kOreWall,
  kCount
};
const char* contact_type_name(ContactType t);

// Histograms of the contacts that ended, by type, size class and peak energy. A contact is
// booked when it ends, on the rank that books its energies (the rank owning its lower-id
// particle, or the particle for a wall), by the smaller particle's diameter.
class CollisionSpectra {
 public:
  // Energy bins: [0, kEnergyMin) first, then kBinsPerDecade per decade up to kEnergyMax, then
  // everything above in the last.
  static constexpr double kEnergyMin = 1e-12, kEnergyMax = 1e6;  // J
  static constexpr int kBinsPerDecade = 10;
  static constexpr int kEnergyBins = 18 * kBinsPerDecade + 2;

  CollisionSpectra() = default;
  // size_edges: increasing diameters (m) between the size classes (classes: below the first,
  // between consecutive edges, at or above the last). ore: which materials are ore.
  CollisionSpectra(std::vector<double> size_edges, std::vector<bool> ore);

  // Books the contacts of the committed histories (peak energy at slot `peak` of each
  // contact's `width` values) that the trial histories no longer hold (ended this step).
  void book_ended(const ParticleStore& p, const Walls& walls, const double* committed_pairs,
                  const double* trial_pairs, std::span<const std::int32_t> pair_i,
                  std::span<const std::int32_t> pair_j, const double* committed_walls,
                  const double* trial_walls, std::span<const std::int32_t> wall_particle,
                  std::span<const std::int32_t> wall_element, std::size_t width, std::size_t peak);
  void add(ContactType type, double diameter, double energy);

  static int energy_bin(double energy);
  static double energy_edge(int bin);  // lower edge of a bin (0 for the first)
  int size_class(double diameter) const;
  const std::vector<double>& size_edges() const { return edges_; }
  int size_classes() const { return static_cast<int>(edges_.size()) + 1; }
  // Counts [type][class][bin] and energy sums [type][class], flattened, this rank's.
  std::vector<std::int64_t>& counts() { return counts_; }
  const std::vector<std::int64_t>& counts() const { return counts_; }
  std::vector<double>& energies() { return energies_; }
  const std::vector<double>& energies() const { return energies_; }
  std::size_t index(ContactType t, int size_class, int bin) const;
  std::size_t cell(ContactType t, int size_class) const;

 private:
  std::vector<double> edges_;
  std::vector<bool> ore_;
  std::vector<std::int64_t> counts_;
  std::vector<double> energies_;
};

// The mill's numbers an engineer sizes it by (--check, run.json).
struct MillNumbers {
  double critical_speed = 0.0;            // rad/s, sqrt(|g| / R)
  double critical_speed_with_fill = 0.0;  // rad/s, thesis T37
  double speed_fraction = 0.0;            // |drum speed| / critical_speed
  double froude = 0.0;                    // Omega^2 R / |g|
  double fill_fraction = 0.0;             // particle cross-sections / drum area
  double bed_filling = 0.0;               // J, the bed with its voids / drum area
  // The 2D slice is one layer of spheres: its thickness is the charge's mass-weighted mean
  // diameter (ChargeSizes::slice_thickness), and a mill L m long draws about
  // L / slice_thickness times the slice's power (end walls neglected).
  double slice_thickness = 0.0;  // m
};

// Sums over every particle of the charge (collective).
struct ChargeSizes {
  double area = 0.0;           // m^2, sum of pi r^2
  double mass = 0.0;           // kg, sum of m
  double mass_diameter = 0.0;  // kg m, sum of m d
  double d_min = 0.0, d_max = 0.0;
  // The mass-weighted mean diameter sum(m d) / sum(m): the diameter of the typical sphere the
  // charge's mass sits in; exactly the diameter when all are alike (d_min == d_max).
  double slice_thickness() const;
};
ChargeSizes charge_sizes(const ParticleStore& p, const Domain& domain);
MillNumbers mill_numbers(const Scene& scene, const ChargeSizes& sizes);

// The classical critical speed sqrt(|g| / R) and the thesis's with the fill (T37):
// (1 - phi)^(-1/4) sqrt(|g| / R), phi the particles' share of the drum's cross-section.
double critical_speed(double gravity, double radius);
double critical_speed_with_fill(double gravity, double radius, double phi);
// The bed filling J as engineers give it: the bed's share of the mill's cross-section, voids
// included, J = phi / kBedPacking.
inline constexpr double kBedPacking = 0.84;
double bed_filling(double phi);

}  // namespace dem2d
