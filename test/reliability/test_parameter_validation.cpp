/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Every parameter: each out-of-range or non-finite value is rejected, by validate()
// and by extract(), with a message naming the parameter and its valid range; the ends
// of every valid range are accepted.

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>
#include <pcl/console/print.h>

#include <cmath>
#include <functional>
#include <limits>

using pcl::selective_seg::DelaunayBackend;
using pcl::selective_seg::EdgeTriangleNormal;
using pcl::selective_seg::MergeWith;
using pcl::selective_seg::NormalSpreadFrame;
using pcl::selective_seg::PointNormalTriangles;
using pcl::selective_seg::SegmentNormalWeight;
using pcl::selective_seg::SelectiveSegmentationParameters;
using Params = SelectiveSegmentationParameters;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Field {
  const char* name;  ///< must appear in the message
  const char* range; ///< must appear in the message
  std::function<void(Params&, double)> set;
  std::vector<double> invalid;
  std::vector<double> valid;
};

const std::vector<Field>&
fields()
{
  static const std::vector<Field> all = {
      {"max_normal_std_dev",
       "(0, pi]",
       [](Params& p, double v) { p.max_normal_std_dev = v; },
       {0.0, -0.1, M_PI + 1e-9, kNaN, kInf, -kInf},
       {1e-9, 0.13, M_PI}},
      {"max_merge_angle",
       "[0, pi]",
       [](Params& p, double v) { p.max_merge_angle = v; },
       {-1e-9, M_PI + 1e-9, kNaN, kInf, -kInf},
       {0.0, 0.4, M_PI}},
      {"max_edge_triangle_angle",
       "[0, pi]",
       [](Params& p, double v) { p.max_edge_triangle_angle = v; },
       {-1e-9, 4.0, kNaN, kInf, -kInf},
       {0.0, M_PI}},
      {"max_view_incidence_angle",
       "(0, pi/2]",
       [](Params& p, double v) { p.max_view_incidence_angle = v; },
       {0.0, -1.0, M_PI / 2 + 1e-9, kNaN, kInf},
       {1e-6, M_PI / 2}},
      {"normal_rings",
       "[1, 10]",
       [](Params& p, double v) { p.normal_rings = static_cast<int>(v); },
       {0, -1, 11, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()},
       {1, 10}},
      {"min_voxel_size",
       "0 (automatic) or > 0",
       [](Params& p, double v) { p.min_voxel_size = v; },
       {-1e-12, kNaN, kInf, -kInf},
       {0.0, 1e-30, 1e30}},
      {"min_voxel_size_factor",
       "[0.5, 1000]",
       [](Params& p, double v) { p.min_voxel_size_factor = v; },
       {0.0, 0.49, 1000.5, kNaN, kInf},
       {0.5, 1000.0}},
      {"min_points_to_split",
       ">= 2",
       [](Params& p, double v) { p.min_points_to_split = static_cast<int>(v); },
       {1, 0, -5, std::numeric_limits<int>::min()},
       {2, std::numeric_limits<int>::max()}},
      {"max_octree_depth",
       "[1, 21]",
       [](Params& p, double v) { p.max_octree_depth = static_cast<int>(v); },
       {0, -1, 22, std::numeric_limits<int>::max()},
       {1, 21}},
      {"angle_quantization",
       "[2.5e-8, 1e-2]",
       [](Params& p, double v) { p.angle_quantization = v; },
       {0.0, 2.4e-8, 0.011, kNaN, kInf, -kInf},
       {2.5e-8, 1e-2}},
      {"num_threads",
       "[0, 1024]",
       [](Params& p, double v) { p.num_threads = static_cast<int>(v); },
       {-1, 1025, std::numeric_limits<int>::min()},
       {0, 1, 1024}},
      {"edge_triangle_normal",
       "facet or vertex_mean",
       [](Params& p, double v) {
         p.edge_triangle_normal = static_cast<EdgeTriangleNormal>(static_cast<int>(v));
       },
       {2, 7, 255},
       {0, 1}},
      {"segment_normal_weight",
       "inverse_area or area",
       [](Params& p, double v) {
         p.segment_normal_weight =
             static_cast<SegmentNormalWeight>(static_cast<int>(v));
       },
       {2, 7, 255},
       {0, 1}},
      {"merge_with",
       "seeds or segments",
       [](Params& p, double v) {
         p.merge_with = static_cast<MergeWith>(static_cast<int>(v));
       },
       {2, 7, 255},
       {0, 1}},
      {"point_normal_triangles",
       "all or not_edge_on",
       [](Params& p, double v) {
         p.point_normal_triangles =
             static_cast<PointNormalTriangles>(static_cast<int>(v));
       },
       {2, 7, 255},
       {0, 1}},
      {"normal_spread_frame",
       "sensor or mean_normal",
       [](Params& p, double v) {
         p.normal_spread_frame = static_cast<NormalSpreadFrame>(static_cast<int>(v));
       },
       {2, 7, 255},
       {0, 1}},
      {"delaunay_backend",
       "sweep, boost",
       [](Params& p, double v) {
         p.delaunay_backend = static_cast<DelaunayBackend>(static_cast<int>(v));
       },
       {3, 17, 255},
       {static_cast<double>(DelaunayBackend::Sweep),
        static_cast<double>(DelaunayBackend::BoostVoronoi)}},
  };
  return all;
}

