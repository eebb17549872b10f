// The main of every doctest executable. It pins the plugins' stepping kernels to the baseline instruction set
// (NONSEP_INSTRUCTION_SET, unless the environment sets it already), for this process and the `nonsep` processes the
// tests start: the bit-for-bit comparisons with the core compiled into the tests hold for the baseline; a wider set
// may fuse multiplications and additions (docs/performance.md). A build with the tests therefore compiles the plugins'
// baseline kernels beside this machine's widest (NONSEP_KERNEL_SETS, cmake/NonsepOptions.cmake).
#include <cstdlib>

#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

int main(int argc, char** argv) {
  ::setenv("NONSEP_INSTRUCTION_SET", "baseline", 0);
  return doctest::Context(argc, argv).run();
}
