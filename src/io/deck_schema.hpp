// The deck's description: every key of every table written once, with its type, unit, allowed
// range, default, documentation line and the Scene field it fills. Everything else about a key
// comes from its entry here:
//   - the reader (deck.cpp, its TableReader in deck_reader.cpp) checks each key's type, range
//     and presence, names the valid keys for "unknown key ...; did you mean", and stores the
//     value through `field`;
//   - the resolved deck (deck_resolved.cpp, also in run.json) writes each key back through
//     `field`, in this order;
//   - the key tables of docs/input.md are generated from it (key_tables(); the test
//     DeckDocs.KeyTablesMatchTheDescription names the key where the docs differ);
//   - tests/io/test_deck.cpp compares two scenes key by key through it.
// Defaults are not written here: a key's default is its Scene field's initial value
// (core/base/scene.hpp), which the docs show. Rules between keys (speed / speed_rpm /
// critical_fraction, count / fill_fraction / file, poisson_ratio / shear_modulus, ...) are code
// in deck.cpp that runs after the per-key pass.
//
// Adding a key: one entry below, the Scene field it fills, and the physics that uses it; then
// regenerate the docs table (DEM2D_UPDATE_DOCS=1 test_io --gtest_filter='DeckDocs.*').
#pragma once

#include <array>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/base/scene.hpp"
#include "io/deck.hpp"  // kRadiansPerDegree, kRadPerSecondPerRpm

