/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 *
 *  Unit tests of the triangulation in the sensor's spherical space (paper, eq. 1 and
 *  Sec. III.A).
 */

#include <pcl_selective_seg/impl/radix_sort.hpp>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <gtest/gtest.h>
#include <pcl/PolygonMesh.h>
#include <pcl/common/transforms.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <vector>

using pcl::selective_seg::DelaunayInsertion;
using pcl::selective_seg::kBehindSensor;
using pcl::selective_seg::kNonFinite;
using pcl::selective_seg::kOutsideIndices;
using pcl::selective_seg::QuantizedPoint;
using pcl::selective_seg::SphericalDelaunay;
using pcl::selective_seg::SphericalTriangulation;
using pcl::selective_seg::Triangle;

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

/** The point at range \a r seen at angles (theta, phi) by a sensor at the origin
 * looking along +z (eq. 1, inverted). */
pcl::PointXYZ
pointAt(double theta, double phi, double r)
{
  const Eigen::Vector3d p =
      r * Eigen::Vector3d(std::tan(theta), std::tan(phi), 1.0).normalized();
  return {
      static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

/** A w x h grid of angles theta = i * d_theta, phi = j * d_phi (row-major, i fastest),
 * at ranges that vary so that the points do not lie on one plane. */
Cloud::Ptr
angleGrid(int w, int h, double d_theta, double d_phi)
{
  Cloud::Ptr cloud(new Cloud);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      cloud->push_back(
          pointAt(i * d_theta, j * d_phi, 2.0 + 0.1 * ((i * 7 + j * 3) % 5)));
  return cloud;
}

std::int64_t
twiceSignedArea(const QuantizedPoint& a,
                const QuantizedPoint& b,
                const QuantizedPoint& c)
{
  return (static_cast<std::int64_t>(b[0]) - a[0]) *
             (static_cast<std::int64_t>(c[1]) - a[1]) -
         (static_cast<std::int64_t>(b[1]) - a[1]) *
             (static_cast<std::int64_t>(c[0]) - a[0]);
}

SphericalTriangulation
triangulate(const Cloud::ConstPtr& cloud, double step)
{
  SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setInputCloud(cloud);
  delaunay.setAngleQuantization(step);
  EXPECT_TRUE(delaunay.triangulate());
  return delaunay.getTriangulation();
}

void
expectSameTriangulation(const SphericalTriangulation& a,
                        const SphericalTriangulation& b)
{
  EXPECT_EQ(a.vertex_angles, b.vertex_angles);
  EXPECT_EQ(a.vertex_point, b.vertex_point);
  EXPECT_EQ(a.point_vertex, b.point_vertex);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.neighbours, b.neighbours);
}

} // namespace

