// The deck's vocabulary, shared by the reader (deck.cpp) and the writer (deck_resolved.cpp):
// the valid keys of every table and the words of every choice. docs/input.md documents each
// key; a key added here must be read in deck.cpp, written in deck_resolved.cpp and documented.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

#include "core/scene.hpp"

namespace dem2d::deck {

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
inline constexpr std::array kFillRegions = {
    Choice<FillRegion>{"bottom", FillRegion::kBottom},
    Choice<FillRegion>{"full", FillRegion::kFull},
    Choice<FillRegion>{"box", FillRegion::kBox},
    Choice<FillRegion>{"annulus", FillRegion::kAnnulus},
};

// The word for `value` (choices are exhaustive, so one always matches).
template <class E, std::size_t N>
constexpr std::string_view choice_name(const std::array<Choice<E>, N>& choices, E value) {
  for (const auto& choice : choices) {
    if (choice.value == value) return choice.name;
  }
  return "?";
}

// Valid keys, table by table, in the order of docs/input.md.
inline constexpr std::array<std::string_view, 10> kRootKeys = {
    "title", "run",  "contact",  "material", "interaction",
    "drum",  "fill", "particle", "wall",     "output"};
inline constexpr std::array<std::string_view, 12> kRunKeys = {
    "duration", "dt",      "integrator", "tolerance", "max_passes",
    "seed",     "gravity", "skin",       "dt_safety", "allow_unsafe_dt",
    "sectors_per_rank", "repartition_threshold"};
inline constexpr std::array<std::string_view, 3> kContactKeys = {"model", "rolling",
                                                                 "rolling_damping"};
inline constexpr std::array<std::string_view, 11> kMaterialKeys = {"name",
                                                                   "density",
                                                                   "youngs_modulus",
                                                                   "poisson_ratio",
                                                                   "shear_modulus",
                                                                   "restitution",
                                                                   "damping_normal",
                                                                   "damping_tangential",
                                                                   "sliding_friction",
                                                                   "rolling_friction",
                                                                   "normal_stiffness"};
inline constexpr std::array<std::string_view, 6> kInteractionKeys = {
    "materials",        "restitution",    "sliding_friction",
    "rolling_friction", "damping_normal", "damping_tangential"};
inline constexpr std::array<std::string_view, 10> kDrumKeys = {
    "radius",    "center", "speed", "speed_rpm", "critical_fraction",
    "ramp_time", "sides",  "angle", "material",  "lifter"};
inline constexpr std::array<std::string_view, 5> kLifterKeys = {"count", "height", "width", "angle",
                                                                "material"};
inline constexpr std::array<std::string_view, 11> kFillKeys = {
    "material",   "count",  "fill_fraction", "file",    "radius",  "radius_min",
    "radius_max", "region", "box_min",       "box_max", "velocity"};
inline constexpr std::array<std::string_view, 5> kParticleKeys = {"material", "radius", "position",
                                                                  "velocity", "spin"};
inline constexpr std::array<std::string_view, 4> kWallKeys = {"from", "to", "material", "velocity"};
inline constexpr std::array<std::string_view, 5> kOutputKeys = {
    "directory", "series_interval", "snapshot_interval", "checkpoint_interval",
    "progress_interval"};

// The arrays of tables, by dotted path: a --set names one element by index (or by name for
// [[material]]).
inline constexpr std::array<std::string_view, 6> kTableArrays = {
    "material", "interaction", "fill", "particle", "wall", "drum.lifter"};

// Columns of a [[fill]] file (x, y, radius required).
inline constexpr std::array<std::string_view, 7> kCsvColumns = {"x",  "y",    "radius",  "vx",
                                                                "vy", "spin", "material"};

}  // namespace dem2d::deck
