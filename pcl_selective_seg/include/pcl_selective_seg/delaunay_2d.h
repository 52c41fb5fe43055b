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
 * scans of 5k-46k points (docs/performance_history.md, "Round 5" and "passes from 8,192
 * points (session 17)"). No result depends on it. */
constexpr std::size_t kMinParallelItems = 8192;
} // namespace detail

/** \brief A triangle as three vertex ids, counter-clockwise in the 2-D plane. */
using Triangle = std::array<pcl::index_t, 3>;

/** \brief Delaunay backends. */
enum class DelaunayBackend : std::uint8_t {
  /** Dual of Boost.Polygon's exact Voronoi diagram (BSD-compatible licence): the same
   * triangles as Sweep, several times slower. Sweep is the default. */
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

/** \brief Delaunay triangulation of distinct points on a cylinder: x is periodic.
 *
 * The points are triangulated in a strip that repeats those within a margin of either
 * end on the other side (x +- \a period), with two periodic rows of 64 sentinels a
 * sixty-fourth of the period below and above the points; a triangle is kept when no
 * corner is a sentinel and the lexicographically smallest corner is one of the points
 * themselves, and named over their ids. The sentinels stand in for the points' own
 * lower and upper hulls, rows of nearly equal y whose slivers have circles far wider
 * than any margin: the mesh ends where the points end, without those slivers, and a
 * point that only a sentinel's triangles reach (an outlier at the top or bottom) has
 * no triangle. When \a closed, every triangle is a Delaunay triangle of the points on
 * the cylinder: its circle is empty of the points, their copies and the sentinels. The
 * margin starts at period / 32 and doubles, up to period / 2 (from twice the widest gap
 * between the points' x, when larger), until the kept triangles close the cylinder for
 * certain: every triangle narrower than half the period (so that its edges are edges of
 * the cylinder, not of a copy) and the part of its circle between the sentinel rows
 * inside the strip (the strip holds every copy there, so the circle is empty on the
 * cylinder: computed from exact determinants, with a slack); no directed edge used
 * twice; every boundary loop winding once around the cylinder (a seam left open or a
 * hole makes a loop that does not); and every triangle near the seam Delaunay against
 * its neighbours (exact in-circle tests). A gap of half the period or more between
 * neighbouring x cannot be closed: the result is then the planar one at once. A
 * triangle wider than the period (two of its corners one point: where one point rises
 * above all others, the hull runs from it to its own copy) is left out. Inside the
 * strip the triangulation is delaunay2d()'s, co-circular points included: the canonical
 * fan rule depends on coordinate differences only, so it splits a group the same way on
 * both sides of the seam.
 *
 * \param[in] points distinct points with x in [-period / 2, period / 2), |y| <=
 *            kMaxDelaunayCoordinate - max(1, period / 64) (integer division)
 * \param[in] period an even number in [4, kMaxDelaunayCoordinate]
 * \param[in] backend BoostVoronoi or Sweep (an exact backend)
 * \param[out] triangles counter-clockwise, in canonical order (as delaunay2d())
 * \param[out] neighbours the adjacency (computeTriangleNeighbours()), -1 only along
 *             the open ends of the cylinder (the smallest and largest y)
 * \param[out] closed whether the triangulation closes around the cylinder. When no
 *             margin up to period / 2 gives a closed triangulation (points too few
 *             or too far apart for it, a gap of half the period, a spread in y
 *             that no margin covers), the result is delaunay2d() of the points in
 *             the plane, open at the seam, and \a closed is false.
 * \param[out] error the reason for a failure (may be null)
 * \param[in] num_threads threads of the adjacency (the result does not depend on it)
 * \return false on a precondition violation (range, duplicates, period, backend). */
PCL_EXPORTS bool delaunay2dPeriodic(const std::vector<QuantizedPoint>& points,
                                    std::int32_t period,
                                    DelaunayBackend backend,
                                    std::vector<Triangle>& triangles,
                                    std::vector<Triangle>& neighbours,
                                    bool& closed,
                                    std::string* error = nullptr,
                                    unsigned int num_threads = 1);

/** \brief Triangle adjacency of a triangle mesh.
 *
 * \param[in] triangles triangles over vertex ids 0..num_vertices-1, consistently
 * oriented. \param[in] num_vertices number of vertices. \param[out] neighbours
 * neighbours[t][i] is the triangle sharing the edge opposite vertex i of triangle t
 * (the edge triangles[t][(i+1)%3] - triangles[t][(i+2)%3]), or -1 on the boundary.
 * \param[in] num_threads threads for the lookups (the result does not depend on it).
 * A vertex id not below num_vertices gives a PCL_ERROR and no neighbours.
 */
PCL_EXPORTS void computeTriangleNeighbours(const std::vector<Triangle>& triangles,
                                           std::size_t num_vertices,
                                           std::vector<Triangle>& neighbours,
                                           unsigned int num_threads = 1);

} // namespace selective_seg
} // namespace pcl
