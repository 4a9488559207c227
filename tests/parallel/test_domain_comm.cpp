// parallel/comm.hpp, the MPI verbs every layer uses, at 1 to 5 ranks (part of the test_domain
// binary). Values carry the rank they came from, so routing and order are checked, not only
// the sizes.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "parallel/comm.hpp"

namespace {

using namespace dem2d;

TEST(Comm, RankSizeAndIntegerSums) {
  const int r = mpi::rank(MPI_COMM_WORLD), n = mpi::size(MPI_COMM_WORLD);
  ASSERT_GE(r, 0);
  ASSERT_LT(r, n);
  const auto x = static_cast<std::uint64_t>(r + 1);
  EXPECT_EQ(mpi::exclusive_scan_sum(MPI_COMM_WORLD, x),
            static_cast<std::uint64_t>(r * (r + 1) / 2));
  EXPECT_EQ(mpi::sum(MPI_COMM_WORLD, x), static_cast<std::uint64_t>(n * (n + 1) / 2));
  EXPECT_EQ(mpi::sum(MPI_COMM_WORLD, std::int64_t{-2}), -2 * n);
  EXPECT_EQ(mpi::max(MPI_COMM_WORLD, static_cast<double>(r)), n - 1);
  EXPECT_TRUE(mpi::any(MPI_COMM_WORLD, r == n - 1));
  EXPECT_FALSE(mpi::any(MPI_COMM_WORLD, false));
}

TEST(Comm, GatherBroadcastAndAllToAllKeepRankOrder) {
  const int r = mpi::rank(MPI_COMM_WORLD), n = mpi::size(MPI_COMM_WORLD);
  const std::vector<double> all = mpi::all_gather(MPI_COMM_WORLD, 10.0 * r);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(n));
  for (int q = 0; q < n; ++q) EXPECT_EQ(all[static_cast<std::size_t>(q)], 10.0 * q);

  std::vector<int> values = {r, r, r};
  mpi::broadcast(MPI_COMM_WORLD, values, n - 1);
  EXPECT_EQ(values, (std::vector<int>{n - 1, n - 1, n - 1}));
  EXPECT_EQ(mpi::broadcast_string(MPI_COMM_WORLD, "from " + std::to_string(r), n - 1),
            "from " + std::to_string(n - 1));
  EXPECT_EQ(mpi::broadcast_string(MPI_COMM_WORLD, r == 0 ? "" : "junk", 0), "");

  // Two values per rank: what rank r sends to q is (100 r + q, -q); q receives them at [2 r].
  std::vector<std::int64_t> send;
  for (int q = 0; q < n; ++q) {
    send.push_back(100 * r + q);
    send.push_back(-q);
  }
  const std::vector<std::int64_t> recv = mpi::all_to_all(MPI_COMM_WORLD, send, 2);
  ASSERT_EQ(recv.size(), send.size());
  for (int q = 0; q < n; ++q) {
    EXPECT_EQ(recv[2 * static_cast<std::size_t>(q)], 100 * q + r);
    EXPECT_EQ(recv[2 * static_cast<std::size_t>(q) + 1], -r);
  }
}

TEST(Comm, ExchangeBytesAroundARing) {
  const int r = mpi::rank(MPI_COMM_WORLD), n = mpi::size(MPI_COMM_WORLD);
  if (n == 1) GTEST_SKIP() << "one rank: no peer";
  // Rank r sends r + 1 bytes of value r to its successor; an empty message to its
  // predecessor (not sent at all), except on two ranks, where both are the same peer.
  const int next = (r + 1) % n, prev = (r + n - 1) % n;
  std::vector<int> peers = {next};
  std::vector<std::vector<std::byte>> send(1), recv(1);
  send[0].assign(static_cast<std::size_t>(r + 1), static_cast<std::byte>(r));
  recv[0].resize(static_cast<std::size_t>(prev + 1));
  if (n > 2) {
    peers.push_back(prev);
    send.emplace_back();
    recv.emplace_back();
    std::swap(recv[0], recv[1]);  // nothing from the successor, prev + 1 bytes from prev
  }
  std::vector<MPI_Request> requests;
  mpi::exchange_bytes(MPI_COMM_WORLD, peers, send, recv, requests);
  const std::vector<std::byte>& got = n > 2 ? recv[1] : recv[0];
  EXPECT_EQ(got, std::vector<std::byte>(static_cast<std::size_t>(prev + 1),
                                        static_cast<std::byte>(prev)));
}

// The one agree-on-failure: every rank throws the requested type with the lowest failing
// rank's message, or none throws.
TEST(Comm, AgreeOnFailureThrowsTheLowestFailingRanksMessageEverywhere) {
  const int r = mpi::rank(MPI_COMM_WORLD), n = mpi::size(MPI_COMM_WORLD);
  EXPECT_NO_THROW(mpi::agree_on_failure(MPI_COMM_WORLD, ""));
  EXPECT_EQ(mpi::first_failure(MPI_COMM_WORLD, ""), "");
  // Every rank from the middle one up fails, each with its own message.
  const int first = n / 2;
  const std::string mine = r >= first ? "rank " + std::to_string(r) + " failed" : "";
  EXPECT_EQ(mpi::first_failure(MPI_COMM_WORLD, mine), "rank " + std::to_string(first) + " failed");
  std::string what;
  try {
    mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, mine);
  } catch (const IoError& e) {
    what = e.what();
  }
  EXPECT_EQ(what, "rank " + std::to_string(first) + " failed");
  EXPECT_THROW(mpi::agree_on_failure(MPI_COMM_WORLD, r == n - 1 ? "last" : ""), std::runtime_error);
}

}  // namespace
