#include "core/run/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/base/errors.hpp"
#include "core/setup/fill.hpp"
#include "core/shape/disc.hpp"

namespace dem2d {

namespace {

// The scene as the core runs it: the models a table asks for switched on.
Scene prepared(const Scene& scene) {
  Scene s = scene;
  s.contact = active_contact(scene);
  return s;
}

std::string format_seconds(double s) {
  std::ostringstream o;
  o.precision(3);
  o << s << " s";
  return o.str();
}

}  // namespace

Simulation::Simulation(const Scene& scene, Domain* domain, const Resumption* resume)
    : scene_(prepared(scene)),
      domain_(domain ? domain : &serial_domain_),
      walls_(scene_),
      contacts_(scene_),
      sort_policy_(scene_.run.spatial_sort) {
  if (scene_.breakage.present) particles_.enable_damage();
  if (scene_.drum.present) particles_.enable_last_contact();
  if (has_shaped_particles(scene_)) particles_.enable_shape();
  if (resume)
    load_particles(*resume);
  else
    place_particles(scene_, walls_, particles_);
  scales_ = time_scales(scene_, particles_);
  if (resume)
    dt_ = resume->state.dt;
  else
    choose_dt();
  if (!resume) validate_start(scene_, particles_, dt_);  // bad input before step 1
  integrator_ = make_integrator(scene_.run, dt_, scene_.run.gravity);
  set_up_lists();
  if (resume) {
    resume_from(*resume);
  } else {
    domain_->adopt(particles_, halo_width_);
    rebuild();
    refresh_forces();
  }
  backup_.save(particles_, time_, step_);
  builds_at_backup_ = contacts_.builds();
  if (scene_.breakage.present || scene_.feed.present || scene_.sieve.present)
    grinding_ = std::make_unique<Grinding>(scene_, particles_, *domain_);
  if (resume && grinding_) grinding_->restore(resume->state.grinding);
  set_up_analytics(resume);
}

// The analysis window and the collision spectra (output.collision_spectra), continued from a
// checkpoint's: its sums go to rank 0.
void Simulation::set_up_analytics(const Resumption* resume) {
  mill_window_ = MillWindow(scene_.output.analysis_window);
  if (resume) {
    mill_window_.restore(resume->state.mill_samples);
  }
  if (!scene_.output.collision_spectra) return;
  std::vector<double> edges;
  for (double d = scene_.output.size_class_min; d < 10.0; d *= scene_.output.size_class_ratio)
    edges.push_back(d);
  std::vector<bool> ore(scene_.materials.size(), false);
  if (grinding_) ore[static_cast<std::size_t>(grinding_->ore_material())] = true;
  spectra_ = std::make_unique<CollisionSpectra>(std::move(edges), std::move(ore));
  if (!resume) return;
  // The counts cannot be rebinned: other size classes than the checkpoint's are refused (every
  // rank reads the same checkpoint, so every rank refuses alike).
  if (resume->state.spectra_counts.size() != spectra_->counts().size())
    throw InputError("the checkpoint's collision spectra have " +
                     std::to_string(resume->state.spectra_counts.size()) +
                     " bins, this deck's output.size_class_min and size_class_ratio give " +
                     std::to_string(spectra_->counts().size()) +
                     "; keep the checkpoint's size classes to continue its spectra");
  if (domain_->rank() == 0) {
    spectra_->counts() = resume->state.spectra_counts;
    spectra_->energies() = resume->state.spectra_energies;
  }
}

// The skin and the halo, then every rank keeps its own particles (every rank placed or loaded
// the same ones).
void Simulation::set_up_lists() {
  double r_min = std::numeric_limits<double>::max(), r_max = 0.0;
  for (std::size_t k = 0; k < particles_.size(); ++k) {
    r_min = std::min(r_min, particles_.radius[k]);
    r_max = std::max(r_max, particles_.radius[k]);
  }
  rebuilds_ = RebuildMonitor(scene_.run.skin >= 0.0 ? scene_.run.skin
                                                    : (particles_.size() ? 0.4 * r_min : 0.0));
  // A pair interacts within r_i + r_j + skin, so a rank needs the particles within
  // 2 r_max + skin of its region.
  if (scene_.feed.present) r_max = std::max(r_max, scene_.feed.radius_max);
  halo_width_ = 2.0 * r_max + rebuilds_.skin();
  ghost_fields_ = {&particles_.pos, &particles_.vel, &particles_.omega};
  // A shaped particle's contacts depend on its angle too.
  if (particles_.shaped()) ghost_fields_.push_back(&particles_.theta);
}

// Every particle of the checkpoint, in id order (whatever order the ranks wrote them in).
void Simulation::load_particles(const Resumption& resume) {
  const std::vector<FieldBase*>& fields = particles_.fields();
  if (resume.columns.size() != fields.size())
    throw std::logic_error("Simulation: a resumption needs one column per particle field");
  const std::size_t n = resume.n_particles;
  particles_.add_owned(n);
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (resume.columns[f].size() != n * fields[f]->bytes_per_item())
      throw std::logic_error("Simulation: resumption column " + fields[f]->name() +
                             " has the wrong size");
    fields[f]->unpack_items(0, n, resume.columns[f].data());
  }
  std::vector<std::size_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return particles_.id[a] < particles_.id[b]; });
  particles_.permute(order);
}

