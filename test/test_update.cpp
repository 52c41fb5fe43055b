/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// SelectiveSegmentation::update(): folding a finer scan into an existing result must
// give the result of a from-scratch run on the union of the points.

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>

#include <cube_scene.h>

using pcl::selective_seg::SelectiveSegmentation;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace {

Cloud::Ptr
toXYZ(const pcl::PointCloud<pcl::PointXYZL>& in, std::size_t begin, std::size_t end)
{
  auto out = pcl::make_shared<Cloud>();
  for (std::size_t i = begin; i < end; ++i)
    out->push_back(pcl::PointXYZ(in[i].x, in[i].y, in[i].z));
  return out;
}

} // namespace

TEST(SelectiveSegmentationUpdate, EqualsExtractOnTheUnionWithTheSameVoxelSize)
{
  const auto scan = selseg_test::cubeScan(6000, 7);
  ASSERT_GT(scan->size(), 5000u);
  const std::size_t split = scan->size() * 4 / 5;
  SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setInputCloud(toXYZ(*scan, 0, split));
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.extract(clusters));
  const double voxel = seg.getResult().min_voxel_size;
  ASSERT_TRUE(seg.update(*toXYZ(*scan, split, scan->size()), clusters));
  EXPECT_EQ(seg.getResult().labels.size(), scan->size());
  EXPECT_EQ(seg.getResult().min_voxel_size, voxel);

  SelectiveSegmentation<pcl::PointXYZ> ref;
  ref.setInputCloud(toXYZ(*scan, 0, scan->size()));
  ref.setMinVoxelSize(voxel);
  std::vector<pcl::PointIndices> ref_clusters;
  ASSERT_TRUE(ref.extract(ref_clusters));
  EXPECT_EQ(seg.getResult().labels, ref.getResult().labels);
  EXPECT_EQ(clusters.size(), ref_clusters.size());
}

TEST(SelectiveSegmentationUpdate, NeedsAResultToUpdate)
{
  SelectiveSegmentation<pcl::PointXYZ> seg;
  std::vector<pcl::PointIndices> clusters;
  EXPECT_FALSE(seg.update(Cloud(), clusters));
  EXPECT_TRUE(clusters.empty());
}
