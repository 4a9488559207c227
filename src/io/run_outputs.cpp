#include "io/run_outputs.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.hpp"
#include "io/output_dir.hpp"
#include "parallel/comm.hpp"
#include "parallel/ore_records.hpp"

namespace dem2d {

SeriesOutput::SeriesOutput(const Scene& scene, const Simulation& sim, bool resumed) {
  std::string error;
  try {
    file_ = std::make_unique<SeriesWriter>(scene.output.directory + "/" + kSeriesFile,
                                           scene.run.integrator == IntegratorKind::kIterative,
                                           mpi::rank(MPI_COMM_WORLD) == 0, is_ore_scene(scene),
                                           resumed ? sim.step_count() : -1, scene.drum.present);
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
}

void SeriesOutput::write(const SeriesRow& row) {
  std::string error;
  try {
    file_->write(row);
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
}

OreOutput::OreOutput(const Scene& scene, const Simulation& sim, bool resumed) {
  if (!is_ore_scene(scene)) return;
  std::string error;
  try {
    logs_ = std::make_unique<OreLogs>(scene.output.directory, mpi::rank(MPI_COMM_WORLD) == 0,
                                      resumed ? sim.time() : -1.0);
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
}

void OreOutput::write(Simulation& sim) {
  if (!logs_) return;
  OreRecords mine{sim.grinding()->take_breakages(), sim.grinding()->take_product(),
                  sim.grinding()->take_fragments()};
  OreRecords all = gather_ore_records(MPI_COMM_WORLD, mine);
  std::string error;
  try {
    logs_->write(std::move(all.breakages), std::move(all.product), std::move(all.fragments));
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
}

namespace {

// Every rank's records on every rank, in key order (key_before): each rank's block, in that
// order already, travels as [its count, R::kWords words per record] (doubles bit for bit), and
// the blocks are merged pairwise, O(n log ranks). Codec gives kWords, put(record, words) and
// from(const word*).
template <class Codec, class R>
std::vector<R> gather_in_key_order(const std::vector<R>& mine) {
  if (mpi::size(MPI_COMM_WORLD) == 1) return mine;
  std::vector<std::int64_t> words;
  words.reserve(1 + Codec::kWords * mine.size());
  words.push_back(static_cast<std::int64_t>(mine.size()));
  for (const R& c : mine) Codec::put(c, words);
  const std::vector<std::int64_t> all = mpi::all_gather(MPI_COMM_WORLD, words);
  std::vector<R> out;
  std::vector<std::size_t> starts;  // each rank's block in `out`
  for (std::size_t at = 0; at < all.size();) {
    const auto n = static_cast<std::size_t>(all[at++]);
    starts.push_back(out.size());
    for (std::size_t k = 0; k < n; ++k, at += Codec::kWords) out.push_back(Codec::from(&all[at]));
  }
  for (std::size_t width = 1; width < starts.size(); width *= 2) {
    for (std::size_t b = 0; b + width < starts.size(); b += 2 * width) {
      const std::size_t end = b + 2 * width < starts.size() ? starts[b + 2 * width] : out.size();
      const auto base = out.begin();
      std::inplace_merge(base + static_cast<std::ptrdiff_t>(starts[b]),
                         base + static_cast<std::ptrdiff_t>(starts[b + width]),
                         base + static_cast<std::ptrdiff_t>(end),
                         [](const R& x, const R& y) { return key_before(x, y); });
    }
  }
  return out;
}

// A lifter contact as words: id, element, bar, normal, radial, torque.
struct LifterCodec {
  static constexpr std::size_t kWords = 6;
  static void put(const LifterContact& c, std::vector<std::int64_t>& w) {
    w.insert(w.end(),
             {c.id, c.element, c.bar, std::bit_cast<std::int64_t>(c.normal),
              std::bit_cast<std::int64_t>(c.radial), std::bit_cast<std::int64_t>(c.torque)});
  }
  static LifterContact from(const std::int64_t* w) {
    return {w[0],
            static_cast<std::int32_t>(w[1]),
            static_cast<std::int32_t>(w[2]),
            std::bit_cast<double>(w[3]),
            std::bit_cast<double>(w[4]),
            std::bit_cast<double>(w[5])};
  }
};

// A wall load record on the shell or a bar, with its particle's id: the shell's input.
struct ShellContact {
  std::int64_t id = 0;
  std::int32_t element = 0;
  Vec2 point{}, force{};
};
bool key_before(const ShellContact& a, const ShellContact& b) {
  return a.id < b.id || (a.id == b.id && a.element < b.element);
}
struct ShellCodec {
  static constexpr std::size_t kWords = 6;
  static void put(const ShellContact& c, std::vector<std::int64_t>& w) {
    w.insert(w.end(),
             {c.id, c.element, std::bit_cast<std::int64_t>(c.point.x),
              std::bit_cast<std::int64_t>(c.point.y), std::bit_cast<std::int64_t>(c.force.x),
              std::bit_cast<std::int64_t>(c.force.y)});
  }
  static ShellContact from(const std::int64_t* w) {
    return {w[0], static_cast<std::int32_t>(w[1]),
            Vec2{std::bit_cast<double>(w[2]), std::bit_cast<double>(w[3])},
            Vec2{std::bit_cast<double>(w[4]), std::bit_cast<double>(w[5])}};
  }
};

// This rank's records on the shell and the bars, in the records' order (by particle id, then
// element, as one rank's wall list runs).
std::vector<ShellContact> shell_contacts(const Simulation& sim) {
  std::vector<ShellContact> out;
  const auto& elements = sim.walls().elements();
  for (const WallLoad& l : sim.contacts().wall_loads()) {
    if (elements[static_cast<std::size_t>(l.element)].part == WallPart::kWall) continue;
    out.push_back(
        {sim.particles().id[static_cast<std::size_t>(l.particle)], l.element, l.point, l.force});
  }
  return out;
}

// Collective: every rank's records on the shell and the bars from the last force evaluation, in
// (particle id, element) order, as the shell takes them (Shell::respond, Shell::field).
std::vector<WallLoad> gathered_shell_records(const Simulation& sim) {
  const std::vector<ShellContact> all = gather_in_key_order<ShellCodec>(shell_contacts(sim));
  std::vector<WallLoad> records;
  records.reserve(all.size());
  for (const ShellContact& c : all)
    records.push_back({c.element, 0, c.point, c.force, 0.0, Vec2{}});
  return records;
}

}  // namespace

LifterOutput::LifterOutput(const Scene& scene, const Simulation& sim, bool resumed) {
  auto bars = std::make_unique<LifterBars>(scene, sim.walls());
  if (bars->empty()) return;
  bars_ = std::move(bars);
  has_shell_ = scene.shell.present;
  std::string error;
  try {
    const bool active = mpi::rank(MPI_COMM_WORLD) == 0;
    log_ = std::make_unique<LifterLog>(scene.output.directory + "/" + kLiftersFile, active,
                                       has_shell_, resumed ? sim.time() : -1.0);
    if (has_shell_ && active) shell_ = std::make_unique<Shell>(scene, sim.walls());
  } catch (const IoError& e) {
    error = e.what();
  } catch (const std::invalid_argument& e) {
    error = std::string("cannot build the shell's finite elements: ") + e.what();
  }
  mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
}

LifterOutput::~LifterOutput() = default;

void LifterOutput::write(const Simulation& sim) {
  if (!bars_) return;
  const std::vector<LifterContact> all = gather_in_key_order<LifterCodec>(
      bars_->contacts(sim.contacts().wall_loads(), sim.particles(), sim.walls()));
  std::vector<WallLoad> on_shell;
  if (has_shell_) on_shell = gathered_shell_records(sim);
  std::string error;
  try {
    if (mpi::rank(MPI_COMM_WORLD) == 0) {
      if (shell_) response_ = shell_->respond(on_shell, sim.walls());
      log_->write(sim.time(), bars_->sum(all, sim.walls()), response_.bars);
    }
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
}

std::optional<ShellField> LifterOutput::shell_field(const Simulation& sim) const {
  if (!has_shell_) return std::nullopt;
  const std::vector<WallLoad> records = gathered_shell_records(sim);
  if (!shell_) return std::nullopt;
  return shell_->field(records, sim.walls());
}

}  // namespace dem2d
