// The angular-sector decomposition under MPI. One binary, run by CTest at 1, 2, 3, 4
// and 5 ranks and at 8 (oversubscribed: tests/CMakeLists.txt); every assertion holds at every
// rank count, and every rank owns particles in every scene (checked), 8 included.
//
//  - Routing and ghost sets: particles placed at the drum centre, on sector edges and along
//    the wall; every rank checks that it owns exactly the particles whose sector is its own,
//    holds as ghosts exactly the others within the halo width of its wedge (a true distance),
//    that each ghost came from its owner (origin rank in the plan) and carries its owner's data;
//    the end-of-step round (ghosts' next state and the step's reduction in one exchange).
//  - Migration: a particle pushed across a boundary arrives with every field and its contact
//    histories; none is lost or duplicated; a particle that jumps past the halo is an error
//    with the same message on every rank.
//  - Reproducibility: every rank runs the serial engine on the whole scene beside the parallel
//    one and compares its owned particles, by id, bit for bit, at many steps, for a
//    polydisperse charge filling the drum centre, a compressed packing in contact across every
//    wedge from its first step, the thesis waterfall scene, and a centrifuging charge that
//    crosses sector boundaries all the time (Verlet and iterative).
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "parallel/mpi_domain.hpp"
#include "support/scenes.hpp"
#include "support/thesis.hpp"