namespace dem2d::deck {

// ---------------------------------------------------------------------------------------------
// Choices: the words of every choice key, each listed once

// One word of a choice key and the value it selects.
template <class E>
struct Choice {
  std::string_view name;
  E value;
};

inline constexpr std::array kContactModels = {
    Choice<ContactModelKind>{"hertz-mindlin", ContactModelKind::kHertzMindlin},
    Choice<ContactModelKind>{"thesis", ContactModelKind::kThesis},
    Choice<ContactModelKind>{"linear", ContactModelKind::kLinear},
};
inline constexpr std::array kRollingModels = {
    Choice<RollingModelKind>{"epsd", RollingModelKind::kEpsd},
    Choice<RollingModelKind>{"constant", RollingModelKind::kConstant},
    Choice<RollingModelKind>{"none", RollingModelKind::kNone},
};
inline constexpr std::array kIntegrators = {
    Choice<IntegratorKind>{"verlet", IntegratorKind::kVerlet},
    Choice<IntegratorKind>{"iterative", IntegratorKind::kIterative},
};
inline constexpr std::array kSpatialSorts = {
    Choice<SpatialSort>{"auto", SpatialSort::kAuto},
    Choice<SpatialSort>{"always", SpatialSort::kAlways},
    Choice<SpatialSort>{"never", SpatialSort::kNever},
};
inline constexpr std::array kGuardModes = {
    Choice<bool>{"stop", false},
    Choice<bool>{"warn", true},
};
inline constexpr std::array kFillRegions = {
    Choice<FillRegion>{"bottom", FillRegion::kBottom},
    Choice<FillRegion>{"full", FillRegion::kFull},
    Choice<FillRegion>{"box", FillRegion::kBox},
    Choice<FillRegion>{"annulus", FillRegion::kAnnulus},
};
inline constexpr std::array kSizeDistributions = {
    Choice<SizeDistribution>{"uniform", SizeDistribution::kUniform},
    Choice<SizeDistribution>{"normal", SizeDistribution::kNormal},
    Choice<SizeDistribution>{"lognormal", SizeDistribution::kLognormal},
    Choice<SizeDistribution>{"table", SizeDistribution::kTable},
};

inline constexpr std::array kParticleShapes = {
    Choice<ParticleShape>{"disc", ParticleShape::kDisc},
    Choice<ParticleShape>{"superellipse", ParticleShape::kSuperellipse},
};

inline constexpr std::array kBreakageModels = {
    Choice<BreakageModel>{"thesis", BreakageModel::kThesis},
    Choice<BreakageModel>{"vogel-peukert", BreakageModel::kVogelPeukert},
};
inline constexpr std::array kEnergySplits = {
    Choice<EnergySplit>{"compliance", EnergySplit::kCompliance},
    Choice<EnergySplit>{"whole", EnergySplit::kWhole},
};
inline constexpr std::array kFragmentLaws = {
    Choice<FragmentLaw>{"equal", FragmentLaw::kEqual},
    Choice<FragmentLaw>{"t10", FragmentLaw::kT10},
};
inline constexpr std::array kDischargeTypes = {
    Choice<DischargeType>{"box", DischargeType::kBox},
    Choice<DischargeType>{"grate", DischargeType::kGrate},
    Choice<DischargeType>{"overflow", DischargeType::kOverflow},
};

// The word for `value` (choices are exhaustive, so one always matches).
template <class E, std::size_t N>
constexpr std::string_view choice_name(const std::array<Choice<E>, N>& choices, E value) {
  for (const auto& choice : choices) {
    if (choice.value == value) return choice.name;
  }
  return "?";
}

// The words of a choice list alone, for messages and the docs.
template <const auto& kChoices>
inline constexpr auto kChoiceNames = [] {
  std::array<std::string_view, std::size(kChoices)> names{};
  for (std::size_t i = 0; i < names.size(); ++i) names[i] = kChoices[i].name;
  return names;
}();

// Columns of a [[fill]] file (x, y, radius required).
inline constexpr std::array<std::string_view, 7> kCsvColumns = {"x",  "y",    "radius",  "vx",
                                                                "vy", "spin", "material"};

// ---------------------------------------------------------------------------------------------
// The parts of a key's description

// What a key holds.
enum class Type {
  kNumber,        // a float (an integer is accepted)
  kInteger,       // an integer (a float is an error)
  kBool,          // true or false
  kString,        // any string
  kMaterial,      // a string naming a defined [[material]]
  kChoice,        // one of the words in `choices`
  kVector,        // [x, y]: exactly two numbers
  kNumberOrAuto,  // a number or "auto" (run.dt)
  kMaterialPair,  // two material names ["a", "b"] (interaction.materials)
  kNumberList,    // [a, b, ...]: one or more numbers, each in the key's range
  kTable,         // a sub-table [name], described by its own Table
  kTableArray,    // an array of tables [[name]], described by its own Table
};

enum class Need { kOptional, kRequired };

// The allowed interval of a number, and its wording ("> 0", "in (0, 1]").
struct Bound {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  constexpr bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  constexpr bool unbounded() const {
    return lo == -std::numeric_limits<double>::infinity() &&
           hi == std::numeric_limits<double>::infinity();
  }
  std::string text() const;      // for messages: "> 0", ">= 1", "in (0, 1]"
  std::string doc_text() const;  // for the docs: "> 0", "≥ 1", "(0, 1]"
};

inline constexpr Bound kAnyNumber{};
inline constexpr Bound kPositive{0.0, Bound{}.hi, true, false};      // > 0
inline constexpr Bound kNonNegative{0.0, Bound{}.hi, false, false};  // >= 0
inline constexpr Bound kRestitution{0.0, 1.0, true, false};          // (0, 1]
inline constexpr Bound kUnitFraction{0.0, 1.0, true, false};         // (0, 1]
inline constexpr Bound kPoissonRatio{0.0, 0.5, false, true};   // [0, 0.5): isotropic, compressible
inline constexpr Bound kFillFraction{0.0, 0.9, true, true};    // (0, 0.9): room left to place them
inline constexpr Bound kBedFilling{0.0, 1.0, true, true};      // (0, 1): J, the bed with its voids
inline constexpr Bound kMassFraction{0.0, 1.0, false, false};  // [0, 1]
inline constexpr Bound kGeometricSd{1.0, Bound{}.hi, true, false};  // > 1
inline constexpr Bound kAtLeastOne{1.0, Bound{}.hi, false, false};  // >= 1 (integers)
inline constexpr Bound kAtLeastTwo{2.0, Bound{}.hi, false, false};  // >= 2 (integers)
inline constexpr Bound kPercent{0.0, 100.0, true, false};           // (0, 100]
inline constexpr Bound kSizeRatio{1.1, 1e3, false, false};          // [1.1, 1000]
inline constexpr Bound kSizeEdge{1e-9, 10.0, false, true};          // [1 nm, 10 m)
inline constexpr Bound kExponent{2.0, 50.0, false, false};          // a superellipse's n
// A particle's radius, at least 1 nm: far below any particle a mill holds, and far above where
// its mass rho 4/3 pi r^3 and moment of inertia 2/5 m r^2 leave the normal doubles (for steel
// the inertia below about 5e-63 m, the mass below 1e-104 m: radius = 1e-120 has mass 0).
inline constexpr double kMinRadius = 1e-9;
inline constexpr Bound kRadius{kMinRadius, Bound{}.hi, false, false};          // >= 1 nm
inline constexpr Bound kDiameter{2.0 * kMinRadius, Bound{}.hi, false, false};  // >= 2 nm

// A key's value once checked: a number, integer, bool, string (also a choice's word, or
// "auto"), [x, y], a list of names, or a list of numbers.
using Names = std::vector<std::string>;
using Numbers = std::vector<double>;
using Value = std::variant<double, std::int64_t, bool, std::string, Vec2, Names, Numbers>;

// The value as TOML writes it ("1e-6", "[0.0, -9.81]", "\"auto\"") and as JSON does.
std::string toml_text(const Value& value);
std::string json_text(const Value& value);

// How a key's value goes into the Scene and comes back out, in the deck's units.
template <class T>
struct Field {
  // Puts a checked value into the target. nullptr: code after the per-key pass uses the value
  // (critical_fraction needs the gravity and the radius; a fill's file is read as a CSV).
  void (*store)(T&, const Value&) = nullptr;
  // The value back from the target; nullopt when unset (an interaction's coefficient).
  // nullptr: never written back (speed_rpm: the resolved deck gives speed).
  std::optional<Value> (*load)(const T&) = nullptr;
};

// The contact models that take a key, as a bit set. A key given under another model is an
// error ("not used by contact.model = ..."), and the resolved deck leaves it out.
using ModelSet = unsigned;
constexpr ModelSet model_bit(ContactModelKind model) { return 1u << static_cast<unsigned>(model); }
inline constexpr ModelSet kAllModels = ~0u;
constexpr bool takes(ModelSet models, ContactModelKind model) {
  return (models & model_bit(model)) != 0;
}

// One key of table T (RunSpec, MaterialSpec, ...).
template <class T>
struct Key {
  std::string_view name;
  Type type = Type::kNumber;
  Need need = Need::kOptional;
  std::string_view unit = "";                      // "" in the docs: "–"
  Bound range = kAnyNumber;                        // kNumber, kInteger, kNumberOrAuto
  std::int64_t max = INT_MAX;                      // kInteger: also at most this (the field's size)
  std::span<const std::string_view> choices = {};  // kChoice
  ModelSet models = kAllModels;
  Field<T> field = {};
  // The resolved deck writes the key only where this holds (nullptr: always); e.g. count only
  // for a fill by count, poisson_ratio only where it reproduces the shear modulus.
  bool (*written_if)(const T&) = nullptr;
  // The docs' "default" and "allowed" columns, where the field's initial value and the range
  // do not say it ("chosen by the program", "0 or ≥ 3").
  std::string_view default_text = "";
  std::string_view allowed = "";
  std::string_view doc = "";  // the docs' "meaning" column (Markdown)
};

// A table of the deck and its keys.
template <class T>
struct Table {
  std::string_view path;  // dotted, without indices ("drum.lifter"); "" for the top level
  bool repeated;          // an array of tables [[path]]
  std::span<const Key<T>> keys;
};

// ---------------------------------------------------------------------------------------------
// Fields: the usual ways a key fills its Scene member

template <class M>
struct MemberOf;
template <class C, class V>
struct MemberOf<V C::*> {
  using Owner = C;
  using Type = V;
};

template <class V>
V from_value(const Value& v) {
  if constexpr (std::is_same_v<V, double> || std::is_same_v<V, std::optional<double>>) {
    return std::get<double>(v);
  } else if constexpr (std::is_same_v<V, bool>) {
    return std::get<bool>(v);
  } else if constexpr (std::is_integral_v<V>) {
    return static_cast<V>(std::get<std::int64_t>(v));  // the reader checked `max`
  } else {
    return std::get<V>(v);  // std::string, Vec2, Numbers
  }
}

template <class V>
std::optional<Value> to_value(const V& x) {
  if constexpr (std::is_same_v<V, std::optional<double>>) {
    return x ? std::optional<Value>(*x) : std::nullopt;
  } else if constexpr (std::is_same_v<V, bool>) {
    return Value(x);
  } else if constexpr (std::is_integral_v<V>) {
    return Value(static_cast<std::int64_t>(x));
  } else {
    return Value(x);
  }
}

// The value is the member as it is (SI units).
template <auto kMember>
constexpr auto member() {
  using Traits = MemberOf<decltype(kMember)>;
  using T = typename Traits::Owner;
  using V = typename Traits::Type;
  return Field<T>{[](T& t, const Value& v) { t.*kMember = from_value<V>(v); },
                  [](const T& t) { return to_value<V>(t.*kMember); }};
}

// A word of `kChoices` for an enum member.
template <auto kMember, const auto& kChoices>
constexpr auto choice() {
  using T = typename MemberOf<decltype(kMember)>::Owner;
  return Field<T>{[](T& t, const Value& v) {
                    for (const auto& c : kChoices) {
                      if (c.name == std::get<std::string>(v)) t.*kMember = c.value;
                    }
                  },
                  [](const T& t) -> std::optional<Value> {
                    return std::string(choice_name(kChoices, t.*kMember));
                  }};
}

// Degrees such that deg * kRadiansPerDegree reproduces `radians` bit for bit (the reader's
// conversion), the shortest such text: 15, not 14.999999999999998.
double degrees_for(double radians);

// Degrees in the deck, radians in the Scene.
template <auto kMember>
constexpr auto degrees() {
  using T = typename MemberOf<decltype(kMember)>::Owner;
  return Field<T>{
      [](T& t, const Value& v) { t.*kMember = std::get<double>(v) * kRadiansPerDegree; },
      [](const T& t) -> std::optional<Value> { return degrees_for(t.*kMember); }};
}

// ---------------------------------------------------------------------------------------------
// The tables, in the order of docs/input.md

inline constexpr Key<RunSpec> kRunKeys[] = {
    {.name = "duration",
     .unit = "s",
     .range = kPositive,
     .field = member<&RunSpec::duration>(),
     .doc = "simulated time to run"},
    {.name = "dt",
     .type = Type::kNumberOrAuto,
     .unit = "s",
     .range = kPositive,
     .field = {[](RunSpec& r, const Value& v) {
                 r.dt_auto = std::holds_alternative<std::string>(v);  // "auto"
                 r.dt = r.dt_auto ? 0.0 : std::get<double>(v);
               },
               [](const RunSpec& r) -> std::optional<Value> {
                 return r.dt_auto ? Value(std::string("auto")) : Value(r.dt);
               }},
     .doc = "time step; `\"auto\"`: the safe dt (below)"},
    {.name = "integrator",
     .type = Type::kChoice,
     .choices = kChoiceNames<kIntegrators>,
     .field = choice<&RunSpec::integrator, kIntegrators>(),
     .doc = "velocity Verlet, or the thesis's iterative predictor–corrector (thesis section "
            "1.7)"},
    {.name = "tolerance",
     .range = kPositive,
     .field = member<&RunSpec::tolerance>(),
     .doc = "iterative only: a step has converged when the largest relative change of the "
            "accelerations between passes is below this (thesis eq. 31)"},
    {.name = "max_passes",
     .type = Type::kInteger,
     .range = kAtLeastOne,
     .field = member<&RunSpec::max_passes>(),
     .doc = "iterative only: passes per step before the step is accepted unconverged "
            "(counted in `run.json`)"},
    {.name = "guards",
     .type = Type::kChoice,
     .choices = kChoiceNames<kGuardModes>,
     .field = choice<&RunSpec::guards_warn, kGuardModes>(),
     .doc =
         "what the run's guards do when one fires (an overlap past 0.25 of the smaller "
         "radius, energy created beyond 5 % of what went through the system, iterative "
         "passes that do not settle): `\"stop\"` ends the run with exit 3; `\"warn\"` tells each "
         "kind when it first fires and runs to the end, which then exits 3 all the same. A "
         "non-finite state and a particle moving more than 0.25 of its radius in one step "
         "always stop"},
    {.name = "seed",
     .type = Type::kInteger,
     .range = kNonNegative,
     .max = INT64_MAX,
     .field = member<&RunSpec::seed>(),
     .doc = "every random draw (fill placement) derives from it; the same seed gives "
            "the same run on any rank count"},
    {.name = "gravity",
     .type = Type::kVector,
     .unit = "m/s²",
     .field = member<&RunSpec::gravity>(),
     .doc = "gravitational acceleration"},
    {.name = "skin",
     .unit = "m",
     .range = kNonNegative,
     .field = member<&RunSpec::skin>(),
     .written_if = [](const RunSpec& r) { return r.skin >= 0.0; },  // < 0: the core chooses
     .default_text = "chosen by the program",
     .doc = "Verlet-list skin: neighbour lists are rebuilt when some particle has moved half "
            "of it; absent, the program chooses (at present 0.4 times the smallest radius)"},
    {.name = "dt_safety",
     .range = kUnitFraction,
     .field = member<&RunSpec::dt_safety>(),
     .doc = "fraction of the Rayleigh time that `dt = \"auto\"` may use"},
    {.name = "allow_unsafe_dt",
     .type = Type::kBool,
     .field = member<&RunSpec::allow_unsafe_dt>(),
     .doc = "run even when a given `dt` exceeds half the contact time bound; otherwise that is "
            "an error naming the safe `dt`"},
    {.name = "sectors_per_rank",
     .type = Type::kInteger,
     .range = kAtLeastOne,
     .max = 4096,
     .field = member<&RunSpec::sectors_per_rank>(),
     .doc = "parallel runs: thin angular sectors per rank about the drum centre, grouped by "
            "METIS into one arc per rank (`bench/partition`: 16 cannot balance a settled "
            "charge within 5 % from 4 ranks up, 24 can)"},
    {.name = "repartition_threshold",
     .range = kPositive,
     .field = member<&RunSpec::repartition_threshold>(),
     .doc = "parallel runs: the sectors are regrouped when max/mean work over ranks (work: "
            "owned particles + listed pairs) exceeds this (at most every 10 neighbour "
            "rebuilds). Waterfall at 2 ranks, 5 s: 1.2 leaves a mean imbalance of 1.072 (5 "
            "partitions), 1.1: 1.028 (7), 1.05: 1.018 (19), 1.02: 1.010 (59)"},
    {.name = "spatial_sort",
     .type = Type::kChoice,
     .choices = kChoiceNames<kSpatialSorts>,
     .field = choice<&RunSpec::spatial_sort, kSpatialSorts>(),
     .doc = "storage order of the particles, for speed only (no bit of the physics changes): "
            "`\"auto\"` sorts them along a space-filling curve at a neighbour rebuild when a "
            "rank owns at least 250 000 of them and over 30 % of their pairs join particles far "
            "apart in memory (ids spatially random); `\"always\"` at every rebuild; "
            "`\"never\"` keeps them in id order"},
};

inline constexpr Key<ContactSpec> kContactKeys[] = {
    {.name = "model",
     .type = Type::kChoice,
     .choices = kChoiceNames<kContactModels>,
     .field = choice<&ContactSpec::model, kContactModels>(),
     .doc = "the normal and tangential contact law"},
    {.name = "rolling",
     .type = Type::kChoice,
     .choices = kChoiceNames<kRollingModels>,
     .field = choice<&ContactSpec::rolling, kRollingModels>(),
     .doc = "the rolling resistance model: elastic–plastic spring–dashpot, constant torque, or "
            "none"},
    {.name = "rolling_damping",
     .range = kNonNegative,
     .field = member<&ContactSpec::rolling_damping>(),
     .doc = "`\"epsd\"` only: damping ratio η_r of the rolling dashpot"},
};

// The coefficients only some contact models take.
inline constexpr ModelSet kRestitutionModels =
    model_bit(ContactModelKind::kHertzMindlin) | model_bit(ContactModelKind::kLinear);
inline constexpr ModelSet kThesisOnly = model_bit(ContactModelKind::kThesis);
inline constexpr ModelSet kLinearOnly = model_bit(ContactModelKind::kLinear);

// G = E / (2 (1 + nu)) reproduces the shear modulus: the resolved deck gives poisson_ratio
// (always so when the deck did), else shear_modulus (from which the reader derives nu).
inline bool poisson_reproduces_shear(const MaterialSpec& m) {
  return m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio)) == m.shear_modulus;
}

