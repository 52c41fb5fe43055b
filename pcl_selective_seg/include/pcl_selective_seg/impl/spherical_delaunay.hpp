/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/impl/radix_sort.hpp>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief Sort key of a quantized angle pair: (theta, phi) lexicographic order. */
inline std::uint64_t
angleKey(const QuantizedPoint& q)
{
  const auto biased = [](std::int32_t v) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>(v) ^ 0x80000000u);
  };
  return (biased(q[0]) << 32) | biased(q[1]);
}

inline QuantizedPoint
keyAngles(std::uint64_t key)
{
  const auto unbiased = [](std::uint64_t v) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(v) ^ 0x80000000u);
  };
  return {unbiased(key >> 32), unbiased(key & 0xffffffffu)};
}

/** \brief Key of an excluded point (sorts last); its index then holds the status. */
constexpr std::uint64_t kExcludedKey = ~std::uint64_t(0);

/** \brief Sorts (angle key, point) pairs by key: a radix sort of the keys packed
 * relative to the smallest theta and phi (entries with equal keys may come in any
 * order; the callers do not depend on it). */
inline void
sortByAngleKey(std::vector<std::pair<std::uint64_t, pcl::index_t>>& entries,
               unsigned int num_threads = 1)
{
  if (entries.size() < 2)
    return;
  std::uint32_t lo_theta = ~0u, hi_theta = 0, lo_phi = ~0u, hi_phi = 0;
  for (const auto& e : entries) {
    const auto theta = static_cast<std::uint32_t>(e.first >> 32);
    const auto phi = static_cast<std::uint32_t>(e.first);
    lo_theta = std::min(lo_theta, theta);
    hi_theta = std::max(hi_theta, theta);
    lo_phi = std::min(lo_phi, phi);
    hi_phi = std::max(hi_phi, phi);
  }
  const int phi_bits = bitWidth(hi_phi - lo_phi);
  const int bits = phi_bits + bitWidth(hi_theta - lo_theta);
  const auto pack = [&](std::uint64_t key) {
    return (std::uint64_t{static_cast<std::uint32_t>(key >> 32) - lo_theta}
            << phi_bits) |
           (static_cast<std::uint32_t>(key) - lo_phi);
  };
  const std::uint64_t phi_mask = (std::uint64_t{1} << phi_bits) - 1;
  const auto unpack = [&](std::uint64_t packed) {
    return (std::uint64_t{static_cast<std::uint32_t>(packed >> phi_bits) + lo_theta}
            << 32) |
           (static_cast<std::uint32_t>(packed & phi_mask) + lo_phi);
  };
  for (auto& e : entries)
    e.first = pack(e.first);
  radixSortByKey(entries, bits, num_threads);
  for (auto& e : entries)
    e.first = unpack(e.first);
}

} // namespace detail

template <typename PointT>
Eigen::Affine3f
SphericalDelaunay<PointT>::getSensorPose() const
{
  if (has_sensor_pose_ || !this->input_)
    return Eigen::Affine3f(sensor_pose_.matrix());
  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  pose.translation() = this->input_->sensor_origin_.template head<3>();
  pose.linear() = this->input_->sensor_orientation_.normalized().toRotationMatrix();
  return pose;
}

template <typename PointT>
bool
SphericalDelaunay<PointT>::wholeCloudIndices()
{
  if (!this->fake_indices_ || this->indices_->size() == this->input_->size())
    return true;
  PCL_ERROR("[pcl::selective_seg::%s::triangulate] out of memory for the indices of "
            "%zu points\n",
            getClassName().c_str(),
            this->input_->size());
  this->deinitCompute();
  return false;
}

template <typename PointT>
bool
SphericalDelaunay<PointT>::sensorPoseIsRigid(std::string* why) const
{
  if (!has_sensor_pose_ && this->input_) {
    // normalized() leaves a zero quaternion as it is, whose matrix is the identity.
    const float norm = this->input_->sensor_orientation_.coeffs().norm();
    if (!(norm >= 1e-6f) || !std::isfinite(norm)) {
      if (why)
        *why = "the cloud's sensor_orientation_ has norm " + std::to_string(norm) +
               ": not a rotation (set a unit quaternion, or setSensorPose())";
      return false;
    }
  }
  const Eigen::Affine3f pose = getSensorPose();
  const Eigen::Matrix3f r = pose.linear();
  // toSensorFrame() inverts the rotation by its transpose: a scaled or sheared pose
  // would map the points wrongly.
  const bool rigid =
      pose.matrix().allFinite() &&
      (r.transpose() * r - Eigen::Matrix3f::Identity()).cwiseAbs().maxCoeff() <=
          1e-4f &&
      r.determinant() > 0.0f;
  if (!rigid && why)
    *why = std::string(has_sensor_pose_
                           ? "the pose given to setSensorPose()"
                           : "the cloud's sensor_origin_ / sensor_orientation_") +
           " is not a finite rotation and translation";
  return rigid;
}

