/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/impl/selective_segmentation.hpp>
#include <pcl_selective_seg/point_types.h>

#include <pcl/impl/instantiate.hpp>

PCL_INSTANTIATE(SelectiveSegmentation, PCL_SELSEG_POINT_TYPES)
