/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

/* Internal header: the checks the mesh functions make of the ids they are given, so
 * that a broken mesh gives a message instead of a read out of bounds. Not installed. */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/parameters.h>

#include <pcl/console/print.h>

#include <cstdint>
#include <type_traits>
#include <vector>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief Whether every id is in [0, bound) (or negative, i.e. none, where
 * \a negative_allowed); a PCL_ERROR "[where] WHAT ..." otherwise. One pass, on both
 * cores when long. */
template <typename Id>
bool
idsBelow(const std::vector<Id>& ids,
         std::size_t bound,
         bool negative_allowed,
         const char* where,
         const char* what,
         int num_threads = 0)
{
  if (meshTrusted())
    return true; // the pipeline's own mesh (TrustedMeshScope)
  const auto upper = static_cast<std::uint64_t>(bound);
  const auto out = [&](pcl::index_t id) {
    return static_cast<std::uint32_t>(
        !(static_cast<std::uint64_t>(static_cast<std::int64_t>(id)) < upper ||
          (negative_allowed && id < 0)));
  };
  const auto n = static_cast<std::ptrdiff_t>(ids.size());
  std::uint32_t beyond = 0;
#ifdef _OPENMP
#pragma omp parallel for num_threads(threadCount(num_threads)) reduction(| : beyond)   \
    schedule(static) if (ids.size() >= 4 * kMinParallelItems)
#endif
  for (std::ptrdiff_t k = 0; k < n; ++k) {
    if constexpr (std::is_same<Id, Triangle>::value)
      beyond |= out(ids[k][0]) | out(ids[k][1]) | out(ids[k][2]);
    else
      beyond |= out(ids[k]);
  }
  if (beyond == 0)
    return true;
  PCL_ERROR("[pcl::selective_seg::%s] %s hold an id outside [0, %zu)%s: the arrays "
            "do not belong together\n",
            where,
            what,
            bound,
            negative_allowed ? "" : " (negative ids are not allowed here)");
  return false;
}

/** \brief Whether \a size is \a expected; a PCL_ERROR "[where] WHAT ..." otherwise. */
inline bool
sizeIs(std::size_t size, std::size_t expected, const char* where, const char* what)
{
  if (size == expected)
    return true;
  PCL_ERROR("[pcl::selective_seg::%s] %s: %zu entries where %zu are needed\n",
            where,
            what,
            size,
            expected);
  return false;
}

/** \brief The checks of the functions that sum triangle values into vertices: every
 * triangle's vertex ids below \a num_vertices, and one normal and one area per
 * triangle. */
inline bool
trianglesWithValuesFit(const std::vector<Triangle>& triangles,
                       std::size_t num_vertices,
                       std::size_t num_normals,
                       std::size_t num_areas,
                       const char* where,
                       int num_threads = 0)
{
  return idsBelow(
             triangles, num_vertices, false, where, "the triangles", num_threads) &&
         sizeIs(num_normals, triangles.size(), where, "normals") &&
         sizeIs(num_areas, triangles.size(), where, "areas");
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
