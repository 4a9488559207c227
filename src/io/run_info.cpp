#include "io/run_info.hpp"

#include <algorithm>
#include <numbers>

#include "core/mill/grinding.hpp"
#include "core/mill/mill_analytics.hpp"
#include "core/shape/superellipse_shape.hpp"
#include "io/grinding_report.hpp"
#include "io/text.hpp"

namespace dem2d {

namespace {

// Collective: run.json's "mill" object: the mill's numbers, and the averages and regime over
// the last analysis window.
JsonObject mill_json(const Simulation& sim, const MpiDomain& domain) {
  const MillNumbers m = mill_numbers(sim.scene(), charge_sizes(sim.particles(), domain));
  const WindowSummary w = sim.mill_summary();
  const std::pair<const char*, double> items[] = {
      {"critical_speed_rad_s", m.critical_speed},
      {"critical_speed_rpm", m.critical_speed * 30.0 / std::numbers::pi},
      {"critical_speed_with_fill_rad_s", m.critical_speed_with_fill},
      {"speed_fraction_of_critical", m.speed_fraction},
      {"froude_number", m.froude},
      {"fill_fraction", m.fill_fraction},
      {"bed_filling", m.bed_filling},
      {"bed_packing", kBedPacking},
      {"slice_thickness_m", m.slice_thickness},
      {"window_s", w.span},
      {"power_avg_W", w.power},
      {"power_per_metre_W", m.slice_thickness > 0 ? w.power / m.slice_thickness : 0.0},
      {"airborne_fraction", w.airborne},
      {"corotating_fraction", w.corotating},
      {"toe_angle_deg", w.toe},
      {"shoulder_angle_deg", w.shoulder},
      {"shell_arc_deg", w.shell_arc},
      {"surface_angle_deg", w.surface_angle},
      {"charge_angle_deg", w.charge_angle},
      {"charge_angle_std_deg", w.charge_angle_std}};
  JsonObject mill;
  mill.add_string("regime", regime_name(w.regime));
  for (const auto& [key, value] : items) mill.add_number(key, value, "%.10g");
  return mill;
}

// Collective: the mass of every particle in the mill (balls and ore), kg per slice.
double charge_mass(const Simulation& sim, const MpiDomain& domain) {
  const ParticleStore& p = sim.particles();
  double mass = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) mass += p.mass[k];
  return domain.sum(mass);
}

// run.json's "ore" object: what was fed, broken and let out since the start, and the product
// rate (the mass the sieve let out over the simulated time; 0 without a [sieve], which
// `sieve` says).
JsonObject ore_json(const Simulation& sim, const Scene& scene) {
  JsonObject ore;
  const Grinding* g = sim.grinding();
  const GrindingTotals t = g ? g->totals() : GrindingTotals{};
  const double hours = sim.time() / 3600.0;
  ore.add("sieve", scene.sieve.present ? "true" : "false")
      .add_integer("fed_count", t.fed_count)
      .add_number("fed_mass_kg", t.fed_mass, "%.10g")
      .add_integer("breakages", t.breakages)
      .add_integer("fragments", t.fragments)
      .add_integer("discharged_count", t.discharged_count)
      .add_number("discharged_mass_kg", t.discharged_mass, "%.10g")
      .add_number("fines_mass_kg", t.fines_mass, "%.10g")
      .add_number("product_rate_kg_s", sim.time() > 0 ? t.discharged_mass / sim.time() : 0.0,
                  "%.10g")
      .add_number("product_rate_t_h", hours > 0 ? t.discharged_mass / 1000.0 / hours : 0.0,
                  "%.10g");
  return ore;
}

// The decomposition: per-rank work (owned particles + listed pairs at the last rebuild),
// ghosts, migrations and time in communication; the imbalance against equal angles.
void add_decomposition(JsonObject& extra, const MpiDomain& domain) {
  const DecompositionStats& ds = domain.stats();
  const RankStats per_rank = domain.gather_rank_stats();
  extra.add("rank_work", json_array(per_rank.work, "%.0f"))
      .add("rank_ghosts", json_array(per_rank.ghosts, "%.0f"))
      .add("rank_comm_seconds", json_array(per_rank.comm_seconds, "%.4g"))
      .add_number("imbalance", ds.imbalance_work, "%.4g")
      .add_number("imbalance_mean", ds.imbalance_mean(), "%.4g")
      .add_number("imbalance_equal_angle", ds.imbalance_equal_angle, "%.4g")
      .add_integer("partitions", ds.partitions)
      .add_string("partition_method", ds.method)
      .add_integer("sectors", domain.partition().n_sectors);
}

// The superellipse's contact solves over every rank's process since its start (a restarted run
// counts from the restart): pair solves (contacts in touch), those from a cold start (a new
// contact), the depth's evaluations per pair solve, the solves that did not converge (they keep
// the last iterate, docs/models.md), the pair solves by their number of depth evaluations (a
// histogram), and the wall solves. Collective.
std::string shape_solves_json(const MpiDomain& domain) {
  const SuperEllipseShape::Stats& st = SuperEllipseShape::stats();
  const std::int64_t pairs = domain.sum(std::int64_t{st.pair_solves});
  const std::int64_t evaluations = domain.sum(std::int64_t{st.pair_iterations});
  JsonObject bins;
  for (int b = 0; b < SuperEllipseShape::kEvaluationBins; ++b)
    bins.add_integer(SuperEllipseShape::kEvaluationBinLabels[b],
                     domain.sum(std::int64_t{st.pair_evaluation_bins[b]}));
  JsonObject o;
  o.add_integer("pair_solves", pairs)
      .add_integer("pair_cold_starts", domain.sum(std::int64_t{st.pair_cold}))
      .add_number("depth_evaluations_per_pair_solve",
                  pairs > 0 ? static_cast<double>(evaluations) / static_cast<double>(pairs) : 0.0,
                  "%.4g")
      .add("depth_evaluations_histogram", bins.inline_text())
      .add_integer("pair_unconverged", domain.sum(std::int64_t{st.pair_unconverged}))
      .add_integer("wall_solves", domain.sum(std::int64_t{st.wall_solves}))
      .add_integer("wall_unconverged", domain.sum(std::int64_t{st.wall_unconverged}));
  return o.inline_text();
}

// The shell's mesh and its response at the last lifters.csv row (rank 0's).
JsonObject shell_json(const LifterOutput& lifters) {
  const Shell& shell = *lifters.shell();
  const ShellResponse& r = lifters.last_response();
  JsonObject o;
  o.add_integer("nodes", static_cast<std::int64_t>(shell.model().mesh().nodes.size()))
      .add_integer("elements", static_cast<std::int64_t>(shell.model().mesh().elements.size()))
      .add_integer("free_dofs", static_cast<std::int64_t>(shell.model().free_dofs().size()))
      .add_number("depth_m", shell.depth())
      .add_integer("last_records", static_cast<std::int64_t>(r.records))
      .add_number("last_load_N_per_m", norm(r.applied))
      .add_number("last_nodal_load_error_N_per_m", norm(r.nodal - r.applied))
      .add_number("last_max_displacement_m", r.max_displacement);
  return o;
}

}  // namespace