// The time, step, dt and lists of the checkpoint (its skin and halo: they were chosen from the
// particles at the start), the histories of this rank's particles, and the ledger. The forces
// and accelerations are the checkpoint's (the velocity-dependent ones were evaluated at Verlet's
// half-step velocity, which a new evaluation could not reproduce).
void Simulation::resume_from(const Resumption& resume) {
  const RunState& s = resume.state;
  if (resume.histories.width() != contacts_.history_slots().size())
    throw InputError("the checkpoint's contacts carry " + std::to_string(resume.histories.width()) +
                     " history values, this scene's contact model " +
                     std::to_string(contacts_.history_slots().size()));
  time_ = s.time;
  step_ = s.step;
  walls_.update(time_);
  rebuilds_ = RebuildMonitor(s.skin);
  halo_width_ = s.halo_width;
  domain_->adopt(particles_, halo_width_);
  std::vector<std::int64_t> mine(particles_.id.data(), particles_.id.data() + particles_.n_owned());
  std::sort(mine.begin(), mine.end());
  const auto owned = [&](std::int64_t id) {
    return std::binary_search(mine.begin(), mine.end(), id);
  };
  HistoryRecords records(resume.histories.width());
  for (std::size_t k = 0; k < resume.histories.size(); ++k)
    if (owned(resume.histories.a(k)) ||
        (resume.histories.b(k) >= 0 && owned(resume.histories.b(k))))
      records.push_back(resume.histories.a(k), resume.histories.b(k), resume.histories.values(k));
  records.sort_unique();
  contacts_.adopt(records);
  rebuild();
  ledger_ = s.rank_ledger;
  balance0_ = s.balance0;
  motion0_ = s.motion0;
  potential0_ = s.potential0;
  energy_floor_ = s.energy_floor;
  baseline_taken_ = s.baseline_taken;
  integrator_->passes() = s.passes;
  builds_before_ = s.neighbor_builds - contacts_.builds();
  guards_ = s.guards;
}

RunState Simulation::run_state() const {
  RunState s;
  s.time = time_;
  s.step = step_;
  s.dt = dt_;
  s.skin = rebuilds_.skin();
  s.halo_width = halo_width_;
  s.rank_ledger = ledger_;
  s.baseline_taken = baseline_taken_;
  s.balance0 = balance0_;
  s.motion0 = motion0_;
  s.potential0 = potential0_;
  s.energy_floor = energy_floor_;
  s.passes = integrator_->passes();
  s.neighbor_builds = neighbor_builds();
  s.guards = guards_;
  if (grinding_) s.grinding = grinding_->state();
  s.mill_samples = mill_window_.samples();
  if (spectra_) {
    s.spectra_counts = spectra_->counts();
    s.spectra_energies = spectra_->energies();
  }
  return s;
}

