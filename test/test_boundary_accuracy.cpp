/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Boundary points of a labelled mesh and boundary distances, on hand-made cases.

#include <pcl_selective_seg/segmentation_metrics.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace metrics = pcl::selective_seg::metrics;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Triangles = std::vector<std::array<pcl::index_t, 3>>;

namespace {

/** Two triangles seen from the origin: p0..p2 at z = 1, p3 farther away (z = 2). */
Cloud
square()
{
  Cloud c;
  c.push_back(pcl::PointXYZ(0.0f, 0.0f, 1.0f));
  c.push_back(pcl::PointXYZ(0.1f, 0.0f, 1.0f));
  c.push_back(pcl::PointXYZ(0.0f, 0.1f, 1.0f));
  c.push_back(pcl::PointXYZ(0.2f, 0.2f, 2.0f));
  return c;
}

const Triangles kTriangles = {{0, 1, 2}, {1, 3, 2}};

Cloud
line(std::initializer_list<float> xs)
{
  Cloud c;
  for (const float x : xs)
    c.push_back(pcl::PointXYZ(x, 0.0f, 0.0f));
  return c;
}

} // namespace

TEST(LabelBoundaryPoints, NearerEndPointOfEdgesBetweenLabels)
{
  pcl::Indices boundary;
  // Labels 1 1 2 2: the edges 0-2, 1-2 and 1-3 cross. 0-2 gives 0 (nearer); 1-2 is a
  // tie in range (both sqrt(1.01)) and gives the smaller index 1; 1-3 gives 1.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{0, 1}));
  // Unlabeled points end a region: 0 0 0 1 crosses 1-3 and 3-2 only.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {0, 0, 0, 1}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{1, 2}));
  // One label, or only zeros: no boundary.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {0, 0, 0, 0}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_TRUE(boundary.empty());
  // Seen from far along -z, point 3 is the nearer end of 1-3 and 3-2.
  ASSERT_TRUE(metrics::labelBoundaryPoints(square(),
                                           kTriangles,
                                           {0, 0, 0, 1},
                                           Eigen::Vector3f(0.0f, 0.0f, 10.0f),
                                           M_PI,
                                           boundary));
  EXPECT_EQ(boundary, (pcl::Indices{3}));
}

TEST(LabelBoundaryPoints, LongEdgesAreLeftOut)
{
  pcl::Indices boundary;
  // Edge 0-2 subtends atan(0.1) = 0.09967 rad, 1-2 0.14084 rad, 1-3 0.09918 rad.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), 0.0994, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{1})); // from 1-3 only
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), 0.05, boundary));
  EXPECT_TRUE(boundary.empty());
}

TEST(LabelBoundaryPoints, BadInput)
{
  pcl::Indices boundary{7};
  EXPECT_FALSE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_TRUE(boundary.empty());
  EXPECT_FALSE(metrics::labelBoundaryPoints(
      square(), {{0, 1, 4}}, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_FALSE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), 0.0, boundary));
  // Non-finite points make no boundary.
  Cloud c = square();
  c[0].x = std::numeric_limits<float>::quiet_NaN();
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      c, kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{1}));
}

TEST(BoundaryDistances, HandComputed)
{
  metrics::BoundaryDistances d;
  std::vector<float> per_point;
  Cloud from = line({0.0f, 1.0f, 3.0f, 10.0f});
  from.push_back(pcl::PointXYZ(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
  metrics::boundaryDistances(from, line({0.0f, 2.0f}), d, &per_point);
  // Distances 0, 1, 1, 8; nearest-rank median = 2nd of 4, p90 = 4th of 4.
  EXPECT_EQ(d.num_from, 4u);
  EXPECT_EQ(d.num_to, 2u);
  EXPECT_DOUBLE_EQ(d.mean, 2.5);
  EXPECT_DOUBLE_EQ(d.median, 1.0);
  EXPECT_DOUBLE_EQ(d.p90, 8.0);
  EXPECT_DOUBLE_EQ(d.max, 8.0);
  ASSERT_EQ(per_point.size(), 5u);
  EXPECT_FLOAT_EQ(per_point[3], 8.0f);
  EXPECT_TRUE(std::isnan(per_point[4]));
  // The reverse direction: 0 -> 0, 2 -> 1 or 3.
  metrics::boundaryDistances(line({0.0f, 2.0f}), line({0.0f, 1.0f, 3.0f, 10.0f}), d);
  EXPECT_DOUBLE_EQ(d.mean, 0.5);
  EXPECT_DOUBLE_EQ(d.max, 1.0);
}

TEST(BoundaryDistances, EmptySetsGiveNaN)
{
  metrics::BoundaryDistances d;
  metrics::boundaryDistances(line({1.0f}), Cloud(), d);
  EXPECT_EQ(d.num_from, 1u);
  EXPECT_EQ(d.num_to, 0u);
  EXPECT_TRUE(std::isnan(d.mean));
  EXPECT_TRUE(std::isnan(d.p90));
  metrics::boundaryDistances(Cloud(), line({1.0f}), d);
  EXPECT_EQ(d.num_from, 0u);
  EXPECT_TRUE(std::isnan(d.median));
}