// The fast quantized angle must be std::lround(std::atan2(y, x) / step) exactly: on
// random directions of every steepness and scale, at several steps, and on directions
// whose quotient lies within a hair of a half-integer (where it must fall back).
TEST(QuantizedAngle, SameAsAtan2RoundedEverywhere)
{
  using pcl::selective_seg::detail::quantizedAngle;
  const auto reference = [](double y, double x, double step) {
    return std::lround(std::atan2(y, x) / step);
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), decades(-6.0, 6.0);
  long mismatches = 0, near_half = 0;
  for (const double step : {1e-7, 3.3e-9, 1e-12, 1e-4, 0.01, 0.7}) {
    SCOPED_TRACE(step);
    for (int i = 0; i < 400000; ++i) {
      const double x = std::pow(10.0, decades(rng)) * (0.5 + std::fabs(unit(rng)));
      const double y = unit(rng) * x * std::pow(10.0, decades(rng));
      mismatches += quantizedAngle(y, x, step) != reference(y, x, step);
    }
    // A direction at (k + 1/2) step, and a few ulps around it.
    for (int i = 0; i < 20000; ++i) {
      const double x = 0.5 + std::fabs(unit(rng));
      const double half = (std::floor(unit(rng) * 1.5 / step) + 0.5) * step;
      double y = x * std::tan(half);
      for (int ulp = 0; ulp < 4; ++ulp, y = std::nextafter(y, 2.0 * y)) {
        const double t = std::atan2(y, x) / step;
        near_half += std::fabs(std::fabs(t - std::trunc(t)) - 0.5) < 1e-6;
        mismatches += quantizedAngle(y, x, step) != reference(y, x, step);
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(near_half, 100000); // the fallback was needed
  // Special values: zeros of both signs, the diagonal, extreme slopes, subnormals.
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const double step : {1e-7, 1e-3})
    for (const double x : {1.0, 1e-300, 1e300, 3.0})
      for (const double y : {0.0, -0.0, x, -x, tiny, -tiny, 1e-200 * x, 1e200, -1e200})
        EXPECT_EQ(quantizedAngle(y, x, step), reference(y, x, step)) << y << " " << x;
}

TEST(SphericalDelaunay, AnglesOfEquation1)
{
  // With a step of 1e-4 rad: pi/4 -> 7853.98 -> 7854; atan2(1, 2) = 0.4636476 -> 4636;
  // atan2(0.5, 2) = 0.2449787 -> 2450.
  Cloud::Ptr cloud(new Cloud);
  cloud->push_back({1.f, 0.f, 1.f});   // (pi/4, 0)
  cloud->push_back({0.f, 1.f, 1.f});   // (0, pi/4)
  cloud->push_back({0.f, 0.f, 1.f});   // (0, 0)
  cloud->push_back({1.f, 2.f, 2.f});   // (atan2(1, 2), pi/4)
  cloud->push_back({-1.f, 0.5f, 2.f}); // (-atan2(1, 2), atan2(0.5, 2))
  const SphericalTriangulation result = triangulate(cloud, 1e-4);
  EXPECT_DOUBLE_EQ(result.angle_quantization, 1e-4);
  // Vertices in increasing (theta, phi) order.
  const std::vector<QuantizedPoint> angles{
      {-4636, 2450}, {0, 0}, {0, 7854}, {4636, 7854}, {7854, 0}};
  EXPECT_EQ(result.vertex_angles, angles);
  EXPECT_EQ(result.point_vertex, (std::vector<pcl::index_t>{4, 2, 1, 3, 0}));
  EXPECT_EQ(result.vertex_point, (pcl::Indices{4, 2, 1, 3, 0}));
  EXPECT_FALSE(result.triangles.empty());
  EXPECT_EQ(result.num_outside_indices + result.num_non_finite +
                result.num_behind_sensor,
            0u);
}

TEST(SphericalDelaunay, NonFiniteAndBehindSensor)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  Cloud::Ptr cloud(new Cloud);
  cloud->push_back({0.f, 0.f, 1.f});
  cloud->push_back({nan, 0.f, 1.f});
  cloud->push_back({0.1f, 0.f, 1.f});
  cloud->push_back({0.f, 0.f, inf});
  cloud->push_back({1.f, 1.f, 0.f});  // in the sensor plane
  cloud->push_back({0.f, 0.f, -1.f}); // behind
  cloud->push_back({0.f, 0.1f, 1.f});
  cloud->push_back({5.f, 0.f, -0.5f}); // behind, off axis
  const SphericalTriangulation result = triangulate(cloud, 1e-6);
  EXPECT_EQ(result.num_non_finite, 2u);
  EXPECT_EQ(result.num_behind_sensor, 3u);
  EXPECT_EQ(result.num_outside_indices, 0u);
  const std::vector<pcl::index_t> expected{
      0, kNonFinite, 2, kNonFinite, kBehindSensor, kBehindSensor, 1, kBehindSensor};
  EXPECT_EQ(result.point_vertex, expected);
  EXPECT_EQ(result.vertex_point, (pcl::Indices{0, 6, 2}));
  EXPECT_EQ(result.triangles.size(), 1u);
}

TEST(SphericalDelaunay, Indices)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Cloud::Ptr cloud(new Cloud);
  for (int k = 0; k < 5; ++k)
    cloud->push_back(pointAt(0.01 * k, 0.02 * (k % 2), 1.0));
  cloud->push_back({nan, nan, nan});
  SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setInputCloud(cloud);
  delaunay.setIndices(pcl::IndicesPtr(new pcl::Indices{0, 2, 4, 5}));
  ASSERT_TRUE(delaunay.triangulate());
  const SphericalTriangulation& result = delaunay.getTriangulation();
  EXPECT_EQ(result.num_outside_indices, 2u);
  EXPECT_EQ(result.num_non_finite, 1u);
  EXPECT_EQ(result.point_vertex[1], kOutsideIndices);
  EXPECT_EQ(result.point_vertex[3], kOutsideIndices);
  EXPECT_EQ(result.point_vertex[5], kNonFinite);
  EXPECT_EQ(result.vertex_point, (pcl::Indices{0, 2, 4}));
  // Points 0, 2, 4 lie on the line phi = 0: no triangle.
  EXPECT_TRUE(result.triangles.empty());

  // Out-of-range indices are refused.
  delaunay.setIndices(pcl::IndicesPtr(new pcl::Indices{0, 1, 6}));
  EXPECT_FALSE(delaunay.triangulate());
}

