#pragma once
// hand_written_run and hand_written_run_staged over `count` states (hand_written.hpp), compiled with -march=native
// in hand_written_native.cpp.
#include <cstddef>
#include <cstdint>

namespace bench {

struct HandWrittenStep;
void native_run(const HandWrittenStep& c, double* q, double* p, double* g, std::size_t count, std::uint64_t steps);
void native_run_staged(const HandWrittenStep& c, double* q, double* p, double* g, std::size_t count,
                       std::uint64_t steps);

// coupled3d_run_staged (coupled3d.hpp), compiled the same way.
void native_coupled3d_run_staged(const HandWrittenStep& c, double coupling, double* q, double* p, double* g,
                                 std::size_t count, std::uint64_t steps);

}  // namespace bench
