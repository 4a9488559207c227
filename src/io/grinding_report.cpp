#include "io/grinding_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>

#include "core/base/errors.hpp"
#include "io/output_dir.hpp"

namespace dem2d {

namespace {

constexpr double kJoulesPerKgPerKwhPerT = 3600.0;  // 1 kWh/t = 3.6 MJ / 1000 kg

// The feed: the ore fed, or (a batch mill) the ore at the start.
const SizeMasses& feed_of(const GrindingReport& r) {
  return r.sizes.fed.empty() ? r.sizes.initial : r.sizes.fed;
}

}  // namespace

GrindingReport grinding_report(const Simulation& sim, const Domain& domain) {
  GrindingReport r;
  const Grinding* g = sim.grinding();
  if (g == nullptr) return r;
  r.sizes = g->sizes(domain);
  r.mill = g->mill_sizes(sim.particles(), domain);
  r.drum_work = domain.sum(sim.run_state().rank_ledger.drum_work);
  r.product_mass = g->totals().discharged_mass;
  r.fines_mass = g->totals().fines_mass;
  r.aperture = sim.scene().sieve.present ? sim.scene().sieve.aperture : 0.0;
  r.time = sim.time();
  return r;
}

JsonObject grinding_json(const GrindingReport& r) {
  const SizeMasses& feed = feed_of(r);
  const double f80 = feed.passing_size(80.0), p80 = r.sizes.product.passing_size(80.0);
  const double kwh = r.drum_work / kJoulesPerKgPerKwhPerT;  // J -> kWh/t per kg
  // Ore ground below the aperture: what is below it now (mill and product) less what came in
  // below it (at the start and fed).
  double ground = 0.0;
  if (r.aperture > 0.0)
    ground = r.mill.mass_below(r.aperture) + r.sizes.product.mass_below(r.aperture) -
             r.sizes.initial.mass_below(r.aperture) - r.sizes.fed.mass_below(r.aperture);
  JsonObject j;
  j.add_string("feed", r.sizes.fed.empty() ? "the ore at the start" : "the ore fed")
      .add_number("f80_m", f80, "%.6g")
      .add_number("p80_m", p80, "%.6g")
      .add_number("mill_p80_m", r.mill.passing_size(80.0), "%.6g")
      .add_number("reduction_ratio", f80 / p80, "%.6g")
      .add_number("product_mass_kg", r.product_mass, "%.10g")
      .add_number("fines_mass_kg", r.fines_mass, "%.10g")
      .add_number("ground_below_aperture_kg", ground, "%.10g")
      .add_number("drum_work_J", r.drum_work, "%.10g")
      .add_number("specific_energy_kwh_per_t", r.product_mass > 0 ? kwh / r.product_mass : NAN,
                  "%.6g")
      .add_number("specific_energy_below_aperture_kwh_per_t", ground > 0 ? kwh / ground : NAN,
                  "%.6g")
      .add_string("specific_energy_note", kSliceCaveat);
  return j;
}

std::string sizes_csv_text(const GrindingReport& r) {
  const SizeMasses* all[] = {&r.sizes.initial, &r.sizes.fed, &r.sizes.product, &r.mill};
  int lo = SizeMasses::kClasses, hi = -1;
  for (const SizeMasses* m : all)
    for (int k = 0; k < SizeMasses::kClasses; ++k)
      if (m->units()[static_cast<std::size_t>(k)] != 0) {
        lo = std::min(lo, k);
        hi = std::max(hi, k);
      }
  std::string text =
      "diameter,initial_mass,fed_mass,product_mass,mill_mass,initial_passing,fed_passing,"
      "product_passing,mill_passing\n";
  for (int k = lo; k <= std::min(hi, SizeMasses::kEdges - 1); ++k) {
    fmt::format_to(std::back_inserter(text), "{:.6g}", SizeMasses::edge(k));
    for (const SizeMasses* m : all) fmt::format_to(std::back_inserter(text), ",{:.17g}", m->kg(k));
    for (const SizeMasses* m : all)
      fmt::format_to(std::back_inserter(text), ",{:.10g}", m->passing(k));
    text += "\n";
  }
  return text;
}

void write_sizes_csv(const std::string& directory, const GrindingReport& r) {
  const std::string path = directory + "/" + kSizesFile, temporary = path + ".tmp";
  const std::string text = sizes_csv_text(r);
  std::FILE* f = std::fopen(temporary.c_str(), "wb");
  bool ok = f != nullptr && std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int e = errno;
  if (f != nullptr && std::fclose(f) != 0) ok = false;
  if (!ok || std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw IoError(fmt::format("cannot write {}: {}", path, std::strerror(e != 0 ? e : errno)));
  }
}

}  // namespace dem2d
