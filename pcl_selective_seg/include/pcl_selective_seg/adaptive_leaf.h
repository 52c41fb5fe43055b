/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <Eigen/Core>
#include <pcl/octree/octree_key.h>

#include <cstddef>
#include <cstdint>

namespace pcl {
namespace selective_seg {

/** \brief A node of the multi-resolution octree taken as a leaf (a seed segment). */
struct AdaptiveLeaf {
  pcl::octree::OctreeKey key; ///< key of the node at its own depth
  std::uint32_t depth = 0;    ///< 0 = root
  std::size_t begin = 0;      ///< its points: getOrderedIndices()[begin, end)
  std::size_t end = 0;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero(); ///< N_v (eq. 4), input orientation
  /** Its index in the previous leaves when the octree kept it from them
   * (OctreePointCloudNormalVariance::keepLeavesFrom()); -1 for a leaf computed anew. */
  std::int32_t kept_from = -1;
  double area = 0.0;                                ///< A_v = sum of A_p (eq. 6)
  float sigma_theta = 0.0f;                         ///< eq. 5 [rad]
  float sigma_phi = 0.0f;                           ///< eq. 5 [rad]
};

} // namespace selective_seg
} // namespace pcl
