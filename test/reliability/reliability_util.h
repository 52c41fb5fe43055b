/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Helpers of the reliability tests: peak memory of a call, and the invariants every
// successful result must satisfy whatever the input (docs/reliability.md).

#pragma once

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <string>

namespace selseg_test {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

/** \brief A field of /proc/self/status in bytes (VmHWM, VmRSS), or 0. */
inline std::size_t
procStatusBytes(const std::string& field)
{
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, field.size() + 1, field + ":") == 0)
      return std::stoull(line.substr(field.size() + 1)) * 1024;
  return 0;
}

/** \brief Peak resident memory of the code run between the constructor and peak():
 * the kernel's high-water mark is reset first (/proc/self/clear_refs, value 5). */
class PeakMemory {
public:
  PeakMemory()
  {
    std::ofstream("/proc/self/clear_refs") << "5";
    base_ = procStatusBytes("VmRSS");
  }
  /** \brief Bytes above the resident size at construction. */
  std::size_t
  peak() const
  {
    const std::size_t hwm = procStatusBytes("VmHWM");
    return hwm > base_ ? hwm - base_ : 0;
  }

private:
  std::size_t base_ = 0;
};

/** \brief A generous memory budget for a call on \a points input points: the pipeline
 * needs about 470 bytes per point; allow 1,200 plus 64 MiB (4x and 512 MiB more under
 * AddressSanitizer, whose shadow memory and quarantine grow every allocation). */
inline std::size_t
memoryBudget(std::size_t points)
{
  const std::size_t budget = 1200 * points + (64u << 20);
  return kSanitized ? 4 * budget + (512u << 20) : budget;
}

/** \brief The invariants of a successful extract() on \a cloud: labels in input order
 * and range, clusters, counts and mesh consistent with one another. */
template <typename PointT>
void
expectConsistentResult(const pcl::PointCloud<PointT>& cloud,
                       const pcl::selective_seg::SelectiveSegmentation<PointT>& seg,
                       const std::vector<pcl::PointIndices>& clusters)
{
  const auto& r = seg.getResult();
  ASSERT_EQ(r.labels.size(), cloud.size());
  ASSERT_EQ(clusters.size(), r.segments.size());
  ASSERT_FALSE(r.segments.empty());
  std::size_t labeled = 0;
  for (const auto l : r.labels) {
    ASSERT_LE(l, r.segments.size());
    labeled += l > 0;
  }
  const auto& c = r.counts;
  EXPECT_EQ(labeled, c.labeled);
  EXPECT_EQ(c.labeled + c.without_normal + c.non_finite + c.behind_sensor +
                c.outside_indices,
            cloud.size());
  std::size_t in_clusters = 0;
  for (std::size_t s = 0; s < clusters.size(); ++s) {
    EXPECT_FALSE(clusters[s].indices.empty()) << "segment " << s + 1;
    EXPECT_EQ(clusters[s].indices.size(), r.segments[s].num_points);
    if (s > 0) {
      EXPECT_LE(clusters[s].indices.size(), clusters[s - 1].indices.size());
    }
    in_clusters += clusters[s].indices.size();
  }
  EXPECT_EQ(in_clusters, labeled);
  for (const auto& t : r.mesh.triangles)
    for (const auto v : t)
      ASSERT_TRUE(v >= 0 && static_cast<std::size_t>(v) < cloud.size());
  EXPECT_EQ(r.mesh.labels.size(), r.mesh.triangles.size());
  for (const auto& leaf : r.leaves) {
    EXPECT_GE(leaf.label, 1u);
    EXPECT_LE(leaf.label, r.segments.size());
    EXPECT_TRUE(leaf.normal.allFinite());
    EXPECT_LE(leaf.depth, static_cast<std::uint32_t>(seg.getParameters().max_octree_depth));
  }
  for (const auto& s : r.segments)
    EXPECT_TRUE(s.normal.allFinite()) << "segment " << s.label;
}

} // namespace selseg_test
