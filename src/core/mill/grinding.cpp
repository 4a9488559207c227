#include "core/mill/grinding.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/base/errors.hpp"
#include "core/base/random.hpp"
#include "core/contact/contact_models.hpp"
#include "core/geometry/drum_geometry.hpp"
#include "core/geometry/walls.hpp"
#include "core/mill/breakage_laws.hpp"
#include "core/shape/disc.hpp"
#include "core/shape/superellipse.hpp"
#include "core/shape/superellipse_sizing.hpp"

namespace dem2d {

namespace {

// Independent streams of draws from the one run seed.
constexpr std::uint64_t kStreamTest = 0x7e57'0000'0000'0001ULL;
constexpr std::uint64_t kStreamFragments = 0xf7a6'0000'0000'0002ULL;
constexpr std::uint64_t kStreamFeed = 0xfeed'0000'0000'0003ULL;

std::uint64_t stream(std::uint64_t seed, std::uint64_t which) { return mix64(seed ^ which); }

}  // namespace

Grinding::Grinding(const Scene& scene, const ParticleStore& p, const Domain& domain)
    : scene_(scene) {
  if (scene.breakage.present) break_material_ = find_material(scene, scene.breakage.material);
  if (scene.feed.present) feed_material_ = find_material(scene, scene.feed.material);
  if (scene.sieve.present) sieve_material_ = find_material(scene, scene.sieve.material);
  for (const MaterialSpec& m : scene.materials)
    compliance_.push_back(compliance(m.youngs_modulus, m.poisson_ratio));
  if (break_material_ >= 0) {
    const Walls walls(scene);
    for (const WallElement& e : walls.elements()) element_material_.push_back(e.material);
  }
  double largest = -1.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    largest = std::max(largest, static_cast<double>(p.id[k]));
  next_id_ = static_cast<std::int64_t>(domain.max(largest)) + 1;
  next_feed_try_ = scene.feed.start;
  // The ore at the start, by size (exact integers summed over ranks).
  const int ore = ore_material();
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    if (p.material[k] == ore) sizes_.initial.add(2.0 * size_radius(p, k), p.mass[k]);
  combine(sizes_.initial, domain);
  if (scene.sieve.present && scene.sieve.type == DischargeType::kGrate)
    grate_inner_ = DrumGeometry(scene.drum).inner_radius() - scene.sieve.grate_width;
  if (scene.feed.present && scene.drum.present) {
    // Candidate feed points: rings inside the drum clear of the shell and the lifters, outside
    // the discharge zone (a fed particle would leave there at once).
    const DrumSpec& d = scene.drum;
    const double reach = DrumGeometry(d).clear_radius();
    feed_reach_ = reach;
    const double r_max = scene.feed.radius_max;
    const auto keep = [&](Vec2 x) {
      if (!scene.sieve.present || scene.sieve.material != scene.feed.material) return true;
      const SieveSpec& s = scene.sieve;
      if (s.type == DischargeType::kGrate) return norm(x - d.center) + r_max <= grate_inner_;
      if (s.type == DischargeType::kBox)
        return x.x + r_max < s.box_min.x || x.x - r_max > s.box_max.x ||
               x.y + r_max < s.box_min.y || x.y - r_max > s.box_max.y;
      return true;
    };
    if (keep(d.center)) candidates_.push_back(d.center);
    for (int ring = 1; ring <= 6; ++ring) {
      const double radius = (reach - r_max) * ring / 6.0;
      const int n = 8 * ring;
      for (int k = 0; k < n; ++k) {
        const double a = 2.0 * std::numbers::pi * (k + 0.5 * (ring % 2)) / n;
        const Vec2 x = d.center + radius * Vec2{std::cos(a), std::sin(a)};
        if (keep(x)) candidates_.push_back(x);
      }
    }
    if (candidates_.empty() && !scene.feed.has_point)
      throw InputError(scene.deck_path +
                       ": [feed]: every place the feed could put a particle lies in the "
                       "discharge zone of [sieve] (or too close to it for radius_max); make the "
                       "zone smaller or give feed.point outside it");
  }
}

bool Grinding::plan(double time, std::int64_t step, const ParticleStore& p,
                    const ContactEngine& contacts, Domain& domain, bool evaluated) {
  plan_.tested_pairs.clear();
  plan_.tested_walls.clear();
  plan_.damage.clear();
  plan_.broken.clear();
  if (break_material_ >= 0) {
    std::vector<Test> tests;
    collect_tests(p, contacts, evaluated, tests);
    if (time >= scene_.breakage.start) run_tests(tests, step, p);
  }
  plan_.remove.assign(p.n_owned(), 0);
  for (const Broken& b : plan_.broken) plan_.remove[b.index] = 2;  // a broken one cannot leave
  plan_.product.clear();
  plan_.sieved = 0;
  plan_.sieved_mass = 0.0;
  if (sieve_material_ >= 0) discharge(time, p, domain);
  plan_.changes = domain.sum(static_cast<std::int64_t>(plan_.broken.size()) +
                             plan_.sieved);  // one collective per step
  plan_.feed = feed_due(time);
  return plan_.changes != 0 || plan_.feed;
}

bool Grinding::apply(double time, ParticleStore& p, ContactEngine& contacts, Domain& domain,
                     EnergyLedger& ledger, const std::function<void()>& before_change) {
  if (!plan_.tested_pairs.empty() || !plan_.tested_walls.empty()) {
    const std::size_t off = plan_.tracker_slot;
    const auto mark = [&](double* h) { h[TrackBreakage::kTested] = h[TrackBreakage::kPeak]; };
    PairList& pl = contacts.mutable_pairs();
    for (const std::int32_t k : plan_.tested_pairs)
      mark(pl.history.data() + static_cast<std::size_t>(k) * pl.width + off);
    WallPairList& wl = contacts.mutable_wall_pairs();
    for (const std::int32_t k : plan_.tested_walls)
      mark(wl.history.data() + static_cast<std::size_t>(k) * wl.width + off);
  }
  if (!plan_.damage.empty()) {
    Field<double>& damage = *p.damage();
    for (const auto& [k, d] : plan_.damage) damage[k] = d;
  }
  product_.insert(product_.end(), plan_.product.begin(), plan_.product.end());
  if (plan_.changes != 0) {
    before_change();
    births_from_ = next_id_;
    // The parents as they were, then the store without them and without the product.
    std::vector<Parent> parents;
    std::vector<char>& remove = plan_.remove;
    for (const Broken& b : plan_.broken) {
      const std::size_t k = b.index;
      Parent q{p.id[k], p.material[k], size_radius(p, k), b.energy, p.pos[k], p.vel[k], p.omega[k]};
      if (p.shaped()) {
        const double a = (*p.semi_a())[k], sb = (*p.semi_b())[k], n = (*p.exponent())[k];
        if (a != sb || n != 2.0)
          q.shape = {a >= sb ? sb / a : a / sb, n,
                     a >= sb ? p.theta[k] : p.theta[k] + 0.5 * std::numbers::pi};
      }
      parents.push_back(q);
      remove[k] = 2;
    }
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      if (remove[k] == 1) {
        ledger.discharged += mechanical_energy(p, k, scene_.run.gravity);
        sizes_.product.add(2.0 * size_radius(p, k), p.mass[k]);
      }
    p.remove_if(remove);
    break_parents(time, parents, p, domain, ledger);
    totals_.discharged_count += domain.sum(plan_.sieved);
    totals_.discharged_mass += domain.sum(plan_.sieved_mass);
  }
  if (!plan_.feed) return plan_.changes != 0;
  if (plan_.changes == 0) {
    before_change();
    births_from_ = next_id_;
  }
  const bool fed = feed(time, p, domain, ledger);
  return plan_.changes != 0 || fed;
}

// Every contact of an owned breakable particle past its peak and above the level tested, in
// the order (particle id, partner): pairs in list order, then walls, then sorted. Every contact
// past its peak, breakable or not, is marked tested by apply (on every rank that lists it).
void Grinding::collect_tests(const ParticleStore& p, const ContactEngine& contacts, bool evaluated,
                             std::vector<Test>& out) {
  const std::size_t off = contacts.history_offset("peak_energy");
  plan_.tracker_slot = off;
  const std::size_t n_owned = p.n_owned();
  const double r_min = scene_.breakage.minimum_radius;
  const auto breakable = [&](std::int32_t i) {
    return static_cast<std::size_t>(i) < n_owned && p.material[i] == break_material_ &&
           size_radius(p, static_cast<std::size_t>(i)) >= r_min;
  };
  // The pairs: those the evaluation found due (the only ones: a listed pair not in contact has
  // a zero history), in list order.
  const PairList& pl = contacts.pairs();
  const double* pair_h = evaluated ? contacts.evaluated_pair_histories() : pl.history.data();
  for (const std::int32_t entry : contacts.breakage_tests_due()) {
    const auto k = static_cast<std::size_t>(entry);
    const double* h = pair_h + k * pl.width + off;
    const std::int32_t i = pl.i[k], j = pl.j[k];
    const double peak = h[TrackBreakage::kPeak], tested = h[TrackBreakage::kTested];
    // One loading event, tested once: each breakable body with its share of the energy.
    if (breakable(i)) {
      const double s = share(p.material[i], p.material[j]);
      out.push_back({pl.id_i[k], pl.id_j[k], std::size_t(i), s * peak, s * tested});
    }
    if (breakable(j)) {
      const double s = share(p.material[j], p.material[i]);
      out.push_back({pl.id_j[k], pl.id_i[k], std::size_t(j), s * peak, s * tested});
    }
    plan_.tested_pairs.push_back(entry);
  }
  const WallPairList& wl = contacts.wall_pairs();
  const double* wall_h = evaluated ? wl.trial.data() : wl.history.data();
  for (std::size_t k = 0; k < wl.size(); ++k) {
    const double* h = wall_h + k * wl.width + off;
    const double peak = h[TrackBreakage::kPeak], tested = h[TrackBreakage::kTested];
    if (!TrackBreakage::test_due(peak, h[TrackBreakage::kEnergy], tested)) continue;
    const std::int32_t i = wl.particle[k];
    if (breakable(i)) {
      const double s =
          share(p.material[i], element_material_[static_cast<std::size_t>(wl.element[k])]);
      out.push_back(
          {wl.id[k], -1 - std::int64_t{wl.element[k]}, std::size_t(i), s * peak, s * tested});
    }
    plan_.tested_walls.push_back(static_cast<std::int32_t>(k));
  }
  std::sort(out.begin(), out.end(), [](const Test& a, const Test& b) {
    return a.id < b.id || (a.id == b.id && a.partner < b.partner);
  });
}

// The tests in order: the particles that break (local index, the test's peak energy), in store
// order, and the damage of the others. A particle's tests are consecutive (sorted by id): each
// starts from the damage the one before left.
void Grinding::run_tests(const std::vector<Test>& tests, std::int64_t step,
                         const ParticleStore& p) {
  const BreakageSpec& b = scene_.breakage;
  const bool vp = b.model == BreakageModel::kVogelPeukert;
  const std::uint64_t seed = stream(scene_.run.seed, kStreamTest);
  const Field<double>& damage = *p.damage();
  std::vector<Broken>& broken = plan_.broken;
  std::int64_t last_broken = -1, last_damaged = -1;
  for (const Test& t : tests) {
    if (t.id == last_broken) continue;  // already broken in this step
    const double before = t.id == last_damaged ? plan_.damage.back().second : damage[t.index];
    double probability = 0.0, after = before;
    if (vp) {
      // The specific energy of the loading above the level tested and the size's threshold.
      const double m = p.mass[t.index], d = 2.0 * size_radius(p, t.index);
      const double w = (t.peak - std::max(t.tested, b.xw_min / d * m)) / m;
      if (w <= 0.0) continue;
      probability = vogel_peukert_probability(b.f_mat, 0.0, d, w);
      after = before + w;
    } else {
      const double energy = t.peak - std::max(t.tested, b.minimum_energy);
      if (energy <= 0.0) continue;
      after = before + energy;
      probability = 1.0 - std::exp(-b.strength * after);
    }
    const std::uint64_t key =
        mix64(static_cast<std::uint64_t>(t.id)) ^ static_cast<std::uint64_t>(t.partner);
    if (random_uniform(seed, key, static_cast<std::uint64_t>(step)) < probability) {
      broken.push_back({t.index, t.peak});
      last_broken = t.id;
    } else if (t.id == last_damaged) {
      plan_.damage.back().second = after;
    } else {
      plan_.damage.emplace_back(t.index, after);
      last_damaged = t.id;
    }
  }
  std::sort(broken.begin(), broken.end(),
            [](const Broken& x, const Broken& y) { return x.index < y.index; });
}

double Grinding::share(int material, int partner_material) const {
  if (scene_.breakage.energy_split == EnergySplit::kWhole) return 1.0;
  return energy_share(compliance_[static_cast<std::size_t>(material)],
                      compliance_[static_cast<std::size_t>(partner_material)]);
}

int Grinding::fragment_count(std::int64_t parent) const {
  const BreakageSpec& b = scene_.breakage;
  const double z = random_normal(stream(scene_.run.seed, kStreamFragments),
                                 static_cast<std::uint64_t>(parent), 0);
  const double n = std::round(b.fragments_mean + b.fragments_sd * z);
  return static_cast<int>(std::clamp(n, double(b.fragments_min), double(b.fragments_max)));
}

// Every rank's parents of this step, sorted by id, take the next ids in turn; this rank's are
// replaced by their fragments (the parents are already out of the store). The fines of a t10
// break leave with the product (their energy booked as discharged).
void Grinding::break_parents(double time, const std::vector<Parent>& parents, ParticleStore& p,
                             Domain& domain, EnergyLedger& ledger) {
  const BreakageSpec& b = scene_.breakage;
  std::vector<std::int64_t> mine;
  for (const Parent& parent : parents) mine.push_back(parent.id);
  // The fragment counts of a t10 break are known only to the parent's owner: every rank's
  // parents with their counts, (id, count) pairs.
  std::vector<Progeny> progeny(parents.size());
  std::vector<std::int64_t> mine_counts;
  for (std::size_t k = 0; k < parents.size(); ++k) {
    const Parent& q = parents[k];
    mine_counts.push_back(q.id);
    if (b.fragments == FragmentLaw::kT10) {
      const double density = scene_.materials[static_cast<std::size_t>(q.material)].density;
      const double e_cs = q.energy / Disc::mass(q.radius, density) / 3600.0;  // kWh/t
      const double alpha = progeny_exponent(t10_fraction(b.t10_a, b.t10_b, e_cs));
      progeny[k] = t10_progeny(q.radius, density, alpha, b.fines_diameter);
      mine_counts.push_back(static_cast<std::int64_t>(progeny[k].radii.size()));
    } else {
      mine_counts.push_back(fragment_count(q.id));
    }
  }
  const std::vector<std::int64_t> all = domain.allgather(mine_counts);
  std::vector<std::pair<std::int64_t, std::int64_t>> order;
  for (std::size_t k = 0; k + 1 < all.size(); k += 2) order.emplace_back(all[k], all[k + 1]);
  std::sort(order.begin(), order.end());
  std::int64_t id = next_id_;
  double fines = 0.0;
  for (const auto& [parent_id, count] : order) {
    const int n = static_cast<int>(count);
    const auto it = std::find(mine.begin(), mine.end(), parent_id);
    if (it != mine.end()) {
      const std::size_t k = static_cast<std::size_t>(it - mine.begin());
      fines += bear(time, parents[k], n, id, progeny[k], p, ledger);
    }
    id += n;
    totals_.breakages += 1;
    totals_.fragments += n;
  }
  next_id_ = id;
  if (b.fragments == FragmentLaw::kT10) {
    const double all_fines = domain.sum(fines);
    totals_.fines_mass += all_fines;
    totals_.discharged_mass += all_fines;
  }
}

// Parent q's n fragments, ids from `first` (its progeny g for t10, else n equal spheres), put
// into the store and the logs; returns the mass of its fines, which leave at once.
double Grinding::bear(double time, const Parent& q, int n, std::int64_t first, const Progeny& g,
                      ParticleStore& p, EnergyLedger& ledger) {
  const BreakageSpec& b = scene_.breakage;
  const double density = scene_.materials[static_cast<std::size_t>(q.material)].density;
  const double mass = Disc::mass(q.radius, density);
  const double turn = 2.0 * std::numbers::pi *
                      random_uniform(stream(scene_.run.seed, kStreamFragments),
                                     static_cast<std::uint64_t>(q.id), 1);
  BreakageRecord record{time, q.id, q.radius, q.energy, n, first, mass, q.energy / mass};
  const auto born = [&](std::int64_t fid, double r_f, Vec2 offset) {
    const Vec2 v = q.v + q.omega * Vec2{-offset.y, offset.x};
    if (q.shape) {
      // A superellipse's fragments: its aspect and exponent, turned as it was.
      const SuperEllipse e = superellipse_of_size(r_f, q.shape->aspect, q.shape->exponent);
      p.add_shaped(fid, q.material, e.a, e.b, e.n, density, q.x + offset, v, q.omega,
                   q.shape->angle);
    } else {
      p.add(fid, q.material, r_f, density, q.x + offset, v, q.omega);
    }
    fragment_log_.push_back({time, q.id, fid, r_f, Disc::mass(r_f, density)});
  };
  if (b.fragments == FragmentLaw::kEqual) {
    const double r_f = q.radius / std::cbrt(static_cast<double>(n));
    for (int f = 0; f < n; ++f) {
      const double a = turn + 2.0 * std::numbers::pi * f / n;
      born(first + f, r_f, (q.radius - r_f) * Vec2{std::cos(a), std::sin(a)});
    }
    breakages_.push_back(record);
    return 0.0;
  }
  const std::vector<Offset> at = fragment_offsets(q.radius, g.radii, turn);
  for (int f = 0; f < n; ++f) {
    const auto fk = static_cast<std::size_t>(f);
    born(first + f, g.radii[fk], Vec2{at[fk].x, at[fk].y});
  }
  record.fines_mass = g.fines_mass;
  if (g.fines_mass > 0.0) {
    // The fines: a point mass at the parent's centre with its velocity, out at once.
    ledger.discharged += g.fines_mass * (0.5 * norm2(q.v) - dot(scene_.run.gravity, q.x));
    sizes_.product.add_fines(g.fines_mass, g.fines_law_mass,
                             std::min(b.fines_diameter, 2.0 * q.radius), g.alpha);
  }
  // t10 as the progeny gives it: the fragments below a tenth of the size plus the fines there.
  const double tenth = 0.2 * q.radius;
  double below = tenth >= b.fines_diameter
                     ? g.fines_mass
                     : g.fines_law_mass * std::pow(tenth / b.fines_diameter, g.alpha);
  for (const double r_f : g.radii)
    if (2.0 * r_f < tenth) below += Disc::mass(r_f, density);
  record.t10 = 100.0 * below / mass;
  breakages_.push_back(record);
  return g.fines_mass;
}

bool Grinding::in_zone(Vec2 x) const {
  const SieveSpec& s = scene_.sieve;
  if (s.type == DischargeType::kGrate) return norm(x - scene_.drum.center) > grate_inner_;
  return x.x >= s.box_min.x && x.x <= s.box_max.x && x.y >= s.box_min.y && x.y <= s.box_max.y;
}

// The ore narrower than the aperture that leaves in this step: in the zone (box, grate), or,
// overflow, the finest (then the lowest id) while the ore hold-up exceeds the limit; the
// hold-up is an exact integer sum over ranks, so every rank count decides alike.
void Grinding::discharge(double time, const ParticleStore& p, Domain& domain) {
  const SieveSpec& s = scene_.sieve;
  const auto out = [&](std::size_t k) {
    plan_.remove[k] = 1;
    plan_.product.push_back({time, p.id[k], size_radius(p, k), p.mass[k]});
    plan_.sieved_mass += p.mass[k];
    ++plan_.sieved;
  };
  EquivalentRadii radii;
  if (s.type != DischargeType::kOverflow) {
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      if (plan_.remove[k] == 0 && p.material[k] == sieve_material_ && in_zone(p.pos[k]) &&
          2.0 * size_radius(p, k, radii) < s.aperture)
        out(k);
    return;
  }
  std::int64_t held = 0;
  std::vector<std::int64_t> fine;  // (radius bits, id, mass units) of the candidates
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    if (p.material[k] != sieve_material_) continue;
    held += SizeMasses::units(p.mass[k]);
    if (plan_.remove[k] != 0) continue;
    const double r = size_radius(p, k, radii);
    if (2.0 * r < s.aperture)
      fine.insert(fine.end(),
                  {std::bit_cast<std::int64_t>(r), p.id[k], SizeMasses::units(p.mass[k])});
  }
  held = domain.sum(held);
  const std::int64_t limit = SizeMasses::units(s.holdup);
  if (held <= limit) return;
  std::vector<std::int64_t> all = domain.allgather(fine);
  std::vector<std::array<std::int64_t, 3>> c;
  for (std::size_t k = 0; k + 2 < all.size(); k += 3) c.push_back({all[k], all[k + 1], all[k + 2]});
  std::sort(c.begin(), c.end());  // positive radii: their bits order as the values
  std::vector<std::int64_t> leaving;
  for (const auto& x : c) {
    if (held <= limit) break;
    leaving.push_back(x[1]);
    held -= x[2];
  }
  std::sort(leaving.begin(), leaving.end());
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    if (p.material[k] == sieve_material_ &&
        std::binary_search(leaving.begin(), leaving.end(), p.id[k]))
      out(k);
}

