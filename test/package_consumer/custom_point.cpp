// A point type of the user's own, the PCL way: PCL_NO_PRECOMPILE before the first
// include, so that this file compiles the library's bodies for it. Its segments must
// be those of pcl::PointXYZ on the same coordinates (which come from the library's own
// instantiation: run_consumer_test.cmake checks that this program defines none of it).
#define PCL_NO_PRECOMPILE
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <cstdint>
#include <cstdio>

struct EIGEN_ALIGN16 ScanPoint {
  PCL_ADD_POINT4D;
  float quality;
  std::uint16_t ring;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};
POINT_CLOUD_REGISTER_POINT_STRUCT(ScanPoint,
                                  (float, x, x)(float, y, y)(float, z, z)(
                                      float, quality, quality)(std::uint16_t, ring, ring))

template <typename PointT>
std::vector<pcl::PointIndices>
segment(const std::vector<Eigen::Vector3f>& xyz)
{
  auto cloud = pcl::make_shared<pcl::PointCloud<PointT>>();
  for (const auto& p : xyz) {
    PointT q;
    q.x = p.x();
    q.y = p.y();
    q.z = p.z();
    cloud->push_back(q);
  }
  pcl::selective_seg::SelectiveSegmentation<PointT> seg;
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  if (!seg.extract(segments))
    segments.clear();
  return segments;
}

int
main()
{
  // A wall facing the sensor and a floor below it, as in main.cpp.
  std::vector<Eigen::Vector3f> xyz;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const float u = -0.5f + i / 40.0f, v = -0.5f + j / 40.0f;
      xyz.emplace_back(u, v, 2.0f);
      xyz.emplace_back(u, 0.6f, 1.0f + (v + 0.5f));
    }
  const auto own = segment<ScanPoint>(xyz);
  const auto xyz_segments = segment<pcl::PointXYZ>(xyz);
  std::size_t big = 0;
  for (const auto& s : own)
    big += s.indices.size() > 500;
  bool same = own.size() == xyz_segments.size();
  for (std::size_t i = 0; same && i < own.size(); ++i)
    same = own[i].indices == xyz_segments[i].indices;
  std::printf("own point type: %zu segments, %zu with more than 500 points; %s as "
              "pcl::PointXYZ\n",
              own.size(),
              big,
              same ? "the same" : "NOT the same");
  return big == 2 && same ? 0 : 1;
}
