/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/parameters.h>

#include <atomic>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace pcl {
namespace selective_seg {

namespace {
std::atomic<std::size_t> huge_page_advice_bytes{kDefaultHugePageAdviceBytes};
} // namespace

void
setHugePageAdviceThreshold(std::size_t bytes) noexcept
{
  huge_page_advice_bytes.store(bytes, std::memory_order_relaxed);
}

std::size_t
getHugePageAdviceThreshold() noexcept
{
  return huge_page_advice_bytes.load(std::memory_order_relaxed);
}

namespace detail {

void
adviseHugePages(const void* data, std::size_t bytes) noexcept
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (!data || bytes < getHugePageAdviceThreshold())
    return;
  constexpr std::uintptr_t huge_page = std::uintptr_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + huge_page - 1) & ~(huge_page - 1);
  const std::uintptr_t last = (begin + bytes) & ~(huge_page - 1);
  if (last > first)
    // Advice only: an error (a kernel without transparent huge pages) changes nothing.
    (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

} // namespace detail

} // namespace selective_seg
} // namespace pcl
