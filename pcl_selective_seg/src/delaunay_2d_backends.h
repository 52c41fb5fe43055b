/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

/* Internal header: the Delaunay backends behind delaunay2d() and the exact integer
 * predicates they share. Not installed. */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief No vertex, triangle or half-edge (removed slots, boundary neighbours). */
constexpr index_t kNone = -1;

/** \brief Signed 128-bit integer (a GCC/Clang extension, hence the marker). */
__extension__ typedef __int128 Int128;

/** \brief Twice the signed area of triangle (a, b, c): positive if counter-clockwise.
 *
 * Exact for |coordinate| <= kMaxDelaunayCoordinate = 2^26: every difference is at most
 * 2^27 in magnitude, each product at most 2^54 and the result at most 2^55 < 2^63.
 * Still exact while the coordinate differences stay below 2^29 (the sweep's artificial
 * points): products below 2^58, the result below 2^59.
 */
inline std::int64_t
orientation(const QuantizedPoint& a, const QuantizedPoint& b, const QuantizedPoint& c)
{
  const std::int64_t abx = std::int64_t{b[0]} - a[0];
  const std::int64_t aby = std::int64_t{b[1]} - a[1];
  const std::int64_t acx = std::int64_t{c[0]} - a[0];
  const std::int64_t acy = std::int64_t{c[1]} - a[1];
  return abx * acy - aby * acx;
}

/** \brief In-circle determinant: positive if d lies strictly inside the circumcircle of
 * the counter-clockwise triangle (a, b, c), zero if the four points are co-circular.
 *
 * Exact for |coordinate| <= 2^26. With differences to d of magnitude <= 2^27, each
 * lifted term dx^2 + dy^2 is <= 2^55 and each 2x2 minor dx1 * dy2 - dx2 * dy1 is
 * <= 2^55, both fitting in int64. Each of the three products is <= 2^110, so the
 * determinant is <= 3 * 2^110 < 2^112, far inside the int128 range (2^127). Still exact
 * while the differences stay below 2^29 (the sweep's artificial points): lifted terms
 * and minors below 2^59, the determinant below 3 * 2^118 < 2^120.
 */
inline Int128
inCircle(const QuantizedPoint& a,
         const QuantizedPoint& b,
         const QuantizedPoint& c,
         const QuantizedPoint& d)
{
  const std::int64_t adx = std::int64_t{a[0]} - d[0];
  const std::int64_t ady = std::int64_t{a[1]} - d[1];
  const std::int64_t bdx = std::int64_t{b[0]} - d[0];
  const std::int64_t bdy = std::int64_t{b[1]} - d[1];
  const std::int64_t cdx = std::int64_t{c[0]} - d[0];
  const std::int64_t cdy = std::int64_t{c[1]} - d[1];
  const std::int64_t a_lift = adx * adx + ady * ady;
  const std::int64_t b_lift = bdx * bdx + bdy * bdy;
  const std::int64_t c_lift = cdx * cdx + cdy * cdy;
  return Int128{a_lift} * (bdx * cdy - cdx * bdy) +
         Int128{b_lift} * (cdx * ady - adx * cdy) +
         Int128{c_lift} * (adx * bdy - bdx * ady);
}

/** \brief Sets *error to \a message when \a error is not null. */
void setError(std::string* error, const std::string& message);

/** \brief The error for a duplicated point: names the first two ids at \a position,
 * which must occur at least twice in \a points. */
void reportDuplicate(const std::vector<QuantizedPoint>& points,
                     const QuantizedPoint& position,
                     std::string* error);

/** \brief Whether the \a count points from \a first lie on one line (true for fewer
 * than three points). */
bool allCollinear(const QuantizedPoint* first, std::size_t count);

/** \brief The same for all of \a points. */
inline bool
allCollinear(const std::vector<QuantizedPoint>& points)
{
  return allCollinear(points.data(), points.size());
}

/** \brief The key of the undirected edge {a, b} over point ids. */
inline std::uint64_t
undirectedEdgeKey(index_t a, index_t b)
{
  if (a > b)
    std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

/** \brief Sorts edge records (anything with a \c key member) by key. */
template <typename Edge>
void
sortByKey(std::vector<Edge>& edges)
{
  std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
    return a.key < b.key;
  });
}