// The energy balance as the first step starts (after whatever the caller set by hand), and
// the energy scale below which a balance error does not count: each particle lifted by its
// radius, sum m |g| r (a resting pile's chatter is not a blow-up).
void Simulation::take_energy_baseline() {
  const SeriesRow r = diagnostics();
  motion0_ = r.kinetic_energy + r.rotational_energy + r.elastic_energy;
  potential0_ = r.potential_energy;
  balance0_ = energy_balance(r);
  const double g = norm(scene_.run.gravity);
  double floor = 0.0;
  for (std::size_t k = 0; k < particles_.n_owned(); ++k)
    floor += particles_.mass[k] * g * particles_.radius[k];
  energy_floor_ = domain_->sum(floor);
  baseline_taken_ = true;
}

void Simulation::choose_dt() {
  if (scene_.run.dt_auto || scene_.run.dt <= 0.0) {
    dt_ = scales_.safe_dt;
    return;
  }
  dt_ = scene_.run.dt;
  if (dt_ > scales_.limit_dt && !scene_.run.allow_unsafe_dt) {
    std::ostringstream o;
    o << (scene_.run.dt_where.empty() ? scene_.deck_path : scene_.run.dt_where)
      << ": error: run.dt = " << dt_ << " s is unsafe: it exceeds half of "
      << "the smallest Rayleigh time (" << format_seconds(scales_.rayleigh)
      << ") or Hertz contact time (" << format_seconds(scales_.hertz) << " at "
      << scales_.impact_speed << " m/s); the safe dt is " << scales_.safe_dt
      << " s (dt = \"auto\"); set run.allow_unsafe_dt = true to run anyway";
    throw InputError(o.str());
  }
}

// One step: the integrator's stages, then its round's verdict. The backup is taken at the same
// steps on every rank, and after every rebuild so that it holds the particles this rank owns
// now (a rebuild may migrate them).
void Simulation::step(bool end_observed) {
  if (!baseline_taken_) take_energy_baseline();
  // What reads the state at this step's end: the caller, the energy check, the backup; the last
  // step of the run (the check below, on the same figures); the ore models when they change the
  // population (the integrator asks them, population_changes). A step that rebuilds is backed up
  // too: the integrator does not run ahead after a rebuild.
  integrator_->allow_run_ahead(may_run_ahead(step_ + 1, end_observed));
  population_planned_ = false;
  const StepOutcome outcome = integrator_->step(*this);
  after_step(outcome, integrator_->ran_ahead());
}

void Simulation::after_step(const StepOutcome& outcome, bool ran_ahead) {
  ++step_;
  steps_run_ahead_ += ran_ahead ? 1 : 0;
  if (outcome.unstable) report_unstable(outcome);
  if (grinding_) population_step();
  if (step_ % kEnergyCheckSteps == 0 || time_ + 0.5 * dt_ >= scene_.run.duration) check_energy();
  if (step_ % kBackupSteps == 0 || builds_at_backup_ != contacts_.builds()) {
    backup_.save(particles_, time_, step_);
    builds_at_backup_ = contacts_.builds();
  }
}

bool Simulation::may_run_ahead(std::int64_t k, bool end_observed) const {
  const bool last = static_cast<double>(k) * dt_ + 0.5 * dt_ >= scene_.run.duration;
  return run_ahead_ && !end_observed && !last && k % kEnergyCheckSteps != 0 &&
         k % kBackupSteps != 0;
}

// Velocity Verlet plans the population step within the step (population_changes), the
// iterative scheme here.
bool Simulation::population_changes() {
  if (!grinding_) return false;
  population_planned_ = true;
  return grinding_->plan(time_, step_ + 1, particles_, contacts_, *domain_, /*evaluated=*/true);
}

