/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>
#include <vector>

#include "synthetic_scenes.h"

namespace {

using selseg_test::Face;
using selseg_test::SamplingParams;
using selseg_test::Scene;
using Cloud = pcl::PointCloud<pcl::PointXYZL>;

/** A square facing the sensor at depth \a z [m], half-width \a half [m]. */
Face
frontalSquare(double z, double half, std::uint32_t label)
{
  Face face;
  face.origin = Eigen::Vector3d(-half, -half, z);
  face.u = Eigen::Vector3d(0.0, 2.0 * half, 0.0);
  face.v = Eigen::Vector3d(2.0 * half, 0.0, 0.0);
  face.label = label;
  return face;
}

/** Face coordinates (s, t) of \a p in the plane of \a face. */
Eigen::Vector2d
faceCoordinates(const Face& face, const Eigen::Vector3d& p)
{
  Eigen::Matrix<double, 3, 2> edges;
  edges << face.u, face.v;
  return edges.colPivHouseholderQr().solve(p - face.origin);
}

/** Signed distance of \a p to the plane of \a face [m]. */
double
planeDistance(const Face& face, const Eigen::Vector3d& p)
{
  return face.u.cross(face.v).normalized().dot(p - face.origin);
}

std::map<std::uint32_t, int>
labelCounts(const Cloud& cloud)
{
  std::map<std::uint32_t, int> counts;
  for (const auto& point : cloud)
    ++counts[point.label];
  return counts;
}

TEST(SyntheticScenes, BoxFacesAreOutwardAndLabelledInOrder)
{
  Scene scene;
  const Eigen::Vector3d centre(0.2, 0.3, 1.5);
  const Eigen::Vector3d half(0.1, 0.2, 0.3);
  const double yaw = 0.6;
  EXPECT_EQ(addBox(scene, centre, half, yaw, 5), 11u);
  ASSERT_EQ(scene.faces.size(), 6u);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const int axis[6] = {1, 1, 0, 0, 2, 2};
  const double sign[6] = {-1.0, 1.0, -1.0, 1.0, -1.0, 1.0};
  for (int i = 0; i < 6; ++i) {
    const Face& face = scene.faces[i];
    EXPECT_EQ(face.label, 5u + i);
    const Eigen::Vector3d expected_normal = sign[i] * rotation.col(axis[i]);
    EXPECT_LT((face.u.cross(face.v).normalized() - expected_normal).norm(), 1e-12);
    const Eigen::Vector3d face_centre = face.origin + 0.5 * (face.u + face.v);
    EXPECT_NEAR((face_centre - centre).dot(expected_normal), half[axis[i]], 1e-12);
    EXPECT_LT((face_centre - centre).cross(expected_normal).norm(), 1e-12);
  }
  EXPECT_LT(scene.faces[0].u.cross(scene.faces[0].v).y(), 0.0);
}

TEST(SyntheticScenes, PointsLieOnTheFaceTheirLabelNames)
{
  const Scene scene = selseg_test::makeCubeOnTableScene();
  std::map<std::uint32_t, Face> by_label;
  for (const Face& face : scene.faces)
    by_label[face.label] = face;
  ASSERT_EQ(by_label.size(), scene.faces.size());

  std::vector<Eigen::Vector3d> exact;
  const Cloud cloud = scan(scene, selseg_test::makeCubeOnTableView(5000), &exact);
  ASSERT_EQ(cloud.size(), exact.size());
  ASSERT_GT(cloud.size(), 4000u);
  EXPECT_EQ(cloud.height, 1u);
  EXPECT_EQ(cloud.width, cloud.size());
  EXPECT_TRUE(cloud.is_dense);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto it = by_label.find(cloud[i].label);
    ASSERT_NE(it, by_label.end()) << "label " << cloud[i].label;
    const Face& face = it->second;
    EXPECT_LT(std::abs(planeDistance(face, exact[i])), 1e-9);
    const Eigen::Vector2d st = faceCoordinates(face, exact[i]);
    EXPECT_GE(st.minCoeff(), -1e-9);
    EXPECT_LE(st.maxCoeff(), 1.0 + 1e-9);
    const Eigen::Vector3d stored = cloud[i].getVector3fMap().cast<double>();
    EXPECT_LT((stored - exact[i]).norm(), 1e-6);
    EXPECT_LT(std::abs(planeDistance(face, stored)), 1e-6);
  }
}

