/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/segmentation_result.h>

#include <pcl/pcl_macros.h>

#include <array>
#include <cstdint>
#include <vector>

namespace pcl {
namespace selective_seg {

/** \brief An 8-bit RGB colour. */
using Rgb = std::array<std::uint8_t, 3>;

/** \brief The colour of a segment, as in the paper's Figs. 7-12: one hue of HSV per
 * label, full saturation and value. The hue of label l is l times the golden angle
 * (137.50776405 degrees) modulo 360, so that neighbouring labels, which are segments of
 * similar sizes, differ. Label 0 (unlabeled) is dark grey (64, 64, 64). The same label
 * has the same colour in every run: the command-line tool's meshes, the viewer and
 * SelectiveSegmentation::getColoredCloud() use it. */
PCL_EXPORTS Rgb segmentColor(std::uint32_t label);

/** \brief segmentColor() of labels 0 .. \a max_label, indexed by label: a table for
 * colouring many points or triangles. */
PCL_EXPORTS std::vector<Rgb> segmentColors(std::uint32_t max_label);

/** \brief The colour of a mesh triangle: its segment's colour (segmentColor()) when
 * interior, white for an edge triangle (valid or invalid), as in the paper's figures. */
PCL_EXPORTS Rgb triangleColor(std::uint32_t label, TriangleClass cls);

} // namespace selective_seg
} // namespace pcl