TEST(SphericalDelaunay, SharedVertexKeepsNearestPoint)
{
  Cloud::Ptr cloud(new Cloud);
  cloud->push_back({0.2f, 0.4f, 2.f}); // 0: on the ray of point 1, twice as far
  cloud->push_back({0.1f, 0.2f, 1.f}); // 1
  cloud->push_back({0.3f, 0.6f, 3.f}); // 2: same ray, farther still
  cloud->push_back({0.f, 0.f, 1.f});   // 3
  cloud->push_back({0.5f, 0.f, 1.f});  // 4
  cloud->push_back({0.1f, 0.2f, 1.f}); // 5: duplicate of point 1
  const SphericalTriangulation result = triangulate(cloud, 1e-6);
  ASSERT_EQ(result.vertex_point.size(), 3u);
  const pcl::index_t v = result.point_vertex[1];
  ASSERT_GE(v, 0);
  for (const int i : {0, 2, 5})
    EXPECT_EQ(result.point_vertex[i], v) << "point " << i;
  const pcl::index_t rep = result.vertex_point[v];
  EXPECT_TRUE(rep == 1 || rep == 5) << rep;
  ASSERT_EQ(result.triangles.size(), 1u);

  // Within one quantization cell (step 0.01 rad): theta = 0.1001 and 0.0999 both round
  // to 10; the nearer point represents the vertex.
  Cloud::Ptr close(new Cloud);
  close->push_back(pointAt(0.1001, 0.05, 3.0));
  close->push_back(pointAt(0.0999, 0.05, 2.0));
  close->push_back(pointAt(0.0, 0.0, 1.0));
  close->push_back(pointAt(0.2, 0.0, 1.0));
  const SphericalTriangulation merged = triangulate(close, 0.01);
  ASSERT_EQ(merged.vertex_angles.size(), 3u);
  EXPECT_EQ(merged.point_vertex[0], merged.point_vertex[1]);
  EXPECT_EQ(merged.vertex_angles[merged.point_vertex[0]], (QuantizedPoint{10, 5}));
  EXPECT_EQ(merged.vertex_point[merged.point_vertex[0]], 1);
}

// Two different points at exactly the same range in one angle cell: the representative
// is the one with the smaller x (SphericalTriangulation::vertex_point), in either
// input order. Dyadic coordinates make the squared ranges equal to the last bit; with
// the tie broken on indices only, the vertex took whichever came first.
TEST(SphericalDelaunay, EqualRangesTieOnCoordinatesNotOnOrder)
{
  const float a = std::ldexp(1.f, -9), b = std::ldexp(1.f, -8);
  const pcl::PointXYZ p(a, b, 1.f), q(b, a, 1.f);
  for (const bool p_first : {true, false}) {
    Cloud::Ptr cloud(new Cloud);
    cloud->push_back(p_first ? p : q);
    cloud->push_back(p_first ? q : p);
    cloud->push_back({0.5f, 0.f, 1.f});
    cloud->push_back({0.f, 0.5f, 1.f});
    const SphericalTriangulation result = triangulate(cloud, 0.01);
    const pcl::index_t p_index = p_first ? 0 : 1;
    ASSERT_EQ(result.point_vertex[0], result.point_vertex[1]);
    const pcl::index_t v = result.point_vertex[0];
    ASSERT_GE(v, 0);
    EXPECT_EQ(result.vertex_point[v], p_index) << (p_first ? "p first" : "q first");
    EXPECT_EQ(result.vertex_positions[v], p.getVector3fMap());
  }
}

