/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/pcl_macros.h>
#include <pcl/types.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl {
namespace selective_seg {

/** \brief A point of the 2-D triangulation: integer coordinates on a fine grid.
 *
 * The triangulation works on quantized coordinates so that every predicate is exact.
 * Coordinates must satisfy |x|, |y| <= kMaxDelaunayCoordinate.
 */
using QuantizedPoint = std::array<std::int32_t, 2>;

/** \brief Largest absolute quantized coordinate accepted by delaunay2d() (2^26).
 *
 * Differences then fit in 28 bits and the in-circle determinant in a 128-bit integer.
 */
constexpr std::int32_t kMaxDelaunayCoordinate = 1 << 26;

namespace detail {
/** \brief The fewest items (triangles, vertices, sampled edges, list items) a loop of
 * the pipeline splits among threads; below it one thread is as fast. Measured on door
 * scans of 5k-46k points (docs/performance_notes.md, round 5 and session 17). No result
 * depends on it. */
constexpr std::size_t kMinParallelItems = 8192;
} // namespace detail

/** \brief A triangle as three vertex ids, counter-clockwise in the 2-D plane. */
using Triangle = std::array<pcl::index_t, 3>;

/** \brief Delaunay backends. */
enum class DelaunayBackend : std::uint8_t {
  /** Dual of Boost.Polygon's exact Voronoi diagram (default; BSD-compatible licence).
   */
  BoostVoronoi = 0,
  /** VTK's vtkDelaunay2D (the design's original choice). Available only when the
   * library was built with VTK (see isDelaunayBackendAvailable()). Floating point: it
   * may drop thin triangles along the hull (any triangle whose circumcircle reaches its
   * initial bounding triangulation, which can include triangles one layer inside the
   * hull) and does not split co-circular points by the canonical rule, so its output
   * can differ from the exact backends. It fails (false, with a message) on any error
   * vtkDelaunay2D reports and on a result that is no triangulation (an edge used twice
   * in one direction, or more than 2 n - 5 triangles). Not caught: on hand-made inputs
   * of a few points 1 apart beside points 2^26 away, vtkDelaunay2D recursed until the
   * stack overflowed (no scan has shown it; the ratio of extent to closest distance
   * does not predict it: a laser scan with a ratio of 3e7 triangulates). Use an exact
   * backend where that matters. */
  Vtk = 1,
  /** Our own incremental triangulation: an advancing front sweeps the points in
   * lexicographic order (x, then y), exact integer predicates throughout. Always
   * available. Gives exactly BoostVoronoi's triangles, an order of magnitude faster on
   * clouds (points sampling an area); input already sorted by (x, y), as the vertices
   * of SphericalDelaunay are, skips the sort. On inputs that are a bad insertion order
   * for a sweep (points along concave curves) it returns BoostVoronoi's triangles after
   * a bounded amount of work, so it is never much slower. See docs/delaunay.md. */
  Sweep = 2
};

/** \brief Human-readable backend name ("boost", "vtk", "sweep"). */
PCL_EXPORTS const char* toString(DelaunayBackend backend);

/** \brief Whether the backend was compiled into this build of the library. */
PCL_EXPORTS bool isDelaunayBackendAvailable(DelaunayBackend backend);

/** \brief Delaunay triangulation of distinct 2-D integer points.
 *
 * \param[in] points distinct points, |coordinate| <= kMaxDelaunayCoordinate.
 *            Duplicates are a precondition violation (the call fails with a message).
 * \param[in] backend which implementation to use.
 * \param[out] triangles vertex ids (indices into \a points), each triangle counter-
 *             clockwise, listed in canonical order: each triangle rotated so that its
 *             smallest vertex id comes first, the list sorted lexicographically. The
 *             result therefore depends only on the point coordinates and their ids.
 * \param[out] error reason for a failure (may be null).
 * \return false on a precondition violation, an unavailable backend or a failure of
 *         the Vtk backend (triangles empty). Fewer than three points, or all points
 * collinear, is not a failure: the result is then empty.
 *
 * Groups of four or more co-circular points (every regular grid has them) have no
 * unique Delaunay triangulation. The exact backends split each such empty circle's
 * polygon by a rule that depends only on the coordinates: a fan from the polygon's
 * lexicographically smallest point (smallest x, then smallest y). Point ids do not
 * matter, so a permuted input gives the same triangles up to the renaming of the ids.
 */
PCL_EXPORTS bool delaunay2d(const std::vector<QuantizedPoint>& points,
                            DelaunayBackend backend,
                            std::vector<Triangle>& triangles,
                            std::string* error = nullptr);

/** \brief delaunay2d() with the triangle adjacency (computeTriangleNeighbours()'s
 * result, \a neighbours). The Sweep backend reads it off its own half-edges, which
 * costs a fraction of computing it afterwards; the other backends compute it (with \a
 * num_threads threads). */
PCL_EXPORTS bool delaunay2d(const std::vector<QuantizedPoint>& points,
                            DelaunayBackend backend,
                            std::vector<Triangle>& triangles,
                            std::vector<Triangle>& neighbours,
                            std::string* error = nullptr,
                            unsigned int num_threads = 1);

/** \brief Triangle adjacency of a triangle mesh.
 *
 * \param[in] triangles triangles over vertex ids 0..num_vertices-1, consistently
 * oriented. \param[in] num_vertices number of vertices. \param[out] neighbours
 * neighbours[t][i] is the triangle sharing the edge opposite vertex i of triangle t
 * (the edge triangles[t][(i+1)%3] - triangles[t][(i+2)%3]), or -1 on the boundary.
 * \param[in] num_threads threads for the lookups (the result does not depend on it).
 */
PCL_EXPORTS void computeTriangleNeighbours(const std::vector<Triangle>& triangles,
                                           std::size_t num_vertices,
                                           std::vector<Triangle>& neighbours,
                                           unsigned int num_threads = 1);

} // namespace selective_seg
} // namespace pcl