inline constexpr Key<MaterialSpec> kMaterialKeys[] = {
    {.name = "name",
     .type = Type::kString,
     .need = Need::kRequired,
     .field = member<&MaterialSpec::name>(),
     .allowed = "unique, non-empty, no `.`, `,`, `=` or control characters",
     .doc = "how the rest of the deck (and `--set material.NAME.KEY`) refers to it"},
    {.name = "density",
     .need = Need::kRequired,
     .unit = "kg/m³",
     .range = kPositive,
     .field = member<&MaterialSpec::density>(),
     .doc = "particle mass is ρ times the volume of a sphere, 4/3 π r³"},
    {.name = "youngs_modulus",
     .need = Need::kRequired,
     .unit = "Pa",
     .range = kPositive,
     .field = member<&MaterialSpec::youngs_modulus>(),
     .doc = "Young's modulus E"},
    {.name = "poisson_ratio",
     .range = kPoissonRatio,
     .field = member<&MaterialSpec::poisson_ratio>(),
     .written_if = poisson_reproduces_shear,
     .doc = "Poisson's ratio ν (not with `shear_modulus`)"},
    {.name = "shear_modulus",
     .unit = "Pa",
     .range = kPositive,
     .field = member<&MaterialSpec::shear_modulus>(),
     .written_if = [](const MaterialSpec& m) { return !poisson_reproduces_shear(m); },
     .default_text = "E / (2 (1 + ν))",
     .doc = "shear modulus G (not with `poisson_ratio`)"},
    {.name = "restitution",
     .range = kRestitution,
     .models = kRestitutionModels,
     .field = member<&MaterialSpec::restitution>(),
     .doc = "models `\"hertz-mindlin\"` and `\"linear\"`: coefficient of restitution of a "
            "normal impact"},
    {.name = "damping_normal",
     .range = kNonNegative,
     .models = kThesisOnly,
     .field = member<&MaterialSpec::damping_normal>(),
     .doc = "model `\"thesis\"`: normal damping ratio ζ_n"},
    {.name = "damping_tangential",
     .range = kNonNegative,
     .models = kThesisOnly,
     .field = member<&MaterialSpec::damping_tangential>(),
     .doc = "model `\"thesis\"`: tangential damping ratio ζ_t"},
    {.name = "sliding_friction",
     .range = kNonNegative,
     .field = member<&MaterialSpec::sliding_friction>(),
     .doc = "Coulomb friction coefficient μ_s"},
    {.name = "rolling_friction",
     .range = kNonNegative,
     .field = member<&MaterialSpec::rolling_friction>(),
     .doc = "rolling friction coefficient μ_r (times the effective radius R*)"},
    {.name = "normal_stiffness",
     .unit = "N/m",
     .range = kPositive,
     .models = kLinearOnly,
     .field = member<&MaterialSpec::normal_stiffness>(),
     .written_if = [](const MaterialSpec& m) { return m.normal_stiffness > 0.0; },  // 0: derived
     .default_text = "derived from E",
     .doc = "model `\"linear\"` only: spring stiffness k_n; a pair uses the mean of its two "
            "materials' values when both give one, else the Hertz secant stiffness at an "
            "overlap of 1 % of R*"},
};

