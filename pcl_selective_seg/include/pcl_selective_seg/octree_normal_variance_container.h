/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/octree/octree_container.h>

#include <cstddef>

namespace pcl {
namespace selective_seg {

/** \brief Leaf container of OctreePointCloudNormalVariance: the point indices of one
 * finest voxel, plus where they start in the octree's depth-first ordering of all
 * points. With that ordering the points of every node, leaf or branch, form one
 * contiguous range, so the statistics of eq. 4-5 of any node are one pass over it. */
class OctreeNormalVarianceContainer : public pcl::octree::OctreeContainerPointIndices {
public:
  OctreeNormalVarianceContainer* deepCopy() const override
  {
    return new OctreeNormalVarianceContainer(*this);
  }

  void reset() override
  {
    pcl::octree::OctreeContainerPointIndices::reset();
    first_ = 0;
  }

  /** \brief Position of this voxel's first point in the depth-first ordering. */
  std::size_t getFirstOrderedPoint() const { return first_; }

  void setFirstOrderedPoint(std::size_t first) { first_ = first; }

private:
  std::size_t first_ = 0;
};

} // namespace selective_seg
} // namespace pcl
