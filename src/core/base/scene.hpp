// Scene: the complete, validated description of one run, as plain data.
//
// The deck parser (src/io/deck.*) fills a Scene from a TOML `.in` file and checks every
// value; the core builds the particle system and the simulation from it and never reads a
// file. Every field below has the default that the deck documents (docs/input.md); units are
// SI, angles the parser has already converted to radians.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/base/vec2.hpp"

namespace dem2d {

enum class ContactModelKind { kHertzMindlin, kThesis, kLinear };
enum class RollingModelKind { kNone, kConstant, kEpsd };
enum class IntegratorKind { kVerlet, kIterative };
// Storage order of the particles (core/fast/spatial_order.hpp): it changes no bit of the physics.
enum class SpatialSort { kAuto, kAlways, kNever };

struct MaterialSpec {
  std::string name;
  double density = 0.0;             // kg/m^3
  double youngs_modulus = 0.0;      // Pa
  double poisson_ratio = 0.25;      // resolved: the parser derives it from shear_modulus if given
  double shear_modulus = 0.0;       // Pa, resolved: G = E / (2 (1 + nu)) when not given
  double restitution = 0.5;         // hertz-mindlin and linear: coefficient of restitution asked
  double damping_normal = 0.1;      // thesis model: zeta_n (T22)
  double damping_tangential = 0.1;  // thesis model: zeta_t (T23)
  double sliding_friction = 0.5;    // mu_s
  double rolling_friction = 0.0;    // mu_r (dimensionless, times R*)
  double normal_stiffness = 0.0;    // linear model: k_n in N/m (0: derived from E at 1 % overlap)
};

// Coefficients for one pair of materials; unset values take the mean of the two materials.
struct InteractionSpec {
  std::string material_a;
  std::string material_b;
  std::optional<double> restitution;
  std::optional<double> sliding_friction;
  std::optional<double> rolling_friction;
  std::optional<double> damping_normal;
  std::optional<double> damping_tangential;
};

struct RunSpec {
  double duration = 1.0;  // s of simulated time
  double dt = 0.0;        // s; 0 means "auto"
  bool dt_auto = true;
  std::string dt_where;  // where dt was set, for messages: "deck.in:14:6", "--set run.dt=1e-3"
  IntegratorKind integrator = IntegratorKind::kVerlet;
  double tolerance = 1.0e-6;  // iterative: relative acceleration change (thesis T31)
  int max_passes = 20;        // iterative
  std::uint64_t seed = 1;
  Vec2 gravity{0.0, -9.81};
  double skin = -1.0;            // m, Verlet skin; < 0: 0.4 of the smallest radius (core)
  double dt_safety = 0.2;        // fraction of min(Rayleigh time, Hertz time) used by dt = "auto"
  bool allow_unsafe_dt = false;  // run anyway (with a warning) when dt exceeds the safe bound
  // The run's guards (overlap, energy created, unsettled iterative passes): false, the first one
  // that fires stops the run (exit 3); true, each is reported and the run goes on to its end, which
  // then exits 3 all the same. A non-finite state and the motion guard always stop.
  bool guards_warn = false;
  int sectors_per_rank = 32;  // parallel runs: angular sectors per rank (METIS groups them)
  double repartition_threshold = 1.05;  // parallel runs: max/mean work that triggers a repartition
  SpatialSort spatial_sort = SpatialSort::kAuto;  // particles in space-filling-curve order
};

struct ContactSpec {
  ContactModelKind model = ContactModelKind::kHertzMindlin;
  RollingModelKind rolling = RollingModelKind::kEpsd;
  double rolling_damping = 0.3;  // epsd: eta_r, the rolling dashpot's damping ratio
  // Tracker slot: every contact records its peak strain energy (a history slot). Not a deck
  // key: set by benchmarks and tests (breakage has its own tracker, chosen by [breakage]).
  bool track_peak_energy = false;
  // The breakage tracker (peak energy, the energy now, the level tested, the birth exclusion);
  // set by the core when the scene has a [breakage] table.
  bool track_breakage = false;
  // The pair gather's implementation: with AVX-512 eight candidates at a time (gathers and
  // compressed stores), else one at a time. Both give the same bits; not a deck key: tests set
  // it to compare them.
  bool scalar_gather = false;
  // Shaped particles in the scene (ParticleSpec::shaped): every particle goes through the
  // superellipse's kernel (a disc as a = b = r, n = 2). Set by the core (active_contact).
  bool shaped = false;
};

struct LifterSpec {
  int count = 0;         // bars evenly spaced around the shell
  double height = 0.0;   // m, radial
  double width = 0.0;    // m, along the shell
  double angle = 0.0;    // rad, angular position of the first bar in the drum frame
  std::string material;  // empty: the drum's material
};

struct DrumSpec {
  bool present = false;
  double radius = 0.0;
  Vec2 center{0.0, 0.0};
  double speed = 0.0;  // rad/s, counter-clockwise positive (resolved from rpm / critical_fraction)
  double ramp_time = 0.0;  // s to reach the speed (linear ramp from 0)
  int sides = 0;           // 0: exact circle; N >= 3: regular N-gon with vertices on the circle
  double angle = 0.0;      // rad, initial drum angle
  std::string material;
  std::vector<LifterSpec> lifters;
};

enum class FillRegion { kBottom, kFull, kBox, kAnnulus };

// A particle's shape: the disc (a sphere moving in the plane) or the superellipse
// |x/a|^n + |y/b|^n = 1 (core/shape/superellipse.hpp).
enum class ParticleShape { kDisc, kSuperellipse };

// A placed fill's law of sizes (core/setup/size_law.hpp).
enum class SizeDistribution { kUniform, kNormal, kLognormal, kTable };

struct FillSpec {
  std::string material;
  // Exactly one source: count, fill_fraction, bed_filling, or file (a CSV packing).
  std::int64_t count = 0;
  double fill_fraction = 0.0;  // of the drum's cross-section area (sum of pi r^2)
  double bed_filling = 0.0;    // J: sum of pi r^2 = J kBedPacking (drum area)
  std::string file;            // resolved to an absolute path by the parser
  double radius_min = 0.0;     // mono-disperse: radius_min == radius_max
  double radius_max = 0.0;     // a table: half its smallest and largest size
  SizeDistribution size_distribution = SizeDistribution::kUniform;
  double d50 = 0.0;                    // m, normal and lognormal: the median diameter by mass
  double sigma = 0.0;                  // m, normal: the standard deviation of the diameter by mass
  double geometric_sd = 0.0;           // lognormal: exp of the standard deviation of ln(diameter)
  std::vector<double> sizes;           // m, table: diameters, increasing
  std::vector<double> mass_fractions;  // table: the mass share of each size, summing to 1
  bool mix = false;                    // placed together with the fill before it, interleaved
  FillRegion region = FillRegion::kBottom;
  Vec2 box_min{0.0, 0.0};  // region = "box"
  Vec2 box_max{0.0, 0.0};
  Vec2 velocity{0.0, 0.0};  // initial velocity of every filled particle
  // Superellipses: the size law gives each particle's volume-equivalent radius r (the sphere of
  // its mass), `aspect` = b / a and `exponent` its form; each is turned by a random angle.
  ParticleShape shape = ParticleShape::kDisc;
  double aspect = 1.0;    // b / a, in (0, 1]
  double exponent = 2.0;  // n, in [2, kMaxExponent]
  int source_line = 0;    // deck line, for error messages
  int index = 0;          // its element of the deck's [[fill]] array: "fill[2]" in messages
};

struct ParticleSpec {
  std::string material;
  double radius = 0.0;
  Vec2 position{0.0, 0.0};
  Vec2 velocity{0.0, 0.0};
  double spin = 0.0;  // rad/s, counter-clockwise positive
  int source_line = 0;
  // A shaped particle (core/shape/superellipse.hpp), when semi_a > 0: |x/a|^n + |y/b|^n = 1 in
  // its body frame, turned by `angle` (rad, counter-clockwise); `radius` is then ignored (the
  // store's radius is the bounding circle). The deck's shape = "superellipse" sets it.
  ParticleShape shape = ParticleShape::kDisc;  // the deck's word; semi_a > 0 is what counts
  double semi_a = 0.0;
  double semi_b = 0.0;
  double exponent = 2.0;
  double angle = 0.0;
  bool shaped() const { return semi_a > 0.0; }
};

struct WallSpec {
  Vec2 from{0.0, 0.0};
  Vec2 to{0.0, 0.0};
  std::string material;
  Vec2 velocity{0.0, 0.0};  // a translating wall (moves rigidly)
};

// Ore breakage (docs/models.md, "Grinding"): particles of one material break under the peak
// strain energy of their contacts, each body taking its share of a contact's energy.
enum class BreakageModel { kThesis, kVogelPeukert };
enum class EnergySplit { kCompliance, kWhole };
enum class FragmentLaw { kEqual, kT10 };

struct BreakageSpec {
  bool present = false;
  std::string material;  // the material that breaks (ore)
  BreakageModel model = BreakageModel::kThesis;
  // A contact's peak strain energy shared by the two bodies in proportion to their compliances
  // (1 - nu^2) / E (the Hertz approach of each surface), or the whole energy to each (thesis).
  EnergySplit energy_split = EnergySplit::kCompliance;
  double minimum_energy = 0.1;  // J, E_min: a share below it does no damage (thesis Table 1)
  double strength = 1.0;        // 1/J, S: P = 1 - exp(-S E_t) (thesis Table 1)
  // vogel-peukert: P = 1 - exp(-f_mat d (W_m - W_m,min)) per loading, W_m,min = xw_min / d.
  double f_mat = 0.0;   // kg/(J m)
  double xw_min = 0.0;  // J m/kg: the size times the threshold specific energy
  FragmentLaw fragments = FragmentLaw::kEqual;
  double fragments_mean = 4.0;  // equal: the fragment count's normal law, rounded and clipped
  double fragments_sd = 2.0 / 3.0;
  int fragments_min = 2;
  int fragments_max = 6;
  // t10: t10 = A (1 - exp(-b E_cs)) (%), E_cs the breaking loading's specific energy (kWh/t);
  // progeny passing (x / X)^alpha with t10 = (1/10)^alpha; below fines_diameter: fines.
  double t10_a = 0.0;           // %
  double t10_b = 0.0;           // t/kWh
  double fines_diameter = 0.0;  // m
  double minimum_radius = 0.0;  // m: particles smaller than this do not break
  double start = 0.0;           // s: contacts that peak before this time do no damage
};

// The smallest fragment a break can make (m): equal fragments of the smallest breakable particle,
// or half the fines diameter (t10 progeny are coarser).
inline double smallest_fragment_radius(const BreakageSpec& b) {
  if (b.fragments == FragmentLaw::kT10) return 0.5 * b.fines_diameter;
  return b.minimum_radius / std::cbrt(static_cast<double>(b.fragments_max));
}

// Ore feed: one particle every `period` s (or as a mass rate), radius uniform in
// [radius_min, radius_max], where the charge is thinnest or at `point`.
struct FeedSpec {
  bool present = false;
  std::string material;
  double period = 0.0;     // s between fed particles (0: use mass_rate)
  double mass_rate = 0.0;  // kg/s (0: use period)
  double radius_min = 0.0;
  double radius_max = 0.0;
  double start = 0.0;  // s: the first particle at this time
  bool has_point = false;
  Vec2 point{0.0, 0.0};
  Vec2 velocity{0.0, 0.0};
};

// The discharge ([sieve]): ore narrower than the aperture (a diameter) leaves the mill where
// the type says: in the box (the thesis's central sieve), in the grate zone at the shell (an
// end grate seen in the plane), or, overflow, the finest first while the ore hold-up exceeds
// `holdup`.
enum class DischargeType { kBox, kGrate, kOverflow };

struct SieveSpec {
  bool present = false;
  std::string material;  // the material it lets through (ore)
  DischargeType type = DischargeType::kBox;
  Vec2 box_min{-0.5, -0.5};  // box: thesis: 1 m x 1 m around the drum centre
  Vec2 box_max{0.5, 0.5};
  double aperture = 0.04;    // m, compared with the diameter
  double grate_width = 0.0;  // m, grate: radial width of the zone inside the shell
  double holdup = 0.0;       // kg, overflow: the ore hold-up the mill keeps
};

// The drum's shell ring and its lifter bars as plane-strain finite elements (core/structure,
// docs/models.md "The shell as finite elements"), loaded by the charge's wall contacts.
struct ShellSpec {
  bool present = false;
  double thickness = 0.0;              // m, the ring outside the drum's circle
  std::string material;                // empty: the drum's
  int elements_through_thickness = 2;  // across the ring and across each bar
  std::optional<double> element_size;  // m, along the ring; unset: the thickness
  double depth = 0.0;                  // m, the depth of mill the slice stands for
};

struct OutputSpec {
  std::string directory = "out";
  double series_interval = 1.0e-3;
  double snapshot_interval = 0.0;    // 0: final state only
  double checkpoint_interval = 0.0;  // s of simulated time; 0: none (but at the end)
  double checkpoint_minutes = 0.0;   // min of wall-clock time; 0: none
  double progress_interval = 5.0;    // s of wall time between plain progress lines
  // Mill analytics (core/mill/mill_analytics.hpp): the averaging window of power and regime, and
  // the collision energy spectra with their size classes (edges size_class_min * ratio^k, m).
  double analysis_window = 1.0;
  bool collision_spectra = false;
  double size_class_min = 0.001;
  double size_class_ratio = 2.0;
};

struct Scene {
  std::string title;
  std::string deck_path;  // the deck it came from (for messages and run.json)
  RunSpec run;
  ContactSpec contact;
  std::vector<MaterialSpec> materials;
  std::vector<InteractionSpec> interactions;
  DrumSpec drum;
  std::vector<FillSpec> fills;  // count / fill_fraction fills: the core places them
  // [[fill]] tables with a `file`, as a record (run.json, the resolved deck): the parser has
  // already read each CSV into `particles`, after the [[particle]] tables, in this order; here
  // `count` is the number of rows read and `material` / `velocity` are the defaults for rows
  // without those columns. The core does not read this.
  std::vector<FillSpec> file_fills;
  std::vector<ParticleSpec> particles;
  std::vector<WallSpec> walls;
  BreakageSpec breakage;
  FeedSpec feed;
  SieveSpec sieve;
  ShellSpec shell;
  OutputSpec output;
  // Where the deck gave a value that a check after reading may refuse (core/setup/validate.hpp, the
  // fill placement), by the key's dotted path as messages name it: "run.duration" ->
  // "deck.in:3:12", or "--set run.duration=9" when an override set it; absent for a default.
  // "fill[K].csv" holds the CSV file of a fill from a file as messages name it.
  std::map<std::string, std::string> where;
};

// A scene with ore models ([breakage], [feed] or [sieve]).
inline bool is_ore_scene(const Scene& s) {
  return s.breakage.present || s.feed.present || s.sieve.present;
}

// Whether any particle of the scene is a superellipse (ParticleSpec::shaped).
inline bool has_shaped_particles(const Scene& s) {
  for (const ParticleSpec& p : s.particles)
    if (p.shaped()) return true;
  for (const FillSpec& f : s.fills)
    if (f.shape == ParticleShape::kSuperellipse) return true;
  return false;
}

// The contact models a scene runs: its [contact] with the trackers its tables ask for switched
// on (breakage, which records the peak energy too; else the collision spectra's peak energy).
inline ContactSpec active_contact(const Scene& s) {
  ContactSpec c = s.contact;
  c.track_breakage = s.breakage.present;
  c.track_peak_energy = s.contact.track_peak_energy || s.output.collision_spectra;
  c.shaped = c.shaped || has_shaped_particles(s);
  return c;
}

// Index of a material by name, or -1.
int find_material(const Scene& scene, const std::string& name);

}  // namespace dem2d