inline constexpr Key<InteractionSpec> kInteractionKeys[] = {
    {.name = "materials",
     .type = Type::kMaterialPair,
     .need = Need::kRequired,
     .field = {[](InteractionSpec& s, const Value& v) {
                 s.material_a = std::get<Names>(v)[0];
                 s.material_b = std::get<Names>(v)[1];
               },
               [](const InteractionSpec& s) -> std::optional<Value> {
                 return Names{s.material_a, s.material_b};
               }},
     .doc = "the pair"},
    {.name = "restitution",
     .range = kRestitution,
     .models = kRestitutionModels,
     .field = member<&InteractionSpec::restitution>(),
     .default_text = "mean",
     .doc = "models `\"hertz-mindlin\"`, `\"linear\"`"},
    {.name = "damping_normal",
     .range = kNonNegative,
     .models = kThesisOnly,
     .field = member<&InteractionSpec::damping_normal>(),
     .default_text = "mean",
     .doc = "model `\"thesis\"`"},
    {.name = "damping_tangential",
     .range = kNonNegative,
     .models = kThesisOnly,
     .field = member<&InteractionSpec::damping_tangential>(),
     .default_text = "mean",
     .doc = "model `\"thesis\"`"},
    {.name = "sliding_friction",
     .range = kNonNegative,
     .field = member<&InteractionSpec::sliding_friction>(),
     .default_text = "mean"},
    {.name = "rolling_friction",
     .range = kNonNegative,
     .field = member<&InteractionSpec::rolling_friction>(),
     .default_text = "mean"},
};

inline constexpr Key<DrumSpec> kDrumKeys[] = {
    {.name = "radius",
     .need = Need::kRequired,
     .unit = "m",
     .range = kPositive,
     .field = member<&DrumSpec::radius>(),
     .doc = "inner radius R of the shell (of the circle through the polygon's vertices)"},
    {.name = "center",
     .type = Type::kVector,
     .unit = "m",
     .field = member<&DrumSpec::center>(),
     .doc = "the axis"},
    {.name = "speed",
     .unit = "rad/s",
     .field = member<&DrumSpec::speed>(),
     .doc = "angular speed ω, counter-clockwise positive"},
    {.name = "speed_rpm",
     .unit = "rev/min",
     .field = {[](DrumSpec& d, const Value& v) {
       d.speed = std::get<double>(v) * kRadPerSecondPerRpm;
     }},
     .default_text = "–",
     .doc = "instead of `speed`: ω = rpm · 2π / 60"},
    {.name = "critical_fraction",
     .default_text = "–",
     .doc = "instead of `speed`: ω = f · √(\\|g\\| / R), a fraction of the classical critical "
            "speed (see below)"},
    {.name = "ramp_time",
     .unit = "s",
     .range = kNonNegative,
     .field = member<&DrumSpec::ramp_time>(),
     .doc = "the speed rises linearly from 0 over this time"},
    {.name = "sides",
     .type = Type::kInteger,
     .range = kNonNegative,
     .field = member<&DrumSpec::sides>(),
     .allowed = "0 or ≥ 3",
     .doc = "0: an exact circle; N: a regular N-gon of flat segments with its vertices on the "
            "circle (as in the thesis)"},
    {.name = "angle",
     .unit = "**degrees**",
     .field = degrees<&DrumSpec::angle>(),
     .doc = "initial angle of the shell (where the polygon's first vertex and the lifters "
            "start)"},
    {.name = "material",
     .type = Type::kMaterial,
     .need = Need::kRequired,
     .field = member<&DrumSpec::material>(),
     .doc = "the shell's material"},
    {.name = "lifter", .type = Type::kTableArray},
};

inline constexpr Key<LifterSpec> kLifterKeys[] = {
    {.name = "count",
     .type = Type::kInteger,
     .need = Need::kRequired,
     .range = kAtLeastOne,
     .field = member<&LifterSpec::count>(),
     .doc = "bars, evenly spaced around the shell"},
    {.name = "height",
     .need = Need::kRequired,
     .unit = "m",
     .range = kPositive,
     .field = member<&LifterSpec::height>(),
     .allowed = "> 0, < drum radius",
     .doc = "radial height of a bar"},
    {.name = "width",
     .need = Need::kRequired,
     .unit = "m",
     .range = kPositive,
     .field = member<&LifterSpec::width>(),
     .doc = "width of a bar along the shell"},
    {.name = "angle",
     .unit = "**degrees**",
     .field = degrees<&LifterSpec::angle>(),
     .doc = "angular position of the first bar, in the drum's frame"},
    {.name = "material",
     .type = Type::kMaterial,
     .field = member<&LifterSpec::material>(),
     .written_if = [](const LifterSpec& l) { return !l.material.empty(); },  // "": the drum's
     .default_text = "the drum's",
     .doc = "the bars' material"},
};

// Which keys a fill's resolved deck has: a file fill gives its file, material and velocity
// only; a placed fill its count, fill fraction or bed filling, its sizes (radius or radius
// range, a distribution's keys, a table), region and box; size_distribution and mix only
// where they are not the default.
inline bool placed(const FillSpec& f) { return f.file.empty(); }
inline bool has_law(const FillSpec& f, SizeDistribution law) {
  return placed(f) && f.size_distribution == law;
}
inline bool by_radius(const FillSpec& f) {  // radius, or radius_min and radius_max
  return placed(f) && f.size_distribution != SizeDistribution::kTable;
}
inline bool monodisperse(const FillSpec& f) { return by_radius(f) && f.radius_min == f.radius_max; }
inline bool polydisperse(const FillSpec& f) { return by_radius(f) && f.radius_min != f.radius_max; }
inline bool in_box(const FillSpec& f) { return placed(f) && f.region == FillRegion::kBox; }

