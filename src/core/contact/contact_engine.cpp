#include "core/contact/contact_engine.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>

#include "core/base/errors.hpp"
#include "core/contact/contact_models.hpp"

namespace dem2d {

namespace kernels {
template <class Law>
std::unique_ptr<ContactKernel> make_law_kernel(const ContactSpec& spec, const PairTable& table,
                                               RollingModelKind rolling_kind,
                                               IntegratorKind integrator);
template <class Law>
std::unique_ptr<ContactKernel> make_superellipse_law_kernel(const ContactSpec& spec,
                                                            const PairTable& table,
                                                            RollingModelKind rolling_kind);
}  // namespace kernels

// The model is chosen here, once: one kernel per (law, rolling model, tracker, stepper), each
// law's kernels compiled in its own file (kernels_*.cpp, kernel_factory.hpp).
// A rolling model is run only when some pair of materials has rolling friction: with mu_r = 0
// everywhere it gives no torque and stores nothing (measured bit-identical to none), and the
// epsd kernel cost 6 % more on such a scene.
std::unique_ptr<ContactKernel> make_contact_kernel(const ContactSpec& spec, const PairTable& table,
                                                   IntegratorKind integrator) {
  bool rolling_friction = false;
  for (int a = 0; a < table.n_materials(); ++a)
    for (int b = 0; b < table.n_materials(); ++b) rolling_friction |= table(a, b).mu_r != 0.0;
  const RollingModelKind rolling_kind = rolling_friction ? spec.rolling : RollingModelKind::kNone;
  // Shaped particles: the superellipse's kernel for every particle (a disc as a = b = r, n = 2),
  // made for the Hertz-Mindlin law with the as-seen integrators only (the deck reader refuses
  // the others at their keys).
  if (spec.shaped) {
    if (spec.model != ContactModelKind::kHertzMindlin || integrator == IntegratorKind::kIterative)
      throw InputError(
          "shaped particles run with the hertz-mindlin law and the verlet integrator only");
    return kernels::make_superellipse_law_kernel<HertzMindlin>(spec, table, rolling_kind);
  }
  std::unique_ptr<ContactKernel> out;
  [&]<class... Laws>(std::type_identity<std::tuple<Laws...>>) {
    static_cast<void>(
        ((Laws::kKind == spec.model
              ? (out = kernels::make_law_kernel<Laws>(spec, table, rolling_kind, integrator), true)
              : false) ||
         ...));
  }(std::type_identity<ContactLaws>{});
  return out;
}

ContactEngine::ContactEngine(const Scene& scene)
    : table_(scene), kernel_(make_contact_kernel(scene.contact, table_, scene.run.integrator)) {
  pairs_.width = wall_pairs_.width = kernel_->history_slots().size();
  // Histories written in place need no trial slots (16 bytes per candidate of a Hertz-Mindlin
  // list with rolling).
  search_.set_pair_trials(!kernel_->histories_in_place());
}

void ContactEngine::build(const ParticleStore& p, const Walls& walls, double skin) {
  search_.build(p, walls, skin, pairs_, wall_pairs_);
  kernel_->lists_changed();
}

// The drive's torque and power are the first consumer of the wall loads.
void ContactEngine::evaluate(ParticleStore& p, const Walls& walls, double dt) {
  kernel_->evaluate(p, walls, pairs_, wall_pairs_, dt, totals_, wall_loads_);
  const DriveLoads drive = drive_loads(wall_loads_, walls);
  totals_.drum_torque = drive.drum_torque;
  totals_.lifter_torque = drive.lifter_torque;
  totals_.drive_power = drive.power;
}

void ContactEngine::commit() {
  if (!kernel_->histories_in_place()) pairs_.history.swap(pairs_.trial);
  wall_pairs_.history.swap(wall_pairs_.trial);
  kernel_->committed();
}

HistoryRecords ContactEngine::records() const {
  const std::size_t width = pairs_.width;
  HistoryRecords out(width);
  const auto live = [&](const double* h) {
    return std::any_of(h, h + width, [](double v) { return v != 0.0; });
  };
  for (std::size_t t = 0; t < pairs_.size(); ++t) {
    const std::size_t k = pairs_.entry(t);  // in key order
    if (live(pairs_.history_of(k)))
      out.push_back(pairs_.id_i[k], pairs_.id_j[k], pairs_.history_of(k));
  }
  for (std::size_t k = 0; k < wall_pairs_.size(); ++k)
    if (live(wall_pairs_.history_of(k)))
      out.push_back(wall_pairs_.id[k], -1 - static_cast<std::int64_t>(wall_pairs_.element[k]),
                    wall_pairs_.history_of(k));
  return out;
}

void ContactEngine::adopt(const HistoryRecords& records) {
  // The lists become key + history only: NeighborSearch::build carries histories from the old
  // lists by key (pairs sorted by (id_i, id_j), walls by (id, element)). Records are sorted by
  // (a, b), and b = -1 - element runs backwards within one particle: walls are taken from the
  // end of each particle's run.
  PairList pl;
  WallPairList wl;
  pl.width = wl.width = pairs_.width;
  for (std::size_t s = 0; s < records.size();) {
    std::size_t e = s;
    while (e < records.size() && records.a(e) == records.a(s)) ++e;
    for (std::size_t r = e; r-- > s;) {
      if (records.b(r) >= 0) continue;
      wl.id.push_back(records.a(r));
      wl.element.push_back(static_cast<std::int32_t>(-1 - records.b(r)));
      wl.history.insert(wl.history.end(), records.values(r), records.values(r) + wl.width);
    }
    for (std::size_t r = s; r < e; ++r) {
      if (records.b(r) < 0) continue;
      pl.id_i.push_back(records.a(r));
      pl.id_j.push_back(records.b(r));
      pl.history.insert(pl.history.end(), records.values(r), records.values(r) + pl.width);
    }
    s = e;
  }
  pl.i.resize(pl.id_i.size());
  pl.j.resize(pl.id_i.size());
  wl.particle.resize(wl.id.size());
  pairs_ = std::move(pl);
  wall_pairs_ = std::move(wl);
  kernel_->lists_changed();
}

std::vector<double> ContactEngine::particle_work(std::size_t n_owned) const {
  std::vector<double> work(n_owned, 1.0);
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const auto i = static_cast<std::size_t>(pairs_.i[k]), j = static_cast<std::size_t>(pairs_.j[k]);
    const bool both = i < n_owned && j < n_owned;
    if (i < n_owned) work[i] += both ? 0.5 : 1.0;
    if (j < n_owned) work[j] += both ? 0.5 : 1.0;
  }
  return work;
}

std::size_t ContactEngine::history_offset(std::string_view name) const {
  const auto slots = history_slots();
  for (std::size_t k = 0; k < slots.size(); ++k)
    if (slots[k].name == name) return k;
  throw std::logic_error("the contact model has no history slot " + std::string(name));
}

}  // namespace dem2d
