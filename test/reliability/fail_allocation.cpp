/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Preloaded into a tool (LD_PRELOAD) by test_tool_failures: operator new fails with
// std::bad_alloc at the Nth allocation after main() starts (SELSEG_FAIL_ALLOCATION=N,
// counting from 0), on whichever thread makes it; with SELSEG_COUNT_ALLOCATIONS=FILE it
// writes the number of allocations made after main() started to FILE at exit. The
// allocations of the shared libraries' static initialisers, before main(), are not
// counted: no program can report those.

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>

#include "replaced_operator_new.h"
#include <dlfcn.h>

namespace {

std::atomic<bool> g_started{false};
std::atomic<long> g_count{0};
long g_fail_at = -1;
const char* g_count_file = nullptr;

void
writeCount()
{
  if (FILE* f = std::fopen(g_count_file, "w")) {
    std::fprintf(f, "%ld\n", g_count.load());
    std::fclose(f);
  }
}

using Main = int (*)(int, char**, char**);
Main g_main = nullptr;

int
countingMain(int argc, char** argv, char** env)
{
  if (const char* n = std::getenv("SELSEG_FAIL_ALLOCATION"))
    g_fail_at = std::atol(n);
  g_count_file = std::getenv("SELSEG_COUNT_ALLOCATIONS");
  if (g_count_file)
    std::atexit(writeCount);
  g_started = true;
  return g_main(argc, argv, env);
}

} // namespace

void*
selsegTestAllocate(std::size_t n, std::size_t alignment)
{
  if (g_started.load(std::memory_order_relaxed) &&
      g_count.fetch_add(1, std::memory_order_relaxed) == g_fail_at)
    throw std::bad_alloc();
  return selsegTestMalloc(n, alignment);
}

// The C library's entry, which calls main(): wrapped to start the count.
extern "C" int
__libc_start_main(Main main,
                  int argc,
                  char** argv,
                  void (*init)(),
                  void (*fini)(),
                  void (*rtld_fini)(),
                  void* stack_end)
{
  using Start = int (*)(Main, int, char**, void (*)(), void (*)(), void (*)(), void*);
  const auto start = reinterpret_cast<Start>(dlsym(RTLD_NEXT, "__libc_start_main"));
  g_main = main;
  return start(countingMain, argc, argv, init, fini, rtld_fini, stack_end);
}