namespace {

using namespace dem2d;

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int world_size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}
std::int64_t global_sum(std::int64_t x) {
  std::int64_t r = 0;
  MPI_Allreduce(&x, &r, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  return r;
}

using testing_support::thesis_steel;

// The same hand-placed particles on every rank: the drum centre, both sides of several
// sector edges, a ring near the wall, and a row through the middle.
void place_probe_particles(ParticleStore& p, int n_sectors) {
  std::int64_t id = 0;
  const double r = 0.01;
  p.add(id++, 0, r, 7800.0, {0.0, 0.0}, {}, 0.0);  // the centre: a ghost everywhere
  for (int s = 0; s < n_sectors; s += 3) {
    const double a = s * kTwoPi / n_sectors;
    for (const double off : {-1e-9, 1e-9, -0.015, 0.015})
      for (const double rad : {0.05, 0.3, 0.93})
        p.add(id++, 0, r, 7800.0, {rad * std::cos(a + off / rad), rad * std::sin(a + off / rad)},
              {}, 0.0);
  }
  for (int k = 0; k < 40; ++k) {
    const double a = kTwoPi * (k + 0.5) / 40;
    p.add(id++, 0, r, 7800.0, {0.97 * std::cos(a), 0.97 * std::sin(a)}, {0.1 * k, -0.2}, 0.3 * k);
  }
  for (int k = -20; k <= 20; ++k) p.add(id++, 0, r, 7800.0, {0.045 * k, 0.002 * k}, {}, 0.0);
}

// The probe particles on every rank (`all`) and decomposed about the origin (`p`: this rank's
// own, then the ghosts within `halo` of its wedge).
struct ProbeScene {
  explicit ProbeScene(double halo_width) : domain(MPI_COMM_WORLD, centred()), halo(halo_width) {
    place_probe_particles(all, 16 * world_size());
    place_probe_particles(p, 16 * world_size());
    domain.adopt(p, halo);
    domain.exchange_halo(p);
  }
  static DecompositionOptions centred() {
    DecompositionOptions opt;
    opt.has_center = true;
    return opt;
  }
  MpiDomain domain;
  ParticleStore all, p;
  double halo;
};

TEST(Decomposition, OwnershipAndExactGhostSets) {
  const int rank = world_rank(), size = world_size();
  ProbeScene scene(0.05);
  auto& [domain, all, p, halo] = scene;
  const SectorPartition& part = domain.partition();
  ASSERT_TRUE(is_valid(part));
  ASSERT_EQ(part.parts(), size);

  std::set<std::int64_t> owned, ghosts;
  for (std::size_t k = 0; k < p.n_owned(); ++k) owned.insert(p.id[k]);
  for (std::size_t k = p.n_owned(); k < p.size(); ++k) ghosts.insert(p.id[k]);
  std::set<std::int64_t> want_owned, want_ghosts;
  for (std::size_t k = 0; k < all.n_owned(); ++k) {
    const int owner =
        part.owner[static_cast<std::size_t>(sector_of(all.pos[k], {}, part.n_sectors))];
    if (owner == rank)
      want_owned.insert(all.id[k]);
    else if (distance_to_part(all.pos[k], {}, part, rank) < halo)
      want_ghosts.insert(all.id[k]);
  }
  EXPECT_EQ(owned, want_owned);
  EXPECT_EQ(ghosts, want_ghosts);
  EXPECT_EQ(global_sum(static_cast<std::int64_t>(p.n_owned())),
            static_cast<std::int64_t>(all.n_owned()));
  EXPECT_EQ(global_sum(p.n_owned() > 0 ? 1 : 0), size) << "every rank owns probe particles";
  EXPECT_EQ(global_sum(p.n_ghost() > 0 ? 1 : 0), size > 1 ? size : 0)
      << "every rank holds ghosts (none on one rank)";
  // The centre particle is on every rank, owned by one.
  const std::int64_t has_centre = owned.count(0) + ghosts.count(0);
  EXPECT_EQ(has_centre, 1);
  EXPECT_EQ(global_sum(static_cast<std::int64_t>(owned.count(0))), 1);
  // Routing: each ghost came from the rank that owns it and carries its data, bit for bit.
  const std::vector<int> origin = domain.ghost_origin();
  ASSERT_EQ(origin.size(), p.n_ghost());
  for (std::size_t g = 0; g < p.n_ghost(); ++g) {
    const std::size_t k = p.n_owned() + g;
    const std::size_t src = static_cast<std::size_t>(p.id[k]);  // ids are indices in `all`
    EXPECT_EQ(origin[g],
              part.owner[static_cast<std::size_t>(sector_of(all.pos[src], {}, part.n_sectors))]);
    EXPECT_NE(origin[g], rank);
    EXPECT_EQ(std::memcmp(&p.pos[k], &all.pos[src], sizeof(Vec2)), 0);
    EXPECT_EQ(std::memcmp(&p.vel[k], &all.vel[src], sizeof(Vec2)), 0);
    EXPECT_EQ(p.omega[k], all.omega[src]);
    EXPECT_EQ(p.mass[k], all.mass[src]);
  }
}

// The end-of-step round of velocity Verlet (Domain::exchange_step): the ghosts receive their
// owners' prepared fields (here: position + (id, 0), spin = 10 id), read from exactly the
// halo sources, and the values are maximised over ranks in the same messages, a NaN on one
// rank giving NaN on all.
TEST(Decomposition, EndOfStepRoundCarriesGhostsAndTheReduction) {
  const int rank = world_rank(), size = world_size();
  ProbeScene scene(0.05);
  auto& [domain, all, p, halo] = scene;
  const SectorPartition& part = domain.partition();

  // Halo sources: ascending, and exactly the owned particles within the halo of another rank.
  const std::span<const std::int32_t> sources = domain.halo_sources();
  EXPECT_TRUE(std::is_sorted(sources.begin(), sources.end()));
  std::set<std::int64_t> got, want;
  for (const std::int32_t k : sources) got.insert(p.id[static_cast<std::size_t>(k)]);
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    for (int q = 0; q < size; ++q)
      if (q != rank && distance_to_part(p.pos[k], {}, part, q) < halo) want.insert(p.id[k]);
  EXPECT_EQ(got.size(), sources.size()) << "no repeats";
  EXPECT_EQ(got, want);

  std::vector<FieldBase*> registry;
  Field<Vec2> next_pos{"next_position", registry};
  Field<double> next_spin{"next_spin", registry};
  for (FieldBase* f : registry) f->resize(p.n_owned());
  for (std::size_t k = 0; k < p.n_owned(); ++k) {  // NaN except at the sources: must not travel
    next_pos[k] = {std::nan(""), std::nan("")};
    next_spin[k] = std::nan("");
  }
  for (const std::int32_t k : sources) {
    const std::size_t u = static_cast<std::size_t>(k);
    next_pos[u] = p.pos[u] + Vec2{static_cast<double>(p.id[u]), 0.0};
    next_spin[u] = 10.0 * static_cast<double>(p.id[u]);
  }
  const std::vector<FieldBase*> recv = {&p.pos, &p.omega};
  double values[3] = {static_cast<double>(rank), -static_cast<double>(rank),
                      rank == size - 1 ? std::nan("") : 0.0};
  domain.exchange_step(p, registry, recv, values);
  EXPECT_EQ(values[0], size - 1);
  EXPECT_EQ(values[1], 0.0);
  EXPECT_TRUE(std::isnan(values[2])) << "a NaN on the last rank reaches rank " << rank;
  for (std::size_t g = 0; g < p.n_ghost(); ++g) {
    const std::size_t k = p.n_owned() + g;
    const std::size_t src = static_cast<std::size_t>(p.id[k]);  // ids are indices in `all`
    const Vec2 want_pos = all.pos[src] + Vec2{static_cast<double>(p.id[k]), 0.0};
    EXPECT_EQ(std::memcmp(&p.pos[k], &want_pos, sizeof(Vec2)), 0) << "ghost " << p.id[k];
    EXPECT_EQ(p.omega[k], 10.0 * static_cast<double>(p.id[k])) << "ghost " << p.id[k];
    EXPECT_EQ(std::memcmp(&p.vel[k], &all.vel[src], sizeof(Vec2)), 0) << "fields not listed stay";
  }
}

TEST(Decomposition, MigrationCarriesFieldsAndHistories) {
  const int rank = world_rank(), size = world_size();
  DecompositionOptions opt;
  opt.has_center = true;
  MpiDomain domain(MPI_COMM_WORLD, opt);
  ParticleStore p;
  place_probe_particles(p, 16 * size);
  const std::int64_t total = static_cast<std::int64_t>(p.n_owned());
  const double halo = 0.05;
  domain.adopt(p, halo);
  // Turn every owned particle by 1/4 sector counter-clockwise (less than the halo at these
  // radii), and mark it: spin = its id, angle = the rank it started on.
  const double turn = 0.25 * kTwoPi / (16 * size);
  // The rank each particle starts on (ids are indices in `all`).
  ParticleStore all;
  place_probe_particles(all, 16 * size);
  std::vector<int> started_on(all.n_owned());
  for (std::size_t k = 0; k < all.n_owned(); ++k) started_on[k] = domain.owner_of(all.pos[k]);
  HistoryRecords records(2);
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const Vec2 x = p.pos[k];
    p.pos[k] = {x.x * std::cos(turn) - x.y * std::sin(turn),
                x.x * std::sin(turn) + x.y * std::cos(turn)};
    p.omega[k] = static_cast<double>(p.id[k]);
    p.theta[k] = rank;
    // A history with the next particle and one with wall element 3, keyed by this id.
    const double pair_values[2] = {1e-6 * static_cast<double>(p.id[k]), 2.0};
    const double wall_values[2] = {3e-6, static_cast<double>(p.id[k])};
    records.push_back(p.id[k], p.id[k] + 1, pair_values);
    records.push_back(p.id[k], -1 - 3, wall_values);
  }
  records.sort_unique();
  domain.migrate(p, records);
  EXPECT_EQ(global_sum(static_cast<std::int64_t>(p.n_owned())), total);
  std::int64_t moved_here = 0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    EXPECT_EQ(domain.owner_of(p.pos[k]), rank) << "id " << p.id[k];
    EXPECT_EQ(p.omega[k], static_cast<double>(p.id[k])) << "fields travel with the particle";
    if (p.theta[k] != rank) ++moved_here;
    // Both of its records are here.
    const auto find = [&](std::int64_t a, std::int64_t b) {
      for (std::size_t r = 0; r < records.size(); ++r)
        if (records.a(r) == a && records.b(r) == b) return static_cast<std::ptrdiff_t>(r);
      return std::ptrdiff_t{-1};
    };
    EXPECT_GE(find(p.id[k], p.id[k] + 1), 0) << "id " << p.id[k];
    // The record keyed by its predecessor travels with it too (as its second particle) when
    // both started on the same rank, where that record was made.
    const auto id = static_cast<std::size_t>(p.id[k]);
    if (id > 0 && started_on[id - 1] == started_on[id]) {
      EXPECT_GE(find(p.id[k] - 1, p.id[k]), 0) << "id " << p.id[k];
    }
    const std::ptrdiff_t wall = find(p.id[k], -4);
    ASSERT_GE(wall, 0) << "id " << p.id[k];
    EXPECT_EQ(records.values(static_cast<std::size_t>(wall))[1], static_cast<double>(p.id[k]));
  }
  EXPECT_TRUE(std::is_sorted(p.id.data(), p.id.data() + p.n_owned()));
  bool sorted = true;
  for (std::size_t r = 1; r < records.size(); ++r)
    sorted = sorted && (records.a(r - 1) < records.a(r) ||
                        (records.a(r - 1) == records.a(r) && records.b(r - 1) < records.b(r)));
  EXPECT_TRUE(sorted) << "records sorted by key, without repeats";
  if (size > 1) {
    EXPECT_GT(global_sum(moved_here), 0) << "the turn should move some particles";
  }
  EXPECT_EQ(global_sum(moved_here), domain.sum(domain.stats().migrated));
}

