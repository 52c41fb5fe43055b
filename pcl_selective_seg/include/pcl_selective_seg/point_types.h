/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <boost/preprocessor/seq/for_each.hpp>
#include <pcl/pcl_macros.h>
#include <pcl/point_types.h>

/** \brief The point types for which the library's templates are instantiated (PCL's
 * common XYZ types). Other types work with PCL_NO_PRECOMPILE defined. */
#define PCL_SELSEG_POINT_TYPES                                                         \
  (pcl::PointXYZ)(pcl::PointXYZI)(pcl::PointXYZL)(pcl::PointXYZRGB)(                   \
      pcl::PointXYZRGBA)(pcl::PointXYZRGBL)(pcl::PointXYZRGBNormal)(pcl::PointNormal)( \
      pcl::PointXYZINormal)

#define PCL_SELSEG_EXTERN_TEMPLATE_IMPL(r, CLASS, T)                                   \
  extern template class PCL_EXPORTS CLASS<T>;
/** \brief Declares the library's explicit instantiations of \a CLASS for
 * PCL_SELSEG_POINT_TYPES. Not PCL_INSTANTIATE: pcl/impl/instantiate.hpp makes that a
 * no-op under PCL_NO_PRECOMPILE, exactly when the bodies are visible and a program
 * would otherwise make its own (weak, interposing) copies of the library's types. */
#define PCL_SELSEG_EXTERN_TEMPLATES(CLASS)                                             \
  BOOST_PP_SEQ_FOR_EACH(PCL_SELSEG_EXTERN_TEMPLATE_IMPL, CLASS, PCL_SELSEG_POINT_TYPES)
