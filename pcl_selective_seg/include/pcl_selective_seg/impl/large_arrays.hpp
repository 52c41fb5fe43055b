/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/pcl_macros.h>

#include <cstddef>
#include <vector>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief Asks the kernel to back the whole 2 MB pages inside [data, data + bytes)
 * with transparent huge pages (Linux `madvise(MADV_HUGEPAGE)`), when \a bytes is at
 * least getHugePageAdviceThreshold() (32 MB unless set); otherwise, or on other
 * systems, or where the kernel refuses, nothing happens.
 *
 * Called on a new array before it is first written. Memory a large array takes from the
 * system is otherwise mapped in 4 KB pages, one page fault each on first touch; on
 * virtual machines a fault costs several microseconds, and at millions of points those
 * faults take longer than the computation (docs/performance.md, "Huge pages"). The
 * advice changes no value, and the pages covered are the array's own, all written at
 * once, so it adds no resident memory. The system's setting
 * (/sys/kernel/mm/transparent_hugepage/enabled = never) turns it off. */
PCL_EXPORTS void adviseHugePages(const void* data, std::size_t bytes) noexcept;

/** \brief v.reserve(n), with the new storage advised as huge-page memory
 * (adviseHugePages()) before anything is written to it. */
template <typename T, typename Allocator>
void
reserveLarge(std::vector<T, Allocator>& v, std::size_t n)
{
  if (n <= v.capacity())
    return;
  v.reserve(n);
  adviseHugePages(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(T));
}

/** \brief v.resize(n) into storage advised as huge-page memory (reserveLarge()). */
template <typename T, typename Allocator>
void
resizeLarge(std::vector<T, Allocator>& v, std::size_t n)
{
  reserveLarge(v, n);
  v.resize(n);
}

/** \brief v.assign(n, value) into storage advised as huge-page memory
 * (reserveLarge()). */
template <typename T, typename Allocator>
void
assignLarge(std::vector<T, Allocator>& v,
            std::size_t n,
            const typename std::vector<T, Allocator>::value_type& value)
{
  reserveLarge(v, n);
  v.assign(n, value);
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