void Simulation::population_step() {
  if (!population_planned_)  // reset at the start of every step
    grinding_->plan(time_, step_, particles_, contacts_, *domain_, /*evaluated=*/false);
  // The energy before the change, taken only in a step that changes the store (most do not).
  double before = 0.0;
  const double fed = ledger_.fed, discharged = ledger_.discharged;
  if (!grinding_->apply(time_, particles_, contacts_, *domain_, ledger_,
                        [&] { before = local_energy(); }))
    return;
  domain_->population_changed(domain_->sum(static_cast<std::int64_t>(particles_.n_owned())));
  rebuild();
  grinding_->exclude_births(contacts_);
  refresh_forces();
  integrator_->after_population_change();
  // Fragments keep the parents' mass and momentum and lose kinetic energy (their spin inertia
  // is smaller); the springs of the parents' and the product's contacts and of contacts
  // excluded at birth are gone: all of it is booked as dissipated, so the balance holds.
  ledger_.dissipated +=
      before - local_energy() + (ledger_.fed - fed) - (ledger_.discharged - discharged);
  backup_.save(particles_, time_, step_);
  builds_at_backup_ = contacts_.builds();
}

double Simulation::local_energy() const {
  const ParticleStore& p = particles_;
  double e = contacts_.totals().elastic;
  for (std::size_t k = 0; k < p.n_owned(); ++k) e += mechanical_energy(p, k, scene_.run.gravity);
  return e;
}

void Simulation::run_until(double t_end) {
  // The loop's own test for the next step's end, on the time it will set (advance_clock).
  while (time_ + 0.5 * dt_ < t_end)
    step(/*end_observed=*/static_cast<double>(step_ + 1) * dt_ + 0.5 * dt_ >= t_end);
}

// ---------------------------------------------------------------------------------------------
// The stages an integrator calls

void Simulation::advance_clock() {
  time_ = static_cast<double>(step_ + 1) * dt_;
  walls_.update(time_);
}

void Simulation::rebuild() {
  if (step_ > 0) check_contained();
  const bool sorted = build_lists(/*migrate=*/true);
  // The lists just built may show that the store should be sorted (at the first build, before
  // any list, nothing was known): then at once, and the lists built again (collective: a rank
  // that need not sort builds again all the same).
  if (!sorted && domain_->any(sort_policy_.due(particles_.n_owned()))) build_lists(false);
  if (domain_->size() > 1) {
    domain_->report_work(contacts_.particle_work(particles_.n_owned()));
    integrator_->after_rebuild(particles_.n_owned());
  }
  rebuilds_.record(particles_, walls_, time_);
}

// Migration (parallel, if asked), the storage order, the ghosts, then the lists; true if the
// store was sorted.
bool Simulation::build_lists(bool migrate) {
  bool sorted = false;
  if (domain_->size() > 1) {
    // Particles that left this rank's region move to their owner with their contact
    // histories; then a new ghost set; the lists take their histories from the records.
    HistoryRecords records = contacts_.records();
    if (migrate) domain_->migrate(particles_, records);
    sorted = sort_particles();
    domain_->exchange_halo(particles_);
    contacts_.adopt(records);
  } else {
    sorted = sort_particles();
  }
  contacts_.build(particles_, walls_, rebuilds_.skin());
  sort_policy_.built(contacts_.far_fraction(), sorted);
  return sorted;
}

// The owned particles in Hilbert order of cells about one particle wide, when it pays
// (core/fast/spatial_order.hpp). Their lists are rebuilt next, so nothing indexed by the old order
// survives: the histories are keyed by ids, every per-particle quantity is a registered field.
bool Simulation::sort_particles() {
  const std::size_t n = particles_.n_owned();
  if (!sort_policy_.due(n)) return false;
  double area = 0.0;
  for (std::size_t k = 0; k < n; ++k) area += particles_.radius[k] * particles_.radius[k];
  const double cell = 2.0 * std::sqrt(area / static_cast<double>(n));  // twice the rms radius
  particles_.permute(hilbert_order(particles_, cell));
  return true;
}