inline constexpr Key<FillSpec> kFillKeys[] = {
    {.name = "material",
     .type = Type::kMaterial,
     .field = member<&FillSpec::material>(),
     .written_if = [](const FillSpec& f) { return !f.material.empty(); },
     .default_text = "**required** (see `file`)",
     .doc = "the particles' material"},
    {.name = "count",
     .type = Type::kInteger,
     .range = kAtLeastOne,
     .max = INT64_MAX,
     .field = member<&FillSpec::count>(),
     .written_if =
         [](const FillSpec& f) {
           return placed(f) && f.fill_fraction <= 0.0 && f.bed_filling <= 0.0;
         },
     .default_text = "–",
     .doc = "place this many particles"},
    {.name = "fill_fraction",
     .range = kFillFraction,
     .field = member<&FillSpec::fill_fraction>(),
     .written_if = [](const FillSpec& f) { return placed(f) && f.fill_fraction > 0.0; },
     .default_text = "–",
     .doc = "place particles until their total area Σ π r² is this fraction of the drum's "
            "cross-section (needs a `[drum]`)"},
    {.name = "bed_filling",
     .range = kBedFilling,
     .field = member<&FillSpec::bed_filling>(),
     .written_if = [](const FillSpec& f) { return placed(f) && f.bed_filling > 0.0; },
     .default_text = "–",
     .doc = "J, the bed with its voids over the drum's cross-section: place particles until Σ "
            "π r² is J × 0.84 (the bed's packing) of the drum's cross-section (needs a "
            "`[drum]`)"},
    {.name = "file",
     .type = Type::kString,
     .field = {nullptr,  // read as a CSV by the code after the per-key pass
               [](const FillSpec& f) -> std::optional<Value> { return f.file; }},
     .written_if = [](const FillSpec& f) { return !placed(f); },
     .default_text = "–",
     .allowed = "a readable CSV file",
     .doc = "read the particles from a packing made elsewhere (below)"},
    {.name = "radius",
     .unit = "m",
     .range = kRadius,
     .field = {
         [](FillSpec& f, const Value& v) { f.radius_min = f.radius_max = std::get<double>(v); },
         [](const FillSpec& f) -> std::optional<Value> { return f.radius_min; }},
     .written_if = monodisperse,
     .default_text = "–",
     .doc = "every particle has this radius"},
    {.name = "radius_min",
     .unit = "m",
     .range = kRadius,
     .field = member<&FillSpec::radius_min>(),
     .written_if = polydisperse,
     .default_text = "–",
     .allowed = "≥ 1e-09, ≤ `radius_max`",
     .doc = "instead of `radius`: radii are drawn uniformly in [`radius_min`, `radius_max`]; "
            "for a normal or lognormal law, the smallest radius it is truncated to"},
    {.name = "radius_max",
     .unit = "m",
     .range = kRadius,
     .field = member<&FillSpec::radius_max>(),
     .written_if = polydisperse,
     .default_text = "–",
     .allowed = "≥ 1e-09, ≥ `radius_min`",
     .doc = "instead of `radius`: the largest radius (with `radius_min`); for a normal or "
            "lognormal law, the largest radius it is truncated to"},
    {.name = "size_distribution",
     .type = Type::kChoice,
     .choices = kChoiceNames<kSizeDistributions>,
     .field = choice<&FillSpec::size_distribution, kSizeDistributions>(),
     .written_if =
         [](const FillSpec& f) {
           return placed(f) && f.size_distribution != SizeDistribution::kUniform;
         },
     .doc = "the law of the sizes (below): uniform in radius between `radius_min` and "
            "`radius_max` (or one `radius`), a normal or lognormal law of diameters by mass "
            "truncated to [2 `radius_min`, 2 `radius_max`], or a table of sizes and mass "
            "fractions"},
    {.name = "d50",
     .unit = "m",
     .range = kPositive,
     .field = member<&FillSpec::d50>(),
     .written_if =
         [](const FillSpec& f) {
           return has_law(f, SizeDistribution::kNormal) || has_law(f, SizeDistribution::kLognormal);
         },
     .default_text = "**required** with `\"normal\"`, `\"lognormal\"`",
     .allowed = "in [2 `radius_min`, 2 `radius_max`]",
     .doc = "the median diameter by mass (half the charge's mass is in smaller particles); "
            "for `\"normal\"` also the mean"},
    {.name = "sigma",
     .unit = "m",
     .range = kPositive,
     .field = member<&FillSpec::sigma>(),
     .written_if = [](const FillSpec& f) { return has_law(f, SizeDistribution::kNormal); },
     .default_text = "**required** with `\"normal\"`",
     .doc = "`\"normal\"`: the standard deviation of the diameter by mass"},
    {.name = "geometric_sd",
     .range = kGeometricSd,
     .field = member<&FillSpec::geometric_sd>(),
     .written_if = [](const FillSpec& f) { return has_law(f, SizeDistribution::kLognormal); },
     .default_text = "**required** with `\"lognormal\"`",
     .doc = "`\"lognormal\"`: the geometric standard deviation of the diameter by mass, the "
            "exponential of the standard deviation of ln d (d84 / d50)"},
    {.name = "sizes",
     .type = Type::kNumberList,
     .unit = "m",
     .range = kDiameter,
     .field = member<&FillSpec::sizes>(),
     .written_if = [](const FillSpec& f) { return has_law(f, SizeDistribution::kTable); },
     .default_text = "**required** with `\"table\"`",
     .allowed = "each ≥ 2e-09, increasing",
     .doc = "`\"table\"`: the particles' diameters"},
    {.name = "mass_fractions",
     .type = Type::kNumberList,
     .range = kMassFraction,
     .field = member<&FillSpec::mass_fractions>(),
     .written_if = [](const FillSpec& f) { return has_law(f, SizeDistribution::kTable); },
     .default_text = "**required** with `\"table\"`",
     .allowed = "each in [0, 1], one per size, summing to 1 (within 1e-9)",
     .doc = "`\"table\"`: the share of the fill's mass in particles of each size"},
    {.name = "region",
     .type = Type::kChoice,
     .choices = kChoiceNames<kFillRegions>,
     .field = choice<&FillSpec::region, kFillRegions>(),
     .written_if = placed,
     .doc = "where the particles start (below)"},
    {.name = "box_min",
     .type = Type::kVector,
     .unit = "m",
     .field = member<&FillSpec::box_min>(),
     .written_if = in_box,
     .default_text = "**required** with `\"box\"`",
     .allowed = "below and left of `box_max`",
     .doc = "lower left corner of the box"},
    {.name = "box_max",
     .type = Type::kVector,
     .unit = "m",
     .field = member<&FillSpec::box_max>(),
     .written_if = in_box,
     .default_text = "**required** with `\"box\"`",
     .allowed = "above and right of `box_min`",
     .doc = "upper right corner of the box"},
    {.name = "velocity",
     .type = Type::kVector,
     .unit = "m/s",
     .field = member<&FillSpec::velocity>(),
     .doc = "initial velocity of every particle of the fill"},
    {.name = "shape",
     .type = Type::kChoice,
     .choices = kChoiceNames<kParticleShapes>,
     .field = choice<&FillSpec::shape, kParticleShapes>(),
     .written_if = [](const FillSpec& f) { return f.shape != ParticleShape::kDisc; },
     .doc = "the particles' shape: `\"disc\"` (a sphere moving in the plane) or "
            "`\"superellipse\"` (\\|x/a\\|ⁿ + \\|y/b\\|ⁿ = 1, each turned by a random angle); "
            "a superellipse's radius (from the size keys) is its volume-equivalent radius"},
    {.name = "aspect",
     .range = kUnitFraction,
     .field = member<&FillSpec::aspect>(),
     .written_if = [](const FillSpec& f) { return f.shape == ParticleShape::kSuperellipse; },
     .allowed = "(0, 1], with `\"superellipse\"`",
     .doc = "`\"superellipse\"`: b / a, the short semi-axis over the long one"},
    {.name = "exponent",
     .range = kExponent,
     .field = member<&FillSpec::exponent>(),
     .written_if = [](const FillSpec& f) { return f.shape == ParticleShape::kSuperellipse; },
     .allowed = "[2, 50], with `\"superellipse\"`",
     .doc = "`\"superellipse\"`: n; 2 an ellipse, larger a rounded box"},
    {.name = "mix",
     .type = Type::kBool,
     .field = member<&FillSpec::mix>(),
     .written_if = [](const FillSpec& f) { return f.mix; },
     .doc = "place this fill together with the `[[fill]]` just before it (same region), "
            "their particles interleaved at random in one bed, instead of after it (below)"},
};

