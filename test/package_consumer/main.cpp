// Segments a small synthetic scene through the installed package: two perpendicular
// planes seen from the origin must give two segments.
#include <pcl_selective_seg/selective_segmentation.h>

#include <cstdio>

int
main()
{
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const float u = -0.5f + i / 40.0f, v = -0.5f + j / 40.0f;
      cloud->push_back(pcl::PointXYZ(u, v, 2.0f)); // wall facing the sensor
      cloud->push_back(pcl::PointXYZ(u, 0.6f, 1.0f + (v + 0.5f))); // floor below it
    }
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  if (!seg.extract(segments))
    return 1;
  std::size_t big = 0;
  for (const auto& s : segments)
    big += s.indices.size() > 500;
  std::printf("%zu segments, %zu with more than 500 points\n", segments.size(), big);
  return big == 2 ? 0 : 1;
}
