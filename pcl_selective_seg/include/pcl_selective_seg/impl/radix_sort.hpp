/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/impl/large_arrays.hpp>

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
 * keys keep their order).
 *
 * With several threads each pass cuts the entries into one consecutive chunk per thread;
 * a chunk's counts give it its own starting slot per digit, after the earlier chunks'
 * entries of that digit, so the result is the one-thread result. */
inline void
radixSortByKey(std::vector<std::pair<std::uint64_t, pcl::index_t>>& entries,
               int bits,
               unsigned int num_threads = 1)
{
  const std::size_t n = entries.size();
  if (n < 2 || bits <= 0)
    return;
  const int passes = (bits + 10) / 11;
  const int digit_bits = (bits + passes - 1) / passes;
  const std::size_t digits = std::size_t{1} << digit_bits;
  const std::uint64_t mask = digits - 1;
  // Split from 8,192 entries, half of the pipeline's kMinParallelItems: measured on the
  // 46k-point door scan, whose two sorts then run on both cores (performance notes,
  // round 5).
  const std::size_t chunks = num_threads > 1 && n >= 8192 ? num_threads : 1;
  const std::size_t chunk_size = (n + chunks - 1) / chunks;
  const auto chunk_begin = [&](std::size_t c) { return std::min(n, c * chunk_size); };
  std::vector<std::pair<std::uint64_t, pcl::index_t>> buffer;
  resizeLarge(buffer, n);
  // slots[c * digits + d]: entries of digit d in chunk c, then where the first goes.
  std::vector<std::size_t> slots(chunks * digits);
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * digit_bits;
    std::fill(slots.begin(), slots.end(), 0);
#ifdef _OPENMP
#pragma omp parallel for num_threads(static_cast<int>(chunks)) schedule(static, 1)
#endif
    for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(chunks); ++c) {
      std::size_t* count = slots.data() + c * digits;
      for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i)
        ++count[(entries[i].first >> shift) & mask];
    }
    std::size_t total = 0;
    for (std::size_t d = 0; d < digits; ++d)
      for (std::size_t c = 0; c < chunks; ++c) {
        const std::size_t count = slots[c * digits + d];
        slots[c * digits + d] = total;
        total += count;
      }
    if (slots[1] == n) // digit 1 starts after all entries: every digit is 0 here
      continue;
#ifdef _OPENMP
#pragma omp parallel for num_threads(static_cast<int>(chunks)) schedule(static, 1)
#endif
    for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(chunks); ++c) {
      std::size_t* next = slots.data() + c * digits;
      for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i)
        buffer[next[(entries[i].first >> shift) & mask]++] = entries[i];
    }
    entries.swap(buffer);
  }
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
