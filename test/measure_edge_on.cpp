/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Measures the effect of max_view_incidence_angle (the edge-on triangle test) on the
// simulated cube scene and, when the data folder is given, on the mOSD frames. Prints
// the markdown table of docs/parameters.md.
//
// Usage: selseg_measure_edge_on [shared_data_dir]

#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/io/pcd_io.h>

#include <cstdio>
#include <string>

#include <leakage.h>
#include <cube_scene.h>

namespace {

struct Score {
  double leakage = 0.0; // fraction of points in a segment of another majority label
  std::size_t segments = 0;
};

Score
score(const pcl::PointCloud<pcl::PointXYZL>::ConstPtr& cloud, double incidence)
{
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZL> seg;
  seg.setInputCloud(cloud);
  seg.setMaxViewIncidenceAngle(incidence);
  std::vector<pcl::PointIndices> segments;
  Score s;
  if (!seg.extract(segments))
    return s;
  s.leakage = selseg_test::leakage(*cloud, segments);
  s.segments = segments.size();
  return s;
}

void
row(const std::string& name, const pcl::PointCloud<pcl::PointXYZL>::ConstPtr& cloud)
{
  const Score paper = score(cloud, M_PI / 2.0);
  const Score edge_on = score(cloud, 85.0 * M_PI / 180.0);
  std::printf("| %s | %zu | %.2f%% (%zu) | %.2f%% (%zu) |\n",
              name.c_str(),
              cloud->size(),
              100.0 * paper.leakage,
              paper.segments,
              100.0 * edge_on.leakage,
              edge_on.segments);
}

} // namespace

int
main(int argc, char** argv)
{
  std::printf("| scene | points | leakage (segments), 90 deg = paper | leakage "
              "(segments), 85 deg |\n|---|---|---|---|\n");
  for (const std::size_t rays : {5432, 46255})
    for (const unsigned seed : {1u, 2u, 3u}) {
      const auto cloud = selseg_test::cubeScan(rays, seed);
      row("cube, seed " + std::to_string(seed), cloud);
    }
  if (argc > 1)
    for (const char* frame : {"learn0", "learn17", "test0"}) {
      auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
      if (pcl::io::loadPCDFile(std::string(argv[1]) + "/mosd/" + frame + ".pcd",
                               *cloud) == 0)
        row(std::string("mOSD ") + frame, cloud);
    }
  return 0;
}