TEST(SphericalDelaunay, SensorPose)
{
  // Angles on multiples of the step, so that rounding errors of the transform cannot
  // move a point to another grid position.
  const Cloud::Ptr local = angleGrid(5, 4, 0.01, 0.01);
  const SphericalTriangulation expected = triangulate(local, 1e-4);
  ASSERT_EQ(expected.triangles.size(), 2u * 4u * 3u);

  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  pose.linear() =
      Eigen::AngleAxisf(0.5f, Eigen::Vector3f(0.2f, 1.f, 0.3f).normalized()).matrix();
  pose.translation() = Eigen::Vector3f(1.f, -2.f, 0.5f);
  Cloud::Ptr moved(new Cloud);
  pcl::transformPointCloud(*local, *moved, pose);
  moved->sensor_origin_ << pose.translation(), 0.f;
  moved->sensor_orientation_ = Eigen::Quaternionf(pose.linear());

  SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setAngleQuantization(1e-4);
  delaunay.setInputCloud(moved);
  EXPECT_TRUE(delaunay.getSensorPose().isApprox(pose, 1e-6f));
  ASSERT_TRUE(delaunay.triangulate());
  expectSameTriangulation(delaunay.getTriangulation(), expected);

  // The same cloud without its sensor pose, the pose given by setSensorPose().
  Cloud::Ptr bare(new Cloud(*moved));
  bare->sensor_origin_.setZero();
  bare->sensor_orientation_.setIdentity();
  delaunay.setInputCloud(bare);
  EXPECT_TRUE(delaunay.getSensorPose().isApprox(Eigen::Affine3f::Identity()));
  delaunay.setSensorPose(pose);
  EXPECT_TRUE(delaunay.getSensorPose().isApprox(pose));
  ASSERT_TRUE(delaunay.triangulate());
  expectSameTriangulation(delaunay.getTriangulation(), expected);

  // The override wins over the cloud's own pose; resetSensorPose() restores it.
  bare->sensor_origin_ << 5.f, 5.f, 5.f, 0.f;
  ASSERT_TRUE(delaunay.triangulate());
  expectSameTriangulation(delaunay.getTriangulation(), expected);
  bare->sensor_origin_.setZero();
  delaunay.resetSensorPose();
  ASSERT_TRUE(delaunay.triangulate());
  EXPECT_NE(delaunay.getTriangulation().vertex_angles, expected.vertex_angles);
}

TEST(SphericalDelaunay, PoseMustBeARotationAndATranslation)
{
  // toSensorFrame() inverts the rotation by its transpose: a scaled or mirrored pose
  // would map the points wrongly. triangulate() and insertPoints() refuse it, and a
  // cloud orientation that is no quaternion (a zero one is read as the identity).
  const Cloud::Ptr cloud = angleGrid(5, 4, 0.01, 0.01);
  SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setAngleQuantization(1e-4);
  delaunay.setInputCloud(cloud);
  ASSERT_TRUE(delaunay.sensorPoseIsRigid());
  ASSERT_TRUE(delaunay.triangulate());
  std::vector<Triangle> neighbours;
  delaunay.takeNeighbours(neighbours);
  Cloud::Ptr more(new Cloud(*cloud));
  more->push_back(pcl::PointXYZ(0.015f, 0.015f, 1.f));
  delaunay.setInputCloud(more);
  Eigen::Affine3f scaled = Eigen::Affine3f::Identity();
  scaled.scale(1.5f);
  delaunay.setSensorPose(scaled);
  std::string why;
  EXPECT_FALSE(delaunay.sensorPoseIsRigid(&why));
  EXPECT_NE(why.find("setSensorPose"), std::string::npos) << why;
  DelaunayInsertion info;
  std::vector<pcl::index_t> moved;
  EXPECT_FALSE(delaunay.insertPoints(cloud->size(), neighbours, info, moved));
  delaunay.resetSensorPose();
  EXPECT_TRUE(delaunay.insertPoints(cloud->size(), neighbours, info, moved));
  delaunay.setSensorPose(scaled);
  EXPECT_FALSE(delaunay.triangulate());
  delaunay.resetSensorPose();

  Cloud::Ptr zero(new Cloud(*cloud));
  zero->sensor_orientation_ = Eigen::Quaternionf(0.f, 0.f, 0.f, 0.f);
  delaunay.setInputCloud(zero);
  EXPECT_FALSE(delaunay.sensorPoseIsRigid(&why));
  EXPECT_NE(why.find("sensor_orientation_"), std::string::npos) << why;
  EXPECT_FALSE(delaunay.triangulate());
}

