/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/console/print.h>

#include <array>
#include <cstddef>
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

/** \brief Grow the heap of a process that keeps its freed memory (after
 * keepFreedMemory() returned true) by \a bytes at once, advised as huge-page memory.
 *
 * A block of \a bytes is taken from the heap, its whole 2 MB pages are advised as the
 * library advises its own large arrays (pcl::selective_seg::detail::adviseHugePages(),
 * with the threshold of setHugePageAdviceThreshold()), and it is freed: the heap, which
 * is never trimmed, keeps it, and the allocations that follow (the scan, the
 * pipeline's arrays, the outputs) come from it, one page fault for each 2 MB instead of
 * each 4 KB first touched. Nothing is written to it: what the run does not use stays
 * virtual, and the peak resident memory grows by the unwritten parts of the huge pages
 * the run touches (0.4-2.3 MiB at 1M points; docs/performance.md, "Huge pages"). Call
 * it from the main thread: glibc serves another thread's large requests apart from
 * the heap. The block need not be used up: its size costs only address space.
 * \return true when the block was taken and freed into the heap (whether the kernel
 *         takes the advice is its setting's affair, as for the library's arrays);
 *         false (nothing done) when the freed memory is not kept, when \a bytes is 0,
 *         under a limit on the address space or the data segment (RLIMIT_AS,
 *         RLIMIT_DATA: the reservation would spend that budget beyond what the run
 *         needs), or when the allocator refuses the block (it is only virtual memory,
 *         but a system that does not overcommit may refuse a large one). */
bool reserveHeapInHugePages(std::size_t bytes);

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
