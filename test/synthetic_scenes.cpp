/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "synthetic_scenes.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace selseg_test {

namespace {

constexpr double kPi = 3.14159265358979323846;

/** Uniform deviate in (0, 1) built from the engine's 32-bit output only, so that the
 * sequence does not depend on the standard library's distribution implementations. */
double
uniform01(std::mt19937& engine)
{
  return (static_cast<double>(engine()) + 0.5) / 4294967296.0;
}

/** Standard normal deviate (Box-Muller, one value per call). */
double
standardNormal(std::mt19937& engine)
{
  const double radius = std::sqrt(-2.0 * std::log(uniform01(engine)));
  return radius * std::cos(2.0 * kPi * uniform01(engine));
}

void
checkParams(const SamplingParams& params)
{
  const double limit = 0.5 * kPi;
  const bool window_ok = params.theta_min > -limit && params.theta_max < limit &&
                         params.theta_min < params.theta_max &&
                         params.phi_min > -limit && params.phi_max < limit &&
                         params.phi_min < params.phi_max;
  if (!window_ok)
    throw std::invalid_argument("scan: view window must be non-empty within +-pi/2");
  if (!(params.density_ratio >= 1.0))
    throw std::invalid_argument("scan: density_ratio must be >= 1");
  if (!(params.range_noise >= 0.0))
    throw std::invalid_argument("scan: range_noise must be >= 0");
}

/** Range along the unit direction \a dir at which the ray from the origin hits \a face,
 * or infinity when it misses it. */
double
intersect(const Face& face, const Eigen::Vector3d& dir)
{
  constexpr double kMiss = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d normal = face.u.cross(face.v);
  const double denominator = normal.dot(dir);
  if (denominator == 0.0)
    return kMiss;
  const double range = normal.dot(face.origin) / denominator;
  if (!(range > 0.0))
    return kMiss;
  const Eigen::Vector3d offset = range * dir - face.origin;
  const double uu = face.u.squaredNorm();
  const double uv = face.u.dot(face.v);
  const double vv = face.v.squaredNorm();
  const double ou = offset.dot(face.u);
  const double ov = offset.dot(face.v);
  const double determinant = uu * vv - uv * uv;
  const double s = (vv * ou - uv * ov) / determinant;
  const double t = (uu * ov - uv * ou) / determinant;
  if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0)
    return kMiss;
  return range;
}

/** Draw one (theta, phi) by rejection sampling of relativeDensity(). */
Eigen::Vector2d
drawAngles(const SamplingParams& params, std::mt19937& engine)
{
  while (true) {
    const double theta =
        params.theta_min + (params.theta_max - params.theta_min) * uniform01(engine);
    const double phi =
        params.phi_min + (params.phi_max - params.phi_min) * uniform01(engine);
    const double accept = relativeDensity(params, theta, phi) / params.density_ratio;
    if (uniform01(engine) < accept)
      return {theta, phi};
  }
}

Face
makeFace(const Eigen::Vector3d& origin,
         const Eigen::Vector3d& u,
         const Eigen::Vector3d& v,
         std::uint32_t label)
{
  Face face;
  face.origin = origin;
  face.u = u;
  face.v = v;
  face.label = label;
  return face;
}

} // namespace

std::uint32_t
addBox(Scene& scene,
       const Eigen::Vector3d& centre,
       const Eigen::Vector3d& half_sizes,
       double yaw,
       std::uint32_t first_label)
{
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d ex = 2.0 * half_sizes.x() * rotation.col(0);
  const Eigen::Vector3d ey = 2.0 * half_sizes.y() * rotation.col(1);
  const Eigen::Vector3d ez = 2.0 * half_sizes.z() * rotation.col(2);
  // Per face, in the documented order: the full edge along its outward normal (from
  // the opposite face to it) and its two edges (u, v) with u x v along that normal.
  const Eigen::Vector3d across[6] = {-ey, ey, -ex, ex, -ez, ez};
  const Eigen::Vector3d edges[6][2] = {
      {ex, ez}, {ez, ex}, {ez, ey}, {ey, ez}, {ey, ex}, {ex, ey}};
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d& u = edges[i][0];
    const Eigen::Vector3d& v = edges[i][1];
    const Eigen::Vector3d origin = centre + 0.5 * (across[i] - u - v);
    scene.faces.push_back(makeFace(origin, u, v, first_label + i));
  }
  return first_label + 6;
}

double
relativeDensity(const SamplingParams& params, double theta, double phi)
{
  const double a = (theta - params.theta_min) / (params.theta_max - params.theta_min);
  const double b = (phi - params.phi_min) / (params.phi_max - params.phi_min);
  const double w = 0.5 * (std::clamp(a, 0.0, 1.0) + std::clamp(b, 0.0, 1.0));
  return std::pow(params.density_ratio, w * w * (3.0 - 2.0 * w));
}

pcl::PointCloud<pcl::PointXYZL>
scan(const Scene& scene,
     const SamplingParams& params,
     std::vector<Eigen::Vector3d>* exact_hits)
{
  checkParams(params);
  std::mt19937 engine(params.seed);
  pcl::PointCloud<pcl::PointXYZL> cloud;
  if (exact_hits)
    exact_hits->clear();
  for (std::size_t i = 0; i < params.num_rays; ++i) {
    const Eigen::Vector2d angles = drawAngles(params, engine);
    const Eigen::Vector3d dir =
        Eigen::Vector3d(std::tan(angles[0]), std::tan(angles[1]), 1.0).normalized();
    double nearest = std::numeric_limits<double>::infinity();
    const Face* hit = nullptr;
    for (const Face& face : scene.faces) {
      const double range = intersect(face, dir);
      if (range < nearest) {
        nearest = range;
        hit = &face;
      }
    }
    if (!hit)
      continue;
    double range = nearest;
    if (params.range_noise > 0.0)
      range += params.range_noise * nearest * nearest * standardNormal(engine);
    const Eigen::Vector3f point = (range * dir).cast<float>();
    pcl::PointXYZL out;
    out.x = point.x();
    out.y = point.y();
    out.z = point.z();
    out.label = hit->label;
    cloud.push_back(out);
    if (exact_hits)
      exact_hits->push_back(nearest * dir);
  }
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  return cloud;
}

Scene
makeCubeOnTableScene()
{
  constexpr double kTableY = 0.8;
  constexpr double kWallZ = 2.2;
  constexpr double kCubeHalf = 0.15;
  Scene scene;
  scene.faces.push_back(makeFace(Eigen::Vector3d(-1.5, -1.2, kWallZ),
                                 Eigen::Vector3d(0.0, kTableY + 1.2, 0.0),
                                 Eigen::Vector3d(3.0, 0.0, 0.0),
                                 1));
  scene.faces.push_back(makeFace(Eigen::Vector3d(-1.2, kTableY, 0.5),
                                 Eigen::Vector3d(2.4, 0.0, 0.0),
                                 Eigen::Vector3d(0.0, 0.0, kWallZ - 0.5),
                                 2));
  addBox(scene,
         Eigen::Vector3d(0.0, kTableY - kCubeHalf, 0.9),
         Eigen::Vector3d::Constant(kCubeHalf),
         35.0 * kPi / 180.0,
         3);
  return scene;
}

SamplingParams
makeCubeOnTableView(std::size_t num_rays)
{
  SamplingParams params;
  params.theta_min = -0.35;
  params.theta_max = 0.35;
  params.phi_min = 0.05;
  params.phi_max = 0.9;
  params.num_rays = num_rays;
  return params;
}

} // namespace selseg_test