TEST(SphericalDelaunay, ReconstructGrid)
{
  const int w = 6, h = 4;
  // Cells of 200 x 300 quantization steps.
  const Cloud::Ptr cloud = angleGrid(w, h, 0.02, 0.03);
  SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setAngleQuantization(1e-4);
  delaunay.setInputCloud(cloud);

  pcl::PolygonMesh mesh;
  delaunay.reconstruct(mesh);
  const std::size_t expected = 2 * (w - 1) * (h - 1);
  ASSERT_EQ(mesh.polygons.size(), expected);
  EXPECT_EQ(static_cast<std::size_t>(mesh.cloud.width) * mesh.cloud.height,
            cloud->size());

  const SphericalTriangulation& tri = delaunay.getTriangulation();
  ASSERT_EQ(tri.vertex_angles.size(), cloud->size());
  std::set<std::set<pcl::index_t>> distinct;
  for (const auto& polygon : mesh.polygons) {
    ASSERT_EQ(polygon.vertices.size(), 3u);
    std::vector<QuantizedPoint> corners;
    for (const auto i : polygon.vertices) {
      ASSERT_GE(i, 0);
      ASSERT_LT(i, static_cast<pcl::index_t>(cloud->size()));
      corners.push_back(tri.vertex_angles[tri.point_vertex[i]]);
    }
    // Each triangle is half a cell, counter-clockwise in (theta, phi).
    EXPECT_EQ(twiceSignedArea(corners[0], corners[1], corners[2]), 200 * 300);
    distinct.insert({polygon.vertices.begin(), polygon.vertices.end()});
  }
  EXPECT_EQ(distinct.size(), expected);

  std::vector<pcl::Vertices> polygons;
  delaunay.reconstruct(polygons);
  ASSERT_EQ(polygons.size(), mesh.polygons.size());
  for (std::size_t t = 0; t < polygons.size(); ++t)
    EXPECT_EQ(polygons[t].vertices, mesh.polygons[t].vertices);

  // Over a sub-grid given by indices (columns 1..4, rows 0..2): a 4 x 3 grid.
  pcl::IndicesPtr indices(new pcl::Indices);
  for (int j = 0; j < 3; ++j)
    for (int i = 1; i < 5; ++i)
      indices->push_back(j * w + i);
  delaunay.setIndices(indices);
  delaunay.reconstruct(polygons);
  EXPECT_EQ(polygons.size(), 2u * 3u * 2u);
  const std::set<pcl::index_t> allowed(indices->begin(), indices->end());
  for (const auto& polygon : polygons)
    for (const auto i : polygon.vertices)
      EXPECT_EQ(allowed.count(i), 1u) << i;
}

TEST(SphericalDelaunay, NoInput)
{
  SphericalDelaunay<pcl::PointXYZ> delaunay;
  pcl::PolygonMesh mesh;
  mesh.polygons.resize(3);
  delaunay.reconstruct(mesh);
  EXPECT_TRUE(mesh.polygons.empty());
  std::vector<pcl::Vertices> polygons(2);
  delaunay.reconstruct(polygons);
  EXPECT_TRUE(polygons.empty());
  EXPECT_FALSE(delaunay.triangulate());
  EXPECT_TRUE(delaunay.getTriangulation().triangles.empty());

  // An empty cloud is no error and gives no triangle.
  delaunay.setInputCloud(Cloud::Ptr(new Cloud));
  delaunay.reconstruct(mesh);
  EXPECT_TRUE(mesh.polygons.empty());
  EXPECT_TRUE(delaunay.getTriangulation().vertex_point.empty());
}

