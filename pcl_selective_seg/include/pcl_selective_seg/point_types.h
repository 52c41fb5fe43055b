/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/point_types.h>

/** \brief The point types for which the library's templates are instantiated (PCL's
 * common XYZ types). Other types work with PCL_NO_PRECOMPILE defined. */
#define PCL_SELSEG_POINT_TYPES                                                         \
  (pcl::PointXYZ)(pcl::PointXYZI)(pcl::PointXYZL)(pcl::PointXYZRGB)(                   \
      pcl::PointXYZRGBA)(pcl::PointXYZRGBL)(pcl::PointXYZRGBNormal)(pcl::PointNormal)( \
      pcl::PointXYZINormal)