inline constexpr Key<ParticleSpec> kParticleKeys[] = {
    {.name = "material",
     .type = Type::kMaterial,
     .need = Need::kRequired,
     .field = member<&ParticleSpec::material>()},
    {.name = "shape",
     .type = Type::kChoice,
     .choices = kChoiceNames<kParticleShapes>,
     .field = choice<&ParticleSpec::shape, kParticleShapes>(),
     .written_if = [](const ParticleSpec& p) { return p.shaped(); },
     .doc = "`\"disc\"` (a sphere moving in the plane) or `\"superellipse\"` "
            "(\\|x/a\\|ⁿ + \\|y/b\\|ⁿ = 1 in the body's frame)"},
    {.name = "radius",
     .unit = "m",
     .range = kRadius,
     .field = member<&ParticleSpec::radius>(),
     .written_if = [](const ParticleSpec& p) { return !p.shaped(); },
     .default_text = "**required** for a disc"},
    {.name = "semi_axes",
     .type = Type::kVector,
     .unit = "m",
     .field = {[](ParticleSpec& p, const Value& v) {
                 p.semi_a = std::get<Vec2>(v).x;
                 p.semi_b = std::get<Vec2>(v).y;
               },
               [](const ParticleSpec& p) -> std::optional<Value> {
                 return Vec2{p.semi_a, p.semi_b};
               }},
     .written_if = [](const ParticleSpec& p) { return p.shaped(); },
     .default_text = "**required** with `\"superellipse\"`",
     .allowed = "[a, b], each ≥ 1e-09",
     .doc = "the semi-axes a (along the body's x) and b"},
    {.name = "exponent",
     .range = kExponent,
     .field = member<&ParticleSpec::exponent>(),
     .written_if = [](const ParticleSpec& p) { return p.shaped(); },
     .allowed = "[2, 50], with `\"superellipse\"`",
     .doc = "n; 2 an ellipse, larger a rounded box"},
    {.name = "angle",
     .unit = "**degrees**",
     .field = degrees<&ParticleSpec::angle>(),
     .written_if = [](const ParticleSpec& p) { return p.shaped(); },
     .doc = "`\"superellipse\"`: the body's x axis from the lab's x, counter-clockwise"},
    {.name = "position",
     .type = Type::kVector,
     .need = Need::kRequired,
     .unit = "m",
     .field = member<&ParticleSpec::position>(),
     .doc = "centre"},
    {.name = "velocity",
     .type = Type::kVector,
     .unit = "m/s",
     .field = member<&ParticleSpec::velocity>()},
    {.name = "spin",
     .unit = "rad/s",
     .field = member<&ParticleSpec::spin>(),
     .doc = "counter-clockwise positive"},
};

inline constexpr Key<WallSpec> kWallKeys[] = {
    {.name = "from",
     .type = Type::kVector,
     .need = Need::kRequired,
     .unit = "m",
     .field = member<&WallSpec::from>(),
     .doc = "one end"},
    {.name = "to",
     .type = Type::kVector,
     .need = Need::kRequired,
     .unit = "m",
     .field = member<&WallSpec::to>(),
     .allowed = "≠ `from`",
     .doc = "the other end"},
    {.name = "material",
     .type = Type::kMaterial,
     .need = Need::kRequired,
     .field = member<&WallSpec::material>()},
    {.name = "velocity",
     .type = Type::kVector,
     .unit = "m/s",
     .field = member<&WallSpec::velocity>(),
     .doc = "the wall translates rigidly at this velocity"},
};

inline constexpr Key<BreakageSpec> kBreakageKeys[] = {
    {.name = "material",
     .type = Type::kMaterial,
     .need = Need::kRequired,
     .field = member<&BreakageSpec::material>(),
     .doc = "the material that breaks (ore); its particles carry `damage`"},
    {.name = "model",
     .type = Type::kChoice,
     .choices = kChoiceNames<kBreakageModels>,
     .field = choice<&BreakageSpec::model, kBreakageModels>(),
     .doc = "the breakage probability: `\"thesis\"`, P = 1 - exp(-S E_t) on the share's energy "
            "(J, thesis T34-T36); `\"vogel-peukert\"`, P = 1 - exp(-f_mat d (W_m - W_m,min)) on "
            "its specific energy W_m (J/kg), a size effect through d (docs/models.md, "
            "\"Breakage\")"},
    {.name = "energy_split",
     .type = Type::kChoice,
     .choices = kChoiceNames<kEnergySplits>,
     .field = choice<&BreakageSpec::energy_split, kEnergySplits>(),
     .doc = "each body of a contact takes the share (1 - nu^2)/E of the two compliances of the "
            "contact's strain energy (`\"compliance\"`), or all of it (`\"whole\"`, the thesis's "
            "reading)"},
    {.name = "minimum_energy",
     .unit = "J",
     .range = kNonNegative,
     .field = member<&BreakageSpec::minimum_energy>(),
     .written_if = [](const BreakageSpec& b) { return b.model == BreakageModel::kThesis; },
     .doc = "thesis model: E_min, a share below it does no damage (thesis T34, Table 1)"},
    {.name = "strength",
     .unit = "1/J",
     .range = kPositive,
     .field = member<&BreakageSpec::strength>(),
     .written_if = [](const BreakageSpec& b) { return b.model == BreakageModel::kThesis; },
     .doc = "thesis model: S in the breakage probability P = 1 - exp(-S E_t), E_t = damage + E "
            "- E_min (thesis T36, Table 1)"},
    {.name = "f_mat",
     .unit = "kg/(J m)",
     .range = kPositive,
     .field = member<&BreakageSpec::f_mat>(),
     .written_if = [](const BreakageSpec& b) { return b.model == BreakageModel::kVogelPeukert; },
     .allowed = "> 0; required by vogel-peukert",
     .doc = "vogel-peukert: the material's breakage strength parameter f_mat"},
    {.name = "xw_min",
     .unit = "J m/kg",
     .range = kNonNegative,
     .field = member<&BreakageSpec::xw_min>(),
     .written_if = [](const BreakageSpec& b) { return b.model == BreakageModel::kVogelPeukert; },
     .doc = "vogel-peukert: the diameter times the threshold specific energy, x W_m,min (a "
            "particle of diameter d needs W_m > xw_min / d)"},
    {.name = "fragments",
     .type = Type::kChoice,
     .choices = kChoiceNames<kFragmentLaws>,
     .field = choice<&BreakageSpec::fragments, kFragmentLaws>(),
     .doc = "the fragments: `\"equal\"` spheres, their count from a normal law (thesis); "
            "`\"t10\"`, sizes from the breakage index t10 = A (1 - exp(-b E_cs)), fines below "
            "`fines_diameter`"},
    {.name = "fragments_mean",
     .range = kPositive,
     .field = member<&BreakageSpec::fragments_mean>(),
     .written_if = [](const BreakageSpec& b) { return b.fragments == FragmentLaw::kEqual; },
     .doc = "equal: mean of the normal law of the fragment count (rounded, then clipped to "
            "[fragments_min, fragments_max])"},
    {.name = "fragments_sd",
     .range = kNonNegative,
     .field = member<&BreakageSpec::fragments_sd>(),
     .written_if = [](const BreakageSpec& b) { return b.fragments == FragmentLaw::kEqual; },
     .doc = "equal: standard deviation of that law (thesis: 99.7 % of counts between 2 and 6)"},
    {.name = "fragments_min",
     .type = Type::kInteger,
     .range = kAtLeastTwo,
     .max = 6,
     .field = member<&BreakageSpec::fragments_min>(),
     .written_if = [](const BreakageSpec& b) { return b.fragments == FragmentLaw::kEqual; },
     .doc = "equal: fewest fragments"},
    {.name = "fragments_max",
     .type = Type::kInteger,
     .range = kAtLeastTwo,
     .max = 6,
     .field = member<&BreakageSpec::fragments_max>(),
     .written_if = [](const BreakageSpec& b) { return b.fragments == FragmentLaw::kEqual; },
     .allowed = "fragments_min to 6",
     .doc = "equal: most fragments"},
    {.name = "t10_a",
     .unit = "%",
     .range = kPercent,
     .field = member<&BreakageSpec::t10_a>(),
     .written_if = [](const BreakageSpec& b) { return b.fragments == FragmentLaw::kT10; },
     .allowed = "(0, 100]; required by t10",
     .doc = "t10: A, the largest breakage index (drop-weight test)"},
    {.name = "t10_b",
     .unit = "t/kWh",
     .range = kPositive,
     .field = member<&BreakageSpec::t10_b>(),
     .written_if = [](const BreakageSpec& b) { return b.fragments == FragmentLaw::kT10; },
     .allowed = "> 0; required by t10",
     .doc = "t10: b, the breakage index's rise with the specific energy E_cs (kWh/t) of the "
            "breaking loading"},
    {.name = "fines_diameter",
     .unit = "m",
     .range = kDiameter,
     .field = member<&BreakageSpec::fines_diameter>(),
     .written_if = [](const BreakageSpec& b) { return b.fragments == FragmentLaw::kT10; },
     .allowed = "≥ 2e-09; required by t10",
     .doc = "t10: progeny below this diameter are fines, which leave the mill with the product "
            "at once; half of it is the smallest fragment radius, which sets `dt = \"auto\"`"},
    {.name = "minimum_radius",
     .need = Need::kRequired,
     .unit = "m",
     .range = kRadius,
     .field = member<&BreakageSpec::minimum_radius>(),
     .allowed = "≥ 1e-09; 2 minimum_radius ≥ sieve.aperture",
     .doc = "smaller particles do not break; with equal fragments the smallest fragment, "
            "minimum_radius / fragments_max^(1/3), sets `dt = \"auto\"` from the start"},
    {.name = "start",
     .unit = "s",
     .range = kNonNegative,
     .field = member<&BreakageSpec::start>(),
     .doc = "contacts that peak before this time do no damage (the charge falls from its fill "
            "first)"},
};

