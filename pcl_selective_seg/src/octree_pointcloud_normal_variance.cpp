/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/octree_pointcloud_normal_variance.h>
#include <pcl_selective_seg/point_types.h>

#include <pcl/impl/instantiate.hpp>

// The header always includes the bodies (custom-container octrees are usually compiled
// by their users); these instantiations are compiled once here and checked.
#define PCL_INSTANTIATE_OctreePointCloudNormalVariance(T)                              \
  template class PCL_EXPORTS pcl::selective_seg::OctreePointCloudNormalVariance<T>;

PCL_INSTANTIATE(OctreePointCloudNormalVariance, PCL_SELSEG_POINT_TYPES)
