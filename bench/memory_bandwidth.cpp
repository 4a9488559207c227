// memory_bandwidth: what one core can stream from and to memory, the ceiling to compare a step's
// traffic with (docs/performance.md, "Where the time goes").
//
//   build/bench/memory_bandwidth [--mb M] [--repeats R] [--results DIR]
//   taskset -c 0 build/bench/memory_bandwidth          (one core, as bench/throughput is timed)
//
// Three arrays of M MB each (default 400, far past any cache), R passes (default 3) of:
//  - read:      sum of one array, eight independent sums (not bound by the adds' latency);
//  - triad:     c = a + 1.5 b with ordinary stores: counted as 3 streams (what the program
//               asks for) and as 4 (with the read for ownership of c's lines);
//  - triad nt:  the same with non-temporal stores (AVX-512 builds only): no read of c.
// Prints GB/s per pass and writes DIR/memory_bandwidth.csv (kernel, pass, GB/s; table only).
#include <immintrin.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double* aligned_array(std::size_t n, double value) {
  auto* a = static_cast<double*>(std::aligned_alloc(64, n * sizeof(double)));
  if (!a) {
    std::fprintf(stderr, "memory_bandwidth: cannot allocate %zu MB\n", n * sizeof(double) >> 20);
    std::exit(1);
  }
  for (std::size_t i = 0; i < n; ++i) a[i] = value;
  return a;
}

struct Row {
  std::string kernel;
  int pass;
  double gb_per_s;
};

}  // namespace

int main(int argc, char** argv) {
  std::size_t mb = 400;
  int repeats = 3;
  std::string results = std::string(DEM2D_SOURCE_DIR) + "/bench/results";
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--mb" && k + 1 < argc) {
      mb = std::strtoul(argv[++k], nullptr, 10);
    } else if (a == "--repeats" && k + 1 < argc) {
      repeats = std::atoi(argv[++k]);
    } else if (a == "--results" && k + 1 < argc) {
      results = argv[++k];
    } else {
      std::fprintf(stderr, "usage: memory_bandwidth [--mb M] [--repeats R] [--results DIR]\n");
      return a == "--help" ? 0 : 2;
    }
  }
  const std::size_t n = (mb << 20) / sizeof(double) / 64 * 64;
  double* a = aligned_array(n, 1.0);
  double* b = aligned_array(n, 2.0);
  double* c = aligned_array(n, 0.0);
  const double bytes = static_cast<double>(n * sizeof(double));
  std::vector<Row> rows;
  double check = 0.0;
  std::printf("memory_bandwidth: 3 arrays of %zu MB, one core\n", mb);
  std::printf("%-22s %5s %8s\n", "kernel", "pass", "GB/s");
  auto record = [&](const char* kernel, int pass, double streams, double s) {
    rows.push_back({kernel, pass, streams * bytes / s / 1e9});
    std::printf("%-22s %5d %8.1f\n", kernel, pass, rows.back().gb_per_s);
  };
  for (int pass = 1; pass <= repeats; ++pass) {
    Clock::time_point t0 = Clock::now();
    double sum[8] = {};
    for (std::size_t i = 0; i < n; i += 8)
      for (std::size_t l = 0; l < 8; ++l) sum[l] += a[i + l];
    record("read", pass, 1.0, seconds_since(t0));
    for (const double s : sum) check += s;

    t0 = Clock::now();
    for (std::size_t i = 0; i < n; ++i) c[i] = a[i] + 1.5 * b[i];
    const double triad = seconds_since(t0);
    record("triad (3 streams)", pass, 3.0, triad);
    record("triad (4, with RFO)", pass, 4.0, triad);
    check += c[n / 2];
#if defined(__AVX512F__)
    t0 = Clock::now();
    const __m512d k15 = _mm512_set1_pd(1.5);
    for (std::size_t i = 0; i < n; i += 8)
      _mm512_stream_pd(c + i, _mm512_fmadd_pd(k15, _mm512_load_pd(b + i), _mm512_load_pd(a + i)));
    _mm_sfence();
    record("triad nt (3 streams)", pass, 3.0, seconds_since(t0));
    check += c[n / 3];
#endif
  }
  std::printf("(checksum %g)\n", check);
  const std::string path = results + "/memory_bandwidth.csv";
  std::ofstream out(path);
  out << "kernel,pass,gb_per_s\n";
  for (const Row& r : rows) out << r.kernel << ',' << r.pass << ',' << r.gb_per_s << '\n';
  if (!out) {
    std::fprintf(stderr, "memory_bandwidth: cannot write %s\n", path.c_str());
    return 1;
  }
  std::printf("wrote %s\n", path.c_str());
  std::free(a);
  std::free(b);
  std::free(c);
  return 0;
}
