/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <map>
#include <vector>

namespace selseg_test {

/** \brief Under-segmentation error: the fraction of the ground-truth-labeled points
 * that lie in a segment whose majority ground-truth label is not theirs (ground truth 0
 * = invalid, ignored). \param[in] truth the ground-truth labels, indexed like the
 * segments' indices \param[in] segments the segmentation */
inline double
leakage(const pcl::PointCloud<pcl::PointXYZL>& truth,
        const std::vector<pcl::PointIndices>& segments)
{
  std::size_t leaked = 0, total = 0;
  for (const auto& s : segments) {
    std::map<std::uint32_t, std::size_t> votes;
    for (const auto i : s.indices)
      if (truth[i].label != 0)
        ++votes[truth[i].label];
    std::size_t in_segment = 0, majority = 0;
    for (const auto& v : votes) {
      in_segment += v.second;
      majority = std::max(majority, v.second);
    }
    leaked += in_segment - majority;
    total += in_segment;
  }
  return total ? static_cast<double>(leaked) / total : 0.0;
}

} // namespace selseg_test
