/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Ten million points: an organized 4000 x 2500 scan of a gently waved wall with range
// noise. Bounds: peak memory (reliability_util.h: 1,200 bytes per point) and time (the
// ctest TIMEOUT of this executable, far below what any quadratic step would need).
// Labelled "large": the sanitizer run leaves it out (docs/reliability.md). It prints
// the measured time and peak memory.

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>
#include <pcl/common/time.h>
#include <pcl/console/print.h>

#include <cmath>
#include <random>

#include "reliability_util.h"

TEST(LargeCloud, TenMillionPoints)
{
  const int w = 4000, h = 2500;
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>(w, h);
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 2e-4f);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const float x = 0.0005f * (c - w / 2), y = 0.0005f * (r - h / 2);
      const float z = 2.0f + 0.05f * std::sin(3.0f * x) * std::cos(2.0f * y) + noise(rng);
      cloud->at(c, r) = pcl::PointXYZ(x, y, z);
    }
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setSensorPose(Eigen::Affine3f::Identity());
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  selseg_test::PeakMemory memory;
  pcl::StopWatch watch;
  ASSERT_TRUE(seg.extract(clusters));
  const double seconds = watch.getTimeSeconds();
  const std::size_t peak = memory.peak();
  std::printf("10M points: %.1f s, peak memory %.0f MiB (%.0f bytes per point), "
              "%zu segments\n",
              seconds,
              peak / 1048576.0,
              static_cast<double>(peak) / cloud->size(),
              clusters.size());
  EXPECT_LE(peak, selseg_test::memoryBudget(cloud->size()));
  selseg_test::expectConsistentResult(*cloud, seg, clusters);
  EXPECT_EQ(seg.getResult().counts.labeled, cloud->size());
}

int
main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  return RUN_ALL_TESTS();
}
