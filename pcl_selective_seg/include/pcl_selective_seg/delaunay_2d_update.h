/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>

#include <pcl/pcl_macros.h>

#include <string>
#include <vector>

namespace pcl {
namespace selective_seg {

/** \brief How insertDelaunayPoints() renumbered and changed a triangulation. */
struct DelaunayInsertion {
  /** \#V_old new id of each old point. Increasing: the old points keep their order. */
  std::vector<pcl::index_t> old_to_new_point;
  /** New ids of the inserted points, increasing. */
  std::vector<pcl::index_t> inserted_points;
  /** \#T_old new id of each old triangle, or -1 for one that the insertion replaced. */
  std::vector<pcl::index_t> old_to_new_triangle;
  /** New ids of the triangles that were not in the old triangulation, increasing. */
  std::vector<pcl::index_t> new_triangles;
  /** Old triangles replaced (their circumcircle holds a new point, or the hull grew
   * over them). */
  std::size_t replaced_triangles = 0;
  /** Points of the local triangulation that re-tiled the replaced region. */
  std::size_t local_points = 0;
};

/** \brief Insert points into an exact Delaunay triangulation with the canonical split
 * of co-circular points (the output of delaunay2d() with an exact backend), changing
 * only the region where the triangulation changes.
 *
 * The result is the triangulation delaunay2d() gives on the union of the points,
 * numbered as delaunay2d() numbers it when the points are sorted lexicographically (x,
 * then y), with the triangles in the same canonical order. Old triangles whose closed
 * circumcircle holds no new point, and that the convex hull does not grow over, are
 * kept; the replaced region is re-triangulated with the exact sweep over its points
 * and those around it, and stitched back in. Cost: linear passes over the arrays
 * (renumbering) plus the size of the changed region.
 *
 * \param[in,out] points the old points, sorted lexicographically and distinct; on
 *                success the union, sorted
 * \param[in,out] triangles the old triangles (canonical order); on success the union's
 * \param[in,out] neighbours the old adjacency (computeTriangleNeighbours()); on success
 *                the union's
 * \param[in] new_points points to insert: distinct, none equal to an old point, within
 *            kMaxDelaunayCoordinate; any order
 * \param[out] info the renumbering and what changed
 * \param[out] error why it failed (may be null)
 * \param[in] num_threads threads for the linear passes (the result is the same for any
 *            number)
 * \return false, inputs unchanged, on a precondition violation (unsorted or repeated
 *         points, out of range), on an old triangulation without triangles, or when
 *         the stitched result fails its consistency checks; the caller then
 *         triangulates the union from scratch.
 */
PCL_EXPORTS bool insertDelaunayPoints(std::vector<QuantizedPoint>& points,
                                      std::vector<Triangle>& triangles,
                                      std::vector<Triangle>& neighbours,
                                      std::vector<QuantizedPoint> new_points,
                                      DelaunayInsertion& info,
                                      std::string* error = nullptr,
                                      unsigned int num_threads = 1);

} // namespace selective_seg
} // namespace pcl