TEST(SphericalDelaunay, BadQuantizationRefused)
{
  SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setInputCloud(angleGrid(3, 3, 0.01, 0.01));
  delaunay.setAngleQuantization(0.1);
  EXPECT_FALSE(delaunay.triangulate());
  delaunay.setAngleQuantization(1e-9);
  EXPECT_FALSE(delaunay.triangulate());
  delaunay.setAngleQuantization(1e-3);
  EXPECT_TRUE(delaunay.triangulate());
  EXPECT_EQ(delaunay.getTriangulation().triangles.size(), 8u);
}

// The radix sort behind the vertex order and the octree's Morton order: stable, and
// the same order for any thread count.
TEST(RadixSort, StableAndThreadIndependent)
{
  std::mt19937_64 rng(11);
  // Sizes on both sides of the threaded path's threshold (8,192 entries).
  for (const std::size_t size : {8191u, 8192u, 10001u, 150000u}) {
    SCOPED_TRACE(size);
    for (const int bits : {1, 7, 22, 33, 50, 64}) {
      SCOPED_TRACE(bits);
      std::vector<std::pair<std::uint64_t, pcl::index_t>> entries(size);
      const std::uint64_t mask =
          bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
      for (std::size_t i = 0; i < entries.size(); ++i) // many equal keys
        entries[i] = {(rng() % 5000) * 0x9e3779b97f4a7c15ull & mask,
                      static_cast<pcl::index_t>(i)};
      auto expected = entries;
      std::stable_sort(expected.begin(),
                       expected.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      for (const unsigned threads : {1u, 2u, 3u}) {
        SCOPED_TRACE(threads);
        auto sorted = entries;
        pcl::selective_seg::detail::radixSortByKey(sorted, bits, threads);
        EXPECT_TRUE(sorted == expected);
      }
    }
  }
}

TEST(SphericalDelaunay, NeighboursConsistent)
{
  // Random points in a cone of half-angle ~0.5 rad, fixed seed.
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> angle(-0.5, 0.5);
  std::uniform_real_distribution<double> range(1.0, 5.0);
  Cloud::Ptr cloud(new Cloud);
  for (int k = 0; k < 300; ++k)
    cloud->push_back(pointAt(angle(rng), angle(rng), range(rng)));
  const SphericalTriangulation result = triangulate(cloud, 1e-7);
  const auto& triangles = result.triangles;
  ASSERT_GT(triangles.size(), 400u);
  ASSERT_EQ(result.neighbours.size(), triangles.size());

  // Triangles at each undirected edge, counted independently.
  std::map<std::pair<pcl::index_t, pcl::index_t>, int> edge_count;
  const auto edge = [&](std::size_t t, int i) {
    const pcl::index_t a = triangles[t][(i + 1) % 3], b = triangles[t][(i + 2) % 3];
    return std::make_pair(std::min(a, b), std::max(a, b));
  };
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    EXPECT_GT(twiceSignedArea(result.vertex_angles[triangles[t][0]],
                              result.vertex_angles[triangles[t][1]],
                              result.vertex_angles[triangles[t][2]]),
              0);
    for (int i = 0; i < 3; ++i)
      ++edge_count[edge(t, i)];
  }
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) {
      SCOPED_TRACE(testing::Message() << "triangle " << t << " side " << i);
      const pcl::index_t u = result.neighbours[t][i];
      const int count = edge_count[edge(t, i)];
      ASSERT_LE(count, 2);
      if (u < 0) {
        EXPECT_EQ(count, 1);
        continue;
      }
      EXPECT_EQ(count, 2);
      ASSERT_LT(u, static_cast<pcl::index_t>(triangles.size()));
      ASSERT_NE(u, static_cast<pcl::index_t>(t));
      int back = -1;
      for (int j = 0; j < 3; ++j)
        if (result.neighbours[u][j] == static_cast<pcl::index_t>(t))
          back = j;
      ASSERT_GE(back, 0) << "neighbour " << u << " does not list it back";
      EXPECT_EQ(edge(u, back), edge(t, i));
    }
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