/** \brief The record with \a key in \a edges sorted by sortByKey(), or null. */
template <typename Edge>
Edge*
findByKey(std::vector<Edge>& edges, std::uint64_t key)
{
  const auto it = std::lower_bound(
      edges.begin(), edges.end(), key, [](const Edge& e, std::uint64_t k) {
        return e.key < k;
      });
  return it != edges.end() && it->key == key ? &*it : nullptr;
}

/** \brief Rotates each triangle so that its smallest id comes first, then sorts the
 * list (linear time: a counting sort on the first id, then small buckets). Slots whose
 * first corner is kNone (removed triangles) are dropped. With \a neighbours (the
 * adjacency of the slots as given, in computeTriangleNeighbours()'s layout, never
 * naming a removed slot), the adjacency is carried along: rows rotated and reordered,
 * triangle numbers renamed. The result does not depend on \a num_threads. */
void canonicalize(std::vector<Triangle>& triangles,
                  std::size_t num_points,
                  std::vector<Triangle>* neighbours = nullptr,
                  int num_threads = 1);

/** \brief Replaces the triangles of one co-circular group (a triangulated convex
 * polygon, \a group its triangle indices) by the fan from the polygon's
 * lexicographically smallest point. \a corners is scratch space. */
void refanGroup(const std::vector<QuantizedPoint>& points,
                const std::vector<index_t>& group,
                Triangle* triangles,
                std::vector<index_t>& corners);

/** \brief Exact Delaunay triangulation through the dual of Boost.Polygon's Voronoi
 * diagram, co-circular polygons split by the canonical fan rule.
 *
 * Expects distinct points within range (delaunay2d() checks). The triangles are
 * counter-clockwise but not in canonical order. Returns false, with a message, only if
 * the Voronoi diagram cannot be turned into a triangulation (an internal error).
 */
bool delaunayBoostVoronoi(const std::vector<QuantizedPoint>& points,
                          std::vector<Triangle>& triangles,
                          std::string* error);

/** \brief Exact Delaunay triangulation by an advancing-front sweep over the points in
 * lexicographic order (delaunay_2d_sweep.cpp), co-circular polygons split by the
 * canonical fan rule: the triangles of delaunayBoostVoronoi(), much faster.
 *
 * Expects coordinates within range (delaunay2d() checks). Unlike the other backends it
 * does the rest of delaunay2d()'s work itself: it finds duplicates while ordering the
 * points (same error as delaunay2d()), returns no triangles for fewer than three or
 * collinear points, and lists the triangles in canonical order. On inputs where the
 * sweep order is a bad insertion order (points along concave curves) it gives up after
 * a budget of flips and returns delaunayBoostVoronoi()'s triangles. With \a neighbours
 * it also gives the adjacency (computeTriangleNeighbours()'s result), read off the
 * sweep's half-edges.
 */
bool delaunaySweep(const std::vector<QuantizedPoint>& points,
                   std::vector<Triangle>& triangles,
                   std::vector<Triangle>* neighbours,
                   std::string* error,
                   int num_threads = 1);

/** \brief The path delaunaySweep() takes on several threads, with \a num_slabs slabs
 * whatever the number of points: the points, sorted lexicographically and distinct,
 * split into slabs between distinct x, each triangulated by the sweep, the triangles
 * whose circumdisks reach a neighbouring slab re-triangulated and stitched (see
 * delaunay_2d_sweep.cpp). Gives the canonical triangles and their adjacency, or false
 * (and nothing) where that path does not apply (a collinear slab, a slab over the
 * sweep's flip budget, unsorted points) or a check of the stitching fails;
 * delaunaySweep() then triangulates in one piece. For tests. */
bool delaunaySweepInSlabs(const std::vector<QuantizedPoint>& points,
                          int num_slabs,
                          std::vector<Triangle>& triangles,
                          std::vector<Triangle>& neighbours);

/** \brief Triangulation by vtkDelaunay2D (floating point), triangles oriented counter-
 * clockwise by the exact orientation, degenerate ones dropped, not in canonical order.
 *
 * Defined only when the library is built with VTK (PCL_SELSEG_HAVE_VTK).
 */
bool delaunayVtk(const std::vector<QuantizedPoint>& points,
                 std::vector<Triangle>& triangles,
                 std::string* error);

} // namespace detail
} // namespace selective_seg
} // namespace pcl
