// ParticleStore: structure-of-arrays particle storage driven by one field registry.
//
// Each per-particle quantity is a named column (`Field<T>`). Every column registers itself,
// so resizing, removing, reordering, packing for migration and writing snapshots go through
// one list: a new field is added in one place. Owned particles occupy [0, n_owned); ghosts
// (copies of other ranks' particles, parallel runs only) follow in [n_owned, size()).
//
// A field also says what it means (FieldMeta: unit, a one-line description, whether snapshots
// hold it). io/snapshots writes every field marked `snapshot` as a dataset of its name with
// that unit and description, and a test checks docs/output.md's table of snapshot datasets
// against the marked fields (tests/io/test_output.cpp).
//
// Conventions (docs/models.md, "Bodies and frame"): a particle is a sphere whose centre moves in
// the plane; mass m = 4/3 pi r^3 rho, moment of inertia I = 2/5 m r^2; angles and spins are
// counter-clockwise positive.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/base/array.hpp"
#include "core/base/vec2.hpp"

namespace dem2d {

// What a field means, for output and documentation.
struct FieldMeta {
  std::string unit{};     // SI unit as written in snapshots ("m/s"); "1" for a pure number
  std::string doc{};      // one line
  bool snapshot = false;  // written to snapshots.h5 (state a user reads back)
  // Set when a particle is added and seldom changed after (id, material, radius): snapshots.h5
  // stores it again only when its rows differ from the last stored ones (io/snapshots.hpp).
  bool stable = false;
};

class FieldBase {
 public:
  explicit FieldBase(std::string name, FieldMeta meta = {})
      : name_(std::move(name)), meta_(std::move(meta)) {}
  virtual ~FieldBase() = default;
  FieldBase(const FieldBase&) = delete;
  FieldBase& operator=(const FieldBase&) = delete;

  const std::string& name() const { return name_; }
  const FieldMeta& meta() const { return meta_; }
  virtual std::size_t bytes_per_item() const = 0;
  virtual void resize(std::size_t n) = 0;
  virtual void copy_item(std::size_t dst, std::size_t src) = 0;
  virtual void pack(std::size_t i, std::byte* out) const = 0;
  virtual void unpack(std::size_t i, const std::byte* in) = 0;
  virtual void permute(const std::vector<std::size_t>& order) = 0;  // new[k] = old[order[k]]
  // Items idx[0], idx[1], ... one after the other (the halo: one virtual call per field).
  virtual std::byte* pack_items(std::span<const std::int32_t> idx, std::byte* out) const = 0;
  // Items first, first + 1, ..., first + n - 1 from consecutive bytes.
  virtual const std::byte* unpack_items(std::size_t first, std::size_t n, const std::byte* in) = 0;

 private:
  std::string name_;
  FieldMeta meta_;
};

template <class T>
class Field final : public FieldBase {
 public:
  Field(std::string name, std::vector<FieldBase*>& registry, FieldMeta meta = {})
      : FieldBase(std::move(name), std::move(meta)) {
    registry.push_back(this);
  }
  std::size_t bytes_per_item() const override { return sizeof(T); }
  void resize(std::size_t n) override { data_.resize(n); }
  void copy_item(std::size_t dst, std::size_t src) override { data_[dst] = data_[src]; }
  void pack(std::size_t i, std::byte* out) const override {
    std::memcpy(out, &data_[i], sizeof(T));
  }
  void unpack(std::size_t i, const std::byte* in) override {
    std::memcpy(&data_[i], in, sizeof(T));
  }
  std::byte* pack_items(std::span<const std::int32_t> idx, std::byte* out) const override {
    for (const std::int32_t i : idx) {
      std::memcpy(out, &data_[static_cast<std::size_t>(i)], sizeof(T));
      out += sizeof(T);
    }
    return out;
  }
  const std::byte* unpack_items(std::size_t first, std::size_t n, const std::byte* in) override {
    if (n) std::memcpy(static_cast<void*>(&data_[first]), in, n * sizeof(T));
    return in + n * sizeof(T);
  }
  void permute(const std::vector<std::size_t>& order) override {
    Array<T> out(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) out[k] = data_[order[k]];
    data_.swap(out);
  }

  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::size_t size() const { return data_.size(); }
  const Array<T>& vector() const { return data_; }

 private:
  Array<T> data_;
};

class ParticleStore {
  // Declared first: the fields below register themselves in it as they are constructed.
  std::vector<FieldBase*> registry_;

 public:
  ParticleStore() = default;
  ParticleStore(const ParticleStore&) = delete;
  ParticleStore& operator=(const ParticleStore&) = delete;

