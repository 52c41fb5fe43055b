/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/adaptive_leaf.h>
#include <pcl_selective_seg/mesh_normals.h>
#include <pcl_selective_seg/parameters.h>
#include <pcl_selective_seg/segmentation_result.h>

#include <pcl/PointIndices.h>
#include <pcl/types.h>

#include <vector>

namespace pcl {
namespace selective_seg {

/** \brief A previous merge whose segments the seed merging may take over as they were
 * instead of growing them again (SelectiveSegmentation::update()).
 *
 * A previous segment S is taken over at its seed's turn when (1) every leaf of S is a
 * leaf of this merge unchanged: the same vertices with the same normals and areas, so
 * the same leaf normal and area, and the same triangles at its vertices, with the same
 * facet normals and edge-on flags, in the same relative order; (2) all of S's leaves
 * are free; (3) every other leaf that shares a listed triangle with a leaf of S is
 * held when it is changed or when its previous segment is numbered below S (it was
 * held when S grew). S's growth reads nothing else: a leaf of a later previous segment
 * was free when S grew and was not taken, and whether it is free or held now it is not
 * taken either. So the growth would make S's decisions in S's order and end with S's
 * normal: taking S over gives the merge's result bit for bit. The caller vouches for
 * (1) and for the merge parameters (the same angles and weights, facet normals for the
 * edge test); the merging checks (2) and (3) at each seed's turn. Arrays of the wrong
 * size, or a leaf's segment beyond the segments given, make it ignored: every segment
 * grows.
 */
struct MergeReplay {
  /** \#L of this merge: the previous segment (its number) of each unchanged leaf, -1
   * for a changed leaf. */
  const std::vector<pcl::index_t>* leaf_segment = nullptr;
  /** \#S of the previous merge: the seed of each previous segment whose leaves are
   * all unchanged, as a leaf of this merge; -1 for the others. */
  const std::vector<pcl::index_t>* segment_seed = nullptr;
  /** \#S of the previous merge: its segment normals (the merge's output). */
  const Vector3fVector* segment_normals = nullptr;
  /** Output: the segments taken over. */
  std::size_t num_replayed = 0;
};

/** \brief Inputs of the seed merging (paper, Sec. III.D), as parallel arrays. */
struct MergeInput {
  const Vector3fVector* leaf_normals = nullptr; ///< \#L unit voxel normals N_v (eq. 4)
  /** \#L voxel areas A_v (eq. 6) [m^2] */
  const std::vector<double>* leaf_areas = nullptr;
  /** Instead of leaf_normals and leaf_areas (then unused): the octree's leaves, whose
   * normal and area fields are read in place. */
  const std::vector<AdaptiveLeaf>* leaves = nullptr;
  const std::vector<pcl::index_t>* vertex_leaf =
      nullptr; ///< \#V leaf of each vertex, -1: none
  const std::vector<Triangle>* triangles = nullptr; ///< \#T triangles over vertex ids
  const Vector3fVector* triangle_normals =
      nullptr; ///< \#T unit normals, NaN if degenerate
  /** \#T optional: 1 for a triangle seen edge-on (a depth discontinuity), never valid.
   */
  const std::vector<std::uint8_t>* triangle_edge_on = nullptr;
  double max_merge_angle = 0.0;         ///< eq. 9 threshold [rad]
  /** Weight of a leaf's normal in eq. 7: 1 / A_v (the paper) or A_v. */
  SegmentNormalWeight segment_normal_weight = SegmentNormalWeight::InverseArea;
  double max_edge_triangle_angle = 0.0; ///< eq. 8 threshold [rad]
  /** Which segments a growing segment merges with: the free seeds only (Seeds), or
   * also the segments grown before it (Segments: one thread, no replay). */
  MergeWith merge_with = MergeWith::Seeds;
  /** Threads for building the incidence lists and for growing seeds ahead of their
   * turn (0: defaultThreads()). The result does not depend on it. */
  int num_threads = 1;
  /** Optional: a previous merge whose unchanged segments are taken over (MergeReplay);
   * the result is the same as without it. */
  MergeReplay* replay = nullptr;
};

/** \brief Merge the seed segments (octree leaves) across valid edge triangles.
 *
 * Seeds are taken in a fixed order, largest first (by number of vertices, ties by leaf
 * index, i.e. octree position), so the result depends on the data only. An unassigned
 * seed starts a segment S_k, which grows breadth first: for every triangle at a vertex
 * of a seed of S_k that has a vertex outside S_k (an edge triangle) and whose normal is
 * within max_edge_triangle_angle of N_Sk (valid edge, eq. 8), each unassigned seed at
 * its vertices joins S_k when its normal is within max_merge_angle of N_Sk (eq. 9-10).
 * N_Sk is the normalized sum of N_v / A_v (N_v A_v with segment_normal_weight = Area)
 * over its seeds (eq. 7), updated at every join. Each seed joins once and each triangle
 * is examined at most once per leaf of its vertices: linear in the mesh size.
 *
 * With merge_with = MergeWith::Segments, a segment grown before S_k that holds a vertex
 * of such a valid edge triangle is absorbed when its normal is within max_merge_angle
 * of N_Sk: its leaves join S_k and its eq. 7 sum is added to S_k's (its leaves are not
 * searched again: they were when it grew, which keeps the merge linear). The segments
 * left keep their creation order. One thread, and no replay.
 *
 * With several threads and at least 1,024 leaves, the threads grow seeds ahead of
 * their turn, each over its own part of the leaves, and a segment so grown is kept
 * only when the state it met is the one the sequential growth meets (otherwise it
 * grows again in turn): the result is the one-thread result, bit for bit
 * (docs/performance_history.md, "Round 6").
 *
 * \param[in] input the seeds and the mesh. A missing array, arrays whose sizes
 *            disagree, an angle outside [0, pi] (NaN included), a triangle's vertex id
 *            not below \#V (vertex_leaf's size) or a vertex_leaf entry not below \#L
 *            (negative: no leaf) give a PCL_ERROR and empty outputs.
 * \param[out] leaf_segment \#L segment id of each seed, 0..#S-1 in creation order
 * \param[out] segment_normals \#S unit segment normals N_S (eq. 7)
 */
PCL_EXPORTS void mergeSeedSegments(const MergeInput& input,
                                   std::vector<pcl::index_t>& leaf_segment,
                                   Vector3fVector& segment_normals);

/** \brief The order in which mergeSeedSegments() takes the seeds: most vertices first,
 * ties by leaf index. A segment grows from its leaf that comes first in this order,
 * and the segments grow (and are numbered) in the order of their seeds.
 *
 * \param[in] vertex_leaf \#V leaf of each vertex, -1: none
 * \param[in] num_leaves \#L
 * \return the leaves in that order; empty, with a PCL_ERROR, when a vertex_leaf
 *         entry is not below num_leaves
 */
PCL_EXPORTS std::vector<pcl::index_t>
seedOrder(const std::vector<pcl::index_t>& vertex_leaf, std::size_t num_leaves);

/** \brief Label and class of each triangle (eq. 8) from the final vertex labels.
 *
 * Interior: three vertices with one label. Otherwise the triangle takes the label,
 * among its vertices', whose segment normal is closest to its own normal (ties, and
 * every label of a degenerate triangle: the smallest label), and is a valid edge when
 * that angle is at most max_edge_triangle_angle and it is not seen edge-on, an
 * invalid edge otherwise.
 *
 * \param[in] triangles \#T triangles over vertex ids
 * \param[in] triangle_normals \#T unit normals (NaN: degenerate, never a valid edge)
 * \param[in] triangle_edge_on \#T 1 where seen edge-on (never a valid edge), or null
 * \param[in] vertex_labels \#V labels, 0 = unlabeled
 * \param[in] label_normals normal of label l at [l - 1]
 * \param[in] max_edge_triangle_angle [rad], in [0, pi]
 * \param[out] labels \#T labels (0 when no vertex is labeled)
 * \param[out] classes \#T classes
 *
 * Per-triangle arrays of another size, an angle outside [0, pi] (NaN included), a
 * vertex id not below vertex_labels' size or a vertex label above label_normals' size
 * give a PCL_ERROR and empty outputs.
 * \param[in] num_threads threads (0: defaultThreads()); the result does not
 *            depend on it
 */
PCL_EXPORTS void classifyTriangles(const std::vector<Triangle>& triangles,
                                   const Vector3fVector& triangle_normals,
                                   const std::vector<std::uint8_t>* triangle_edge_on,
                                   const std::vector<std::uint32_t>& vertex_labels,
                                   const Vector3fVector& label_normals,
                                   double max_edge_triangle_angle,
                                   std::vector<std::uint32_t>& labels,
                                   std::vector<TriangleClass>& classes,
                                   int num_threads = 1);

/** \brief Compressed incidence lists: the items of group g are
 * items[offsets[g] .. offsets[g + 1]), in increasing item order.
 * \param[in] group_of group of each item, negative = none
 * \param[in] num_groups number of groups (a group_of entry not below it: a
 *            PCL_ERROR, and every group empty) */
struct PCL_EXPORTS Incidence {
  std::vector<std::size_t> offsets;
  std::vector<pcl::index_t> items;

  static Incidence build(const std::vector<pcl::index_t>& group_of,
                         std::size_t num_groups);
};

/** \brief The points of each label: clusters[l - 1].indices lists the i with labels[i]
 * == l, in increasing order, for l = 1 .. num_labels (label 0, and labels above
 * num_labels, are left out). Headers are left as they are.
 * \param[in] num_threads threads (0: defaultThreads()); the result does not
 *            depend on it */
PCL_EXPORTS void clustersFromLabels(const std::vector<std::uint32_t>& labels,
                                    std::size_t num_labels,
                                    std::vector<pcl::PointIndices>& clusters,
                                    int num_threads = 1);

/** \brief Triangles at each vertex, in increasing triangle order (a triangle naming
 * a vertex not below num_vertices: a PCL_ERROR, and every list empty).
 * \param[in] num_threads threads (0: defaultThreads()); the result does not
 *            depend on it */
PCL_EXPORTS Incidence vertexTriangles(const std::vector<Triangle>& triangles,
                                      std::size_t num_vertices,
                                      int num_threads = 1);

} // namespace selective_seg
} // namespace pcl
