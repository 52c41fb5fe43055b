/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/types.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief Number of bits needed to write \a value. */
inline int
bitWidth(std::uint64_t value)
{
  int bits = 0;
  while (bits < 64 && (value >> bits))
    ++bits;
  return bits;
}

/** \brief Stable sort of (key, index) pairs by key, every key below 2^bits: a
 * least-significant-digit radix sort with digits of at most 11 bits (entries with equal
 * keys keep their order). */
inline void
radixSortByKey(std::vector<std::pair<std::uint64_t, pcl::index_t>>& entries, int bits)
{
  const std::size_t n = entries.size();
  if (n < 2 || bits <= 0)
    return;
  const int passes = (bits + 10) / 11;
  const int digit_bits = (bits + passes - 1) / passes;
  const std::uint64_t mask = (std::uint64_t{1} << digit_bits) - 1;
  std::vector<std::pair<std::uint64_t, pcl::index_t>> buffer(n);
  std::vector<std::size_t> offsets(mask + 2);
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * digit_bits;
    std::fill(offsets.begin(), offsets.end(), 0);
    for (const auto& e : entries)
      ++offsets[((e.first >> shift) & mask) + 1];
    if (offsets[1] == n) // every entry has digit 0 here: nothing moves
      continue;
    for (std::size_t d = 1; d < offsets.size(); ++d)
      offsets[d] += offsets[d - 1];
    for (const auto& e : entries)
      buffer[offsets[(e.first >> shift) & mask]++] = e;
    entries.swap(buffer);
  }
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
