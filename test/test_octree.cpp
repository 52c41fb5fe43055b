/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 *
 *  Unit tests of the multi-resolution octree (paper, Sec. III.C, eq. 3-6).
 */

#include <pcl_selective_seg/octree_pointcloud_normal_variance.h>

#include <gtest/gtest.h>
#include <pcl/octree/octree_pointcloud_pointvector.h>
#include <pcl/pcl_base.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <vector>

using pcl::selective_seg::AdaptiveLeaf;
using pcl::selective_seg::NormalSpreadFrame;
using Octree = pcl::selective_seg::OctreePointCloudNormalVariance<pcl::PointXYZ>;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kPaperThreshold = 7.6 * kDeg;
constexpr std::size_t kMinPoints = 8;

/** A cloud with per-point normals (toward the sensor) and areas A_p. */
struct Scene {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::PointCloud<pcl::Normal>::Ptr normals{new pcl::PointCloud<pcl::Normal>};
  std::shared_ptr<std::vector<double>> areas{new std::vector<double>};

  void add(const Eigen::Vector3f& p, const Eigen::Vector3f& n, double area)
  {
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    normals->push_back(pcl::Normal(n.x(), n.y(), n.z()));
    areas->push_back(area);
  }
};

/** Build the tree over \a scene (optionally over \a indices) and split it. */
std::unique_ptr<Octree>
buildOctree(const Scene& scene,
            double resolution,
            double max_std_dev,
            std::size_t min_points = kMinPoints,
            const pcl::IndicesPtr& indices = nullptr,
            const Eigen::Quaternionf* orientation = nullptr,
            unsigned int threads = 0,
            NormalSpreadFrame frame = NormalSpreadFrame::Sensor)
{
  auto octree = std::make_unique<Octree>(resolution);
  if (threads > 0)
    octree->setNumberOfThreads(threads);
  octree->setNormalSpreadFrame(frame);
  octree->setInputCloud(scene.cloud, indices);
  octree->setInputNormals(scene.normals, scene.areas);
  if (orientation)
    octree->setSensorOrientation(*orientation);
  EXPECT_TRUE(octree->addPointsFromInputCloud());
  octree->computeAdaptiveLeaves(max_std_dev, min_points);
  return octree;
}

/** A unit normal facing a sensor on the -z side, tilted by theta about y and phi about
 * x: the reversed normal (what eq. 5 measures) is (tan theta, tan phi, 1), normalized.
 */
Eigen::Vector3f
facingNormal(double theta, double phi)
{
  return -Eigen::Vector3d(std::tan(theta), std::tan(phi), 1.0)
              .normalized()
              .cast<float>();
}

/** A ridge of two planes at 90 degrees seen from the origin: z = 2 + x for x in
 * [-1, 0] and z = 2 - x for x in (0, 0.65], y in [0, 1], on a grid of step 0.05. The
 * asymmetry keeps the fold off the octree's first split planes. */
Scene
ridge()
{
  Scene scene;
  const float s = static_cast<float>(1.0 / std::sqrt(2.0));
  for (int i = -20; i <= 13; ++i)
    for (int j = 0; j <= 20; ++j) {
      const float x = 0.05f * static_cast<float>(i);
      const float y = 0.05f * static_cast<float>(j);
      const Eigen::Vector3f n =
          i <= 0 ? Eigen::Vector3f(s, 0.f, -s) : Eigen::Vector3f(-s, 0.f, -s);
      scene.add(Eigen::Vector3f(x, y, 2.f - std::abs(x)), n, 0.005);
    }
  return scene;
}

/** The independent reference of eq. 4-5 over a set of points: theta and phi of each
 * reversed normal in the sensor frame, deviations from the angles of the 1/A_p weighted
 * mean normal wrapped into (-pi, pi]. */
struct Reference {
  Eigen::Vector3d normal; ///< input orientation
  double sigma_theta;
  double sigma_phi;
  double area;
};

double
wrap(double a)
{
  return std::remainder(a, 2.0 * M_PI);
}

Reference
reference(const Scene& scene,
          const std::vector<pcl::index_t>& points,
          const Eigen::Matrix3d& orientation = Eigen::Matrix3d::Identity())
{
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double sum_w = 0.0, area = 0.0;
  std::vector<Eigen::Vector3d> m;
  for (const auto i : points) {
    const Eigen::Vector3d n = (*scene.normals)[i].getNormalVector3fMap().cast<double>();
    m.push_back(-(orientation.transpose() * n).normalized());
    sum += m.back() / (*scene.areas)[i];
    sum_w += 1.0 / (*scene.areas)[i];
    area += (*scene.areas)[i];
  }
  const Eigen::Vector3d mean = sum.normalized();
  double var_theta = 0.0, var_phi = 0.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const double w = 1.0 / (*scene.areas)[points[k]];
    const double dt =
        wrap(std::atan2(m[k].x(), m[k].z()) - std::atan2(mean.x(), mean.z()));
    const double dp =
        wrap(std::atan2(m[k].y(), m[k].z()) - std::atan2(mean.y(), mean.z()));
    var_theta += w * dt * dt;
    var_phi += w * dp * dp;
  }
  return {-(orientation * mean),
          std::sqrt(var_theta / sum_w),
          std::sqrt(var_phi / sum_w),
          area};
}

std::vector<pcl::index_t>
leafPoints(const Octree& octree, const AdaptiveLeaf& leaf)
{
  const auto& ordered = octree.getOrderedIndices();
  return {ordered.begin() + leaf.begin, ordered.begin() + leaf.end};
}

/** Finest-level key of a point, as PCL's octree computes it from its bounding box. */
pcl::octree::OctreeKey
finestKey(const Octree& octree, const pcl::PointXYZ& p)
{
  double min_x, min_y, min_z, max_x, max_y, max_z;
  octree.getBoundingBox(min_x, min_y, min_z, max_x, max_y, max_z);
  const double r = octree.getResolution();
  return pcl::octree::OctreeKey(static_cast<pcl::uindex_t>((p.x - min_x) / r),
                                static_cast<pcl::uindex_t>((p.y - min_y) / r),
                                static_cast<pcl::uindex_t>((p.z - min_z) / r));
}

bool
inNode(const pcl::octree::OctreeKey& finest,
       unsigned shift,
       const pcl::octree::OctreeKey& key)
{
  return (finest.x >> shift) == key.x && (finest.y >> shift) == key.y &&
         (finest.z >> shift) == key.z;
}

std::vector<pcl::index_t>
validPoints(const Scene& scene)
{
  std::vector<pcl::index_t> valid;
  for (std::size_t i = 0; i < scene.cloud->size(); ++i)
    if (pcl::isFinite((*scene.cloud)[i]) && pcl::isNormalFinite((*scene.normals)[i]) &&
        (*scene.normals)[i].getNormalVector3fMap().squaredNorm() > 0.0f &&
        std::isfinite((*scene.areas)[i]) && (*scene.areas)[i] > 0.0 &&
        std::isfinite(1.0 / (*scene.areas)[i]))
      valid.push_back(static_cast<pcl::index_t>(i));
  return valid;
}

/** The leaves' ranges tile [0, #ordered) in order, and the ordered indices are a
 * permutation of \a expected. */
void
expectPartition(const Octree& octree, std::vector<pcl::index_t> expected)
{
  const auto& leaves = octree.getAdaptiveLeaves();
  ASSERT_FALSE(leaves.empty());
  std::size_t next = 0;
  for (const auto& leaf : leaves) {
    EXPECT_EQ(leaf.begin, next);
    EXPECT_LT(leaf.begin, leaf.end);
    next = leaf.end;
  }
  EXPECT_EQ(next, octree.getOrderedIndices().size());
  pcl::Indices ordered = octree.getOrderedIndices();
  std::sort(ordered.begin(), ordered.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(ordered, expected);
}

} // namespace

TEST(OctreePointCloudNormalVariance, PlaneFacingSensorIsOneLeaf)
{
  Scene scene;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      scene.add(
          Eigen::Vector3f(0.1f * i, 0.1f * j, 2.f), Eigen::Vector3f(0, 0, -1), 0.01);
  const auto octree = buildOctree(scene, 0.02, kPaperThreshold);
  ASSERT_GE(octree->getTreeDepth(), 4u); // 0.4 m / 0.02 m = 20 voxels: room to split
  const auto& leaves = octree->getAdaptiveLeaves();
  ASSERT_EQ(leaves.size(), 1u);
  const AdaptiveLeaf& leaf = leaves[0];
  EXPECT_EQ(leaf.depth, 0u);
  EXPECT_EQ(leaf.key.x, 0u);
  EXPECT_EQ(leaf.key.y, 0u);
  EXPECT_EQ(leaf.key.z, 0u);
  EXPECT_EQ(leaf.begin, 0u);
  EXPECT_EQ(leaf.end, 25u);
  EXPECT_FLOAT_EQ(leaf.sigma_theta, 0.f);
  EXPECT_FLOAT_EQ(leaf.sigma_phi, 0.f);
  EXPECT_NEAR(leaf.normal.x(), 0.f, 1e-6f);
  EXPECT_NEAR(leaf.normal.y(), 0.f, 1e-6f);
  EXPECT_NEAR(leaf.normal.z(), -1.f, 1e-6f);
  EXPECT_NEAR(leaf.area, 0.25, 1e-12); // eq. 6: 25 x 0.01
}