bool Grinding::feed_due(double time) const {
  const FeedSpec& f = scene_.feed;
  if (feed_material_ < 0 || time < next_feed_try_) return false;
  if (f.period > 0.0) return time >= f.start + static_cast<double>(totals_.fed_count) * f.period;
  return totals_.fed_mass <= f.mass_rate * (time - f.start);
}

double Grinding::feed_radius() const {
  const FeedSpec& f = scene_.feed;
  const double u = random_uniform(stream(scene_.run.seed, kStreamFeed),
                                  static_cast<std::uint64_t>(totals_.fed_count), 0);
  return f.radius_min + u * (f.radius_max - f.radius_min);
}

// One fed particle, where the charge is thinnest (or at the feed point), on the rank that owns
// that place; false (on every rank) when no place is free: the feed waits 1 ms.
bool Grinding::feed(double time, ParticleStore& p, Domain& domain, EnergyLedger& ledger) {
  const FeedSpec& f = scene_.feed;
  const double r = feed_radius();
  const std::vector<Vec2> points = f.has_point ? std::vector<Vec2>{f.point} : candidates_;
  // Clearance of every point: distance to the nearest particle surface (all ranks) and, for
  // the candidates, to the ring that keeps clear of shell and lifters.
  std::vector<double> neg_clear(points.size());
  for (std::size_t c = 0; c < points.size(); ++c) {
    double clear = std::numeric_limits<double>::max();
    if (!f.has_point) clear = feed_reach_ - norm(points[c] - scene_.drum.center);
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      clear = std::min(clear, norm(points[c] - p.pos[k]) - p.radius[k]);
    neg_clear[c] = -clear;
  }
  domain.max(neg_clear);
  std::size_t best = 0;
  for (std::size_t c = 1; c < points.size(); ++c)
    if (neg_clear[c] < neg_clear[best]) best = c;
  if (-neg_clear[best] < r) {
    next_feed_try_ = time + 1e-3;
    return false;
  }
  const double density = scene_.materials[static_cast<std::size_t>(feed_material_)].density;
  const double mass = Disc::mass(r, density);
  if (domain.owns(points[best])) {
    p.clear_ghosts();
    const std::size_t k =
        p.add(next_id_, feed_material_, r, density, points[best], f.velocity, 0.0);
    ledger.fed += mechanical_energy(p, k, scene_.run.gravity);
  }
  ++next_id_;
  totals_.fed_count += 1;
  totals_.fed_mass += mass;
  sizes_.fed.add(2.0 * r, mass);
  return true;
}