inline constexpr Key<FeedSpec> kFeedKeys[] = {
    {.name = "material",
     .type = Type::kMaterial,
     .need = Need::kRequired,
     .field = member<&FeedSpec::material>()},
    {.name = "period",
     .unit = "s",
     .range = kPositive,
     .field = member<&FeedSpec::period>(),
     .written_if = [](const FeedSpec& f) { return f.period > 0.0; },
     .allowed = "> 0; exactly one of period, mass_rate",
     .doc = "one particle every `period`"},
    {.name = "mass_rate",
     .unit = "kg/s",
     .range = kPositive,
     .field = member<&FeedSpec::mass_rate>(),
     .written_if = [](const FeedSpec& f) { return f.mass_rate > 0.0; },
     .doc = "a particle whenever the mass fed falls behind mass_rate x (t - start)"},
    {.name = "radius_min",
     .need = Need::kRequired,
     .unit = "m",
     .range = kRadius,
     .field = member<&FeedSpec::radius_min>(),
     .doc = "radii are uniform in [radius_min, radius_max]"},
    {.name = "radius_max",
     .need = Need::kRequired,
     .unit = "m",
     .range = kRadius,
     .field = member<&FeedSpec::radius_max>(),
     .allowed = "≥ 1e-09, ≥ radius_min"},
    {.name = "start",
     .unit = "s",
     .range = kNonNegative,
     .field = member<&FeedSpec::start>(),
     .doc = "time of the first fed particle"},
    {.name = "point",
     .type = Type::kVector,
     .unit = "m",
     .field = {[](FeedSpec& f, const Value& v) {
                 f.has_point = true;
                 f.point = std::get<Vec2>(v);
               },
               [](const FeedSpec& f) -> std::optional<Value> {
                 return f.has_point ? std::optional<Value>(f.point) : std::nullopt;
               }},
     .default_text = "where the charge is thinnest",
     .doc = "where each particle is placed (it waits while something is there); without it, "
            "the free point inside the drum farthest from every particle and wall"},
    {.name = "velocity",
     .type = Type::kVector,
     .unit = "m/s",
     .field = member<&FeedSpec::velocity>(),
     .doc = "velocity of each fed particle"},
};

inline constexpr Key<SieveSpec> kSieveKeys[] = {
    {.name = "material",
     .type = Type::kMaterial,
     .need = Need::kRequired,
     .field = member<&SieveSpec::material>(),
     .doc = "the material it lets through (ore)"},
    {.name = "type",
     .type = Type::kChoice,
     .choices = kChoiceNames<kDischargeTypes>,
     .field = choice<&SieveSpec::type, kDischargeTypes>(),
     .doc = "where ore narrower than the aperture leaves: `\"box\"`, with its centre in the "
            "box (the thesis's central sieve); `\"grate\"`, with its centre within `grate_width` "
            "of the shell (an end grate at the periphery, seen in the plane); `\"overflow\"`, "
            "the finest first while the ore in the mill exceeds `holdup`"},
    {.name = "box_min",
     .type = Type::kVector,
     .unit = "m",
     .field = member<&SieveSpec::box_min>(),
     .written_if = [](const SieveSpec& s) { return s.type == DischargeType::kBox; },
     .doc = "box: lower left corner of the zone (thesis: 1 m x 1 m around the drum centre)"},
    {.name = "box_max",
     .type = Type::kVector,
     .unit = "m",
     .field = member<&SieveSpec::box_max>(),
     .written_if = [](const SieveSpec& s) { return s.type == DischargeType::kBox; },
     .allowed = "above and right of `box_min`",
     .doc = "box: upper right corner"},
    {.name = "grate_width",
     .unit = "m",
     .range = kPositive,
     .field = member<&SieveSpec::grate_width>(),
     .written_if = [](const SieveSpec& s) { return s.type == DischargeType::kGrate; },
     .allowed = "> 0, below the drum radius; required by grate",
     .doc = "grate: radial width of the open ring inside the shell"},
    {.name = "holdup",
     .unit = "kg",
     .range = kPositive,
     .field = member<&SieveSpec::holdup>(),
     .written_if = [](const SieveSpec& s) { return s.type == DischargeType::kOverflow; },
     .allowed = "> 0; required by overflow",
     .doc = "overflow: the mass of ore the mill holds; above it the finest ore narrower than "
            "the aperture leaves (smallest first) until the hold-up is back at it"},
    {.name = "aperture",
     .unit = "m",
     .range = kPositive,
     .field = member<&SieveSpec::aperture>(),
     .doc = "the opening: ore whose diameter is below it may leave as product (a diameter, as a "
            "screen's aperture is read)"},
};

inline constexpr Key<ShellSpec> kShellKeys[] = {
    {.name = "thickness",
     .need = Need::kRequired,
     .unit = "m",
     .range = kPositive,
     .field = member<&ShellSpec::thickness>(),
     .allowed = "> 0, below half the drum radius",
     .doc = "the shell ring's wall, outside the drum's circle (its outer surface is held fixed)"},
    {.name = "material",
     .type = Type::kMaterial,
     .field = member<&ShellSpec::material>(),
     .written_if = [](const ShellSpec& s) { return !s.material.empty(); },  // "": the drum's
     .default_text = "the drum's",
     .doc = "the ring's and the bars' material (its density, Young's modulus and Poisson's "
            "ratio)"},
    {.name = "elements_through_thickness",
     .type = Type::kInteger,
     .range = kAtLeastOne,
     .max = 16,
     .field = member<&ShellSpec::elements_through_thickness>(),
     .doc = "quadratic elements across the ring's wall and across each lifter bar"},
    {.name = "element_size",
     .unit = "m",
     .range = kPositive,
     .field = member<&ShellSpec::element_size>(),
     .default_text = "the thickness",
     .allowed = "> 0, from 2π R / 20 000 to R / 4 (R the drum radius)",
     .doc = "the elements' length along the ring (the bars' feet fall on nodes: the spacing is "
            "adjusted to them)"},
    {.name = "depth",
     .need = Need::kRequired,
     .unit = "m",
     .range = kPositive,
     .field = member<&ShellSpec::depth>(),
     .doc = "the depth of mill the slice stands for: a contact force F loads the plane-strain "
            "model with F / depth per metre of shell; `dem2d --check` prints the charge's "
            "slice thickness (its mass-weighted mean diameter), the natural choice"},
};

