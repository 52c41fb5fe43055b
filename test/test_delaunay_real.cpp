/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// The Sweep backend against BoostVoronoi on the vertices of real scans, built as the
// pipeline builds them. Arguments: the shared data folder, then the repository's data/
// folder (which bundles the stereo mug scene); a test skips when its file is in
// neither.

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>

#include <fstream>
#include <string>
#include <vector>

namespace {

using pcl::selective_seg::DelaunayBackend;
using pcl::selective_seg::Triangle;

std::string shared_dir;  // NOLINT: set once in main()
std::string bundled_dir; // NOLINT: set once in main()

struct RealScan {
  /** Candidate paths, the first readable one is used. */
  std::vector<std::string> paths;
  /** Keep only the points in front of the sensor plane (z > 0). */
  bool front_only;
};

/** Loads the first of the candidate paths that exists and reads. */
bool
load(const RealScan& scan, pcl::PointCloud<pcl::PointXYZ>& cloud)
{
  for (const auto& path : scan.paths) {
    std::ifstream exists(path);
    if (exists && pcl::io::loadPCDFile(path, cloud) == 0 && !cloud.empty())
      break;
  }
  if (cloud.empty())
    return false;
  if (scan.front_only) {
    pcl::PointCloud<pcl::PointXYZ> front;
    for (const auto& p : cloud)
      if (p.z > 0)
        front.push_back(p);
    cloud.swap(front);
  }
  return true;
}

/** The pipeline's triangulation of the cloud in the camera frame, by \a backend. */
pcl::selective_seg::SphericalTriangulation
triangulate(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
            DelaunayBackend backend)
{
  pcl::selective_seg::SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setInputCloud(cloud);
  delaunay.setSensorPose(Eigen::Affine3f::Identity());
  delaunay.setBackend(backend);
  EXPECT_TRUE(delaunay.triangulate());
  return delaunay.getTriangulation();
}

} // namespace

class RealScanVertices : public ::testing::TestWithParam<const char*> {
protected:
  RealScan scan() const
  {
    const std::string name = GetParam();
    if (name == "table_scene_mug_stereo_textured")
      return {{bundled_dir + "/" + name + ".pcd",
               shared_dir + "/pcl_test/" + name + ".pcd"},
              false};
    if (name == "milk_cartoon_all_small_clorox")
      return {{shared_dir + "/pcl_test/" + name + ".pcd"}, false};
    if (name == "room_scan1")
      return {{shared_dir + "/laser/" + name + ".pcd"}, true};
    return {{shared_dir + "/mosd/" + name + ".pcd"}, false};
  }
};

// Sweep and BoostVoronoi give the same triangles, triangle for triangle, both called
// directly on the vertex angles and through SphericalDelaunay.
TEST_P(RealScanVertices, SweepGivesBoostsTriangles)
{
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  if (!load(scan(), *cloud))
    GTEST_SKIP() << "'" << GetParam() << "' not found under '" << shared_dir << "' or '"
                 << bundled_dir << "'";
  const auto boost = triangulate(cloud, DelaunayBackend::BoostVoronoi);
  ASSERT_GT(boost.triangles.size(), 10000u);
  std::vector<Triangle> sweep;
  std::string error;
  ASSERT_TRUE(pcl::selective_seg::delaunay2d(
      boost.vertex_angles, DelaunayBackend::Sweep, sweep, &error))
      << error;
  EXPECT_EQ(sweep.size(), boost.triangles.size());
  EXPECT_TRUE(sweep == boost.triangles) << boost.vertex_angles.size() << " vertices";
  const auto pipeline = triangulate(cloud, DelaunayBackend::Sweep);
  EXPECT_TRUE(pipeline.vertex_angles == boost.vertex_angles);
  EXPECT_TRUE(pipeline.triangles == boost.triangles);
  EXPECT_TRUE(pipeline.neighbours == boost.neighbours);
}

INSTANTIATE_TEST_SUITE_P(RealScans,
                         RealScanVertices,
                         ::testing::Values("learn0",
                                           "learn17",
                                           "test0",
                                           "table_scene_mug_stereo_textured",
                                           "milk_cartoon_all_small_clorox",
                                           "room_scan1"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           return std::string(info.param);
                         });

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