// A particle whose centre is beyond the drum's circle (the polygon's vertices lie on it) has
// left the drum through its shell and will never come back: the run is unstable (exit 3), with
// the particle named alike on every rank. Checked at every rebuild (every rank rebuilds at the
// same step; a particle cannot get far between rebuilds, which the skin bounds).
void Simulation::check_contained() {
  if (!walls_.has_drum()) return;
  const Vec2 c = scene_.drum.center;
  const double reach2 = scene_.drum.radius * scene_.drum.radius;
  double escaped = -1.0, distance = 0.0;
  for (std::size_t k = 0; k < particles_.n_owned(); ++k) {
    const double d2 = norm2(particles_.pos[k] - c);
    if (d2 > reach2 && static_cast<double>(particles_.id[k]) > escaped) {
      escaped = static_cast<double>(particles_.id[k]);
      distance = std::sqrt(d2);
    }
  }
  const double id = domain_->max(escaped);
  if (id < 0.0) return;
  distance = domain_->max(escaped == id ? distance : 0.0);
  std::ostringstream o;
  o << "the run became unstable at step " << std::llround(time_ / dt_) << " (t = " << time_
    << " s): particle " << static_cast<std::int64_t>(id) << " left the drum: its centre is "
    << distance << " m from the drum's centre, beyond the shell at " << scene_.drum.radius
    << " m; dt = " << dt_ << " s, the safe dt is " << scales_.safe_dt << " s";
  throw UnstableError(o.str(), step_, time_);
}

void Simulation::refresh_ghosts() { domain_->refresh_ghosts(particles_, ghost_fields_); }

void Simulation::contact_forces(double dt, bool owned_cleared) {
  Vec2* f = particles_.force.data();
  double* tq = particles_.torque.data();
  Vec2* e = particles_.elastic_force.data();
  for (std::size_t k = owned_cleared ? particles_.n_owned() : 0; k < particles_.size(); ++k) {
    f[k] = {};
    tq[k] = 0.0;
    e[k] = {};
  }
  if (Field<double>* et = particles_.elastic_torque())
    std::fill(et->data(), et->data() + particles_.size(), 0.0);
  contacts_.evaluate(particles_, walls_, dt);
}

void Simulation::commit(double dt, double late_loss) {
  if (spectra_) {  // the spectra's tracker keeps the trial slots (Kernel::kInPlace)
    const PairList& pl = contacts_.pairs();
    const WallPairList& wl = contacts_.wall_pairs();
    spectra_->book_ended(particles_, walls_, pl.history.data(), pl.trial.data(),
                         {pl.i.data(), pl.size()}, {pl.j.data(), pl.size()}, wl.history.data(),
                         wl.trial.data(), {wl.particle.data(), wl.size()},
                         {wl.element.data(), wl.size()}, pl.width,
                         contacts_.history_offset("peak_energy"));
  }
  contacts_.commit();
  ledger_.book(contacts_.totals(), dt, late_loss, walls_.drum_omega());
}

void Simulation::refresh_forces() {
  contact_forces(0.0, false);
  accelerations(particles_, scene_.run.gravity);
  contacts_.commit();
}

// ---------------------------------------------------------------------------------------------
// A step went unstable on some rank: every rank builds the same message (the details take a
// few more collectives, only now) and throws, or records it (run.guards = "warn").
void Simulation::report_unstable(const StepOutcome& outcome) {
  const bool finite = !domain_->any(!std::isfinite(outcome.checksum));
  Guard guard = Guard::kFinite;
  std::ostringstream o;
  o << "the run became unstable at step " << step_ << " (t = " << time_
    << " s): " << unstable_reason(outcome, finite, guard) << "; dt = " << dt_
    << " s, the safe dt is " << scales_.safe_dt << " s";
  if (guard_may_warn(guard) && scene_.run.guards_warn) return guard_fired(guard, o.str());
  const std::int64_t failed_step = step_;
  const double failed_time = time_;
  if (!finite) {
    backup_.restore(particles_, time_, step_);
    integrator_->state_replaced();
    o << "; the last snapshot holds the last finite state (t = " << time_ << " s)";
  } else {
    integrator_->step_back(particles_);  // a step that ran ahead: its end state, to the last bits
  }
  throw UnstableError(o.str(), failed_step, failed_time);
}

