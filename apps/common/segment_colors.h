/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/segment_colors.h>

namespace selseg_apps {

// The library's segment colours (pcl_selective_seg/segment_colors.h), under the names
// the tools use.
using pcl::selective_seg::Rgb;
using pcl::selective_seg::segmentColor;
using pcl::selective_seg::triangleColor;

} // namespace selseg_apps
