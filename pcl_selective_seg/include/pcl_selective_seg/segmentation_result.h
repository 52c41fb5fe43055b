/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>

#include <Eigen/Core>
#include <pcl/memory.h>
#include <pcl/pcl_macros.h>
#include <pcl/types.h>

#include <cstdint>
#include <vector>

namespace pcl {
namespace selective_seg {

/** \brief Class of a mesh triangle with respect to the segmentation (eq. 8). */
enum class TriangleClass : std::uint8_t {
  /** All three vertices in one segment (T_I). */
  Interior = 0,
  /** Not interior (vertices in several segments, or a vertex without a label), normal
   * within max_edge_triangle_angle of the normal of one of its vertices' segments, and
   * not seen edge-on (max_view_incidence_angle) (T_VE): the surface continues across
   * it. */
  ValidEdge = 1,
  /** Not interior, and normal far from all its vertices' segments, or seen edge-on, or
   * degenerate, or without any labeled vertex (T_IE): the triangle spans a transition
   * region (an edge, a depth jump). */
  InvalidEdge = 2
};

/** \brief Wall-clock time of each stage [s], the columns of the paper's Table I. */
struct StageTimings {
  double delaunay =
      0.0; ///< spherical projection, quantization, triangulation, adjacency
  double normals = 0.0; ///< triangle normals and areas, point normals (eq. 2, 3)
  double octree = 0.0;  ///< octree build and adaptive subdivision (eq. 4, 5)
  double merge = 0.0;   ///< seed merging (eq. 6-10) and output labels
  double total = 0.0;   ///< the whole extract() call
};

/** \brief What happened to the input points. Every input point is counted once in
 * exactly one of the first five fields. */
struct PointCounts {
  std::size_t outside_indices = 0; ///< not listed in the indices (label 0)
  std::size_t non_finite = 0;      ///< NaN or Inf coordinate (label 0)
  /** No image (label 0): z <= 0 in the sensor frame (forward projection), or at the
   * sensor's own position (panoramic). */
  std::size_t behind_sensor = 0;
  /** No triangle, or only degenerate ones, around it (label 0). Without a triangle:
   * with the panoramic projection, an outlying point at the top or bottom of the view
   * (delaunay2dPeriodic()). */
  std::size_t without_normal = 0;
  std::size_t labeled = 0;         ///< given a segment label > 0
  /// Of the labeled: points on the same quantized angles as a nearer point, which
  /// represents their shared mesh vertex (the representative itself is not counted:
  /// two points on one vertex count 1); they take that vertex's label.
  std::size_t shared_vertex = 0;
};

/** \brief A leaf of the multi-resolution octree: a seed segment. */
struct OctreeLeaf {
  /** Voxel centre, cloud frame [m]. The voxel's axes are the sensor's axes. */
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  float size = 0.0f;                                ///< voxel edge length [m]
  std::uint32_t depth = 0;                          ///< depth in the octree (root = 0)
  std::uint32_t label = 0;                          ///< segment label of its points
  Eigen::Vector3f normal = Eigen::Vector3f::Zero(); ///< N_v (eq. 4), toward the sensor
  float sigma_theta = 0.0f;                         ///< sigma_v,theta (eq. 5) [rad]
  float sigma_phi = 0.0f;                           ///< sigma_v,phi (eq. 5) [rad]
  double area = 0.0;                                ///< A_v (eq. 6) [m^2]
  std::uint32_t num_points = 0;                     ///< mesh vertices in the leaf
};

/** \brief A segment of the result. */
struct Segment {
  /** label >= 1; labels are ranked by size (num_points), largest first; segments of one
   * size in the order they grew (the order of their first leaves in seedOrder()). */
  std::uint32_t label = 0;
  std::size_t num_points = 0; ///< input points with this label
  Eigen::Vector3f normal = Eigen::Vector3f::Zero(); ///< N_S (eq. 7), toward the sensor
  /** N_S in the sensor frame, as the merge computed it (normal is it turned to the
   * cloud frame); update() takes segments over with it. */
  Eigen::Vector3f sensor_normal = Eigen::Vector3f::Zero();
  double area = 0.0;          ///< sum of A_v over its leaves [m^2]
  std::size_t num_leaves = 0; ///< octree leaves merged into it
};

/** \brief The segmented mesh: triangles over input point indices. */
struct SegmentedMesh {
  /** Vertex of each triangle as an input point index (the point representing the mesh
   * vertex), counter-clockwise in (theta, phi). */
  std::vector<Triangle> triangles;
  /** Triangle across the edge opposite each vertex, -1 on the mesh boundary. */
  std::vector<Triangle> neighbours;
  std::vector<std::uint32_t> labels;  ///< per triangle: a segment label, 0 = none
  std::vector<TriangleClass> classes; ///< per triangle, eq. 8
  /** Unit normal per triangle, cloud frame, toward the sensor; NaN when degenerate. */
  std::vector<Eigen::Vector3f> normals;
  std::vector<double> areas; ///< 3-D area per triangle [m^2]
};

/** \brief Everything SelectiveSegmentation::extract() computes besides the clouds. */
struct SegmentationResult {
  /** One label per input point (input order), 0 = unlabeled. */
  std::vector<std::uint32_t> labels;
  std::vector<Segment> segments;  ///< ordered by label: segments[i].label == i + 1
  std::vector<OctreeLeaf> leaves; ///< the labeled multi-resolution octree leaves
  SegmentedMesh mesh;
  PointCounts counts;
  StageTimings timings;
  std::size_t num_vertices = 0; ///< mesh vertices (distinct quantized angles)
  double min_voxel_size = 0.0;  ///< the octree's finest voxel edge actually used [m]
  /// Median 3-D edge length of the mesh [m]; over 100,000 triangles, the median over
  /// every k-th triangle's edges, k = triangles / 100,000 (a fixed sample).
  double median_spacing = 0.0;

  void clear() { *this = SegmentationResult(); }
};

} // namespace selective_seg
} // namespace pcl