std::string Simulation::unstable_reason(const StepOutcome& outcome, bool finite, Guard& guard) {
  const EvaluationTotals& totals = contacts_.totals();
  const double max_overlap = domain_->max(totals.max_overlap);
  // The particle named alike on every rank (ids are below 2^53): the one on the rank whose
  // figure is the global one.
  const auto agreed_id = [&](bool mine, std::int64_t id) {
    return static_cast<std::int64_t>(domain_->max(mine ? static_cast<double>(id) : -2.0));
  };
  std::ostringstream o;
  if (!finite) {
    guard = Guard::kFinite;
    o << "non-finite positions or accelerations";
    // An unstable run's message names the particles (docs/architecture.md, exit 3): name this
    // rank's first few.
    int named = 0;
    const ParticleStore& p = particles_;
    for (std::size_t k = 0; k < p.n_owned() && named < 5; ++k) {
      const Vec2 a = p.acc[k];
      if (std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(p.alpha[k]) &&
          std::isfinite(p.pos[k].x) && std::isfinite(p.pos[k].y))
        continue;
      o << (named++ ? ", particle " : " of particle ") << p.id[k];
    }
  } else if (const double motion = domain_->max(outcome.motion); motion > kMaxStepMotion) {
    guard = Guard::kMotion;
    o << "particle " << agreed_id(outcome.motion == motion, outcome.motion_id) << " moves "
      << motion << " times its radius in one step (at most " << kMaxStepMotion
      << "): bodies could pass through each other";
  } else if (max_overlap > kMaxOverlapRatio) {
    guard = Guard::kOverlap;
    const bool mine = totals.max_overlap == max_overlap;
    const std::int64_t worst_b = agreed_id(mine, totals.worst_b);
    o << "overlap " << max_overlap << " of a radius between particle "
      << agreed_id(mine, totals.worst_a);
    if (worst_b >= 0)
      o << " and particle " << worst_b;
    else
      o << " and a wall";
  } else {
    guard = Guard::kPasses;
    const double last = outcome.shift_last;
    o << "the iterative passes do not settle: the last two passes moved the end position of "
      << "particle " << agreed_id(outcome.shift_mine == last, outcome.shift_id) << " by "
      << outcome.shift_first << " and " << last << " of its radius (at most "
      << IterativeIntegrator::kMaxUnsettledShift
      << "); the passes converge only while omega_contact dt < sqrt(6)";
  }
  return o.str();
}

void Simulation::guard_fired(Guard guard, const std::string& message) {
  const std::string kind = guard_name(guard);
  for (GuardRecord& g : guards_)
    if (g.kind == kind) {
      ++g.count;
      return;
    }
  guards_.push_back({kind, 1, message});
}

// The balance kinetic + rotational + potential + elastic + dissipated - drive work is constant
// up to the integrator's error. Grown beyond the tolerance, the run created energy.
void Simulation::check_energy() {
  const SeriesRow r = diagnostics();
  const double created = energy_balance(r) - balance0_;
  const double through =
      energy_floor_ + motion0_ + std::abs(r.drive_work) + std::abs(r.dissipated_energy) +
      std::abs(r.potential_energy - potential0_) + r.fed_energy + r.discharged_energy;
  if (!(created > kEnergyCreatedTolerance * through)) return;
  std::ostringstream o;
  o << "the run became unstable at step " << step_ << " (t = " << time_
    << " s): energy was created: " << created << " J since the start, " << created / through
    << " of the " << through << " J that went through the system (at most "
    << kEnergyCreatedTolerance << "); dt = " << dt_ << " s, the safe dt is " << scales_.safe_dt
    << " s";
  if (scene_.run.guards_warn && std::isfinite(created)) return guard_fired(Guard::kEnergy, o.str());
  throw UnstableError(o.str(), step_, time_);
}

// ---------------------------------------------------------------------------------------------
// Diagnostics