inline constexpr Key<OutputSpec> kOutputKeys[] = {
    {.name = "directory",
     .type = Type::kString,
     .field = member<&OutputSpec::directory>(),
     .allowed = "non-empty",
     .doc = "where the outputs go (relative to the working directory; `--output DIR` "
            "replaces it)"},
    {.name = "series_interval",
     .unit = "s",
     .range = kPositive,
     .field = member<&OutputSpec::series_interval>(),
     .doc = "simulated time between rows of `series.csv`; shorter than dt: every step"},
    {.name = "snapshot_interval",
     .unit = "s",
     .range = kNonNegative,
     .field = member<&OutputSpec::snapshot_interval>(),
     .doc =
         "simulated time between snapshots (shorter than dt: every step); 0: the final state only"},
    {.name = "checkpoint_interval",
     .unit = "s",
     .range = kNonNegative,
     .field = member<&OutputSpec::checkpoint_interval>(),
     .doc = "simulated time between checkpoints (`checkpoint.h5`, replaced each time; shorter than "
            "dt: every step); 0: none on the way. A checkpoint is always written at the end and "
            "when the run is "
            "interrupted"},
    {.name = "checkpoint_minutes",
     .unit = "min",
     .range = kNonNegative,
     .field = member<&OutputSpec::checkpoint_minutes>(),
     .doc = "wall-clock minutes between checkpoints (rank 0's clock); 0: none"},
    {.name = "progress_interval",
     .unit = "s",
     .range = kPositive,
     .field = member<&OutputSpec::progress_interval>(),
     .doc = "wall-clock time between progress lines when stderr is not a terminal"},
    {.name = "analysis_window",
     .unit = "s",
     .range = kPositive,
     .field = member<&OutputSpec::analysis_window>(),
     .doc = "drum scenes: the window of `series.csv`'s `power_avg` and `regime` (the last this "
            "many seconds of rows)"},
    {.name = "collision_spectra",
     .type = Type::kBool,
     .field = member<&OutputSpec::collision_spectra>(),
     .doc = "bin every contact that ends by type, size class and peak normal strain energy "
            "(`collisions.csv`); off costs nothing"},
    {.name = "size_class_min",
     .unit = "m",
     .range = kSizeEdge,
     .field = member<&OutputSpec::size_class_min>(),
     .doc = "the collision spectra's smallest size-class edge (a diameter)"},
    {.name = "size_class_ratio",
     .range = kSizeRatio,
     .field = member<&OutputSpec::size_class_ratio>(),
     .doc = "the ratio between consecutive size-class edges (edges up to 10 m)"},
};

inline constexpr Key<Scene> kTopLevelKeys[] = {
    {.name = "title",
     .type = Type::kString,
     .field = member<&Scene::title>(),
     .doc = "a description, copied to `run.json`"},
    {.name = "run", .type = Type::kTable},
    {.name = "contact", .type = Type::kTable},
    {.name = "material", .type = Type::kTableArray},
    {.name = "interaction", .type = Type::kTableArray},
    {.name = "drum", .type = Type::kTable},
    {.name = "fill", .type = Type::kTableArray},
    {.name = "particle", .type = Type::kTableArray},
    {.name = "wall", .type = Type::kTableArray},
    {.name = "breakage", .type = Type::kTable},
    {.name = "feed", .type = Type::kTable},
    {.name = "sieve", .type = Type::kTable},
    {.name = "shell", .type = Type::kTable},
    {.name = "output", .type = Type::kTable},
};

inline constexpr Table<Scene> kTopLevel{"", false, kTopLevelKeys};
inline constexpr Table<RunSpec> kRun{"run", false, kRunKeys};
inline constexpr Table<ContactSpec> kContact{"contact", false, kContactKeys};
inline constexpr Table<MaterialSpec> kMaterial{"material", true, kMaterialKeys};
inline constexpr Table<InteractionSpec> kInteraction{"interaction", true, kInteractionKeys};
inline constexpr Table<DrumSpec> kDrum{"drum", false, kDrumKeys};
inline constexpr Table<LifterSpec> kLifter{"drum.lifter", true, kLifterKeys};
inline constexpr Table<FillSpec> kFill{"fill", true, kFillKeys};
inline constexpr Table<ParticleSpec> kParticle{"particle", true, kParticleKeys};
inline constexpr Table<WallSpec> kWall{"wall", true, kWallKeys};
inline constexpr Table<BreakageSpec> kBreakage{"breakage", false, kBreakageKeys};
inline constexpr Table<FeedSpec> kFeed{"feed", false, kFeedKeys};
inline constexpr Table<SieveSpec> kSieve{"sieve", false, kSieveKeys};
inline constexpr Table<ShellSpec> kShell{"shell", false, kShellKeys};
inline constexpr Table<OutputSpec> kOutput{"output", false, kOutputKeys};

// Calls f(table) for every table, in the order of docs/input.md.
template <class F>
constexpr void for_each_table(F&& f) {
  f(kTopLevel);
  f(kRun);
  f(kContact);
  f(kMaterial);
  f(kInteraction);
  f(kDrum);
  f(kLifter);
  f(kFill);
  f(kParticle);
  f(kWall);
  f(kBreakage);
  f(kFeed);
  f(kSieve);
  f(kShell);
  f(kOutput);
}

// True for the arrays of tables ("material", "drum.lifter"): a --set names one element.
bool is_table_array(std::string_view path);

// Keys of one table that say the same thing in different variables (a deck gives at most one
// of each group). A --set of one of them replaces the deck's other one, so that a sweep can be
// written in the engineer's own variable (--set drum.critical_fraction=0.7 on a deck that gives
// drum.speed).
struct AlternativeKeys {
  std::string_view table;                // schema path: "drum", "fill", "material"
  std::array<std::string_view, 4> keys;  // unused entries empty
};
inline constexpr std::array<AlternativeKeys, 3> kAlternativeKeys{{
    {"drum", {"speed", "speed_rpm", "critical_fraction", ""}},
    {"fill", {"count", "fill_fraction", "bed_filling", "file"}},
    {"material", {"poisson_ratio", "shear_modulus", "", ""}},
}};

// The key named `name` of a table (nullptr: none).
template <class T>
constexpr const Key<T>* find_key(std::span<const Key<T>> keys, std::string_view name) {
  for (const Key<T>& key : keys) {
    if (key.name == name) return &key;
  }
  return nullptr;
}

// The names of a table's keys, in order (the valid keys for "unknown key" messages).
template <class T>
std::vector<std::string_view> key_names(std::span<const Key<T>> keys) {
  std::vector<std::string_view> names;
  for (const Key<T>& key : keys) names.push_back(key.name);
  return names;
}

// The coefficients that `model` takes, for messages: "restitution and normal_stiffness".
std::string model_coefficients(ContactModelKind model);

// ---------------------------------------------------------------------------------------------
// The docs: the key tables of docs/input.md

// One row of a key table, as docs/input.md shows it (Markdown cells).
struct KeyRow {
  std::string key, type, default_value, unit, allowed, meaning;
};

// The rows of one table ("drum.lifter"); the top level lists only its values, not its tables.
struct KeyTable {
  std::string path;
  std::vector<KeyRow> rows;
};

// Every table's rows, in the order of docs/input.md.
std::vector<KeyTable> key_tables();

// A table as docs/input.md has it between "<!-- keys: PATH -->" and "<!-- end keys -->": the
// header, the separator and one line per key, each ending in '\n'.
std::string markdown_header();
std::string markdown_row(const KeyRow& row);
std::string markdown(const KeyTable& table);

}  // namespace dem2d::deck
