#pragma once
// Under MPI only rank 0 prints (run_command.cpp): the others' std::cout and std::cerr go nowhere while the run command
// lasts.
#include <iostream>
#include <streambuf>

#include "nonsep/host/cluster/ranks.hpp"

namespace nonsep::host::cli {

class OnlyRankZeroSpeaks {
 public:
  explicit OnlyRankZeroSpeaks(const Ranks& ranks) {
    if (ranks.rank() == 0) return;
    out_ = std::cout.rdbuf(&nowhere_);
    err_ = std::cerr.rdbuf(&nowhere_);
  }
  ~OnlyRankZeroSpeaks() {
    if (out_) std::cout.rdbuf(out_);
    if (err_) std::cerr.rdbuf(err_);
  }
  OnlyRankZeroSpeaks(const OnlyRankZeroSpeaks&) = delete;
  OnlyRankZeroSpeaks& operator=(const OnlyRankZeroSpeaks&) = delete;

 private:
  struct Nowhere : std::streambuf {
    int overflow(int c) override { return c; }
  } nowhere_;
  std::streambuf* out_ = nullptr;
  std::streambuf* err_ = nullptr;
};

}  // namespace nonsep::host::cli
