/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

/* Internal header: a hash of three 64-bit integers (cell keys), for unordered_map. Not
 * installed. */

#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief FNV-1a over the three integers, folded: cells of a grid, or (component,
 * tile, tile) keys. */
struct Int64TripleHash {
  std::size_t operator()(const std::array<std::int64_t, 3>& k) const
  {
    std::uint64_t h = 1469598103934665603ull;
    for (const auto x : k)
      h = (h ^ static_cast<std::uint64_t>(x)) * 1099511628211ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

} // namespace detail
} // namespace selective_seg
} // namespace pcl