TEST(SyntheticScenes, NearestFaceOccludesFartherOnes)
{
  Scene scene;
  scene.faces.push_back(frontalSquare(3.0, 10.0, 1));
  scene.faces.push_back(frontalSquare(1.0, 0.2, 2));
  SamplingParams params;
  params.num_rays = 4000;
  const Cloud cloud = scan(scene, params);
  ASSERT_EQ(cloud.size(), params.num_rays);
  int near_count = 0;
  for (const auto& point : cloud) {
    const double x = point.x / point.z;
    const double y = point.y / point.z;
    const bool behind_near = std::abs(x) < 0.2 && std::abs(y) < 0.2;
    if (point.label == 2) {
      ++near_count;
      EXPECT_NEAR(point.z, 1.0, 1e-6);
    } else {
      EXPECT_NEAR(point.z, 3.0, 1e-6);
      EXPECT_FALSE(behind_near) << x << " " << y;
    }
  }
  EXPECT_GT(near_count, 100);
}

TEST(SyntheticScenes, CubeSceneShowsWallTableAndThreeCubeFaces)
{
  const Cloud cloud =
      scan(selseg_test::makeCubeOnTableScene(), selseg_test::makeCubeOnTableView(5000));
  const std::map<std::uint32_t, int> counts = labelCounts(cloud);
  std::set<std::uint32_t> labels;
  for (const auto& entry : counts) {
    labels.insert(entry.first);
    EXPECT_GE(entry.second, 100) << "label " << entry.first;
  }
  EXPECT_EQ(labels, (std::set<std::uint32_t>{1, 2, 3, 6, 7}));
}

TEST(SyntheticScenes, SeedDeterminesTheCloud)
{
  const Scene scene = selseg_test::makeCubeOnTableScene();
  SamplingParams params = selseg_test::makeCubeOnTableView(2000);
  params.range_noise = 0.005;
  const Cloud first = scan(scene, params);
  const Cloud again = scan(scene, params);
  params.seed = 7;
  const Cloud other = scan(scene, params);
  ASSERT_EQ(first.size(), again.size());
  bool all_equal = true;
  for (std::size_t i = 0; i < first.size(); ++i)
    all_equal = all_equal && first[i].getVector3fMap() == again[i].getVector3fMap() &&
                first[i].label == again[i].label;
  EXPECT_TRUE(all_equal);
  ASSERT_FALSE(other.empty());
  EXPECT_NE(first[0].getVector3fMap(), other[0].getVector3fMap());
  int differing = 0;
  for (std::size_t i = 0; i < std::min(first.size(), other.size()); ++i)
    differing += first[i].getVector3fMap() != other[i].getVector3fMap();
  EXPECT_GT(differing, static_cast<int>(first.size()) * 9 / 10);
}

/** Ratio of the point counts in the densest and the sparsest tenth of the window. */
double
measuredDensityRatio(const SamplingParams& params)
{
  Scene scene;
  scene.faces.push_back(frontalSquare(1.0, 5.0, 1));
  const Cloud cloud = scan(scene, params);
  EXPECT_EQ(cloud.size(), params.num_rays);
  constexpr int kCells = 20;
  const double d_theta = (params.theta_max - params.theta_min) / kCells;
  const double d_phi = (params.phi_max - params.phi_min) / kCells;
  std::vector<int> counts(kCells * kCells, 0);
  for (const auto& point : cloud) {
    const int i =
        static_cast<int>((std::atan2(point.x, point.z) - params.theta_min) / d_theta);
    const int j =
        static_cast<int>((std::atan2(point.y, point.z) - params.phi_min) / d_phi);
    ++counts[std::clamp(i, 0, kCells - 1) * kCells + std::clamp(j, 0, kCells - 1)];
  }
  std::vector<double> density(counts.size());
  for (int i = 0; i < kCells; ++i)
    for (int j = 0; j < kCells; ++j)
      density[i * kCells + j] = relativeDensity(params,
                                                params.theta_min + (i + 0.5) * d_theta,
                                                params.phi_min + (j + 0.5) * d_phi);
  std::vector<int> order(counts.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return density[a] < density[b];
  });
  const std::size_t tenth = order.size() / 10;
  double sparse = 0.0;
  double dense = 0.0;
  for (std::size_t k = 0; k < tenth; ++k) {
    sparse += counts[order[k]];
    dense += counts[order[order.size() - 1 - k]];
  }
  return dense / std::max(sparse, 1.0);
}

