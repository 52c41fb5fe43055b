/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "process_memory.h"

#include <pcl_selective_seg/impl/large_arrays.hpp>

#include <cstdlib>
#include <cstring>
#include <initializer_list>

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__linux__)
#include <sys/resource.h>
#endif

namespace selseg_apps {

namespace {
/** Whether keepFreedMemory() set glibc to keep what this process frees. */
bool heap_kept = false;
} // namespace

bool
keepFreedMemory()
{
#if defined(__GLIBC__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc."))
    return false;
  for (const char* name : kMallocOptionVariables)
    if (std::getenv(name))
      return false;
  // Every allocation from the heap, and the heap never given back: a freed array is
  // there for the next stage's. -1 turns trimming off whatever the heap's size (INT_MAX
  // would still trim a free top of 2 GB or more, e.g. a reservation for a scan of 5.4M
  // points).
  heap_kept = mallopt(M_MMAP_MAX, 0) == 1 && mallopt(M_TRIM_THRESHOLD, -1) == 1;
  return heap_kept;
#else
  return false;
#endif
}

bool
reserveHeapInHugePages(std::size_t bytes)
{
  if (!heap_kept || bytes == 0)
    return false;
#if defined(__linux__)
  // Under a limit on the address space or on the data segment the address space is a
  // budget, and a reservation larger than the run needs would spend it.
  for (const int resource : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit limit{};
    if (getrlimit(resource, &limit) != 0 || limit.rlim_cur != RLIM_INFINITY)
      return false;
  }
#endif
  // Only the block's address is used: nothing is read (GCC takes a const pointer to
  // uninitialized memory for a read, hence the pragma).
  void* block = std::malloc(bytes);
  if (!block)
    return false;
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
  pcl::selective_seg::detail::adviseHugePages(block, bytes);
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
  std::free(block);
  return true;
}

} // namespace selseg_apps
