// Grinding: ore breakage, feed and discharge (docs/models.md, "Grinding").
//
// After every committed step of an ore scene (one with [breakage], [feed] or [sieve]):
//   tests     every contact whose strain energy has fallen below its peak, with a peak above
//             the level already tested, is one loading event, tested once: each breakable body
//             of it takes its share of the energy (by compliance, or all of it: the thesis), and
//             is tested with its share s: E = s peak - max(s tested, E_min) (thesis model:
//             E_t = damage + E, P = 1 - exp(-S E_t), else damage += E; vogel-peukert: the
//             specific energy W = E / m with the threshold xw_min / d, P = 1 - exp(-f_mat d W),
//             else damage += W). Tests run on the owner, in the order of (particle id,
//             partner), with counter-based draws keyed by (particle id, partner, step): the same
//             on any rank count. Before [breakage] start, contacts past their peak are marked
//             tested and do no damage;
//   breaks    the parent is replaced by its fragments: n equal spheres (thesis), or the
//             progeny of the t10 law down to fines_diameter, the rest fines that leave with the
//             product at once; fragments sit inside the parent's circle, with the parent's
//             rigid-body velocity at their centre and its spin (core/mill/breakage_laws.hpp):
//             mass and momentum are conserved, kinetic energy does not grow. Ids: the parents
//             of the step, sorted by id over all ranks, take the next ids in turn;
//   discharge a particle of the sieve's material narrower than the aperture leaves as product
//             where the type says (box, grate ring, or the finest first above the hold-up);
//   feed      a particle of the feed's radius law at the feed point, or where the charge is
//             thinnest: of a fixed set of candidate points inside the drum and outside the
//             discharge zone, the one farthest from every particle surface and the shell;
//             placed on the rank that owns that point, when nothing is within its radius.
// A step that changed the population tells the simulation, which rebuilds the lists (the new
// particles migrate like any other), marks every listed contact of a newborn particle as
// excluded (the first force evaluation keeps only those that overlap:
// core/contact/contact_models.hpp, TrackBreakage) and books the energy the change released.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "core/base/scene.hpp"
#include "core/contact/contact_engine.hpp"
#include "core/mill/breakage_laws.hpp"
#include "core/mill/size_classes.hpp"
#include "core/shape/particles.hpp"
#include "core/step/domain.hpp"
#include "core/step/energy_ledger.hpp"

namespace dem2d {

// Counts and masses since the start (the same on every rank).
struct GrindingTotals {
  std::int64_t breakages = 0, fragments = 0, fed_count = 0, discharged_count = 0;
  double fed_mass = 0.0, discharged_mass = 0.0;  // discharged: the particles and the fines
  double fines_mass = 0.0;                       // the fines of the breaks (left with the product)
};

// The size distributions by mass: the ore at the start, the ore fed, the product (discharged
// particles and fines: this rank's share, summed over ranks by product_sizes()).
struct GrindingSizes {
  SizeMasses initial, fed, product;
};

// One breakage (breakages.csv) and one discharged particle (product.csv).
struct BreakageRecord {
  double time = 0.0;
  std::int64_t parent = 0;
  double radius = 0.0, energy = 0.0;  // the parent's share of the breaking loading's peak (J)
  int fragments = 0;
  std::int64_t first_id = 0;                 // the fragments' ids: first_id, first_id + 1, ...
  double mass = 0.0, specific_energy = 0.0;  // kg; J/kg: energy / mass
  double t10 = 0.0;                          // % of the progeny's mass below a tenth of 2 radius
  double fines_mass = 0.0;                   // kg
};
// One fragment of a break (fragments.csv).
struct FragmentRecord {
  double time = 0.0;
  std::int64_t parent = 0, id = 0;
  double radius = 0.0, mass = 0.0;
};
struct ProductRecord {
  double time = 0.0;
  std::int64_t id = 0;
  double radius = 0.0, mass = 0.0;
};

// What a checkpoint keeps of the grinding (the rest is the scene's): the id counter, the feed's
// wait, the counts, and this rank's share of the energies fed and discharged.
struct GrindingState {
  std::int64_t next_id = 0, births_from = -1;
  double next_feed_try = 0.0;
  GrindingTotals totals;
  GrindingSizes sizes;  // product: this rank's share
};

// A size distribution summed over ranks, in place (collective; exact).
void combine(SizeMasses& m, const Domain& domain);

class Grinding {
 public:
  // The next free id is one above the largest id of the particles placed (all ranks).
  // Collective (the ore at the start is summed over ranks).
  Grinding(const Scene& scene, const ParticleStore& p, const Domain& domain);

