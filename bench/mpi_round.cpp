// mpi_round: what one synchronisation costs between two ranks on this machine, the floor under
// a parallel step (why the 240-ball waterfall cannot run in half the time on 2 ranks).
//
//   OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np 2 build/bench/mpi_round
//   [--results DIR]
//
// Times, per iteration, the exchanges a step of dem2d can make: the end-of-step round of
// velocity Verlet (640 bytes each way: 15 ghosts' next state and the reduction), the same
// with persistent requests, an MPI_Allreduce of 2 doubles, and each of them after 1.5 us of
// work (about a rank's share of a waterfall step) to show whether the latency hides behind it.
// The fastest of 5 repeats of 200 000 iterations; prints a table, writes DIR/mpi_round.csv.
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace {

void work_for(double seconds) {
  const double t0 = MPI_Wtime();
  while (MPI_Wtime() - t0 < seconds) {
  }
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  std::string results = std::string(DEM2D_SOURCE_DIR) + "/bench/results";
  for (int k = 1; k + 1 < argc; ++k)
    if (std::string(argv[k]) == "--results") results = argv[k + 1];
  if (size != 2) {
    if (rank == 0) std::fprintf(stderr, "mpi_round: run it on 2 ranks (mpirun -np 2)\n");
    MPI_Finalize();
    return 2;
  }
  const int peer = 1 - rank, iterations = 200000;
  std::vector<char> out(640), in(640);
  double values[2] = {1.0, 2.0}, reduced[2];
  const double busy = 1.5e-6;
  struct Result {
    std::string name;
    double us;
  };
  std::vector<Result> rows;
  const auto time = [&](const std::string& name, auto&& body) {
    double best = 1e300;
    for (int rep = 0; rep < 5; ++rep) {
      MPI_Barrier(MPI_COMM_WORLD);
      const double t0 = MPI_Wtime();
      for (int i = 0; i < iterations; ++i) body();
      double t = (MPI_Wtime() - t0) / iterations, slowest = 0.0;
      MPI_Allreduce(&t, &slowest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
      best = std::min(best, slowest);
    }
    rows.push_back({name, 1e6 * best});
  };
  const auto round = [&]() {
    MPI_Request req[2];
    MPI_Irecv(in.data(), 640, MPI_BYTE, peer, 1, MPI_COMM_WORLD, &req[0]);
    MPI_Isend(out.data(), 640, MPI_BYTE, peer, 1, MPI_COMM_WORLD, &req[1]);
    MPI_Waitall(2, req, MPI_STATUSES_IGNORE);
  };
  MPI_Request persistent[2];
  MPI_Recv_init(in.data(), 640, MPI_BYTE, peer, 2, MPI_COMM_WORLD, &persistent[0]);
  MPI_Send_init(out.data(), 640, MPI_BYTE, peer, 2, MPI_COMM_WORLD, &persistent[1]);
  time("round 640 B (Irecv, Isend, Waitall)", round);
  time("round 640 B, persistent requests", [&]() {
    MPI_Startall(2, persistent);
    MPI_Waitall(2, persistent, MPI_STATUSES_IGNORE);
  });
  time("MPI_Allreduce max, 2 doubles",
       [&]() { MPI_Allreduce(values, reduced, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD); });
  time("1.5 us of work alone", [&]() { work_for(busy); });
  time("1.5 us of work, then the round", [&]() {
    work_for(busy);
    round();
  });
  time("round posted, 1.5 us of work, wait", [&]() {
    MPI_Request req[2];
    MPI_Irecv(in.data(), 640, MPI_BYTE, peer, 1, MPI_COMM_WORLD, &req[0]);
    MPI_Isend(out.data(), 640, MPI_BYTE, peer, 1, MPI_COMM_WORLD, &req[1]);
    work_for(busy);
    MPI_Waitall(2, req, MPI_STATUSES_IGNORE);
  });
  MPI_Request_free(&persistent[0]);
  MPI_Request_free(&persistent[1]);
  if (rank == 0) {
    std::printf("%-40s %10s\n", "exchange (2 ranks)", "us/iter");
    std::ofstream csv(results + "/mpi_round.csv");
    csv << "exchange,us_per_iteration\n";
    for (const Result& r : rows) {
      std::printf("%-40s %10.3f\n", r.name.c_str(), r.us);
      csv << '"' << r.name << "\"," << r.us << "\n";
    }
    std::printf("wrote %s/mpi_round.csv\n", results.c_str());
  }
  MPI_Finalize();
  return 0;
}