TEST(SyntheticScenes, DensityFunctionSpansTheRequestedRatio)
{
  SamplingParams params;
  params.density_ratio = 6.0;
  EXPECT_NEAR(relativeDensity(params, params.theta_min, params.phi_min), 1.0, 1e-12);
  EXPECT_NEAR(relativeDensity(params, params.theta_max, params.phi_max), 6.0, 1e-12);
  for (double a = 0.0; a <= 1.0; a += 0.05)
    for (double b = 0.0; b <= 1.0; b += 0.05) {
      const double theta = params.theta_min + a * (params.theta_max - params.theta_min);
      const double phi = params.phi_min + b * (params.phi_max - params.phi_min);
      const double density = relativeDensity(params, theta, phi);
      EXPECT_GE(density, 1.0 - 1e-12);
      EXPECT_LE(density, 6.0 + 1e-12);
    }
}

TEST(SyntheticScenes, DensityRatioIsHonoured)
{
  for (const double ratio : {4.0, 10.0}) {
    SamplingParams params;
    params.num_rays = 50000;
    params.density_ratio = ratio;
    const double measured = measuredDensityRatio(params);
    EXPECT_GT(measured, ratio / 2.0) << "requested " << ratio;
    EXPECT_LT(measured, ratio * 2.0) << "requested " << ratio;
  }
  SamplingParams uniform;
  uniform.num_rays = 50000;
  uniform.density_ratio = 1.0;
  EXPECT_NEAR(measuredDensityRatio(uniform), 1.0, 0.15);
}

/** Standard deviation [m] of the range error of a frontal face at depth \a z [m]. */
double
rangeNoiseStd(double z, double range_noise)
{
  Scene scene;
  scene.faces.push_back(frontalSquare(z, 1.0, 1));
  SamplingParams params;
  params.theta_min = params.phi_min = -0.05;
  params.theta_max = params.phi_max = 0.05;
  params.num_rays = 20000;
  params.range_noise = range_noise;
  std::vector<Eigen::Vector3d> exact;
  const Cloud cloud = scan(scene, params, &exact);
  EXPECT_EQ(cloud.size(), params.num_rays);
  double sum = 0.0;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d point = cloud[i].getVector3fMap().cast<double>();
    EXPECT_LT(point.normalized().cross(exact[i].normalized()).norm(), 1e-6);
    EXPECT_EQ(cloud[i].label, 1u);
    const double residual = point.norm() - exact[i].norm();
    sum += residual;
    sum_sq += residual * residual;
  }
  const double n = static_cast<double>(cloud.size());
  const double mean = sum / n;
  const double std_dev = std::sqrt(sum_sq / n - mean * mean);
  EXPECT_LT(std::abs(mean), 0.05 * std_dev);
  return std_dev;
}

TEST(SyntheticScenes, RangeNoiseScalesWithSquaredRange)
{
  const double noise = 0.01;
  EXPECT_NEAR(rangeNoiseStd(2.0, noise), noise * 4.0, 0.2 * noise * 4.0);
  EXPECT_NEAR(rangeNoiseStd(1.0, noise), noise * 1.0, 0.2 * noise * 1.0);
}

TEST(SyntheticScenes, InvalidParametersThrow)
{
  const Scene scene = selseg_test::makeCubeOnTableScene();
  SamplingParams params;
  params.theta_max = params.theta_min;
  EXPECT_THROW(scan(scene, params), std::invalid_argument);
  params = SamplingParams();
  params.phi_max = 1.6;
  EXPECT_THROW(scan(scene, params), std::invalid_argument);
  params = SamplingParams();
  params.density_ratio = 0.5;
  EXPECT_THROW(scan(scene, params), std::invalid_argument);
  params = SamplingParams();
  params.range_noise = -0.1;
  EXPECT_THROW(scan(scene, params), std::invalid_argument);
}

} // namespace

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