  // The population step of step `step`, ending at `time`, in two parts. plan: the tests run,
  // the breaks and the discharges decided, the feed's turn known, from the contact histories
  // of the step's evaluation (`evaluated`: as the force loop wrote them, before the commit;
  // else the committed ones) and the positions at the step's end; nothing is changed
  // (collective). Returns true, on every rank alike, when the population will change: the
  // step's end state is then read. apply, after the committed step: the plan carried out (the
  // contacts tested, damage, breaks, product, feed; collective). Returns true, on every rank
  // alike, when the population changed; the caller then rebuilds and calls exclude_births().
  // `before_change` is called just before the store first changes (not at all in a step that
  // changes nothing). The energy of the particles fed and discharged goes into `ledger`.
  bool plan(double time, std::int64_t step, const ParticleStore& p, const ContactEngine& contacts,
            Domain& domain, bool evaluated);
  bool apply(double time, ParticleStore& p, ContactEngine& contacts, Domain& domain,
             EnergyLedger& ledger, const std::function<void()>& before_change);
  // After the rebuild that follows a change: every listed contact of a particle born in it is
  // excluded (the next evaluation keeps the overlapping ones).
  void exclude_births(ContactEngine& contacts) const;

  const GrindingTotals& totals() const { return totals_; }
  // This rank's records since the last call (the breakages of every rank on rank 0 only when
  // the caller gathers them; here: this rank's own).
  std::vector<BreakageRecord> take_breakages();
  std::vector<ProductRecord> take_product();
  std::vector<FragmentRecord> take_fragments();
  std::int64_t next_id() const { return next_id_; }
  // Checkpoints: the state after a step (records already taken), and the same put back (the
  // product's sizes as a checkpoint holds them: summed, on rank 0).
  GrindingState state() const { return {next_id_, births_from_, next_feed_try_, totals_, sizes_}; }
  void restore(const GrindingState& s) {
    next_id_ = s.next_id;
    births_from_ = s.births_from;
    next_feed_try_ = s.next_feed_try;
    totals_ = s.totals;
    sizes_ = s.sizes;
  }
  // The size distributions (collective: the product and the mill's ore summed over ranks).
  GrindingSizes sizes(const Domain& domain) const;
  SizeMasses mill_sizes(const ParticleStore& p, const Domain& domain) const;
  // The ore: the breakage material, else the feed's, else the sieve's.
  int ore_material() const {
    return break_material_ >= 0 ? break_material_
                                : (feed_material_ >= 0 ? feed_material_ : sieve_material_);
  }

 private:
  struct Test {
    std::int64_t id, partner;  // partner: particle id, or -1 - wall element
    std::size_t index;         // local index of the particle
    double peak, tested;       // the particle's share (J)
  };
  struct Broken {
    std::size_t index;
    double energy;  // the share's peak (J)
  };
  // What plan decided for apply.
  struct Plan {
    std::vector<std::int32_t> tested_pairs, tested_walls;  // list entries: tested := peak
    std::size_t tracker_slot = 0;                          // the histories' "peak_energy" slot
    std::vector<std::pair<std::size_t, double>> damage;    // particles tested, not broken
    std::vector<Broken> broken;
    std::vector<char> remove;  // 1: sieved
    std::vector<ProductRecord> product;
    std::int64_t sieved = 0, changes = 0;  // changes: breaks and discharges on every rank
    double sieved_mass = 0.0;
    bool feed = false;
  };
  // A broken superellipse's form: aspect b / a <= 1, exponent, the angle of its long axis.
  struct ParentShape {
    double aspect, exponent, angle;
  };
  // radius: the size radius (a superellipse's volume-equivalent radius); shape: a
  // superellipse's other than a round one (a disc's fragments are discs).
  struct Parent {
    std::int64_t id;
    std::int32_t material;
    double radius, energy;
    Vec2 x, v;
    double omega;
    std::optional<ParentShape> shape{};
  };
  void collect_tests(const ParticleStore& p, const ContactEngine& contacts, bool evaluated,
                     std::vector<Test>& out);
  void run_tests(const std::vector<Test>& tests, std::int64_t step, const ParticleStore& p);
  int fragment_count(std::int64_t parent) const;
  void break_parents(double time, const std::vector<Parent>& parents, ParticleStore& p,
                     Domain& domain, EnergyLedger& ledger);
  double bear(double time, const Parent& q, int n, std::int64_t first, const Progeny& g,
              ParticleStore& p, EnergyLedger& ledger);
  double share(int material, int partner_material) const;
  bool in_zone(Vec2 x) const;  // the box or the grate ring
  void discharge(double time, const ParticleStore& p, Domain& domain);
  bool feed(double time, ParticleStore& p, Domain& domain, EnergyLedger& ledger);
  bool feed_due(double time) const;
  double feed_radius() const;

  const Scene& scene_;
  int break_material_ = -1, feed_material_ = -1, sieve_material_ = -1;
  std::vector<double> compliance_;     // by material: (1 - nu^2) / E
  std::vector<int> element_material_;  // by wall element
  double grate_inner_ = 0.0;           // m from the drum centre: the grate ring begins there
  std::int64_t next_id_ = 0;
  std::int64_t births_from_ = -1;  // ids >= this were born in the last change
  double next_feed_try_ = 0.0;     // s: a blocked feed waits until then
  std::vector<Vec2> candidates_;   // feed: where the charge may be thinnest
  double feed_reach_ = 0.0;        // m from the drum centre clear of shell and lifters
  GrindingTotals totals_;
  std::vector<BreakageRecord> breakages_;
  std::vector<ProductRecord> product_;
  std::vector<FragmentRecord> fragment_log_;
  GrindingSizes sizes_;
  Plan plan_;
};

}  // namespace dem2d