// Sectors are weighted by the reported work, not by the particle count: with the particles of
// one quadrant reported 9 times as heavy (a dense pile beside balls in flight), the
// repartition balances the work (2000 particles, 32 sectors per rank: within 5 %), which the
// count-balanced start does not.
TEST(Decomposition, RepartitionBalancesReportedWorkNotCounts) {
  const int size = world_size();
  if (size == 1) GTEST_SKIP() << "one rank: nothing to balance";
  DecompositionOptions opt;
  opt.has_center = true;
  opt.repartition_threshold = 1.0;  // any imbalance triggers it
  opt.repartition_gap = 1;
  MpiDomain domain(MPI_COMM_WORLD, opt);
  ParticleStore p;
  for (int k = 0; k < 2000; ++k) {  // a uniform ring: equal counts per sector
    const double a = kTwoPi * (k + 0.5) / 2000;
    p.add(k, 0, 0.001, 7800.0, {0.8 * std::cos(a), 0.8 * std::sin(a)}, {}, 0.0);
  }
  const auto weight = [](Vec2 x) { return x.x > 0.0 && x.y > 0.0 ? 9.0 : 1.0; };
  const auto rank_work = [&]() {
    double w = 0.0;
    for (std::size_t k = 0; k < p.n_owned(); ++k) w += weight(p.pos[k]);
    double max = 0.0, sum = 0.0;
    MPI_Allreduce(&w, &max, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(&w, &sum, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return max / (sum / size);
  };
  domain.adopt(p, 0.01);
  const double by_count = rank_work();
  std::vector<double> work(p.n_owned());
  for (std::size_t k = 0; k < p.n_owned(); ++k) work[k] = weight(p.pos[k]);
  domain.report_work(work);
  HistoryRecords records(2);
  domain.migrate(p, records);
  const double by_work = rank_work();
  EXPECT_EQ(domain.stats().partitions, 2);
  EXPECT_LT(by_work, by_count) << "the count-balanced start is worse";
  EXPECT_LT(by_work, 1.05) << "after the repartition (count-balanced: " << by_count << ")";
}

TEST(Decomposition, AJumpPastTheHaloIsAnErrorOnEveryRank) {
  const int size = world_size();
  if (size == 1) GTEST_SKIP() << "one rank: nothing can leave";
  DecompositionOptions opt;
  opt.has_center = true;
  MpiDomain domain(MPI_COMM_WORLD, opt);
  ParticleStore p;
  place_probe_particles(p, 16 * size);
  domain.adopt(p, 0.05);
  // The owner of the wall particle with the largest id throws it to the opposite side.
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    if (p.id[k] == 1 + 12 * ((16 * size + 2) / 3) + 20) p.pos[k] = -1.0 * p.pos[k];
  HistoryRecords records(2);
  std::string what;
  try {
    domain.migrate(p, records);
  } catch (const std::runtime_error& e) {
    what = e.what();
  }
  EXPECT_NE(what.find("particle " + std::to_string(1 + 12 * ((16 * size + 2) / 3) + 20)),
            std::string::npos)
      << "every rank names the particle: '" << what << "'";
  EXPECT_NE(what.find("halo"), std::string::npos) << what;
}

// ---------------------------------------------------------------------------------------------
// Reproducibility: the parallel run's owned particles equal the serial run's, bit for bit.

struct Mismatch {
  std::int64_t count = 0;
  std::string first;
};

Mismatch compare_to_serial(const Simulation& par, const Simulation& ser) {
  Mismatch m;
  const ParticleStore& a = par.particles();
  const ParticleStore& b = ser.particles();
  std::map<std::int64_t, std::size_t> index;
  for (std::size_t k = 0; k < b.n_owned(); ++k) index[b.id[k]] = k;
  const auto same = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  for (std::size_t k = 0; k < a.n_owned(); ++k) {
    const auto it = index.find(a.id[k]);
    const std::size_t s = it == index.end() ? 0 : it->second;
    const bool ok = it != index.end() && same(a.pos[k], b.pos[s]) && same(a.vel[k], b.vel[s]) &&
                    same(a.acc[k], b.acc[s]) && same(a.theta[k], b.theta[s]) &&
                    same(a.omega[k], b.omega[s]) && same(a.alpha[k], b.alpha[s]);
    if (!ok) {
      if (m.count == 0)
        m.first =
            "particle " + std::to_string(a.id[k]) + " at step " + std::to_string(par.step_count());
      ++m.count;
    }
  }
  return m;
}

// The share of each scene's steps to run: DEM2D_TEST_STEPS_FRACTION, in (0, 1], 1 when unset.
// CTest's 8-rank run sets it (tests/CMakeLists.txt): 8 ranks on this 2-core machine take about
// 2 ms per step, all of it the oversubscribed ranks' synchronisation, so the full scenes take
// 4 minutes there.
double steps_fraction() {
  const char* text = std::getenv("DEM2D_TEST_STEPS_FRACTION");
  const double f = text ? std::atof(text) : 1.0;
  return f > 0.0 && f <= 1.0 ? f : 1.0;
}

// Runs the scene serially and in parallel side by side for `steps` (times steps_fraction()
// unless `full_length`), comparing every `every` (the same number of comparisons whatever the
// fraction). `check` then looks at the serial run's end state.
// `sorted`: the parallel run puts its particles in spatial order at every rebuild (the list in
// storage order, forces summed through the records), the serial one keeps them in id order.
void expect_same_as_serial(const Scene& scene, int steps, int every,
                           const std::function<void(const Simulation&)>& check = {},
                           bool full_length = false, bool sorted = false) {
  const double fraction = full_length ? 1.0 : steps_fraction();
  steps = std::max(1, static_cast<int>(std::lround(fraction * steps)));
  every = std::max(1, static_cast<int>(std::lround(fraction * every)));
  DecompositionOptions opt;
  opt.has_center = scene.drum.present;
  opt.center = scene.drum.center;
  opt.repartition_threshold = 1.05;  // repartition often: ownership changes must not matter
  opt.repartition_gap = 2;
  MpiDomain domain(MPI_COMM_WORLD, opt);
  Scene par_scene = scene, ser_scene = scene;
  if (sorted) {
    par_scene.run.spatial_sort = SpatialSort::kAlways;
    ser_scene.run.spatial_sort = SpatialSort::kNever;
  }
  Simulation par(par_scene, &domain);
  Simulation ser(ser_scene);
  ASSERT_EQ(par.dt(), ser.dt());
  std::int64_t bad = 0, checked = 0;
  std::string first;
  for (int s = 0; s <= steps; ++s) {
    if (s > 0) {
      par.step();
      ser.step();
    }
    if (s % every != 0 && s != steps) continue;
    const Mismatch m = compare_to_serial(par, ser);
    if (m.count && first.empty()) first = m.first;
    bad += m.count;
    checked += 1;
    // Integer diagnostics add exactly: the same contact count on any rank count.
    const SeriesRow row = par.diagnostics();
    EXPECT_EQ(row.contacts, ser.diagnostics().contacts) << "step " << s;
    EXPECT_EQ(row.particles, static_cast<std::int64_t>(ser.particles().n_owned()));
  }
  EXPECT_EQ(global_sum(bad), 0) << "first mismatch on rank " << world_rank() << ": " << first;
  const std::int64_t migrated = global_sum(domain.stats().migrated);
  if (world_size() > 1) {
    EXPECT_GT(migrated, 0) << "the scene should move particles between ranks";
  }
  // Every rank owns particles at the end (each scene is large enough for 8 ranks), so that every
  // rank's migration, halo and comparison are exercised, not only a few ranks'.
  const std::int64_t owning = global_sum(par.particles().n_owned() > 0 ? 1 : 0);
  EXPECT_EQ(owning, world_size()) << "ranks owning particles at the end";
  if (world_rank() == 0)
    std::printf(
        "[ reproducible ] %s: %d steps, %lld comparisons, %lld migrations, %d partitions, "
        "imbalance %.3f, %lld of %d ranks own particles\n",
        scene.title.c_str(), steps, static_cast<long long>(checked),
        static_cast<long long>(migrated), domain.stats().partitions, domain.stats().imbalance_work,
        static_cast<long long>(owning), world_size());
  if (check) check(ser);
}

Scene thesis_drum(int balls, double speed, int sides) {
  return testing_support::thesis_drum_scene(balls, speed, sides, /*ramp_time=*/0.1);
}

// No gravity, an 8-sided shell at 6 rad/s stirring a dense polydisperse charge that fills the
// whole drum, centre included (where every wedge meets).
Scene polydisperse_centre_scene() {
  Scene s;
  s.title = "polydisperse, whole drum, centre filled";
  s.deck_path = "test_domain";
  s.materials.push_back(thesis_steel());
  s.run.dt_auto = true;
  s.run.gravity = {0.0, 0.0};
  s.drum.present = true;
  s.drum.radius = 0.3;
  s.drum.speed = 6.0;
  s.drum.ramp_time = 0.0;
  s.drum.sides = 8;
  s.drum.material = "steel";
  FillSpec f;
  f.material = "steel";
  f.fill_fraction = 0.33;
  f.radius_min = 0.008;
  f.radius_max = 0.016;
  f.region = FillRegion::kFull;
  f.velocity = {0.3, -0.2};
  s.fills.push_back(f);
  return s;
}

TEST(Reproducibility, PolydisperseChargeFillingTheDrumCentre) {
  expect_same_as_serial(polydisperse_centre_scene(), 6000, 500);
}

// Every rank sorts its particles along the Hilbert curve at every rebuild, ghosts and
// migrations included; the serial run keeps id order: the same bits.
TEST(Reproducibility, SpatiallySortedRanksMatchTheUnsortedSerialRun) {
  Scene s = polydisperse_centre_scene();
  s.title = "polydisperse, whole drum, ranks sorted in space";
  expect_same_as_serial(s, 6000, 1000, {}, false, /*sorted=*/true);
}

// Contacts across every wedge boundary from the first step: about 600 spheres of two radii
// (9.5 and 10 mm) on a triangular lattice of spacing 19.4 mm, overlapping their neighbours by
// 0.1-0.6 mm, fill a disc over the drum centre (where every wedge meets) under gravity in a
// turning 8-sided shell: the packing springs apart (1 418 contacts at the start, about 200
// after 1 000 steps), every pair force changing at every step. The thesis scenes' balls fall
// freely for their first ~10 000 steps: a halo cut to 0.3 of its width went unnoticed in their
// first 15 % (not at full length), and this scene caught it at once on 2 and 8 ranks. It runs
// at its full length at every rank count, and is the 8-rank run's check of the forces across
// ranks (tests/CMakeLists.txt).
TEST(Reproducibility, PackingInContactFromTheFirstStep) {
  Scene s;
  s.title = "compressed packing over the drum centre";
  s.deck_path = "test_domain";
  s.materials.push_back(thesis_steel());
  s.run.dt_auto = true;
  s.drum.present = true;
  s.drum.radius = 0.3;
  s.drum.speed = 4.0;
  s.drum.ramp_time = 0.0;
  s.drum.sides = 8;
  s.drum.material = "steel";
  const double pitch = 0.0194, row = pitch * std::sqrt(3.0) / 2.0;
  for (int j = -14; j <= 14; ++j)
    for (int i = -14; i <= 14; ++i) {
      const Vec2 x{(i + 0.5 * (j & 1)) * pitch, j * row};
      if (norm(x) > 0.25) continue;
      s.particles.push_back(
          testing_support::ball("steel", (i * 7 + j * 3) % 2 == 0 ? 0.0100 : 0.0095, x));
    }
  expect_same_as_serial(
      s, 1000, 100,
      [](const Simulation& ser) {
        EXPECT_GT(ser.diagnostics().contacts, 100) << "the packing should still be in contact";
      },
      /*full_length=*/true);
}

// Ore breaking all over a drum filled to its centre (where every wedge meets), so that fragments
// are born across sector boundaries and at the centre, with feed and a sieve at the centre:
// ids, births, removals and every particle's state the same on every rank count.
Scene ore_across_sectors() {
  Scene s;
  s.title = "ore breaking, feed and sieve, whole drum, centre filled";
  s.deck_path = "test_domain";
  s.materials.push_back(thesis_steel());
  s.run.gravity = {0.0, 0.0};
  MaterialSpec ore = thesis_steel();
  ore.name = "ore";
  ore.density = 4800.0;
  ore.youngs_modulus = 6.0e10;
  ore.shear_modulus = 2.4e10;
  s.materials.push_back(ore);
  s.run.dt_auto = true;
  s.drum.present = true;
  s.drum.radius = 0.375;  // the fill boxes' corners inside the 8-gon's inscribed circle
  s.drum.speed = 6.0;
  s.drum.sides = 8;
  s.drum.material = "steel";
  // Two halves of the drum thrown at each other: head-on collisions along the vertical through
  // the centre, across the sector boundaries that meet there.
  for (const double side : {-1.0, 1.0}) {
    FillSpec f;
    f.material = "ore";
    f.count = 80;
    f.radius_min = 0.008;
    f.radius_max = 0.016;
    f.region = FillRegion::kBox;
    f.box_min = {side < 0 ? -0.26 : 0.005, -0.2};
    f.box_max = {side < 0 ? -0.005 : 0.26, 0.2};
    f.velocity = {-1.5 * side, 0.0};
    s.fills.push_back(f);
  }
  s.breakage.present = true;
  s.breakage.material = "ore";
  s.breakage.minimum_energy = 1e-6;
  s.breakage.strength = 1e5;
  s.breakage.minimum_radius = 0.011;
  s.feed.present = true;
  s.feed.material = "ore";
  s.feed.period = 0.003;
  s.feed.radius_min = 0.008;
  s.feed.radius_max = 0.012;
  s.sieve.present = true;
  s.sieve.material = "ore";
  s.sieve.box_min = {-0.05, -0.05};
  s.sieve.box_max = {0.05, 0.05};
  s.sieve.aperture = 0.016;  // a diameter
  return s;
}

TEST(Reproducibility, OreBreakingAcrossSectorsAndAtTheCentre) {
  Scene s = ore_across_sectors();
  const std::size_t initial = static_cast<std::size_t>(Simulation(s).particles().n_owned());
  expect_same_as_serial(s, 12000, 2000, [initial](const Simulation& ser) {
    const SeriesRow r = ser.diagnostics();
    EXPECT_GT(r.breakages, 20);
    EXPECT_GT(r.fed_count, 3);
    EXPECT_GT(r.discharged_count, 0);
    const ParticleStore& p = ser.particles();
    int near_centre = 0;
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      near_centre += p.id[k] >= static_cast<std::int64_t>(initial) && norm(p.pos[k]) < 0.05;
    EXPECT_GT(near_centre, 0) << "no fragment or fed particle near the centre";
  });
}

// The size-aware ore: Vogel-Peukert breakage on each body's compliance share, t10 progeny whose
// counts only the parent's owner knows and whose fines leave at once, and an overflow that lets
// out the finest ore above a hold-up (an exact integer sum over ranks): the same bits on every
// rank count.
TEST(Reproducibility, SizeAwareOreWithT10ProgenyAndOverflow) {
  Scene s = ore_across_sectors();
  s.title = "Vogel-Peukert ore, t10 progeny, overflow";
  BreakageSpec& b = s.breakage;
  b.model = BreakageModel::kVogelPeukert;
  b.f_mat = 400.0;
  b.xw_min = 0.001;
  b.fragments = FragmentLaw::kT10;
  b.t10_a = 60.0;
  b.t10_b = 50.0;
  b.fines_diameter = 0.012;  // the smallest fragment as in the thesis variant: the same dt
  s.sieve.type = DischargeType::kOverflow;
  s.sieve.holdup = 0.97 * Simulation(s).diagnostics().ore_mass;
  expect_same_as_serial(s, 12000, 2000, [](const Simulation& ser) {
    const GrindingTotals& t = ser.grinding()->totals();
    EXPECT_GE(t.breakages, 10);
    EXPECT_GT(t.fines_mass, 0.0);
    EXPECT_GT(t.discharged_count, 0);
  });
}

// The same mill with superellipse ore (rounded boxes n = 4 of aspect 0.6 at random angles):
// their breaks make superellipse fragments, alike on every rank count.
TEST(Reproducibility, SuperellipseOreBreaksAlike) {
  Scene s = ore_across_sectors();
  s.title = "superellipse ore breaking, feed and sieve";
  for (FillSpec& f : s.fills) {
    f.count = 50;
    f.shape = ParticleShape::kSuperellipse;
    f.aspect = 0.6;
    f.exponent = 4.0;
  }
  expect_same_as_serial(s, 12000, 2000, [](const Simulation& ser) {
    EXPECT_GE(ser.grinding()->totals().breakages, 3);
    const ParticleStore& p = ser.particles();
    int fragments = 0;
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      fragments += p.id[k] >= 100 && (*p.exponent())[k] == 4.0;
    EXPECT_GT(fragments, 0) << "superellipse fragments in the store";
  });
}

TEST(Reproducibility, ThesisWaterfallScene) {
  Scene s = thesis_drum(240, 1.8, 16);
  s.title = "thesis waterfall (240 balls, 16-gon, 1.8 rad/s)";
  expect_same_as_serial(s, 40000, 4000);
}

TEST(Reproducibility, CentrifugingChargeCrossesSectorsConstantly) {
  Scene s = thesis_drum(120, 10.0, 8);
  s.title = "centrifuging charge (120 balls, 8-gon, 10 rad/s)";
  expect_same_as_serial(s, 30000, 3000);
}

TEST(Reproducibility, NoDrumPileFallingIntoABox) {
  // No drum: sectors about the centre of the particles' initial bounding box. A polydisperse
  // cloud falls into an open box of three wall segments and piles up across sectors.
  Scene s;
  s.title = "no drum: a cloud falling into a box";
  s.deck_path = "test_domain";
  s.materials.push_back(thesis_steel());
  s.run.dt_auto = true;
  testing_support::add_open_box(s, 0.4, 0.6, "steel");
  FillSpec f = testing_support::box_fill("steel", 150, 0.012, 0.02, {-0.35, 0.05}, {0.35, 0.5});
  f.velocity = {0.5, -0.5};
  s.fills.push_back(f);
  expect_same_as_serial(s, 20000, 2000);
}

// Ellipses (the superellipse's kernel, its normals and R* kept as history) in a drum at 6 rad/s,
// crossing sectors: angles and shape fields ride with the ghosts and migrations.
TEST(Reproducibility, EllipsesInADrum) {
  Scene s = testing_support::shaped_drum_scene(100, 0.6, 6.0, true);
  expect_same_as_serial(s, 20000, 2000);
}

TEST(Reproducibility, IterativeIntegratorCentrifuging) {
  Scene s = thesis_drum(120, 10.0, 8);
  s.title = "centrifuging charge, iterative integrator";
  s.run.integrator = IntegratorKind::kIterative;
  // 0.17 s at the auto dt: long enough for balls to cross sector boundaries.
  expect_same_as_serial(s, 10000, 1000);
}

}  // namespace
