// Contact history: the state a contact carries from step to step (docs/architecture.md,
// "Contact histories").
//
// Each sub-model of the contact model (law, rolling model, tracker) declares the history it
// needs as a list of slots (name, unit, meaning); a contact's history is the concatenation of
// the active sub-models' slots, `width` doubles, zero at first touch. The neighbour lists keep
// it beside each listed contact (core/contact/neighbors.hpp); HistoryRecords key it by particle ids
// so that it travels with its particles through migration (and checkpoints), sized from the
// declarations: a model that needs no history moves no bytes.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <string_view>
#include <vector>

#include "core/base/history_slot.hpp"

namespace dem2d {

// Contact histories keyed by particle ids. Key (a, b): b >= 0 the pair of particles a < b;
// b < 0 particle a against wall element -1 - b. Each record holds width() values.
class HistoryRecords {
 public:
  explicit HistoryRecords(std::size_t width = 0) : width_(width) {}

  std::size_t width() const { return width_; }
  std::size_t size() const { return a_.size(); }
  bool empty() const { return a_.empty(); }
  std::int64_t a(std::size_t k) const { return a_[k]; }
  std::int64_t b(std::size_t k) const { return b_[k]; }
  const double* values(std::size_t k) const { return values_.data() + k * width_; }

  void push_back(std::int64_t a, std::int64_t b, const double* values) {
    a_.push_back(a);
    b_.push_back(b);
    values_.insert(values_.end(), values, values + width_);
  }
  void clear() {
    a_.clear();
    b_.clear();
    values_.clear();
  }

  // One record as bytes: the two ids, then the values (migration, checkpoints).
  std::size_t record_bytes() const { return 2 * sizeof(std::int64_t) + width_ * sizeof(double); }
  std::byte* pack(std::size_t k, std::byte* out) const {
    std::memcpy(out, &a_[k], sizeof(std::int64_t));
    std::memcpy(out + sizeof(std::int64_t), &b_[k], sizeof(std::int64_t));
    if (width_) std::memcpy(out + 2 * sizeof(std::int64_t), values(k), width_ * sizeof(double));
    return out + record_bytes();
  }
  // Append the records packed in `bytes` (a whole number of record_bytes()).
  void unpack_append(const std::byte* in, std::size_t bytes) {
    const std::size_t n = bytes / record_bytes(), first = size();
    a_.resize(first + n);
    b_.resize(first + n);
    values_.resize((first + n) * width_);
    for (std::size_t k = first; k < first + n; ++k, in += record_bytes()) {
      std::memcpy(&a_[k], in, sizeof(std::int64_t));
      std::memcpy(&b_[k], in + sizeof(std::int64_t), sizeof(std::int64_t));
      if (width_)
        std::memcpy(&values_[k * width_], in + 2 * sizeof(std::int64_t), width_ * sizeof(double));
    }
  }

  // Sort by key, keeping the first of records with equal keys.
  void sort_unique() {
    std::vector<std::size_t> order(size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
      return a_[x] < a_[y] || (a_[x] == a_[y] && b_[x] < b_[y]);
    });
    HistoryRecords out(width_);
    for (const std::size_t k : order) {
      const std::size_t n = out.size();
      if (n && out.a_[n - 1] == a_[k] && out.b_[n - 1] == b_[k]) continue;
      out.push_back(a_[k], b_[k], values(k));
    }
    *this = std::move(out);
  }

 private:
  std::size_t width_;
  std::vector<std::int64_t> a_, b_;
  std::vector<double> values_;  // record k: [k * width_, (k + 1) * width_)
};

}  // namespace dem2d
