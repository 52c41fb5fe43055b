/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/segmentation_result.h>

#include <array>
#include <cstdint>

namespace selseg_apps {

using Rgb = std::array<std::uint8_t, 3>;

/** \brief The colour of a segment, as in the paper's Figs. 7-12: one hue of HSV per
 * label (hues spread by the golden angle so that neighbouring labels differ), full
 * saturation and value. Label 0 (unlabeled) is dark grey. */
Rgb segmentColor(std::uint32_t label);

/** \brief The colour of a mesh triangle: its segment's colour when interior, white for
 * an edge triangle (valid or invalid), as in the paper's figures. */
Rgb triangleColor(std::uint32_t label, pcl::selective_seg::TriangleClass cls);

} // namespace selseg_apps