TEST(OctreePointCloudNormalVariance, VoxelNormalIsInverseAreaWeightedMean)
{
  // eq. 4: N' = (0, 0, -1) / 1 + (0.6, 0, -0.8) / 2 + (0, 0.6, -0.8) / 4
  //           = (0.3, 0.15, -1.6); eq. 6: A_v = 1 + 2 + 4 = 7.
  Scene scene;
  scene.add(Eigen::Vector3f(0.f, 0.f, 1.f), Eigen::Vector3f(0.f, 0.f, -1.f), 1.0);
  scene.add(Eigen::Vector3f(0.1f, 0.f, 1.f), Eigen::Vector3f(0.6f, 0.f, -0.8f), 2.0);
  scene.add(Eigen::Vector3f(0.f, 0.1f, 1.f), Eigen::Vector3f(0.f, 0.6f, -0.8f), 4.0);
  const auto octree = buildOctree(scene, 0.01, M_PI);
  ASSERT_EQ(octree->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = octree->getAdaptiveLeaves()[0];
  const double norm = std::sqrt(0.09 + 0.0225 + 2.56);
  EXPECT_NEAR(leaf.normal.x(), 0.3 / norm, 1e-6);
  EXPECT_NEAR(leaf.normal.y(), 0.15 / norm, 1e-6);
  EXPECT_NEAR(leaf.normal.z(), -1.6 / norm, 1e-6);
  EXPECT_NEAR(leaf.area, 7.0, 1e-12);
}

TEST(OctreePointCloudNormalVariance, SigmaThetaAroundWeightedMeanNormal)
{
  // Four normals at theta = 0, 0, 0 and 80 degrees (phi = 0), equal areas. The mean
  // normal's angle is atan2(sin 80, 3 + cos 80) = 17.24 degrees (not the mean angle,
  // 20), and sigma_theta the population standard deviation around it (34.75 degrees,
  // against 34.64 around 20).
  Scene scene;
  const std::vector<double> thetas{0.0, 0.0, 0.0, 80.0 * kDeg};
  for (std::size_t k = 0; k < thetas.size(); ++k)
    scene.add(Eigen::Vector3f(0.1f * k, 0.f, 1.f), facingNormal(thetas[k], 0.0), 1.0);
  const auto octree = buildOctree(scene, 0.01, M_PI);
  ASSERT_EQ(octree->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = octree->getAdaptiveLeaves()[0];

  const double mean = std::atan2(std::sin(thetas[3]), 3.0 + std::cos(thetas[3]));
  EXPECT_NEAR(mean / kDeg, 17.24, 0.01);
  double sum = 0.0;
  for (const double t : thetas)
    sum += (t - mean) * (t - mean);
  const double expected = std::sqrt(sum / 4.0);
  EXPECT_NEAR(expected / kDeg, 34.75, 0.01);
  EXPECT_NEAR(leaf.sigma_theta, expected, 1e-6);
  EXPECT_NEAR(leaf.sigma_phi, 0.0, 1e-6);
}

namespace {

const std::vector<double> kTiltPhis{-30.0 * kDeg, 0.0, 20.0 * kDeg, 50.0 * kDeg};
const std::vector<double> kTiltAreas{1.0, 2.0, 2.0, 4.0};

/** Four normals tilted by kTiltPhis about the x axis, with the areas kTiltAreas. */
Scene
tiltedInPhi()
{
  Scene scene;
  for (std::size_t k = 0; k < kTiltPhis.size(); ++k)
    scene.add(Eigen::Vector3f(0.f, 0.1f * k, 1.f),
              facingNormal(0.0, kTiltPhis[k]),
              kTiltAreas[k]);
  return scene;
}

} // namespace

TEST(OctreePointCloudNormalVariance, SigmaPhiWeightedByInverseArea)
{
  // phi = -30, 0, 20, 50 degrees with A_p = 1, 2, 2, 4: weights 1, 1/2, 1/2, 1/4.
  const Scene scene = tiltedInPhi();
  const std::vector<double>& phis = kTiltPhis;
  const std::vector<double>& areas = kTiltAreas;
  const auto octree = buildOctree(scene, 0.01, M_PI);
  ASSERT_EQ(octree->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = octree->getAdaptiveLeaves()[0];

  double sy = 0.0, sz = 0.0, sw = 0.0;
  for (std::size_t k = 0; k < phis.size(); ++k) {
    sy += std::sin(phis[k]) / areas[k];
    sz += std::cos(phis[k]) / areas[k];
    sw += 1.0 / areas[k];
  }
  const double mean = std::atan2(sy, sz);
  double var = 0.0;
  for (std::size_t k = 0; k < phis.size(); ++k)
    var += (phis[k] - mean) * (phis[k] - mean) / areas[k];
  EXPECT_NEAR(leaf.sigma_phi, std::sqrt(var / sw), 1e-6);
  EXPECT_NEAR(leaf.sigma_theta, 0.0, 1e-6);
  EXPECT_NEAR(leaf.normal.y(), -std::sin(mean), 1e-6);
  EXPECT_NEAR(leaf.normal.z(), -std::cos(mean), 1e-6);
}

TEST(OctreePointCloudNormalVariance, WallFacingSensorHasSmallSigma)
{
  // Normals (+-0.01, +-0.01, -1), signs alternating: atan2(n_x, n_z) would jump between
  // +pi and -pi. The deviations are atan(0.01) ~ 0.01 rad on both axes.
  Scene scene;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const float sx = (i + j) % 2 == 0 ? 0.01f : -0.01f;
      const float sy = i % 2 == 0 ? 0.01f : -0.01f;
      scene.add(Eigen::Vector3f(0.05f * i, 0.05f * j, 3.f),
                Eigen::Vector3f(sx, sy, -1.f).normalized(),
                0.0025);
    }
  const auto octree = buildOctree(scene, 0.01, kPaperThreshold);
  ASSERT_EQ(octree->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = octree->getAdaptiveLeaves()[0];
  EXPECT_NEAR(leaf.sigma_theta, std::atan(0.01), 1e-5);
  EXPECT_NEAR(leaf.sigma_phi, std::atan(0.01), 1e-5);
  EXPECT_NEAR(leaf.normal.z(), -1.f, 1e-6f);

  // The same wall with its normals reversed (facing away): the angles sit at the +-pi
  // seam, and the wrapped deviations keep sigma small.
  for (auto& n : scene.normals->points)
    n.getNormalVector3fMap() *= -1.f;
  const auto reversed = buildOctree(scene, 0.01, kPaperThreshold);
  ASSERT_EQ(reversed->getAdaptiveLeaves().size(), 1u);
  EXPECT_NEAR(reversed->getAdaptiveLeaves()[0].sigma_theta, std::atan(0.01), 1e-5);
  EXPECT_NEAR(reversed->getAdaptiveLeaves()[0].sigma_phi, std::atan(0.01), 1e-5);
}

namespace {

/** Build in the voxel's own frame (NormalSpreadFrame::MeanNormal). */
std::unique_ptr<Octree>
buildInMeanNormalFrame(const Scene& scene, double resolution, double max_std_dev)
{
  return buildOctree(scene,
                     resolution,
                     max_std_dev,
                     kMinPoints,
                     nullptr,
                     nullptr,
                     0,
                     NormalSpreadFrame::MeanNormal);
}

/** A floor seen by a level camera (y down): the plane y = 1 for x in [-1, 1] and z in
 * [1, 3], a 40 x 40 grid, normals (0, -1, 0) toward the sensor with components of
 * +-0.01 along x and z, the signs alternating. */
Scene
noisyFloor()
{
  Scene scene;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const float sx = (i + j) % 2 == 0 ? 0.01f : -0.01f;
      const float sz = i % 2 == 0 ? 0.01f : -0.01f;
      scene.add(Eigen::Vector3f(-1.f + 0.05f * i, 1.f, 1.f + 0.05f * j),
                Eigen::Vector3f(sx, -1.f, sz).normalized(),
                0.0025);
    }
  return scene;
}

} // namespace

TEST(OctreePointCloudNormalVariance, MeanNormalFrameSigmasOnAFloor)
{
  // Four equal-area normals of a floor, reversed m = (+-sin a, cos a, 0) and
  // (0, cos a, +-sin a), a = 4 deg. Mean normal (0, 1, 0); the voxel's frame is
  // u = x, v = mean x u = (0, 0, -1): the tilts are +-a along u, then -+a along v, so
  // sigma_theta = sigma_phi = sqrt(2 a^2 / 4) = a / sqrt(2) = 2.83 deg.
  // In the sensor frame m_z is 0 or +-sin a: theta = atan2(m_x, m_z) of the first two
  // is +-90 deg around a mean of atan2(0, 0) = 0, and the other two sit at 0 and 180
  // deg: sigma_theta = sqrt((2 (pi/2)^2 + pi^2) / 4) = 110 deg, a split at any
  // threshold.
  const double a = 4.0 * kDeg;
  Scene scene;
  const std::vector<Eigen::Vector3d> m{{std::sin(a), std::cos(a), 0.0},
                                       {-std::sin(a), std::cos(a), 0.0},
                                       {0.0, std::cos(a), std::sin(a)},
                                       {0.0, std::cos(a), -std::sin(a)}};
  for (std::size_t k = 0; k < m.size(); ++k)
    scene.add(Eigen::Vector3f(0.1f * k, 1.f, 2.f), -m[k].cast<float>(), 1.0);

  const auto mean_frame = buildInMeanNormalFrame(scene, 0.01, M_PI);
  ASSERT_EQ(mean_frame->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = mean_frame->getAdaptiveLeaves()[0];
  EXPECT_NEAR(leaf.sigma_theta, a / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(leaf.sigma_phi, a / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(leaf.normal.y(), -1.f, 1e-6f);

  const auto sensor_frame = buildOctree(scene, 0.01, M_PI);
  ASSERT_EQ(sensor_frame->getAdaptiveLeaves().size(), 1u);
  const double expected = std::sqrt((2.0 * M_PI * M_PI / 4.0 + M_PI * M_PI) / 4.0);
  EXPECT_NEAR(expected / kDeg, 110.2, 0.1);
  EXPECT_NEAR(sensor_frame->getAdaptiveLeaves()[0].sigma_theta, expected, 1e-6);
}

TEST(OctreePointCloudNormalVariance, MeanNormalFrameSigmasOnAWallAlongX)
{
  // The floor above turned 90 deg about z: a wall whose mean normal lies along the
  // sensor's x axis, reversed m = (cos a, +-sin a, 0) and (cos a, 0, +-sin a). The
  // frame's reference axis must then be y (x projects to nothing: both sigmas were
  // 0, a voxel that never splits): u = y, v = z, and by the same hand computation
  // sigma_theta = sigma_phi = a / sqrt(2) = 2.83 deg.
  const double a = 4.0 * kDeg;
  Scene scene;
  const std::vector<Eigen::Vector3d> m{{std::cos(a), std::sin(a), 0.0},
                                       {std::cos(a), -std::sin(a), 0.0},
                                       {std::cos(a), 0.0, std::sin(a)},
                                       {std::cos(a), 0.0, -std::sin(a)}};
  for (std::size_t k = 0; k < m.size(); ++k)
    scene.add(Eigen::Vector3f(2.f, 0.1f * k, 1.f), -m[k].cast<float>(), 1.0);
  const auto octree = buildInMeanNormalFrame(scene, 0.01, M_PI);
  ASSERT_EQ(octree->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = octree->getAdaptiveLeaves()[0];
  EXPECT_NEAR(leaf.sigma_theta, a / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(leaf.sigma_phi, a / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(leaf.normal.x(), -1.f, 1e-6f);
  // At 2 deg the root splits when its four points may be split (the default minimum
  // is 8; its children, of two points each, may not).
  EXPECT_EQ(buildOctree(scene,
                        0.01,
                        2.0 * kDeg,
                        4,
                        nullptr,
                        nullptr,
                        0,
                        NormalSpreadFrame::MeanNormal)
                ->getAdaptiveLeaves()
                .size(),
            2u);
}

TEST(OctreePointCloudNormalVariance, MeanNormalFrameMatchesSensorFrameInOnePlane)
{
  // Normals tilted within the y-z plane (theta = 0): both frames measure the same
  // angles, phi - phi_mean, so the hand-computed sigmas of
  // SigmaPhiWeightedByInverseArea hold in the voxel's frame too.
  const Scene scene = tiltedInPhi();
  const auto sensor_frame = buildOctree(scene, 0.01, M_PI);
  const auto mean_frame = buildInMeanNormalFrame(scene, 0.01, M_PI);
  ASSERT_EQ(mean_frame->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& s = sensor_frame->getAdaptiveLeaves()[0];
  const AdaptiveLeaf& m = mean_frame->getAdaptiveLeaves()[0];
  EXPECT_GT(s.sigma_phi, 20.0 * kDeg);
  EXPECT_NEAR(m.sigma_phi, s.sigma_phi, 1e-6);
  EXPECT_NEAR(m.sigma_theta, 0.0, 1e-6);
  EXPECT_EQ(m.normal, s.normal);
}

TEST(OctreePointCloudNormalVariance, MeanNormalFrameKeepsAFloorWhole)
{
  // The known weakness of eq. 5 as written: with m_z near 0 the floor's +-0.01 noise
  // swings theta by tens of degrees, and the floor splits down to its finest voxels.
  // In the voxel's frame it is one leaf with the noise's own spread, atan(0.01) on
  // both axes, like the same noise on a wall facing the sensor
  // (WallFacingSensorHasSmallSigma).
  const Scene scene = noisyFloor();
  const auto sensor_frame = buildOctree(scene, 0.05, kPaperThreshold);
  EXPECT_GT(sensor_frame->getAdaptiveLeaves().size(), 100u);
  const auto mean_frame = buildInMeanNormalFrame(scene, 0.05, kPaperThreshold);
  ASSERT_EQ(mean_frame->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = mean_frame->getAdaptiveLeaves()[0];
  EXPECT_NEAR(leaf.sigma_theta, std::atan(0.01), 1e-4);
  EXPECT_NEAR(leaf.sigma_phi, std::atan(0.01), 1e-4);
  expectPartition(*mean_frame, validPoints(scene));

  // The same floor turned about the optical axis by 40 degrees (a camera rolled
  // sideways): still one leaf, the same spread.
  Scene rolled;
  const Eigen::Matrix3f roll =
      Eigen::AngleAxisf(static_cast<float>(40.0 * kDeg), Eigen::Vector3f::UnitZ())
          .toRotationMatrix();
  for (std::size_t i = 0; i < scene.cloud->size(); ++i)
    rolled.add(roll * (*scene.cloud)[i].getVector3fMap(),
               roll * (*scene.normals)[i].getNormalVector3fMap(),
               (*scene.areas)[i]);
  const auto rolled_tree = buildInMeanNormalFrame(rolled, 0.05, kPaperThreshold);
  ASSERT_EQ(rolled_tree->getAdaptiveLeaves().size(), 1u);
  EXPECT_NEAR(rolled_tree->getAdaptiveLeaves()[0].sigma_theta, std::atan(0.01), 1e-4);
}

TEST(OctreePointCloudNormalVariance, MeanNormalFrameStillSplitsACrease)
{
  // The 90-degree ridge: no leaf above the finest level or the point minimum holds
  // both faces.
  const Scene scene = ridge();
  const auto octree = buildInMeanNormalFrame(scene, 0.05, kPaperThreshold);
  const auto& leaves = octree->getAdaptiveLeaves();
  ASSERT_GT(leaves.size(), 2u);
  expectPartition(*octree, validPoints(scene));
  std::size_t largest = 0;
  for (const auto& leaf : leaves) {
    const auto points = leafPoints(*octree, leaf);
    largest = std::max(largest, points.size());
    bool left = false, right = false;
    for (const auto i : points)
      ((*scene.normals)[i].normal_x > 0.f ? left : right) = true;
    if (left && right) {
      EXPECT_TRUE(points.size() < kMinPoints || leaf.depth == octree->getTreeDepth());
      EXPECT_GT(std::max(leaf.sigma_theta, leaf.sigma_phi), kPaperThreshold);
    }
  }
  EXPECT_GE(largest, 16u);
}

TEST(OctreePointCloudNormalVariance, TwoPlanesSplit)
{
  const Scene scene = ridge();
  const double resolution = 0.05;
  const auto octree = buildOctree(scene, resolution, kPaperThreshold);
  const auto& leaves = octree->getAdaptiveLeaves();
  const unsigned depth = octree->getTreeDepth();
  ASSERT_GT(leaves.size(), 2u);
  expectPartition(*octree, validPoints(scene));

  std::vector<pcl::octree::OctreeKey> keys;
  for (const auto& p : scene.cloud->points)
    keys.push_back(finestKey(*octree, p));

  std::size_t largest = 0;
  for (const auto& leaf : leaves) {
    SCOPED_TRACE(testing::Message()
                 << "leaf at depth " << leaf.depth << " key " << leaf.key.x << " "
                 << leaf.key.y << " " << leaf.key.z);
    const auto points = leafPoints(*octree, leaf);
    largest = std::max(largest, points.size());
    for (const auto i : points)
      ASSERT_TRUE(inNode(keys[i], depth - leaf.depth, leaf.key));
    // Its own statistics, as stored.
    const Reference ref = reference(scene, points);
    EXPECT_NEAR(leaf.sigma_theta, ref.sigma_theta, 1e-5);
    EXPECT_NEAR(leaf.sigma_phi, ref.sigma_phi, 1e-5);
    EXPECT_NEAR((leaf.normal.cast<double>() - ref.normal).norm(), 0.0, 1e-5);
    EXPECT_NEAR(leaf.area, ref.area, 1e-9);
    // Kept: homogeneous, or too small to split, or at the finest level.
    const bool homogeneous =
        ref.sigma_theta <= kPaperThreshold && ref.sigma_phi <= kPaperThreshold;
    EXPECT_TRUE(homogeneous || points.size() < kMinPoints || leaf.depth == depth);
    // The highest such node: its parent had to be split.
    if (leaf.depth == 0)
      continue;
    const unsigned shift = depth - leaf.depth + 1;
    const pcl::octree::OctreeKey parent(
        leaf.key.x >> 1, leaf.key.y >> 1, leaf.key.z >> 1);
    std::vector<pcl::index_t> parent_points;
    for (std::size_t i = 0; i < keys.size(); ++i)
      if (inNode(keys[i], shift, parent))
        parent_points.push_back(static_cast<pcl::index_t>(i));
    const Reference up = reference(scene, parent_points);
    EXPECT_TRUE(up.sigma_theta > kPaperThreshold || up.sigma_phi > kPaperThreshold);
    EXPECT_GE(parent_points.size(), kMinPoints);
  }
  // Large flat parts stay whole: some leaf holds far more than one finest voxel.
  EXPECT_GE(largest, 16u);
}

TEST(OctreePointCloudNormalVariance, MinPointsToSplit)
{
  // With a minimum above the point count the root is kept, however much it varies.
  const Scene scene = ridge();
  const auto octree =
      buildOctree(scene, 0.05, kPaperThreshold, scene.cloud->size() + 1);
  ASSERT_EQ(octree->getAdaptiveLeaves().size(), 1u);
  EXPECT_EQ(octree->getAdaptiveLeaves()[0].depth, 0u);
  EXPECT_GT(octree->getAdaptiveLeaves()[0].sigma_theta, kPaperThreshold);
}

TEST(OctreePointCloudNormalVariance, AVoxelOfExactlyMinPointsSplits)
{
  // "A voxel holding fewer points than this is never split": one holding exactly as
  // many may. The ridge with the minimum at its point count splits the root.
  const Scene scene = ridge();
  EXPECT_GT(buildOctree(scene, 0.05, kPaperThreshold, scene.cloud->size())
                ->getAdaptiveLeaves()
                .size(),
            1u);
  // The smallest case by hand: two points 40 deg apart in normal, the documented
  // minimum of 2: the root (sigma_theta 20 deg) splits into two leaves of one point,
  // each without spread.
  Scene pair;
  pair.add(Eigen::Vector3f(0.f, 0.f, 1.f), Eigen::Vector3f(0.f, 0.f, -1.f), 1.0);
  const double t = 40.0 * kDeg;
  pair.add(Eigen::Vector3f(0.5f, 0.f, 1.f),
           -Eigen::Vector3d(std::tan(t), 0.0, 1.0).normalized().cast<float>(),
           1.0);
  const auto octree = buildOctree(pair, 0.01, kPaperThreshold, 2);
  ASSERT_EQ(octree->getAdaptiveLeaves().size(), 2u);
  for (const auto& leaf : octree->getAdaptiveLeaves()) {
    EXPECT_EQ(leaf.end - leaf.begin, 1u);
    EXPECT_NEAR(leaf.sigma_theta, 0.0, 1e-6);
  }
}

TEST(OctreePointCloudNormalVariance, InvalidPointsSkipped)
{
  Scene scene = ridge();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  (*scene.normals)[3].normal_x = nan;
  (*scene.areas)[10] = 0.0;
  (*scene.areas)[11] = -1.0;
  (*scene.areas)[12] = std::numeric_limits<double>::infinity();
  (*scene.areas)[13] = std::numeric_limits<double>::quiet_NaN();
  (*scene.cloud)[20].x = nan;
  // A zero normal has no direction; a subnormal area an infinite weight 1 / A_p (the
  // leaf normal was NaN).
  (*scene.normals)[4].getNormalVector3fMap().setZero();
  (*scene.areas)[14] = 1e-320;
  const auto valid = validPoints(scene);
  ASSERT_EQ(valid.size(), scene.cloud->size() - 8);
  const auto octree = buildOctree(scene, 0.05, kPaperThreshold);
  expectPartition(*octree, valid);

  // With indices: only the listed valid points.
  pcl::IndicesPtr indices(new pcl::Indices);
  for (pcl::index_t i = 0; i < static_cast<pcl::index_t>(scene.cloud->size()); i += 3)
    indices->push_back(i);
  const auto subset = buildOctree(scene, 0.05, kPaperThreshold, kMinPoints, indices);
  std::vector<pcl::index_t> expected;
  std::set_intersection(indices->begin(),
                        indices->end(),
                        valid.begin(),
                        valid.end(),
                        std::back_inserter(expected));
  expectPartition(*subset, expected);
  for (const auto& leaf : octree->getAdaptiveLeaves())
    EXPECT_TRUE(leaf.normal.allFinite() && std::isfinite(leaf.area));
}

TEST(OctreePointCloudNormalVariance, PointsFromPclsOwnInsertionAreRefused)
{
  // OctreePointCloud's insertion methods are not virtual: called through a base
  // reference, or addPointToCloud(), they add points this class never checked, here
  // points without normals and areas. computeAdaptiveLeaves() read past the end of
  // both arrays; it now refuses the tree.
  Scene scene = ridge();
  auto normals = pcl::make_shared<pcl::PointCloud<pcl::Normal>>(*scene.normals);
  auto areas = std::make_shared<std::vector<double>>(*scene.areas);
  normals->resize(normals->size() / 3);
  areas->resize(areas->size() / 3);
  {
    Octree octree(0.05);
    octree.setInputCloud(scene.cloud);
    octree.setInputNormals(normals, areas);
    Octree::OctreeT& base = octree;
    base.addPointsFromInputCloud();
    octree.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
    EXPECT_TRUE(octree.getAdaptiveLeaves().empty());
    EXPECT_TRUE(octree.getOrderedIndices().empty());
  }
  {
    auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>(*scene.cloud);
    cloud->resize(normals->size());
    Octree octree(0.05);
    octree.setInputCloud(cloud);
    octree.setInputNormals(normals, areas);
    ASSERT_TRUE(octree.addPointsFromInputCloud());
    octree.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
    ASSERT_FALSE(octree.getAdaptiveLeaves().empty());
    octree.addPointToCloud((*scene.cloud)[cloud->size()], cloud); // no normal
    octree.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
    EXPECT_TRUE(octree.getAdaptiveLeaves().empty());
  }
}

TEST(OctreePointCloudNormalVariance, ResolutionMustBePositiveAndFinite)
{
  const Scene scene = ridge();
  for (const double resolution : {-1.0,
                                  0.0,
                                  std::numeric_limits<double>::infinity(),
                                  std::numeric_limits<double>::quiet_NaN()}) {
    SCOPED_TRACE(resolution);
    // Given to the constructor: the insertion refuses it (-1 and inf gave one leaf).
    Octree octree(resolution);
    octree.setInputCloud(scene.cloud);
    octree.setInputNormals(scene.normals, scene.areas);
    EXPECT_FALSE(octree.addPointsFromInputCloud());
    octree.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
    EXPECT_TRUE(octree.getAdaptiveLeaves().empty());
    // Given to setResolution(): refused, the resolution kept (PCL's own converts it to
    // voxel counts out of range: undefined behaviour).
    Octree kept(0.05);
    kept.setResolution(resolution);
    EXPECT_EQ(kept.getResolution(), 0.05);
  }
}

/** Every field of two trees' leaves and orderings, bit for bit. */
void
expectSameLeaves(const Octree& a, const Octree& b)
{
  EXPECT_EQ(a.getOrderedIndices(), b.getOrderedIndices());
  ASSERT_EQ(a.getAdaptiveLeaves().size(), b.getAdaptiveLeaves().size());
  for (std::size_t l = 0; l < a.getAdaptiveLeaves().size(); ++l) {
    SCOPED_TRACE(l);
    const AdaptiveLeaf& x = a.getAdaptiveLeaves()[l];
    const AdaptiveLeaf& y = b.getAdaptiveLeaves()[l];
    EXPECT_EQ(x.key, y.key);
    EXPECT_EQ(x.depth, y.depth);
    EXPECT_EQ(x.begin, y.begin);
    EXPECT_EQ(x.end, y.end);
    EXPECT_EQ(x.area, y.area);
    EXPECT_EQ(x.sigma_theta, y.sigma_theta);
    EXPECT_EQ(x.sigma_phi, y.sigma_phi);
    EXPECT_EQ(x.normal, y.normal);
  }
}

TEST(OctreePointCloudNormalVariance, RecomputeWithAnotherThreshold)
{
  // computeAdaptiveLeaves() may run again on the same tree: the result is that of a
  // fresh tree with the new parameters.
  const Scene scene = ridge();
  const auto tree = buildOctree(scene, 0.05, M_PI);
  ASSERT_EQ(tree->getAdaptiveLeaves().size(), 1u);
  tree->computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
  const auto fresh = buildOctree(scene, 0.05, kPaperThreshold);
  ASSERT_GT(tree->getAdaptiveLeaves().size(), 1u);
  expectSameLeaves(*tree, *fresh);
}

// The normals as plain 3-vectors (the form SelectiveSegmentation lends without a copy)
// give the same tree as a pcl::Normal cloud, invalid points and leaf areas included.
TEST(OctreePointCloudNormalVariance, NormalVectorsGiveTheSameTree)
{
  Scene scene = ridge();
  (*scene.normals)[3].normal_y = std::numeric_limits<float>::quiet_NaN();
  (*scene.areas)[7] = 0.0;
  const auto from_cloud = buildOctree(scene, 0.05, kPaperThreshold);
  auto vectors = std::make_shared<Octree::NormalVectors>();
  for (const auto& n : *scene.normals)
    vectors->push_back(n.getNormalVector3fMap());
  Octree from_vectors(0.05);
  from_vectors.setInputCloud(scene.cloud);
  from_vectors.setInputNormals(vectors, scene.areas);
  ASSERT_TRUE(from_vectors.addPointsFromInputCloud());
  from_vectors.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
  expectPartition(from_vectors, validPoints(scene));
  ASSERT_GT(from_cloud->getAdaptiveLeaves().size(), 1u);
  expectSameLeaves(from_vectors, *from_cloud);
  double total_area = 0.0;
  for (const AdaptiveLeaf& leaf : from_cloud->getAdaptiveLeaves())
    total_area += leaf.area;
  // eq. 6: the leaves' areas add up to the areas of the valid points.
  double expected_area = 0.0;
  for (const auto i : validPoints(scene))
    expected_area += (*scene.areas)[i];
  EXPECT_NEAR(total_area, expected_area, 1e-12 * expected_area);
  // Without normals of either kind, nothing is inserted.
  Octree none(0.05);
  none.setInputCloud(scene.cloud);
  none.setInputNormals(Octree::NormalVectorsConstPtr(), scene.areas);
  EXPECT_FALSE(none.addPointsFromInputCloud());
}

TEST(OctreePointCloudNormalVariance, NoValidPoint)
{
  Scene scene;
  scene.add(Eigen::Vector3f(0.f, 0.f, 1.f), Eigen::Vector3f(0.f, 0.f, -1.f), 0.0);
  Octree octree(0.1);
  octree.setInputCloud(scene.cloud);
  octree.setInputNormals(scene.normals, scene.areas);
  EXPECT_FALSE(octree.addPointsFromInputCloud());
  octree.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
  EXPECT_TRUE(octree.getAdaptiveLeaves().empty());
  EXPECT_TRUE(octree.getOrderedIndices().empty());
}

TEST(OctreePointCloudNormalVariance, InsertionOrderIndependence)
{
  const Scene scene = ridge();
  const auto reference_tree = buildOctree(scene, 0.05, kPaperThreshold);
  const auto& expected = reference_tree->getAdaptiveLeaves();

  pcl::IndicesPtr shuffled(new pcl::Indices(scene.cloud->size()));
  std::iota(shuffled->begin(), shuffled->end(), 0);
  std::mt19937 rng(42);
  std::shuffle(shuffled->begin(), shuffled->end(), rng);
  const auto shuffled_tree =
      buildOctree(scene, 0.05, kPaperThreshold, kMinPoints, shuffled);

  // The same cloud with its points permuted: point k of the copy is point perm[k].
  std::vector<pcl::index_t> perm(scene.cloud->size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  Scene permuted;
  for (const auto i : perm)
    permuted.add((*scene.cloud)[i].getVector3fMap(),
                 (*scene.normals)[i].getNormalVector3fMap(),
                 (*scene.areas)[i]);
  const auto permuted_tree = buildOctree(permuted, 0.05, kPaperThreshold);

  for (const Octree* other : {shuffled_tree.get(), permuted_tree.get()}) {
    const bool is_permuted = other == permuted_tree.get();
    SCOPED_TRACE(is_permuted ? "permuted cloud" : "shuffled indices");
    const auto& leaves = other->getAdaptiveLeaves();
    ASSERT_EQ(leaves.size(), expected.size());
    for (std::size_t l = 0; l < leaves.size(); ++l) {
      SCOPED_TRACE(l);
      EXPECT_EQ(leaves[l].key, expected[l].key);
      EXPECT_EQ(leaves[l].depth, expected[l].depth);
      EXPECT_EQ(leaves[l].begin, expected[l].begin);
      EXPECT_EQ(leaves[l].end, expected[l].end);
      EXPECT_NEAR((leaves[l].normal - expected[l].normal).norm(), 0.f, 1e-6f);
      EXPECT_NEAR(leaves[l].sigma_theta, expected[l].sigma_theta, 1e-6f);
      EXPECT_NEAR(leaves[l].sigma_phi, expected[l].sigma_phi, 1e-6f);
      EXPECT_NEAR(leaves[l].area, expected[l].area, 1e-9);
      std::set<pcl::index_t> mine;
      for (const auto i : leafPoints(*other, leaves[l]))
        mine.insert(is_permuted ? perm[i] : i);
      const auto theirs = leafPoints(*reference_tree, expected[l]);
      EXPECT_EQ(mine, std::set<pcl::index_t>(theirs.begin(), theirs.end()));
    }
  }
}

// addPointsFromInputCloud() builds the tree along the sorted Morton codes; it must be
// the tree PCL's own point-by-point insertion builds: same nodes, same leaf keys, same
// indices in every leaf container, same counts.
TEST(OctreePointCloudNormalVariance, SameTreeAsPclInsertion)
{
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-1.f, 1.f);
  Scene scene = ridge();
  // Scattered points, some sharing finest voxels; enough for the parallel key
  // generation and sort, with 1 to 3 threads.
  for (int k = 0; k < 70000; ++k)
    scene.add(Eigen::Vector3f(coordinate(rng), coordinate(rng), 3.f + coordinate(rng)),
              Eigen::Vector3f(0.f, 0.f, -1.f),
              0.01);
  scene.add(Eigen::Vector3f(0.f, 0.f, 2.f), Eigen::Vector3f(0.f, 0.f, -1.f), 0.0);
  for (const auto& [resolution, threads] : std::vector<std::pair<double, unsigned>>{
           {0.5, 2}, {0.05, 1}, {0.05, 2}, {0.05, 3}, {0.003, 2}}) {
    SCOPED_TRACE(resolution);
    SCOPED_TRACE(threads);
    const auto ours =
        buildOctree(scene, resolution, kPaperThreshold, kMinPoints, nullptr, nullptr, threads);
    pcl::IndicesPtr valid(new pcl::Indices);
    for (pcl::index_t i = 0; i < static_cast<pcl::index_t>(scene.cloud->size()); ++i)
      if ((*scene.areas)[i] > 0.0) // the invalid point is not inserted
        valid->push_back(i);
    pcl::octree::OctreePointCloudPointVector<pcl::PointXYZ> pcl_tree(resolution);
    pcl_tree.setInputCloud(scene.cloud, valid);
    double min_x, min_y, min_z, max_x, max_y, max_z;
    ours->getBoundingBox(min_x, min_y, min_z, max_x, max_y, max_z);
    pcl_tree.defineBoundingBox(min_x, min_y, min_z, max_x, max_y, max_z);
    ASSERT_EQ(pcl_tree.getTreeDepth(), ours->getTreeDepth());
    pcl_tree.addPointsFromInputCloud(); // point by point, in index order
    EXPECT_EQ(ours->getLeafCount(), pcl_tree.getLeafCount());
    EXPECT_EQ(ours->getBranchCount(), pcl_tree.getBranchCount());
    auto mine = ours->leaf_depth_begin();
    auto theirs = pcl_tree.leaf_depth_begin();
    std::size_t leaves = 0;
    for (; mine != ours->leaf_depth_end() && theirs != pcl_tree.leaf_depth_end();
         ++mine, ++theirs, ++leaves) {
      ASSERT_EQ(mine.getCurrentOctreeKey(), theirs.getCurrentOctreeKey());
      pcl::Indices mine_indices, their_indices;
      mine.getLeafContainer().getPointIndices(mine_indices);
      theirs.getLeafContainer().getPointIndices(their_indices);
      ASSERT_EQ(mine_indices, their_indices);
      ASSERT_EQ(mine.getLeafContainer().getSize(), theirs.getLeafContainer().getSize());
    }
    EXPECT_TRUE(mine == ours->leaf_depth_end());
    EXPECT_TRUE(theirs == pcl_tree.leaf_depth_end());
    EXPECT_EQ(leaves, pcl_tree.getLeafCount());
  }
}

// The bulk insertion's leaf containers view one array of the tree; a copy of the tree
// holds its own indices (it outlives the original here), and a container that PCL's
// point-by-point insertion adds to keeps its indices and the new one.
TEST(OctreePointCloudNormalVariance, LeafContainersViewAndCopy)
{
  const Scene scene = ridge();
  using Octree = pcl::selective_seg::OctreePointCloudNormalVariance<pcl::PointXYZ>;
  std::vector<pcl::Indices> original;
  std::unique_ptr<Octree> copy;
  {
    const auto built = buildOctree(scene, 0.05, kPaperThreshold);
    for (auto it = built->leaf_depth_begin(); it != built->leaf_depth_end(); ++it) {
      original.emplace_back();
      it.getLeafContainer().getPointIndices(original.back());
      ASSERT_EQ(original.back().size(), it.getLeafContainer().getSize());
    }
    copy = std::make_unique<Octree>(*built);
  } // the original tree and its index array are gone
  std::size_t l = 0;
  for (auto it = copy->leaf_depth_begin(); it != copy->leaf_depth_end(); ++it, ++l) {
    pcl::Indices indices;
    it.getLeafContainer().getPointIndices(indices);
    ASSERT_LT(l, original.size());
    EXPECT_EQ(indices, original[l]);
  }
  EXPECT_EQ(l, original.size());

  const auto tree = buildOctree(scene, 0.05, kPaperThreshold);
  auto& container = tree->leaf_depth_begin().getLeafContainer();
  pcl::Indices before;
  container.getPointIndices(before);
  container.addPointIndex(12345);
  pcl::Indices after;
  container.getPointIndices(after);
  before.push_back(12345);
  EXPECT_EQ(after, before);
  EXPECT_EQ(container.getPointIndex(), 12345);
  pcl::selective_seg::OctreeNormalVarianceContainer same(container);
  EXPECT_TRUE(same == container);
  container.reset();
  EXPECT_EQ(container.getSize(), 0u);
  EXPECT_FALSE(same == container);
}

TEST(OctreePointCloudNormalVariance, VoxelGeometry)
{
  const Scene scene = ridge();
  const double resolution = 0.05;
  const auto octree = buildOctree(scene, resolution, kPaperThreshold);
  const unsigned depth = octree->getTreeDepth();
  EXPECT_DOUBLE_EQ(octree->getVoxelSideLength(depth), resolution);
  for (unsigned d = 0; d < depth; ++d)
    EXPECT_DOUBLE_EQ(octree->getVoxelSideLength(d),
                     2.0 * octree->getVoxelSideLength(d + 1));
  // The root covers the bounding box.
  double min_x, min_y, min_z, max_x, max_y, max_z;
  octree->getBoundingBox(min_x, min_y, min_z, max_x, max_y, max_z);
  EXPECT_NEAR(octree->getVoxelSideLength(0), max_x - min_x, 1e-9);

  std::set<unsigned> depths;
  for (const auto& leaf : octree->getAdaptiveLeaves()) {
    depths.insert(leaf.depth);
    const Eigen::Vector3f centre = octree->getVoxelCentre(leaf);
    const float half =
        0.5f * static_cast<float>(octree->getVoxelSideLength(leaf.depth));
    for (const auto i : leafPoints(*octree, leaf)) {
      const Eigen::Vector3f offset = (*scene.cloud)[i].getVector3fMap() - centre;
      EXPECT_LE(offset.cwiseAbs().maxCoeff(), half * (1.f + 1e-5f))
          << "point " << i << " outside its leaf at depth " << leaf.depth;
    }
  }
  EXPECT_GT(depths.size(), 1u); // several resolutions
}

TEST(OctreePointCloudNormalVariance, SensorOrientation)
{
  // A noisy wall facing a sensor at the origin that looks along +z.
  Scene wall;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      wall.add(Eigen::Vector3f(0.05f * i, 0.05f * j, 3.f),
               Eigen::Vector3f(noise(rng), noise(rng), -1.f).normalized(),
               0.0025);
  const auto upright = buildOctree(wall, 0.01, M_PI);
  ASSERT_EQ(upright->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf expected = upright->getAdaptiveLeaves()[0];
  ASSERT_GT(expected.sigma_theta, 0.01f);

  // Rotate the cloud, its normals and the sensor together: the wall now faces a sensor
  // that looks roughly along +x.
  const Eigen::Quaternionf q(
      Eigen::AngleAxisf(80.f * static_cast<float>(kDeg), Eigen::Vector3f::UnitY()) *
      Eigen::AngleAxisf(10.f * static_cast<float>(kDeg), Eigen::Vector3f::UnitX()));
  Scene rotated;
  for (std::size_t i = 0; i < wall.cloud->size(); ++i)
    rotated.add(q * (*wall.cloud)[i].getVector3fMap(),
                q * (*wall.normals)[i].getNormalVector3fMap(),
                (*wall.areas)[i]);
  const auto turned = buildOctree(rotated, 0.01, M_PI, kMinPoints, nullptr, &q);
  ASSERT_EQ(turned->getAdaptiveLeaves().size(), 1u);
  const AdaptiveLeaf& leaf = turned->getAdaptiveLeaves()[0];
  EXPECT_NEAR(leaf.sigma_theta, expected.sigma_theta, 1e-5f);
  EXPECT_NEAR(leaf.sigma_phi, expected.sigma_phi, 1e-5f);
  // The leaf normal is reported in the cloud frame.
  EXPECT_NEAR((leaf.normal - q * expected.normal).norm(), 0.f, 1e-5f);
  const Reference ref = reference(
      rotated, leafPoints(*turned, leaf), q.toRotationMatrix().cast<double>());
  EXPECT_NEAR(leaf.sigma_theta, ref.sigma_theta, 1e-5);

  // Without the orientation the angles are measured in the wrong frame.
  const auto unaware = buildOctree(rotated, 0.01, M_PI);
  EXPECT_GT(std::abs(unaware->getAdaptiveLeaves()[0].sigma_phi - expected.sigma_phi),
            0.01f);
}

namespace {

/** \a count points at uniform random (x, y) in [-1, 1]^2 and z = height(x, y), facing a
 * sensor on the -z side: normal (s_x + noise u, s_y + noise u, -1), normalized, where
 * (s_x, s_y) = slope(x, y) and u is uniform in [-1, 1]; areas 1e-4 (1.5 + u). */
template <typename Height, typename Slope>
Scene
randomSheet(unsigned seed, int count, Height height, Slope slope, float noise)
{
  Scene scene;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  for (int i = 0; i < count; ++i) {
    const float x = u(rng), y = u(rng);
    const Eigen::Vector2f s = slope(x, y);
    const Eigen::Vector3f n =
        Eigen::Vector3f(s.x() + noise * u(rng), s.y() + noise * u(rng), -1.f)
            .normalized();
    scene.add(Eigen::Vector3f(x, y, height(x, y)), n, 1e-4 * (1.5 + u(rng)));
  }
  return scene;
}

} // namespace

// addPointsAndComputeAdaptiveLeaves() computes the normal angles while it builds the
// tree: the tree and leaves must be those of the two separate calls for any thread
// count and sensor orientation, and a later computeAdaptiveLeaves() must start afresh.
TEST(OctreePointCloudNormalVariance, OneCallGivesTheSameLeaves)
{
  // A bumpy sheet with noisy normals, a few invalid points, and a turned sensor.
  Scene scene = randomSheet(
      11,
      20000,
      [](float x, float y) { return 3.f + 0.2f * std::sin(4.f * x) * std::cos(3.f * y); },
      [](float x, float y) {
        return Eigen::Vector2f(0.8f * std::cos(4.f * x) * std::cos(3.f * y),
                               -0.6f * std::sin(4.f * x) * std::sin(3.f * y));
      },
      0.1f);
  (*scene.normals)[17].normal_x = std::numeric_limits<float>::quiet_NaN();
  (*scene.areas)[99] = 0.0;
  const Eigen::Quaternionf q(
      Eigen::AngleAxisf(0.3f, Eigen::Vector3f(0.2f, 1.f, 0.1f).normalized()));
  for (const Eigen::Quaternionf* orientation :
       {static_cast<const Eigen::Quaternionf*>(nullptr), &q}) {
    const auto two_calls = buildOctree(
        scene, 0.01, kPaperThreshold, kMinPoints, nullptr, orientation, 1);
    ASSERT_GT(two_calls->getAdaptiveLeaves().size(), 100u);
    for (unsigned int threads : {1u, 2u, 3u}) {
      SCOPED_TRACE(threads);
      Octree one_call(0.01);
      one_call.setNumberOfThreads(threads);
      one_call.setInputCloud(scene.cloud);
      one_call.setInputNormals(scene.normals, scene.areas);
      if (orientation)
        one_call.setSensorOrientation(*orientation);
      ASSERT_TRUE(one_call.addPointsAndComputeAdaptiveLeaves(kPaperThreshold, kMinPoints));
      expectSameLeaves(one_call, *two_calls);
      expectPartition(one_call, validPoints(scene));
      // Again with another threshold: the angles are computed again.
      one_call.computeAdaptiveLeaves(2.0 * kPaperThreshold, kMinPoints);
      const auto coarser = buildOctree(
          scene, 0.01, 2.0 * kPaperThreshold, kMinPoints, nullptr, orientation, 1);
      expectSameLeaves(one_call, *coarser);
      // The tree built again, by the two calls, on the same octree.
      one_call.deleteTree();
      ASSERT_TRUE(one_call.addPointsFromInputCloud());
      one_call.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
      expectSameLeaves(one_call, *two_calls);
      one_call.computeAdaptiveLeaves(2.0 * kPaperThreshold, kMinPoints);
      expectSameLeaves(one_call, *coarser);
    }
  }
  // Nothing to insert: false, no leaves.
  Scene invalid;
  invalid.add(Eigen::Vector3f(0.f, 0.f, 1.f), Eigen::Vector3f(0.f, 0.f, -1.f), 0.0);
  Octree none(0.1);
  none.setInputCloud(invalid.cloud);
  none.setInputNormals(invalid.normals, invalid.areas);
  EXPECT_FALSE(none.addPointsAndComputeAdaptiveLeaves(kPaperThreshold, kMinPoints));
  EXPECT_TRUE(none.getAdaptiveLeaves().empty());
}

// Every adaptive leaf is a node of the PCL tree: its points are exactly the valid
// points whose finest voxel lies in the node of its key and depth (the leaves are found
// from the finest voxels' codes, not by walking the tree). Checked on a deep tree built
// in one call and in two, and on a tree filled by PCL's point-by-point insertion, which
// gives the same leaves.
TEST(OctreePointCloudNormalVariance, LeavesAreNodesOfTheTree)
{
  // A wavy sheet with a crease at y = 0.3.
  Scene scene = randomSheet(
      5,
      6000,
      [](float x, float y) {
        return 3.f + 0.3f * std::sin(5.f * x) + 0.2f * (y > 0.3f ? y : 0.f);
      },
      [](float x, float y) {
        return Eigen::Vector2f(1.5f * std::cos(5.f * x), y > 0.3f ? 0.2f : 0.f);
      },
      0.05f);
  (*scene.areas)[42] = 0.0; // not inserted
  const double resolution = 0.004;
  const auto valid = validPoints(scene);
  const auto two_calls = buildOctree(scene, resolution, kPaperThreshold);
  Octree one_call(resolution);
  one_call.setNumberOfThreads(2);
  one_call.setInputCloud(scene.cloud);
  one_call.setInputNormals(scene.normals, scene.areas);
  ASSERT_TRUE(one_call.addPointsAndComputeAdaptiveLeaves(kPaperThreshold, kMinPoints));
  ASSERT_GE(one_call.getTreeDepth(), 8u);
  for (const Octree* tree : {static_cast<const Octree*>(two_calls.get()),
                             static_cast<const Octree*>(&one_call)}) {
    const unsigned depth = tree->getTreeDepth();
    std::vector<pcl::octree::OctreeKey> keys;
    for (const pcl::index_t i : valid)
      keys.push_back(finestKey(*tree, (*scene.cloud)[i]));
    const auto& leaves = tree->getAdaptiveLeaves();
    ASSERT_GT(leaves.size(), 200u);
    std::set<std::uint32_t> depths;
    for (const AdaptiveLeaf& leaf : leaves) {
      depths.insert(leaf.depth);
      std::vector<pcl::index_t> in_node;
      for (std::size_t k = 0; k < valid.size(); ++k)
        if (inNode(keys[k], depth - leaf.depth, leaf.key))
          in_node.push_back(valid[k]);
      auto points = leafPoints(*tree, leaf);
      std::sort(points.begin(), points.end());
      ASSERT_EQ(points, in_node) << "leaf at depth " << leaf.depth;
    }
    EXPECT_GE(depths.size(), 3u); // leaves at several depths
    expectPartition(*tree, valid);
  }
  expectSameLeaves(one_call, *two_calls);
  // PCL's insertion, point by point in index order, into the same box.
  Octree pointwise(resolution);
  pointwise.setInputCloud(scene.cloud);
  pointwise.setInputNormals(scene.normals, scene.areas);
  double min_x, min_y, min_z, max_x, max_y, max_z;
  two_calls->getBoundingBox(min_x, min_y, min_z, max_x, max_y, max_z);
  pointwise.defineBoundingBox(min_x, min_y, min_z, max_x, max_y, max_z);
  for (const pcl::index_t i : valid)
    pointwise.addPointFromCloud(i, nullptr);
  ASSERT_EQ(pointwise.getTreeDepth(), two_calls->getTreeDepth());
  pointwise.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
  expectSameLeaves(pointwise, *two_calls);
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

namespace {

/** Points of every leaf of \a octree lying outside the leaf's voxel (beyond a
 * thousandth of a voxel). */
std::size_t
pointsOutsideTheirVoxel(Octree& octree)
{
  const auto& cloud = *octree.getInputCloud();
  const double tolerance = 1e-3 * octree.getResolution();
  std::size_t outside = 0;
  for (auto it = octree.leaf_depth_begin(); it != octree.leaf_depth_end(); ++it) {
    pcl::Indices indices;
    it.getLeafContainer().getPointIndices(indices);
    Eigen::Vector3f lo, hi;
    octree.getVoxelBounds(it, lo, hi);
    for (const auto i : indices) {
      const Eigen::Array3d p = cloud[i].getArray3fMap().cast<double>();
      outside += (p < lo.cast<double>().array() - tolerance).any() ||
                 (p > hi.cast<double>().array() + tolerance).any();
    }
  }
  return outside;
}

/** \a n points spread over a cube of side \a extent at \a offset, normals tilted
 * at random by up to about 45 deg. */
Scene
randomCube(std::size_t n, double extent, double offset = 0.0)
{
  Scene scene;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0), tilt(-0.8, 0.8);
  for (std::size_t i = 0; i < n; ++i)
    scene.add((Eigen::Vector3d::Constant(offset) +
               extent * Eigen::Vector3d(u(rng), u(rng), u(rng)))
                  .cast<float>(),
              facingNormal(tilt(rng), tilt(rng)),
              1.0);
  return scene;
}

} // namespace

// Voxels far below FLT_EPSILON (1.2e-7, which PCL's octree subtracts from the box's
// sides when it counts voxels): the box must still hold every point in its voxel.
TEST(OctreePointCloudNormalVariance, VoxelsBelowFloatEpsilonHoldTheirPoints)
{
  // 1e-9 voxels: PCL counts 119 voxels fewer than the extent holds, which drops a
  // level below 1,074 and 2,100 voxels (not below 480).
  for (const double extent : {1.074e-6, 2.1e-6, 4.8e-7}) {
    const Scene scene = randomCube(3000, extent);
    const auto octree = buildOctree(scene, 1e-9, kPaperThreshold);
    EXPECT_GE(std::ldexp(octree->getResolution(), octree->getTreeDepth()), extent);
    EXPECT_EQ(pointsOutsideTheirVoxel(*octree), 0u) << "extent " << extent;
    std::size_t in_leaves = 0;
    for (const AdaptiveLeaf& leaf : octree->getAdaptiveLeaves())
      in_leaves += leaf.end - leaf.begin;
    EXPECT_EQ(in_leaves, scene.cloud->size());
  }
  // A flat axis far from the origin, where FLT_EPSILON is below a double's ulp.
  Scene flat;
  for (int i = 0; i < 100; ++i)
    flat.add(Eigen::Vector3f(1e-6f * static_cast<float>(i % 10), 1e12f, 1.0f),
             facingNormal(0.0, 0.0),
             1.0);
  Octree octree(1e-8);
  octree.setInputCloud(flat.cloud);
  octree.setInputNormals(flat.normals, flat.areas);
  if (octree.addPointsFromInputCloud()) { // or refused for its depth, with a message
    EXPECT_LE(octree.getTreeDepth(), Octree::kMaxDepth);
    EXPECT_EQ(pointsOutsideTheirVoxel(octree), 0u);
  }
}

// Depth-first codes hold 21 levels: a deeper tree is refused, not split on codes cut
// short.
TEST(OctreePointCloudNormalVariance, TreesDeeperThan21LevelsAreRefused)
{
  const Scene scene = randomCube(500, 1.0);
  Octree fine(1.0 / std::ldexp(1.0, 22)); // 2^22 voxels across
  fine.setInputCloud(scene.cloud);
  fine.setInputNormals(scene.normals, scene.areas);
  EXPECT_FALSE(fine.addPointsAndComputeAdaptiveLeaves(kPaperThreshold, kMinPoints));
  EXPECT_TRUE(fine.getAdaptiveLeaves().empty());
  const auto ok = buildOctree(scene, 1.0 / std::ldexp(1.0, 20), kPaperThreshold);
  EXPECT_LE(ok->getTreeDepth(), Octree::kMaxDepth);
  EXPECT_FALSE(ok->getAdaptiveLeaves().empty());
}

// A second insertion into a tree that holds points keeps its box, as PCL's octree
// does (redefining it re-anchored the existing leaves).
TEST(OctreePointCloudNormalVariance, SecondInsertionKeepsTheBox)
{
  const Scene scene = randomCube(1000, 1.6, -0.3);
  Octree octree(0.05);
  octree.setInputCloud(scene.cloud);
  octree.setInputNormals(scene.normals, scene.areas);
  ASSERT_TRUE(octree.addPointsFromInputCloud());
  const std::size_t leaves = octree.getLeafCount();
  Eigen::Array<double, 6, 1> before, after;
  octree.getBoundingBox(
      before[0], before[1], before[2], before[3], before[4], before[5]);
  ASSERT_TRUE(octree.addPointsFromInputCloud());
  octree.getBoundingBox(after[0], after[1], after[2], after[3], after[4], after[5]);
  EXPECT_TRUE((before == after).all());
  EXPECT_EQ(octree.getLeafCount(), leaves);
  EXPECT_EQ(pointsOutsideTheirVoxel(octree), 0u);
}

// A second insertion whose points lie so far away that the grown box would need more
// than kMaxDepth levels is refused before PCL starts growing it (it grew a level at a
// time until memory ran out), and the tree is left as it was.
TEST(OctreePointCloudNormalVariance, GrowthBeyondTheDepthLimitIsRefusedUpFront)
{
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  auto normals = std::make_shared<std::vector<Eigen::Vector3f>>();
  auto areas = std::make_shared<std::vector<double>>();
  for (int i = 0; i < 100; ++i) {
    cloud->push_back(pcl::PointXYZ(0.01f * static_cast<float>(i), 0.0f, 1.0f));
    normals->push_back(Eigen::Vector3f(0.0f, 0.0f, -1.0f));
    areas->push_back(1e-4);
  }
  cloud->push_back(pcl::PointXYZ(1e8f, 0.0f, 1.0f)); // 2^33 voxels away
  normals->push_back(Eigen::Vector3f(0.0f, 0.0f, -1.0f));
  areas->push_back(1e-4);
  Octree octree(0.01);
  octree.setInputNormals(normals, areas);
  pcl::Indices first(100);
  std::iota(first.begin(), first.end(), 0);
  octree.setInputCloud(cloud, pcl::make_shared<const pcl::Indices>(first));
  ASSERT_TRUE(octree.addPointsFromInputCloud());
  const unsigned depth = octree.getTreeDepth();
  const std::size_t leaves = octree.getLeafCount();
  octree.setInputCloud(cloud, pcl::make_shared<const pcl::Indices>(pcl::Indices{100}));
  EXPECT_FALSE(octree.addPointsFromInputCloud());
  EXPECT_EQ(octree.getTreeDepth(), depth);
  EXPECT_EQ(octree.getLeafCount(), leaves);
  // Within reach, the same insertion grows the box (PCL's behaviour).
  (*cloud)[100].x = 100.0f;
  EXPECT_TRUE(octree.addPointsFromInputCloud());
  EXPECT_GT(octree.getTreeDepth(), depth);
  EXPECT_EQ(octree.getLeafCount(), leaves + 1);
}

// Inputs that disagree are refused with a message, not read as "invalid points":
// normals or areas fewer than the points, and indices beyond the cloud.
TEST(OctreePointCloudNormalVariance, InputsThatDisagreeAreRefused)
{
  const Scene scene = randomCube(200, 1.0);
  {
    auto fewer = pcl::make_shared<pcl::PointCloud<pcl::Normal>>(*scene.normals);
    fewer->resize(100);
    Octree octree(0.1);
    octree.setInputCloud(scene.cloud);
    octree.setInputNormals(fewer, scene.areas);
    EXPECT_FALSE(octree.addPointsFromInputCloud());
    EXPECT_EQ(octree.getLeafCount(), 0u);
  }
  {
    auto fewer = std::make_shared<std::vector<double>>(*scene.areas);
    fewer->pop_back();
    Octree octree(0.1);
    octree.setInputCloud(scene.cloud);
    octree.setInputNormals(scene.normals, fewer);
    EXPECT_FALSE(octree.addPointsAndComputeAdaptiveLeaves(kPaperThreshold, kMinPoints));
    EXPECT_TRUE(octree.getAdaptiveLeaves().empty());
  }
  for (const pcl::index_t bad : {pcl::index_t{-5}, pcl::index_t{200}}) {
    Octree octree(0.1);
    octree.setInputCloud(
        scene.cloud, pcl::make_shared<const pcl::Indices>(pcl::Indices{0, 1, 2, bad}));
    octree.setInputNormals(scene.normals, scene.areas);
    EXPECT_FALSE(octree.addPointsFromInputCloud()) << bad;
    EXPECT_EQ(octree.getLeafCount(), 0u) << bad;
  }
  Octree none(0.1); // no normals at all
  none.setInputCloud(scene.cloud);
  EXPECT_FALSE(none.addPointsFromInputCloud());
}

// A split threshold outside (0, pi] (NaN included) or a sensor orientation that is no
// rotation gives no leaves, with a message, instead of one leaf or every finest voxel.
TEST(OctreePointCloudNormalVariance, InvalidThresholdOrOrientationGivesNoLeaves)
{
  const Scene scene = randomCube(300, 1.0);
  for (const double threshold :
       {std::numeric_limits<double>::quiet_NaN(), -1.0, 0.0, 4.0, HUGE_VAL}) {
    const auto octree = buildOctree(scene, 0.1, threshold);
    EXPECT_TRUE(octree->getAdaptiveLeaves().empty()) << threshold;
  }
  Octree octree(0.1);
  octree.setInputCloud(scene.cloud);
  octree.setInputNormals(scene.normals, scene.areas);
  octree.setSensorOrientation(Eigen::Quaternionf(NAN, 0.0f, 0.0f, 0.0f));
  ASSERT_TRUE(octree.addPointsFromInputCloud());
  octree.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
  EXPECT_TRUE(octree.getAdaptiveLeaves().empty());
  octree.setSensorOrientation(Eigen::Quaternionf::Identity());
  octree.computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
  EXPECT_FALSE(octree.getAdaptiveLeaves().empty());
}

TEST(OctreePointCloudNormalVariance, DeleteTreeDeletesTheLeaves)
{
  const Scene scene = ridge();
  auto octree = buildOctree(scene, 0.05, kPaperThreshold);
  ASSERT_FALSE(octree->getAdaptiveLeaves().empty());
  octree->deleteTree();
  EXPECT_TRUE(octree->getAdaptiveLeaves().empty());
  EXPECT_TRUE(octree->getOrderedIndices().empty());
  EXPECT_EQ(octree->getLeafCount(), 0u);
  // And the tree can be filled again: the same leaves as a new one.
  ASSERT_TRUE(octree->addPointsFromInputCloud());
  octree->computeAdaptiveLeaves(kPaperThreshold, kMinPoints);
  expectSameLeaves(*octree, *buildOctree(scene, 0.05, kPaperThreshold));
}
