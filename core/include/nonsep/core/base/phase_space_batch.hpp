#pragma once
// A batch of phase-space points (q, p), the state every integrator steps. Layout as in model.hpp:
// component i of state b at index b*n + i, in two separate contiguous arrays for q and p, each starting on a cache
// line when it holds 32 numbers or more (aligned_allocator.hpp).
#include <cstddef>
#include <span>
#include <vector>

#include "nonsep/core/base/aligned_allocator.hpp"
#include "nonsep/core/base/error.hpp"

namespace nonsep {

class PhaseSpaceBatch {
 public:
  PhaseSpaceBatch() = default;
  // `count` states of dimension `dimension`, all zero. Throws InvalidArgument if dimension == 0.
  PhaseSpaceBatch(std::size_t dimension, std::size_t count)
      : dimension_(dimension), count_(count), q_(dimension * count), p_(dimension * count) {
    if (dimension == 0) throw InvalidArgument("phase-space dimension must be at least 1");
  }
  // One state. Throws InvalidArgument if q and p differ in length or are empty.
  static PhaseSpaceBatch single(std::span<const double> q, std::span<const double> p) {
    if (q.size() != p.size())
      throw InvalidArgument("q has " + std::to_string(q.size()) + " components but p has " + std::to_string(p.size()));
    PhaseSpaceBatch batch(q.size(), 1);
    batch.q_.assign(q.begin(), q.end());
    batch.p_.assign(p.begin(), p.end());
    return batch;
  }

  // Keeps the first min(count, count()) states as they are; states added are zero. Shrinking keeps the storage, so
  // growing back to at most the largest count so far does not allocate.
  void resize(std::size_t count) {
    count_ = count;
    q_.resize(dimension_ * count);
    p_.resize(dimension_ * count);
  }

  std::size_t dimension() const { return dimension_; }
  std::size_t count() const { return count_; }
  // Numbers in each of q and p: dimension * count.
  std::size_t size() const { return q_.size(); }

  std::span<double> q() { return q_; }
  std::span<double> p() { return p_; }
  std::span<const double> q() const { return q_; }
  std::span<const double> p() const { return p_; }
  // State b alone.
  std::span<double> q(std::size_t b) { return std::span<double>(q_).subspan(b * dimension_, dimension_); }
  std::span<double> p(std::size_t b) { return std::span<double>(p_).subspan(b * dimension_, dimension_); }
  std::span<const double> q(std::size_t b) const {
    return std::span<const double>(q_).subspan(b * dimension_, dimension_);
  }
  std::span<const double> p(std::size_t b) const {
    return std::span<const double>(p_).subspan(b * dimension_, dimension_);
  }

  friend bool operator==(const PhaseSpaceBatch&, const PhaseSpaceBatch&) = default;

 private:
  std::size_t dimension_ = 0;
  std::size_t count_ = 0;
  AlignedDoubles q_;
  AlignedDoubles p_;
};

}  // namespace nonsep