  // Identity and material.
  Field<std::int64_t> id{
      "id", registry_, {"1", "particle id, unique and stable for the whole run", true, true}};
  Field<std::int32_t> material{"material", registry_, {"1", "row of /materials", true, true}};
  // Kinematics: position, velocity, acceleration (translational), angle, spin, angular acc.
  Field<Vec2> pos{"position", registry_, {"m", "x and y of the centre", true}};
  Field<Vec2> vel{"velocity", registry_, {"m/s", "x and y of the centre's velocity", true}};
  Field<Vec2> acc{"acceleration", registry_, {"m/s^2", "x and y of the acceleration"}};
  Field<double> theta{
      "angle", registry_, {"rad", "rotation since the start, counter-clockwise positive", true}};
  Field<double> omega{
      "spin", registry_, {"rad/s", "angular velocity, counter-clockwise positive", true}};
  Field<double> alpha{"angular_acceleration", registry_, {"rad/s^2", "angular acceleration"}};
  // Shape and inertia (derived from radius and material density when a particle is added).
  Field<double> radius{"radius", registry_, {"m", "radius", true, true}};
  Field<double> mass{"mass", registry_, {"kg", "mass, 4/3 pi r^3 rho"}};
  Field<double> inv_mass{"inv_mass", registry_, {"1/kg", "1 / mass"}};
  Field<double> inv_inertia{"inv_inertia", registry_, {"1/(kg m^2)", "1 / (2/5 m r^2)"}};
  // Force and torque accumulators of the current force evaluation (not state).
  Field<Vec2> force{"force", registry_, {"N", "force of the current evaluation"}};
  Field<double> torque{"torque", registry_, {"N m", "torque of the current evaluation"}};
  // The elastic normal part of `force` (ContactForceT::f_el): the rest of the force and the
  // whole torque do work the energy ledger books as dissipated.
  Field<Vec2> elastic_force{"elastic_force", registry_, {"N", "elastic normal part of `force`"}};

  // Fields a model registers only when a scene uses it (nullptr otherwise): a scene without the
  // model moves no bytes for it. Enabled before the first particle is added.
  Field<double>* damage() { return damage_.get(); }
  const Field<double>* damage() const { return damage_.get(); }
  void enable_damage();
  // Drum scenes (mill analytics): the time each particle last touched anything, as seen at the
  // series rows; a particle untouched for kFlightTime is in free flight.
  Field<double>* last_contact() { return last_contact_.get(); }
  const Field<double>* last_contact() const { return last_contact_.get(); }
  void enable_last_contact();
  // Shaped particles (core/shape/superellipse.hpp, core/shape/superellipse_shape.hpp): each
  // particle's semi-axes a, b and exponent n, registered only when a scene has shaped particles
  // (a disc there is a = b = r, n = 2). Snapshots, checkpoints and migration carry them like any
  // registered field. The `radius` of a shaped particle is its bounding circle (the broad phase
  // uses it), `mass` and `inv_inertia` those of its superellipsoid.
  Field<double>* semi_a() { return semi_a_.get(); }
  const Field<double>* semi_a() const { return semi_a_.get(); }
  Field<double>* semi_b() { return semi_b_.get(); }
  const Field<double>* semi_b() const { return semi_b_.get(); }
  Field<double>* exponent() { return exponent_.get(); }
  const Field<double>* exponent() const { return exponent_.get(); }
  // With the shape fields: the torque of the elastic normal part of `force` (a superellipse's
  // contact arm leaves its normal, so that force turns it; a disc's passes through its centre).
  // The energy ledger leaves its work out of the dissipated energy, as it does the force's.
  Field<double>* elastic_torque() { return elastic_torque_.get(); }
  const Field<double>* elastic_torque() const { return elastic_torque_.get(); }
  bool shaped() const { return semi_a_ != nullptr; }
  void enable_shape();

  std::size_t size() const { return id.size(); }
  std::size_t n_owned() const { return n_owned_; }
  // Changes whenever the owned particles or their order change (add, remove, permute): what
  // is derived from the storage order (the neighbour search's id order) is valid while it holds.
  std::uint64_t layout() const { return layout_; }
  std::size_t n_ghost() const { return size() - n_owned_; }
  const std::vector<FieldBase*>& fields() const { return registry_; }
  std::size_t bytes_per_particle() const;

  // Append an owned particle (no ghosts may be present). Returns its index.
  std::size_t add(std::int64_t pid, std::int32_t mat, double r, double density, Vec2 x, Vec2 v,
                  double spin);
  // Append an owned superellipse |x/a|^n + |y/b|^n = 1 turned by `angle` (enable_shape first):
  // radius the bounding circle, mass and inertia of the superellipsoid with c = min(a, b).
  std::size_t add_shaped(std::int64_t pid, std::int32_t mat, double a, double b, double n,
                         double density, Vec2 x, Vec2 v, double spin, double angle);
  // Append n owned particle slots (no ghosts may be present); returns the first index. The
  // caller fills every field (migration unpacks them).
  std::size_t add_owned(std::size_t n);
  // Remove the owned particles whose flag is set, keeping the order of the rest.
  void remove_if(const std::vector<char>& remove);
  // Reorder owned particles: new[k] = old[order[k]].
  void permute(const std::vector<std::size_t>& order);
  // Ghost management (parallel layer): drop all ghosts / append n ghost slots.
  void clear_ghosts();
  std::size_t add_ghosts(std::size_t n);

 private:
  void resize_all(std::size_t n);
  std::size_t n_owned_ = 0;
  std::uint64_t layout_ = 0;
  std::unique_ptr<Field<double>> damage_;
  std::unique_ptr<Field<double>> last_contact_;
  std::unique_ptr<Field<double>> semi_a_, semi_b_, exponent_, elastic_torque_;
};

// The radius that sizes particle k (its sieve size is twice it): a disc's radius, a
// superellipse's volume-equivalent radius (the sphere of its mass; core/shape/superellipse.hpp).
double size_radius(const ParticleStore& p, std::size_t k);
// The same, the superellipse's Gamma functions kept in `radii` while the exponent repeats.
class EquivalentRadii;
double size_radius(const ParticleStore& p, std::size_t k, EquivalentRadii& radii);

// 1/2 I w^2 of particle k: the disc's formula in a store without shaped particles (its bits
// unchanged), else from the stored inverse inertia.
double rotational_energy(const ParticleStore& p, std::size_t k);

}  // namespace dem2d
