/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Real scans: the mOSD RGB-D frames with object-part ground truth, and PCL's stereo mug
// scene. Arguments: the shared data folder, then the repository's data/ folder (which
// bundles the mug scene); a test skips when its file is in neither.

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>

#include <fstream>
#include <string>
#include <vector>

#include <leakage.h>

namespace {

std::string shared_dir;  // NOLINT: set once in main()
std::string bundled_dir; // NOLINT: set once in main()

/** Load the first of the candidate paths that exists and reads. */
bool
load(const std::vector<std::string>& paths, pcl::PointCloud<pcl::PointXYZL>& cloud)
{
  for (const auto& path : paths) {
    std::ifstream exists(path);
    if (exists && pcl::io::loadPCDFile(path, cloud) == 0 && !cloud.empty())
      return true;
  }
  return false;
}

} // namespace

class MosdFrame : public ::testing::TestWithParam<const char*> {};

// The mOSD labels are object parts (a box is one label), so splitting a box into faces
// is expected; merging a box with the table is not. Measured with the default
// parameters: learn0 0.14%, learn17 0.18%, test0 0.09% of the points leak; asserted
// below 0.5%.
TEST_P(MosdFrame, SegmentsDoNotLeakAcrossObjects)
{
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
  if (!load({shared_dir + "/mosd/" + GetParam() + ".pcd"}, *cloud))
    GTEST_SKIP() << "mOSD frame not found under '" << shared_dir << "'";
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZL> seg;
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  ASSERT_TRUE(seg.extract(segments));
  const auto& r = seg.getResult();
  EXPECT_EQ(r.labels.size(), cloud->size());
  EXPECT_GT(r.counts.labeled, 150000u);
  EXPECT_EQ(r.counts.non_finite + r.counts.labeled + r.counts.without_normal +
                r.counts.behind_sensor,
            cloud->size());
  EXPECT_LT(selseg_test::leakage(*cloud, segments), 0.005);
  // The table top is the largest segment and almost all table.
  std::size_t table = 0;
  for (const auto i : segments[0].indices)
    table += (*cloud)[i].label >= 1 && (*cloud)[i].label <= 9;
  EXPECT_GT(table, 0.99 * segments[0].indices.size());
}

INSTANTIATE_TEST_SUITE_P(RealScans,
                         MosdFrame,
                         ::testing::Values("learn0", "learn17", "test0"));

TEST(StereoScan, MugSceneSegments)
{
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
  const std::string name = "table_scene_mug_stereo_textured.pcd";
  if (!load({bundled_dir + "/" + name, shared_dir + "/pcl_test/" + name}, *cloud))
    GTEST_SKIP() << "stereo mug scene not found in '" << bundled_dir << "'";
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZL> seg;
  seg.setInputCloud(cloud);
  // The file's VIEWPOINT says the sensor is turned 180 degrees about x, which would put
  // every point behind it; the cloud is in fact in the camera frame.
  std::vector<pcl::PointIndices> none;
  EXPECT_FALSE(seg.extract(none));
  EXPECT_EQ(seg.getResult().counts.behind_sensor, 209280u);
  seg.setSensorPose(Eigen::Affine3f::Identity());
  std::vector<pcl::PointIndices> segments;
  ASSERT_TRUE(seg.extract(segments));
  const auto labeled = seg.getLabeledCloud();
  EXPECT_EQ(labeled->width, 640u);
  EXPECT_EQ(labeled->height, 480u);
  // The table dominates the view.
  EXPECT_GT(segments[0].indices.size(), 0.4 * seg.getResult().counts.labeled);
  EXPECT_GT(segments.size(), 10u);
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  if (argc > 1)
    shared_dir = argv[1];
  if (argc > 2)
    bundled_dir = argv[2];
  return RUN_ALL_TESTS();
}
