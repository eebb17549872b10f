// Another user's library, for test_formula_cache_safety.cpp: loading it runs its constructor, which leaves the file
// NONSEP_TEST_INTRUDER_MARKER behind. It is no plugin: what matters is that nonsep never loads it.
#include <cstdio>
#include <cstdlib>

namespace {

__attribute__((constructor)) void intrude() {
  if (const char* marker = std::getenv("NONSEP_TEST_INTRUDER_MARKER"))
    if (std::FILE* file = std::fopen(marker, "w")) std::fclose(file);
}

}  // namespace