SeriesRow Simulation::diagnostics() const {
  const ParticleStore& p = particles_;
  const Vec2 gravity = scene_.run.gravity;
  SeriesRow row;
  row.time = time_;
  row.step = step_;
  double ke = 0.0, re = 0.0, pe = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    ke += 0.5 * p.mass[k] * norm2(p.vel[k]);
    re += rotational_energy(p, k);
    pe -= p.mass[k] * dot(gravity, p.pos[k]);
  }
  const EvaluationTotals& totals = contacts_.totals();
  row.particles = domain_->sum(static_cast<std::int64_t>(p.n_owned()));
  row.contacts = domain_->sum(totals.contacts);
  row.kinetic_energy = domain_->sum(ke);
  row.rotational_energy = domain_->sum(re);
  row.potential_energy = domain_->sum(pe);
  row.elastic_energy = domain_->sum(totals.elastic);
  row.dissipated_energy = domain_->sum(ledger_.dissipated);
  row.drum_torque = domain_->sum(totals.drum_torque);
  row.drum_power = row.drum_torque * walls_.drum_omega();
  row.drive_work = domain_->sum(ledger_.drive_work);
  row.lifter_torque = domain_->sum(totals.lifter_torque);
  row.shell_torque = row.drum_torque - row.lifter_torque;
  row.shell_power = row.shell_torque * walls_.drum_omega();
  row.lifter_power = row.lifter_torque * walls_.drum_omega();
  row.drum_work = domain_->sum(ledger_.drum_work);
  row.passes = integrator_->passes().mean_since_row();
  if (grinding_) grinding_row(row);
  return row;
}

SeriesRow Simulation::record_row() {
  SeriesRow row = diagnostics();
  if (!scene_.drum.present) return row;
  clock_contacts(particles_, time_, scene_.run.gravity);
  const ChargeShape c =
      measure_charge(particles_, walls_, scene_.drum, *domain_, time_, scene_.run.gravity, false);
  row.com_x = c.com_x;
  row.com_y = c.com_y;
  row.airborne_fraction = c.airborne_fraction;
  row.corotating_fraction = c.corotating_fraction;
  const double sense = scene_.drum.speed < 0.0 ? -1.0 : 1.0;
  MillSample sample{row.time, row.drum_work, c.airborne_fraction, c.corotating_fraction};
  sample.charge_angle = std::atan2(sense * c.com_x, -c.com_y) * 180.0 / std::numbers::pi;
  sample.shell = c.shell;
  mill_window_.add(sample);
  // Toe and shoulder of the window's time-averaged shell profile, this row included; the
  // surface across their chord.
  const ShellArc arc = mill_window_.arc();
  row.toe_angle = arc.toe;
  row.shoulder_angle = arc.shoulder;
  row.shell_arc = arc.arc;
  row.surface_angle = measure_surface_angle(particles_, scene_.drum, *domain_, arc.toe,
                                            arc.shoulder, scene_.run.gravity);
  mill_window_.set_last_shape(arc.toe, arc.shoulder, row.surface_angle);
  const WindowSummary w = mill_window_.summary();
  row.power_avg = w.span > 0.0 ? w.power : row.drum_power;
  row.regime = regime_name(w.regime);
  return row;
}

void Simulation::grinding_row(SeriesRow& row) const {
  const GrindingTotals& g = grinding_->totals();
  row.breakages = g.breakages;
  row.fragments = g.fragments;
  row.fed_count = g.fed_count;
  row.fed_mass = g.fed_mass;
  row.discharged_count = g.discharged_count;
  row.discharged_mass = g.discharged_mass;
  const int ore = grinding_->ore_material();
  double mill = 0.0, ore_mass = 0.0;
  for (std::size_t k = 0; k < particles_.n_owned(); ++k) {
    mill += particles_.mass[k];
    if (particles_.material[k] == ore) ore_mass += particles_.mass[k];
  }
  row.mill_mass = domain_->sum(mill);
  row.ore_mass = domain_->sum(ore_mass);
  row.fed_energy = domain_->sum(ledger_.fed);
  row.discharged_energy = domain_->sum(ledger_.discharged);
}

void Simulation::reset_pass_window() {
  integrator_->passes().since_row = 0;
  integrator_->passes().steps_since_row = 0;
}

}  // namespace dem2d