template <typename PointT>
Eigen::Vector3d
SphericalDelaunay<PointT>::toSensorFrame(const Eigen::Affine3d& pose,
                                         pcl::index_t index) const
{
  return pose.linear().transpose() *
         ((*this->input_)[index].getVector3fMap().template cast<double>() -
          pose.translation());
}

template <typename PointT>
void
SphericalDelaunay<PointT>::projectAndMergeVertices(SphericalTriangulation& result) const
{
  const auto& cloud = *this->input_;
  const auto& indices = *this->indices_;
  const Eigen::Affine3d pose = getSensorPose().template cast<double>();
  // (angle key, point index), one per index; computed in parallel, point by point.
  std::vector<std::pair<std::uint64_t, pcl::index_t>> keyed;
  detail::resizeLarge(keyed, indices.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(dynamic, 1024)
#endif
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(indices.size()); ++k)
    keyed[k] = projectPoint(pose, indices[k]);
  detail::assignLarge(result.point_vertex, cloud.size(), kOutsideIndices);
  result.angle_quantization = angle_quantization_;
  result.projection = projection_;
  for (std::size_t k = 0; k < keyed.size(); ++k)
    if (keyed[k].first == detail::kExcludedKey)
      result.point_vertex[indices[k]] = keyed[k].second;
  keyed.erase(std::remove_if(keyed.begin(),
                             keyed.end(),
                             [](const std::pair<std::uint64_t, pcl::index_t>& e) {
                               return e.first == detail::kExcludedKey;
                             }),
              keyed.end());
  detail::sortByAngleKey(keyed, num_threads_);
  mergeEqualAngles(keyed, pose, result);
  countExcluded(result);
}

template <typename PointT>
std::pair<std::uint64_t, pcl::index_t>
SphericalDelaunay<PointT>::projectPoint(const Eigen::Affine3d& pose,
                                        pcl::index_t index) const
{
  if (!pcl::isXYZFinite((*this->input_)[index]))
    return {detail::kExcludedKey, kNonFinite};
  const Eigen::Vector3d s = toSensorFrame(pose, index);
  if (projection_ == ViewProjection::Panoramic)
    return projectPanoramic(s, index);
  if (!(s.z() > 0.0))
    return {detail::kExcludedKey, kBehindSensor};
  // eq. 1; both angles lie in (-pi/2, pi/2) because z > 0.
  const QuantizedPoint q{
      static_cast<std::int32_t>(
          detail::quantizedAngle(s.x(), s.z(), angle_quantization_)),
      static_cast<std::int32_t>(
          detail::quantizedAngle(s.y(), s.z(), angle_quantization_))};
  return {detail::angleKey(q), index};
}

template <typename PointT>
std::pair<std::uint64_t, pcl::index_t>
SphericalDelaunay<PointT>::projectPanoramic(const Eigen::Vector3d& s,
                                            pcl::index_t index) const
{
  // Squares of floats: no overflow in double.
  const double horizontal = std::sqrt(s.x() * s.x() + s.z() * s.z());
  if (!(horizontal > 0.0 || s.y() != 0.0))
    return {detail::kExcludedKey, kBehindSensor}; // the sensor's own position
  const double step = angle_quantization_;
  const long period = panoramicPeriod(step);
  // theta = atan2(x, z) on the quantization grid, through quantizedAngle() (twice as
  // fast as atan2): behind the sensor atan2(x, z) = +-pi - atan(x / -z), and the
  // quantized value is +-period / 2 minus that of atan(x / -z).
  long theta;
  if (s.z() > 0.0)
    theta = detail::quantizedAngle(s.x(), s.z(), step);
  else if (s.z() < 0.0)
    theta = (s.x() >= 0.0 ? period / 2 : -period / 2) -
            detail::quantizedAngle(s.x(), -s.z(), step);
  else
    theta = std::lround(std::atan2(s.x(), 0.0) / step);
  if (theta >= period / 2) // +pi is -pi
    theta -= period;
  const long phi = horizontal > 0.0 ? detail::quantizedAngle(s.y(), horizontal, step)
                                    : std::lround(std::atan2(s.y(), 0.0) / step);
  const QuantizedPoint q{static_cast<std::int32_t>(theta),
                         static_cast<std::int32_t>(phi)};
  return {detail::angleKey(q), index};
}

