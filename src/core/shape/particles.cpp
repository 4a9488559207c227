#include "core/shape/particles.hpp"

#include <atomic>
#include <stdexcept>

#include "core/shape/disc.hpp"
#include "core/shape/superellipse.hpp"

namespace dem2d {

namespace {
// Layout stamps are unique over all stores, so a stamp never matches another store's.
std::uint64_t next_layout() {
  static std::atomic<std::uint64_t> counter{0};
  return counter.fetch_add(1, std::memory_order_relaxed) + 1;
}
}  // namespace

std::size_t ParticleStore::bytes_per_particle() const {
  std::size_t b = 0;
  for (const FieldBase* f : registry_) b += f->bytes_per_item();
  return b;
}

void ParticleStore::enable_damage() {
  if (damage_) return;
  damage_ = std::make_unique<Field<double>>(
      "damage", registry_,
      FieldMeta{"J", "accumulated damage E_cum of a breakable particle (thesis T34)", true});
  damage_->resize(size());
}

void ParticleStore::enable_last_contact() {
  if (last_contact_) return;
  last_contact_ = std::make_unique<Field<double>>(
      "last_contact", registry_,
      FieldMeta{"s", "time the particle last touched anything, seen at the series rows"});
  last_contact_->resize(size());
}

void ParticleStore::enable_shape() {
  if (semi_a_) return;
  semi_a_ = std::make_unique<Field<double>>(
      "semi_axis_a", registry_,
      FieldMeta{"m", "semi-axis a along the body's x (a disc: its radius)", true, true});
  semi_b_ = std::make_unique<Field<double>>(
      "semi_axis_b", registry_,
      FieldMeta{"m", "semi-axis b along the body's y (a disc: its radius)", true, true});
  exponent_ = std::make_unique<Field<double>>(
      "exponent", registry_,
      FieldMeta{"1", "superellipse exponent n (2: an ellipse or a disc)", true, true});
  elastic_torque_ = std::make_unique<Field<double>>(
      "elastic_torque", registry_,
      FieldMeta{"N m", "torque of the elastic normal part of `force` (superellipses)"});
  elastic_torque_->resize(size());
  semi_a_->resize(size());
  semi_b_->resize(size());
  exponent_->resize(size());
}

double rotational_energy(const ParticleStore& p, std::size_t k) {
  if (!p.shaped()) return Disc::rotational_energy(p.mass[k], p.radius[k], p.omega[k]);
  return 0.5 * p.omega[k] * p.omega[k] / p.inv_inertia[k];
}

void ParticleStore::resize_all(std::size_t n) {
  for (FieldBase* f : registry_) f->resize(n);
}

std::size_t ParticleStore::add(std::int64_t pid, std::int32_t mat, double r, double density, Vec2 x,
                               Vec2 v, double spin) {
  if (n_ghost() != 0) throw std::logic_error("ParticleStore::add with ghosts present");
  const std::size_t i = size();
  resize_all(i + 1);
  id[i] = pid;
  material[i] = mat;
  pos[i] = x;
  vel[i] = v;
  acc[i] = {};
  theta[i] = 0.0;
  omega[i] = spin;
  alpha[i] = 0.0;
  radius[i] = r;
  const double m = Disc::mass(r, density);
  mass[i] = m;
  inv_mass[i] = 1.0 / m;
  inv_inertia[i] = 1.0 / Disc::inertia(m, r);
  force[i] = {};
  torque[i] = 0.0;
  if (semi_a_) {  // a disc among shaped particles: the superellipse a = b = r, n = 2
    (*semi_a_)[i] = r;
    (*semi_b_)[i] = r;
    (*exponent_)[i] = 2.0;
  }
  n_owned_ = i + 1;
  layout_ = next_layout();
  return i;
}

std::size_t ParticleStore::add_shaped(std::int64_t pid, std::int32_t mat, double a, double b,
                                      double n, double density, Vec2 x, Vec2 v, double spin,
                                      double angle) {
  if (!semi_a_) throw std::logic_error("ParticleStore::add_shaped without enable_shape");
  const SuperEllipse s{a, b, n};
  const std::size_t i = add(pid, mat, bounding_radius(s), density, x, v, spin);
  theta[i] = angle;
  mass[i] = dem2d::mass(s, density);
  inv_mass[i] = 1.0 / mass[i];
  inv_inertia[i] = 1.0 / inertia_z(s, density);
  (*semi_a_)[i] = a;
  (*semi_b_)[i] = b;
  (*exponent_)[i] = n;
  return i;
}

std::size_t ParticleStore::add_owned(std::size_t n) {
  if (n_ghost() != 0) throw std::logic_error("ParticleStore::add_owned with ghosts present");
  const std::size_t first = size();
  resize_all(first + n);
  n_owned_ = first + n;
  layout_ = next_layout();
  return first;
}

void ParticleStore::remove_if(const std::vector<char>& remove) {
  clear_ghosts();
  std::size_t k = 0;
  for (std::size_t i = 0; i < n_owned_; ++i) {
    if (remove[i]) continue;
    if (k != i)
      for (FieldBase* f : registry_) f->copy_item(k, i);
    ++k;
  }
  resize_all(k);
  n_owned_ = k;
  layout_ = next_layout();
}

void ParticleStore::permute(const std::vector<std::size_t>& order) {
  clear_ghosts();
  for (FieldBase* f : registry_) f->permute(order);
  layout_ = next_layout();
}

void ParticleStore::clear_ghosts() { resize_all(n_owned_); }

std::size_t ParticleStore::add_ghosts(std::size_t n) {
  const std::size_t first = size();
  resize_all(first + n);
  return first;
}

double size_radius(const ParticleStore& p, std::size_t k) {
  if (!p.shaped()) return p.radius[k];
  return equivalent_radius(SuperEllipse{(*p.semi_a())[k], (*p.semi_b())[k], (*p.exponent())[k]});
}

double size_radius(const ParticleStore& p, std::size_t k, EquivalentRadii& radii) {
  if (!p.shaped()) return p.radius[k];
  return radii(SuperEllipse{(*p.semi_a())[k], (*p.semi_b())[k], (*p.exponent())[k]});
}

}  // namespace dem2d
