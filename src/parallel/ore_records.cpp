#include "parallel/ore_records.hpp"

#include <bit>
#include <cstdint>
#include <type_traits>

#include "parallel/comm.hpp"

namespace dem2d {

namespace {

// One rank's block: [its length, breakage count, breakages (10 words each), fragment count,
// fragments (5 words each), products (4 words each), product count]; the reader walks it from
// both ends.
std::vector<std::int64_t> encode(const OreRecords& mine) {
  std::vector<std::int64_t> words;
  const auto put = [&words](auto x) {
    if constexpr (std::is_same_v<decltype(x), double>)
      words.push_back(std::bit_cast<std::int64_t>(x));
    else
      words.push_back(static_cast<std::int64_t>(x));
  };
  put(mine.breakages.size());
  for (const BreakageRecord& r : mine.breakages) {
    put(r.time), put(r.parent), put(r.radius), put(r.energy), put(r.fragments), put(r.first_id);
    put(r.mass), put(r.specific_energy), put(r.t10), put(r.fines_mass);
  }
  put(mine.fragments.size());
  for (const FragmentRecord& r : mine.fragments)
    put(r.time), put(r.parent), put(r.id), put(r.radius), put(r.mass);
  for (const ProductRecord& r : mine.product) put(r.time), put(r.id), put(r.radius), put(r.mass);
  put(mine.product.size());  // last: the reader walks each rank's block from both ends
  words.insert(words.begin(), static_cast<std::int64_t>(words.size()) + 1);
  return words;
}

OreRecords decode(const std::vector<std::int64_t>& all) {
  OreRecords records;
  const auto real = [](std::int64_t w) { return std::bit_cast<double>(w); };
  for (std::size_t at = 0; at < all.size(); at += static_cast<std::size_t>(all[at])) {
    const std::int64_t* w = &all[at + 1];
    const std::int64_t nb = *w++;
    for (std::int64_t k = 0; k < nb; ++k, w += 10)
      records.breakages.push_back({real(w[0]), w[1], real(w[2]), real(w[3]), static_cast<int>(w[4]),
                                   w[5], real(w[6]), real(w[7]), real(w[8]), real(w[9])});
    const std::int64_t nf = *w++;
    for (std::int64_t k = 0; k < nf; ++k, w += 5)
      records.fragments.push_back({real(w[0]), w[1], w[2], real(w[3]), real(w[4])});
    const std::size_t end = at + static_cast<std::size_t>(all[at]);
    const std::int64_t np = all[end - 1];
    for (std::int64_t k = 0; k < np; ++k, w += 4)
      records.product.push_back({real(w[0]), w[1], real(w[2]), real(w[3])});
  }
  return records;
}

}  // namespace

OreRecords gather_ore_records(MPI_Comm comm, const OreRecords& mine) {
  return decode(mpi::all_gather(comm, encode(mine)));
}

}  // namespace dem2d