template <typename PointT>
pcl::index_t
SphericalDelaunay<PointT>::representative(
    const std::vector<std::pair<std::uint64_t, pcl::index_t>>& sorted,
    std::size_t begin,
    std::size_t end,
    const Eigen::Affine3d& pose) const
{
  // Nearest to the sensor, ties by x, y, z, then index: the choice depends on the
  // points only, not on their order.
  pcl::index_t best = sorted[begin].second;
  for (std::size_t k = begin + 1; k < end; ++k)
    if (isCloserRepresentative(pose, sorted[k].second, best))
      best = sorted[k].second;
  return best;
}

template <typename PointT>
void
SphericalDelaunay<PointT>::countExcluded(SphericalTriangulation& result)
{
  result.num_outside_indices = result.num_non_finite = result.num_behind_sensor = 0;
  for (const auto v : result.point_vertex) {
    result.num_outside_indices += (v == kOutsideIndices);
    result.num_non_finite += (v == kNonFinite);
    result.num_behind_sensor += (v == kBehindSensor);
  }
}

template <typename PointT>
void
SphericalDelaunay<PointT>::mergeEqualAngles(
    const std::vector<std::pair<std::uint64_t, pcl::index_t>>& sorted,
    const Eigen::Affine3d& pose,
    SphericalTriangulation& result) const
{
  // One vertex per run of equal keys; the runs are filled in parallel (a point belongs
  // to one run, so every entry is written once).
  std::vector<std::size_t> run_begin;
  detail::reserveLarge(run_begin, sorted.size() + 1);
  for (std::size_t k = 0; k < sorted.size(); ++k)
    if (k == 0 || sorted[k].first != sorted[k - 1].first)
      run_begin.push_back(k);
  const std::size_t num_vertices = run_begin.size();
  run_begin.push_back(sorted.size());
  detail::resizeLarge(result.vertex_point, num_vertices);
  detail::resizeLarge(result.vertex_angles, num_vertices);
  detail::resizeLarge(result.vertex_positions, num_vertices);
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(static)
#endif
  for (std::ptrdiff_t v = 0; v < static_cast<std::ptrdiff_t>(num_vertices); ++v) {
    const std::size_t begin = run_begin[v], end = run_begin[v + 1];
    // The points are read in angle order, scattered in the cloud: ask for the point of
    // the run a few vertices ahead (a hint; no effect on the values).
    if (static_cast<std::size_t>(v) + 16 < num_vertices) {
      const pcl::index_t ahead = sorted[run_begin[v + 16]].second;
      __builtin_prefetch(&(*this->input_)[ahead]);
      __builtin_prefetch(&result.point_vertex[ahead]);
    }
    const pcl::index_t best = representative(sorted, begin, end, pose);
    result.vertex_point[v] = best;
    result.vertex_angles[v] = detail::keyAngles(sorted[begin].first);
    result.vertex_positions[v] = toSensorFrame(pose, best).template cast<float>();
    for (std::size_t k = begin; k < end; ++k)
      result.point_vertex[sorted[k].second] = static_cast<pcl::index_t>(v);
  }
}

template <typename PointT>
bool
SphericalDelaunay<PointT>::isCloserRepresentative(const Eigen::Affine3d& pose,
                                                  pcl::index_t a,
                                                  pcl::index_t b) const
{
  const auto& pa = (*this->input_)[a];
  const auto& pb = (*this->input_)[b];
  const double ra = toSensorFrame(pose, a).squaredNorm();
  const double rb = toSensorFrame(pose, b).squaredNorm();
  return std::tie(ra, pa.x, pa.y, pa.z, a) < std::tie(rb, pb.x, pb.y, pb.z, b);
}

template <typename PointT>
bool
SphericalDelaunay<PointT>::triangulateVertices()
{
  std::string why;
  bool ok;
  if (projection_ == ViewProjection::Panoramic) {
    // The periodic triangulation makes the adjacency anyway (its checks read it).
    std::vector<Triangle> neighbours;
    ok = delaunay2dPeriodic(triangulation_.vertex_angles,
                            panoramicPeriod(angle_quantization_),
                            backend_,
                            triangulation_.triangles,
                            neighbours,
                            triangulation_.seam_closed,
                            &why,
                            num_threads_);
    if (compute_neighbours_)
      triangulation_.neighbours.swap(neighbours);
  } else
    ok = compute_neighbours_ ? delaunay2d(triangulation_.vertex_angles,
                                          backend_,
                                          triangulation_.triangles,
                                          triangulation_.neighbours,
                                          &why,
                                          num_threads_)
                             : delaunay2d(triangulation_.vertex_angles,
                                          backend_,
                                          triangulation_.triangles,
                                          &why);
  if (!ok)
    PCL_ERROR("[pcl::selective_seg::%s::triangulate] %s\n",
              getClassName().c_str(),
              why.c_str());
  return ok;
}

