/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/segment_colors.h>

#include <cmath>

namespace pcl {
namespace selective_seg {

Rgb
segmentColor(std::uint32_t label)
{
  if (label == 0)
    return {64, 64, 64};
  // Golden-angle hue sequence, HSV with S = V = 1.
  const double hue = std::fmod(label * 137.50776405, 360.0) / 60.0;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const auto byte = [](double v) {
    return static_cast<std::uint8_t>(std::lround(255 * v));
  };
  const std::uint8_t up = byte(f), down = byte(1.0 - f);
  switch (sector) {
  case 0:
    return {255, up, 0};
  case 1:
    return {down, 255, 0};
  case 2:
    return {0, 255, up};
  case 3:
    return {0, down, 255};
  case 4:
    return {up, 0, 255};
  default:
    return {255, 0, down};
  }
}

std::vector<Rgb>
segmentColors(std::uint32_t max_label)
{
  std::vector<Rgb> colors(std::size_t{max_label} + 1);
  for (std::uint32_t l = 0; l <= max_label; ++l)
    colors[l] = segmentColor(l);
  return colors;
}

Rgb
triangleColor(std::uint32_t label, TriangleClass cls)
{
  if (cls != TriangleClass::Interior)
    return {255, 255, 255};
  return segmentColor(label);
}

} // namespace selective_seg
} // namespace pcl
