/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/console/print.h>

#include <array>
#include <new>

namespace selseg_apps {

/** \brief The environment variables (besides GLIBC_TUNABLES with glibc.malloc.*) by
 * which a user sets glibc's malloc options; keepFreedMemory() leaves the allocator
 * alone when any is set. */
inline constexpr std::array<const char*, 5> kMallocOptionVariables = {
    "MALLOC_ARENA_MAX",
    "MALLOC_MMAP_MAX_",
    "MALLOC_MMAP_THRESHOLD_",
    "MALLOC_TRIM_THRESHOLD_",
    "MALLOC_TOP_PAD_"};

/** \brief Let this process reuse the memory it frees instead of returning it to the
 * system and asking for it again (glibc's allocator: no allocation mapped on its own,
 * no trimming of the heap).
 *
 * The pipeline frees large arrays between its stages and allocates others of similar
 * sizes; by default glibc maps each array above its threshold afresh (32 MB at most)
 * and the process pays a page fault for every 4 KB of it again. The command-line tool
 * runs one pipeline and exits, so keeping the freed memory costs nothing: measured on
 * the 1M and 3M-point door scans, the same peak resident memory (within 0.3%) and a
 * 7-12% faster pipeline (docs/performance.md, "Memory").
 *
 * The library itself never does this: it does not own its users' processes.
 * \return false (nothing changed) with another C library, with an allocator that
 *         ignores mallopt() (a sanitizer's), or when the environment already sets
 *         glibc's malloc options (GLIBC_TUNABLES with glibc.malloc.*, or one of
 *         kMallocOptionVariables): the user's choice wins. */
bool keepFreedMemory();

/** \brief Run \a work and return its exit code; when memory runs out in it beyond
 * what the library reports itself (std::bad_alloc out of \a work, whose stack unwinds
 * first, so that the outputs' temporaries are removed), print "Out of memory: " and
 * \a advice and return \a out_of_memory_code. */
template <typename Work>
int
runReportingOutOfMemory(Work&& work, const char* advice, int out_of_memory_code)
{
  try {
    return work();
  } catch (const std::bad_alloc&) {
    pcl::console::print_error("Out of memory: %s\n", advice);
    return out_of_memory_code;
  }
}

} // namespace selseg_apps