template <typename PointT>
bool
SphericalDelaunay<PointT>::triangulate()
{
  triangulation_ = SphericalTriangulation();
  if (!this->input_) {
    PCL_ERROR("[pcl::selective_seg::%s::triangulate] no input cloud: call "
              "setInputCloud() first\n",
              getClassName().c_str());
    return false;
  }
  if (!(angle_quantization_ >= 2.5e-8 && angle_quantization_ <= 1e-2)) {
    PCL_ERROR("[pcl::selective_seg::%s::triangulate] angle quantization %g rad is "
              "outside [2.5e-8, 1e-2]\n",
              getClassName().c_str(),
              angle_quantization_);
    return false;
  }
  if (projection_ == ViewProjection::Panoramic &&
      (angle_quantization_ < 1e-7 || backend_ == DelaunayBackend::Vtk)) {
    PCL_ERROR("[pcl::selective_seg::%s::triangulate] the panoramic projection needs an "
              "angle quantization of at least 1e-7 rad (not %g) and an exact backend "
              "(sweep or boost, not %s)\n",
              getClassName().c_str(),
              angle_quantization_,
              toString(backend_));
    return false;
  }
  std::string bad_pose;
  if (!sensorPoseIsRigid(&bad_pose)) {
    PCL_ERROR("[pcl::selective_seg::%s::triangulate] %s\n",
              getClassName().c_str(),
              bad_pose.c_str());
    return false;
  }
  if (!this->initCompute())
    return false;
  if (!wholeCloudIndices())
    return false;
  const auto n = static_cast<pcl::index_t>(this->input_->size());
  const bool bad_index = std::any_of(this->indices_->begin(),
                                     this->indices_->end(),
                                     [n](pcl::index_t i) { return i < 0 || i >= n; });
  if (bad_index) {
    PCL_ERROR(
        "[pcl::selective_seg::%s::triangulate] an index lies outside the cloud of "
        "%d points\n",
        getClassName().c_str(),
        static_cast<int>(n));
    this->deinitCompute();
    return false;
  }
  projectAndMergeVertices(triangulation_);
  const bool ok = triangulateVertices();
  if (!ok)
    triangulation_ = SphericalTriangulation();
  this->deinitCompute();
  return ok;
}

template <typename PointT>
void
SphericalDelaunay<PointT>::reconstruct(pcl::PolygonMesh& output)
{
  if (!this->input_) {
    PCL_ERROR("[pcl::selective_seg::%s::reconstruct] no input cloud: call "
              "setInputCloud() first\n",
              getClassName().c_str());
    output = pcl::PolygonMesh();
    return;
  }
  pcl::MeshConstruction<PointT>::reconstruct(output);
}

template <typename PointT>
void
SphericalDelaunay<PointT>::toPolygons(std::vector<pcl::Vertices>& polygons) const
{
  polygons.resize(triangulation_.triangles.size());
  for (std::size_t t = 0; t < polygons.size(); ++t) {
    const Triangle& tri = triangulation_.triangles[t];
    polygons[t].vertices.assign({triangulation_.vertex_point[tri[0]],
                                 triangulation_.vertex_point[tri[1]],
                                 triangulation_.vertex_point[tri[2]]});
  }
}

template <typename PointT>
void
SphericalDelaunay<PointT>::performReconstruction(pcl::PolygonMesh& output)
{
  performReconstruction(output.polygons);
}

template <typename PointT>
void
SphericalDelaunay<PointT>::performReconstruction(std::vector<pcl::Vertices>& polygons)
{
  polygons.clear();
  // The base class has run initCompute(); triangulate() runs it again, harmlessly.
  if (triangulate())
    toPolygons(polygons);
}

} // namespace selective_seg
} // namespace pcl

#include <pcl_selective_seg/impl/spherical_delaunay_update.hpp>

#define PCL_INSTANTIATE_SphericalDelaunay(T)                                           \
  template class PCL_EXPORTS pcl::selective_seg::SphericalDelaunay<T>;
