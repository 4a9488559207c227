#include "io/run_outputs.hpp"

#include <string>
#include <utility>

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

}  // namespace dem2d
