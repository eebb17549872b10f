// The hand-written loops over states compiled for the building machine (-march=native, bench/CMakeLists.txt), in
// the portable build as in any other: the limit that the kernels chosen at run time are measured against (figure
// 2 of nonsep_bench_performance).
#include "hand_written_native.hpp"

#include "coupled3d.hpp"
#include "hand_written.hpp"

namespace bench {

void native_run(const HandWrittenStep& c, double* q, double* p, double* g, std::size_t count, std::uint64_t steps) {
  hand_written_run(c, q, p, g, count, steps);
}
void native_run_staged(const HandWrittenStep& c, double* q, double* p, double* g, std::size_t count,
                       std::uint64_t steps) {
  hand_written_run_staged(c, q, p, g, count, steps);
}

void native_coupled3d_run_staged(const HandWrittenStep& c, double coupling, double* q, double* p, double* g,
                                 std::size_t count, std::uint64_t steps) {
  coupled3d_run_staged(c, coupling, q, p, g, count, steps);
}

}  // namespace bench