/** A small wall seen from the origin: segments with any valid parameters. */
pcl::PointCloud<pcl::PointXYZ>::Ptr
wall()
{
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>(30, 30);
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 30; ++c)
      cloud->at(c, r) = pcl::PointXYZ(0.01f * (c - 15), 0.01f * (r - 15), 1.0f);
  return cloud;
}

} // namespace

TEST(ParameterValidation, DefaultsAreValid)
{
  std::string why = "unchanged";
  EXPECT_TRUE(Params().validate(&why));
  EXPECT_TRUE(Params().validate());
}

TEST(ParameterValidation, EveryInvalidValueIsRejectedByName)
{
  for (const auto& f : fields())
    for (const double v : f.invalid) {
      Params p;
      f.set(p, v);
      std::string why;
      EXPECT_FALSE(p.validate(&why)) << f.name << " = " << v;
      EXPECT_FALSE(p.validate()) << f.name << " = " << v;
      EXPECT_NE(why.find(f.name), std::string::npos) << why;
      EXPECT_NE(why.find(f.range), std::string::npos) << why;
    }
}

TEST(ParameterValidation, EndsOfEveryValidRangeAreAccepted)
{
  for (const auto& f : fields())
    for (const double v : f.valid) {
      Params p;
      f.set(p, v);
      std::string why;
      EXPECT_TRUE(p.validate(&why)) << f.name << " = " << v << ": " << why;
    }
}

// extract() refuses every invalid value, with empty outputs; and runs with the ends of
// the valid ranges (no crash, no hang on an extreme but legal setting).
TEST(ParameterValidation, ExtractRefusesInvalidAndRunsValidExtremes)
{
  const auto cloud = wall();
  for (const auto& f : fields()) {
    for (const double v : f.invalid) {
      Params p;
      f.set(p, v);
      pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
      seg.setParameters(p);
      seg.setInputCloud(cloud);
      std::vector<pcl::PointIndices> clusters(2);
      EXPECT_FALSE(seg.extract(clusters)) << f.name << " = " << v;
      EXPECT_TRUE(clusters.empty());
      EXPECT_FALSE(seg.getLabeledCloud());
    }
    for (const double v : f.valid) {
      Params p;
      f.set(p, v);
      if (std::string(f.name) == "num_threads" && v > 8)
        continue; // legal, but a thousand threads on a test machine is not a test
      pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
      seg.setParameters(p);
      seg.setInputCloud(cloud);
      std::vector<pcl::PointIndices> clusters;
      ASSERT_TRUE(seg.extract(clusters)) << f.name << " = " << v;
      std::size_t labeled = 0;
      for (const auto& c : clusters)
        labeled += c.indices.size();
      EXPECT_EQ(labeled, seg.getResult().counts.labeled) << f.name << " = " << v;
    }
  }
}

int
main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  return RUN_ALL_TESTS();
}
