#include "core/mill/grinding.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/base/random.hpp"
#include "core/contact/contact_models.hpp"
#include "core/geometry/drum_geometry.hpp"
#include "core/shape/disc.hpp"

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
  double largest = -1.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    largest = std::max(largest, static_cast<double>(p.id[k]));
  next_id_ = static_cast<std::int64_t>(domain.max(largest)) + 1;
  next_feed_try_ = scene.feed.start;
  if (scene.feed.present && scene.drum.present) {
    // Candidate feed points: rings inside the drum clear of the shell and the lifters.
    const DrumSpec& d = scene.drum;
    const double reach = DrumGeometry(d).clear_radius();
    feed_reach_ = reach;
    candidates_.push_back(d.center);
    for (int ring = 1; ring <= 6; ++ring) {
      const double radius = (reach - scene.feed.radius_max) * ring / 6.0;
      const int n = 8 * ring;
      for (int k = 0; k < n; ++k) {
        const double a = 2.0 * std::numbers::pi * (k + 0.5 * (ring % 2)) / n;
        candidates_.push_back(d.center + radius * Vec2{std::cos(a), std::sin(a)});
      }
    }
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
  plan_.product.clear();
  plan_.sieved = 0;
  plan_.sieved_mass = 0.0;
  if (sieve_material_ >= 0) sieve(time, p);
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
      parents.push_back(
          {p.id[k], p.material[k], p.radius[k], b.energy, p.pos[k], p.vel[k], p.omega[k]});
      remove[k] = 2;
    }
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      if (remove[k] == 1) ledger.discharged += mechanical_energy(p, k, scene_.run.gravity);
    p.remove_if(remove);
    break_parents(time, parents, p, domain);
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
           p.radius[i] >= r_min;
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
    if (breakable(i)) out.push_back({pl.id_i[k], pl.id_j[k], std::size_t(i), peak, tested});
    if (breakable(j)) out.push_back({pl.id_j[k], pl.id_i[k], std::size_t(j), peak, tested});
    plan_.tested_pairs.push_back(entry);
  }
  const WallPairList& wl = contacts.wall_pairs();
  const double* wall_h = evaluated ? wl.trial.data() : wl.history.data();
  for (std::size_t k = 0; k < wl.size(); ++k) {
    const double* h = wall_h + k * wl.width + off;
    const double peak = h[TrackBreakage::kPeak], tested = h[TrackBreakage::kTested];
    if (!TrackBreakage::test_due(peak, h[TrackBreakage::kEnergy], tested)) continue;
    const std::int32_t i = wl.particle[k];
    if (breakable(i))
      out.push_back({wl.id[k], -1 - std::int64_t{wl.element[k]}, std::size_t(i), peak, tested});
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
  const std::uint64_t seed = stream(scene_.run.seed, kStreamTest);
  const Field<double>& damage = *p.damage();
  std::vector<Broken>& broken = plan_.broken;
  std::int64_t last_broken = -1, last_damaged = -1;
  for (const Test& t : tests) {
    if (t.id == last_broken) continue;  // already broken in this step
    const double energy = t.peak - std::max(t.tested, b.minimum_energy);
    if (energy <= 0.0) continue;
    const double before = t.id == last_damaged ? plan_.damage.back().second : damage[t.index];
    const double e_t = before + energy;
    const double probability = 1.0 - std::exp(-b.strength * e_t);
    const std::uint64_t key =
        mix64(static_cast<std::uint64_t>(t.id)) ^ static_cast<std::uint64_t>(t.partner);
    if (random_uniform(seed, key, static_cast<std::uint64_t>(step)) < probability) {
      broken.push_back({t.index, t.peak});
      last_broken = t.id;
    } else if (t.id == last_damaged) {
      plan_.damage.back().second = e_t;
    } else {
      plan_.damage.emplace_back(t.index, e_t);
      last_damaged = t.id;
    }
  }
  std::sort(broken.begin(), broken.end(),
            [](const Broken& x, const Broken& y) { return x.index < y.index; });
}

int Grinding::fragment_count(std::int64_t parent) const {
  const BreakageSpec& b = scene_.breakage;
  const double z = random_normal(stream(scene_.run.seed, kStreamFragments),
                                 static_cast<std::uint64_t>(parent), 0);
  const double n = std::round(b.fragments_mean + b.fragments_sd * z);
  return static_cast<int>(std::clamp(n, double(b.fragments_min), double(b.fragments_max)));
}

// Every rank's parents of this step, sorted by id, take the next ids in turn; this rank's are
// replaced by their fragments (the parents are already out of the store).
void Grinding::break_parents(double time, const std::vector<Parent>& parents, ParticleStore& p,
                             Domain& domain) {
  std::vector<std::int64_t> mine;
  for (const Parent& parent : parents) mine.push_back(parent.id);
  std::vector<std::int64_t> all = domain.allgather(mine);
  std::sort(all.begin(), all.end());
  std::int64_t id = next_id_;
  const std::uint64_t seed = stream(scene_.run.seed, kStreamFragments);
  for (const std::int64_t parent_id : all) {
    const int n = fragment_count(parent_id);
    const auto it = std::find(mine.begin(), mine.end(), parent_id);
    if (it != mine.end()) {
      const Parent& q = parents[static_cast<std::size_t>(it - mine.begin())];
      breakages_.push_back({time, q.id, q.radius, q.energy, n, id});
      const double r_f = q.radius / std::cbrt(static_cast<double>(n));
      const double turn =
          2.0 * std::numbers::pi * random_uniform(seed, static_cast<std::uint64_t>(q.id), 1);
      const double density = scene_.materials[static_cast<std::size_t>(q.material)].density;
      for (int f = 0; f < n; ++f) {
        const double a = turn + 2.0 * std::numbers::pi * f / n;
        const Vec2 offset = (q.radius - r_f) * Vec2{std::cos(a), std::sin(a)};
        p.add(id + f, q.material, r_f, density, q.x + offset,
              q.v + q.omega * Vec2{-offset.y, offset.x}, q.omega);
      }
    }
    id += n;
    totals_.breakages += 1;
    totals_.fragments += n;
  }
  next_id_ = id;
}

void Grinding::sieve(double time, const ParticleStore& p) {
  const SieveSpec& s = scene_.sieve;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const Vec2 x = p.pos[k];
    if (p.material[k] != sieve_material_ || !(p.radius[k] < s.aperture) || x.x < s.box_min.x ||
        x.x > s.box_max.x || x.y < s.box_min.y || x.y > s.box_max.y)
      continue;
    plan_.remove[k] = 1;
    plan_.product.push_back({time, p.id[k], p.radius[k], p.mass[k]});
    plan_.sieved_mass += p.mass[k];
    ++plan_.sieved;
  }
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

}  // namespace dem2d