void Grinding::exclude_births(ContactEngine& contacts) const {
  if (break_material_ < 0) return;  // only fragments are born overlapping
  // Marked: the next evaluation (at the birth state) takes the overlap as the birth overlap; a
  // contact apart then is cleared by the kernel like any other.
  const std::size_t off = contacts.history_offset("peak_energy") + TrackBreakage::kBirthOverlap;
  PairList& pl = contacts.mutable_pairs();
  for (std::size_t k = 0; k < pl.size(); ++k)
    if (pl.id_i[k] >= births_from_ || pl.id_j[k] >= births_from_)
      pl.history[k * pl.width + off] = -1.0;
  WallPairList& wl = contacts.mutable_wall_pairs();
  for (std::size_t k = 0; k < wl.size(); ++k)
    if (wl.id[k] >= births_from_) wl.history[k * wl.width + off] = -1.0;
}

std::vector<BreakageRecord> Grinding::take_breakages() { return std::exchange(breakages_, {}); }
std::vector<ProductRecord> Grinding::take_product() { return std::exchange(product_, {}); }
std::vector<FragmentRecord> Grinding::take_fragments() { return std::exchange(fragment_log_, {}); }

void combine(SizeMasses& m, const Domain& domain) {
  domain.sum(m.units());
  domain.max(m.neg_low());
  domain.max(m.high());
}

GrindingSizes Grinding::sizes(const Domain& domain) const {
  GrindingSizes s = sizes_;
  combine(s.product, domain);
  return s;
}

SizeMasses Grinding::mill_sizes(const ParticleStore& p, const Domain& domain) const {
  SizeMasses m;
  const int ore = ore_material();
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    if (p.material[k] == ore) m.add(2.0 * size_radius(p, k), p.mass[k]);
  combine(m, domain);
  return m;
}

}  // namespace dem2d
