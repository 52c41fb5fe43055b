/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <pcl/pcl_macros.h>

#include <vector>

namespace pcl {
namespace selective_seg {

/** \brief 3-vectors (Eigen::Vector3f needs no aligned allocator). */
using Vector3fVector = std::vector<Eigen::Vector3f>;

// Inputs every function below checks, with a PCL_ERROR and empty outputs (in-place
// arrays left as they were; medianEdgeLength() gives NaN) when they do not hold: a
// triangle's vertex ids are below the number of vertices the function is given
// (num_vertices, or the size of its per-vertex arrays); per-triangle inputs have one
// entry per triangle; triangle ids (changed triangles, old_to_new, neighbours) are
// below the number of triangles, or negative (none) where documented; rings >= 1;
// max_incidence >= 0 (not NaN). The id checks are one pass over the ids, on both
// cores for large meshes (about 0.03 ms for 90,000 triangles, 0.7 ms for 2 million);
// SelectiveSegmentation skips them on its own meshes (detail::TrustedMeshScope).
// Not checked: the values themselves (NaN positions or normals give NaN results, as
// documented for each function).

/** \brief Unit normal and 3-D area of each triangle (paper, Sec. III.B).
 *
 * \param[in] positions \#V vertex positions [m]
 * \param[in] triangles \#T triangles over vertex ids
 * \param[in] viewpoint sensor origin in the frame of \a positions [m]; each normal is
 *            oriented toward it (n . (centroid - viewpoint) <= 0)
 * \param[out] normals \#T unit normals; NaN for a degenerate triangle: zero or
 *             non-finite area, or flat at float precision (smallest height 2 A_t /
 *             L_max at most 2 FLT_EPSILON max |corner|: within the rounding of its
 *             float corners it may be collinear, so its normal is not determined;
 *             such slivers appear where rows of a pixel grid are straight lines)
 * \param[out] areas \#T areas A_t [m^2], computed in double precision (finite for any
 *             finite float input; a flat triangle keeps its area)
 */
PCL_EXPORTS void computeTriangleNormals(const Vector3fVector& positions,
                                        const std::vector<Triangle>& triangles,
                                        const Eigen::Vector3f& viewpoint,
                                        Vector3fVector& normals,
                                        std::vector<double>& areas,
                                        int num_threads = 0);

/** \brief Point normals (eq. 2) and point areas (eq. 3).
 *
 * N_p = normalize(sum over incident triangles t of N_t / A_t); triangles with zero or
 * non-finite area or normal are skipped. A_p = sum of A_t over the incident triangles.
 *
 * \param[in] num_vertices \#V
 * \param[in] triangles \#T triangles over vertex ids
 * \param[in] normals \#T triangle normals, from computeTriangleNormals()
 * \param[in] areas \#T triangle areas [m^2]
 * \param[out] vertex_normals \#V unit normals; NaN where no valid triangle is incident
 *             or the weighted normals cancel
 * \param[out] vertex_areas \#V areas A_p [m^2]
 * \param[in] num_threads OpenMP threads, 0 = defaultThreads() (the result does
 *            not depend on it)
 * \param[in] neighbours optional: the adjacency of \a triangles
 *            (computeTriangleNeighbours()). Each triangle's terms are added to its
 *            vertices in increasing triangle order: the same sums in the same order as
 *            gathering them per vertex, so the same bits. Large meshes are split among
 *            the threads when the adjacency is given and the triangles come in
 *            delaunay2d()'s canonical order (by smallest vertex); without them the
 *            sums of a large mesh are gathered through vertex -> triangle lists on all
 *            threads (the same bits again). A vertex shared by two threads' triangles
 *            is summed over the triangles found by walking the adjacency around it, or,
 *            when they are fewer than its corners (separate fans meeting at the vertex:
 *            not in a Delaunay mesh), over those found by a pass over the mesh; the
 *            same bits for any mesh. On one thread or below
 *            detail::kMinParallelItems triangles the pass is sequential, for any
 *            triangle order.
 */
PCL_EXPORTS void computeVertexNormals(std::size_t num_vertices,
                                      const std::vector<Triangle>& triangles,
                                      const Vector3fVector& normals,
                                      const std::vector<double>& areas,
                                      Vector3fVector& vertex_normals,
                                      std::vector<double>& vertex_areas,
                                      int num_threads = 0,
                                      const std::vector<Triangle>* neighbours = nullptr);

/** \brief Point normals over a wider neighbourhood: eq. 2 summed over the triangles of
 * the k-ring of each vertex instead of its one ring.
 *
 * N_p = normalize(sum over the triangles with a vertex at most rings - 1 edges from p
 * of N_t / A_t). rings = 1 is eq. 2 exactly. The 1 / area weights keep triangles that
 * span depth jumps (huge in 3-D) from blurring the normals across occlusion edges.
 *
 * \param[in] num_vertices \#V
 * \param[in] triangles \#T triangles over vertex ids
 * \param[in] normals \#T triangle normals
 * \param[in] areas \#T triangle areas [m^2]
 * \param[in] rings k >= 1
 * \param[out] vertex_normals \#V unit normals; NaN where no valid triangle is found
 */
PCL_EXPORTS void computeVertexNormalsOverRings(std::size_t num_vertices,
                                               const std::vector<Triangle>& triangles,
                                               const Vector3fVector& normals,
                                               const std::vector<double>& areas,
                                               int rings,
                                               Vector3fVector& vertex_normals);

/** \brief The triangle normals eq. 2 sums under PointNormalTriangles::NotEdgeOn:
 * \a normals with those of the triangles flagged in \a edge_on set to NaN, so that
 * computeVertexNormals() and its variants skip them (their areas still count in A_p).
 * Follow with fillMissingVertexNormals().
 * \param[in] normals \#T triangle normals
 * \param[in] edge_on \#T flags (markEdgeOnTriangles())
 * \param[out] masked \#T normals
 * \param[in] num_threads OpenMP threads, 0 = defaultThreads() */
PCL_EXPORTS void maskEdgeOnNormals(const Vector3fVector& normals,
                                   const std::vector<std::uint8_t>& edge_on,
                                   Vector3fVector& masked,
                                   int num_threads = 0);

/** \brief The vertices that the masked normals (maskEdgeOnNormals()) left without a
 * normal get eq. 2 over all their triangles: where every triangle at a vertex is seen
 * edge-on, the paper's normal.
 *
 * Each vertex whose normal is NaN gets the normal computeVertexNormals() (rings = 1)
 * or computeVertexNormalsOverRings() gives it from \a normals, bit for bit; it stays
 * NaN where those give none. The other vertices are not touched.
 * \param[in] triangles \#T triangles over vertex ids
 * \param[in] normals \#T triangle normals, none masked
 * \param[in] areas \#T triangle areas [m^2]
 * \param[in] rings k >= 1, as the normals were computed with
 * \param[in,out] vertex_normals \#V unit normals or NaN
 * \param[in] num_threads OpenMP threads, 0 = defaultThreads() (the result does not
 *            depend on it)
 * \return the number of vertices given a normal */
PCL_EXPORTS std::size_t fillMissingVertexNormals(const std::vector<Triangle>& triangles,
                                                 const Vector3fVector& normals,
                                                 const std::vector<double>& areas,
                                                 int rings,
                                                 Vector3fVector& vertex_normals,
                                                 int num_threads = 0);

/** \brief Triangle normals as the normalized mean of their vertices' normals.
 * \param[in] triangles \#T triangles over vertex ids
 * \param[in] vertex_normals \#V unit normals (NaN: no normal)
 * \param[out] normals \#T unit normals; NaN when a vertex has none or they cancel */
PCL_EXPORTS void
computeTriangleNormalsFromVertices(const std::vector<Triangle>& triangles,
                                   const Vector3fVector& vertex_normals,
                                   Vector3fVector& normals);

/** \brief Flag the triangles seen edge-on from the viewpoint.
 *
 * A triangle whose normal makes more than \a max_incidence with the line of sight to
 * its centroid spans a depth discontinuity rather than a surface.
 *
 * \param[in] positions \#V vertex positions [m]
 * \param[in] triangles \#T triangles
 * \param[in] normals \#T unit normals (NaN: degenerate, flagged)
 * \param[in] viewpoint sensor origin [m]
 * \param[in] max_incidence [rad]; pi/2 or more flags only degenerate triangles
 * \param[out] edge_on \#T 1 = seen edge-on
 * \param[in] num_threads OpenMP threads, 0 = defaultThreads()
 */
PCL_EXPORTS void markEdgeOnTriangles(const Vector3fVector& positions,
                                     const std::vector<Triangle>& triangles,
                                     const Vector3fVector& normals,
                                     const Eigen::Vector3f& viewpoint,
                                     double max_incidence,
                                     std::vector<std::uint8_t>& edge_on,
                                     int num_threads = 0);

/** \brief computeTriangleNormals() and markEdgeOnTriangles() in one pass over the
 * triangles (the same normals, areas and flags).
 * \param[in] max_incidence [rad], as markEdgeOnTriangles() */
PCL_EXPORTS void computeTriangleNormalsAndEdgeOn(const Vector3fVector& positions,
                                                 const std::vector<Triangle>& triangles,
                                                 const Eigen::Vector3f& viewpoint,
                                                 double max_incidence,
                                                 Vector3fVector& normals,
                                                 std::vector<double>& areas,
                                                 std::vector<std::uint8_t>& edge_on,
                                                 int num_threads = 0);

/** \brief computeTriangleNormalsAndEdgeOn() after a local change of the mesh: the
 * values of the kept triangles are moved from the old arrays, those of the triangles in
 * \a changed computed again.
 *
 * \param[in] old_to_new \#T_old new id of each old triangle, -1 if it is gone
 * \param[in] changed new ids of the triangles to compute (the new triangles and any
 *            whose corners moved); every other new triangle must have an old one
 * \param[in,out] normals,areas,edge_on on input the old arrays (\#T_old), on output the
 *                new ones (\#T), as computeTriangleNormalsAndEdgeOn() gives them */
PCL_EXPORTS void updateTriangleNormalsAndEdgeOn(const Vector3fVector& positions,
                                                const std::vector<Triangle>& triangles,
                                                const Eigen::Vector3f& viewpoint,
                                                double max_incidence,
                                                const std::vector<pcl::index_t>& old_to_new,
                                                const std::vector<pcl::index_t>& changed,
                                                Vector3fVector& normals,
                                                std::vector<double>& areas,
                                                std::vector<std::uint8_t>& edge_on,
                                                int num_threads = 0);

/** \brief Recompute, after a local change of the mesh, the vertex normals and areas
 * (eq. 2-3) of the changed triangles' vertices, from the triangle normals and areas of
 * the whole mesh; the other vertices' values are taken as valid. Gives the values
 * computeVertexNormals() computes on the whole mesh, bit for bit (each vertex's
 * triangles, found through the adjacency, are summed in increasing order), where each
 * vertex's triangles form one fan (every Delaunay mesh; at a vertex where separate fans
 * meet only the fan of the changed triangle is summed).
 * \param[in] neighbours the triangle adjacency (computeTriangleNeighbours())
 * \param[in] changed_triangles triangles whose corners or corner positions changed
 * \param[in,out] vertex_normals, vertex_areas per vertex, sized for the mesh */
PCL_EXPORTS void updateVertexNormals(const std::vector<Triangle>& triangles,
                                     const std::vector<Triangle>& neighbours,
                                     const Vector3fVector& normals,
                                     const std::vector<double>& areas,
                                     const std::vector<pcl::index_t>& changed_triangles,
                                     Vector3fVector& vertex_normals,
                                     std::vector<double>& vertex_areas,
                                     int num_threads = 0);

/** \brief After updateVertexNormals(), the k-ring vertex normals (as
 * computeVertexNormalsOverRings() gives them, bit for bit) of the vertices whose k-ring
 * holds a changed triangle; the others are taken as valid.
 * \param[in,out] vertex_normals per vertex, sized for the mesh */
PCL_EXPORTS void
updateVertexNormalsOverRings(const std::vector<Triangle>& triangles,
                             const std::vector<Triangle>& neighbours,
                             const Vector3fVector& normals,
                             const std::vector<double>& areas,
                             int rings,
                             const std::vector<pcl::index_t>& changed_triangles,
                             Vector3fVector& vertex_normals);

/** \brief Median 3-D length of the triangles' edges [m] (each interior edge counted
 * twice; over 100,000 triangles, those of every stride-th triangle, stride =
 * triangles / 100,000); 0 for an empty mesh, NaN (with a PCL_ERROR) for a triangle
 * naming a vertex beyond the positions. The octree's automatic minimum voxel size
 * scales it. Threads: 0 = defaultThreads(); the result does not depend on them. */
PCL_EXPORTS double medianEdgeLength(const Vector3fVector& positions,
                                    const std::vector<Triangle>& triangles,
                                    int num_threads = 1);

} // namespace selective_seg
} // namespace pcl