RunInfo run_info(const Simulation& sim, const MpiDomain& domain, const Scene& scene,
                 const RunFacts& facts) {
  RunInfo info;
  info.version = DEM2D_VERSION;
  info.ranks = domain.size();
  info.wall_time_s = facts.wall;
  info.steps = sim.step_count();
  info.particle_steps_per_second =
      facts.wall > 0 ? static_cast<double>(facts.particle_steps) / facts.wall : 0.0;
  info.dt = sim.dt();
  JsonObject& extra = info.extra;
  extra.add_integer("particles", facts.particles)
      .add_integer("particles_at_start", facts.particles_at_start)
      .add_integer("particle_steps", facts.particle_steps)
      .add_number("charge_mass_kg", charge_mass(sim, domain), "%.10g");
  if (is_ore_scene(scene)) {
    extra.add("ore", ore_json(sim, scene).inline_text());
    extra.add("grinding", grinding_json(grinding_report(sim, domain)).inline_text());
  }
  extra.add_integer("neighbor_builds", sim.neighbor_builds());
  if (has_shaped_particles(scene)) extra.add("superellipse_contacts", shape_solves_json(domain));
  if (scene.run.integrator == IntegratorKind::kIterative) {
    extra.add_number("mean_passes",
                     static_cast<double>(sim.passes_total()) /
                         static_cast<double>(std::max<std::int64_t>(1, sim.step_count())),
                     "%.6g");
    extra.add_integer("unconverged_steps", sim.unconverged_steps());
  }
  JsonObject guards;
  for (const GuardRecord& g : sim.guard_records()) guards.add_integer(g.kind, g.count);
  extra.add("guards_fired", guards.inline_text());
  add_decomposition(extra, domain);
  if (scene.drum.present) extra.add("mill", mill_json(sim, domain).inline_text());
  if (facts.lifters != nullptr && facts.lifters->shell() != nullptr)
    extra.add("shell", shell_json(*facts.lifters).inline_text());
  extra.add("interrupted", facts.interrupted ? "true" : "false");
  extra.add("restarted_from",
            facts.restarted_from.empty() ? "null" : quoted_string(facts.restarted_from));
  std::string sets;
  for (const std::string& s : facts.overrides)
    sets += (sets.empty() ? "" : ", ") + quoted_string(s);
  extra.add("overrides", "[" + sets + "]");
  std::string warnings;
  for (const std::string& w : facts.warnings)
    warnings += (warnings.empty() ? "" : ", ") + quoted_string(w);
  extra.add("warnings", "[" + warnings + "]");
  return info;
}

}  // namespace dem2d
