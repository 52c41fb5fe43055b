/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/spherical_delaunay.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief A point's place in the vertex map, sortable into a deterministic order. */
struct ProjectedPoint {
  QuantizedPoint angles;
  double range_squared;
  Eigen::Vector3f xyz;
  Eigen::Vector3f sensor_xyz;
  pcl::index_t index;

  bool operator<(const ProjectedPoint& o) const
  {
    return std::tie(angles, range_squared, xyz.x(), xyz.y(), xyz.z(), index) <
           std::tie(
               o.angles, o.range_squared, o.xyz.x(), o.xyz.y(), o.xyz.z(), o.index);
  }
};

} // namespace detail

template <typename PointT>
Eigen::Affine3f
SphericalDelaunay<PointT>::getSensorPose() const
{
  if (has_sensor_pose_ || !this->input_)
    return sensor_pose_;
  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  pose.translation() = this->input_->sensor_origin_.template head<3>();
  pose.linear() = this->input_->sensor_orientation_.normalized().toRotationMatrix();
  return pose;
}

template <typename PointT>
void
SphericalDelaunay<PointT>::projectAndMergeVertices(SphericalTriangulation& result) const
{
  const auto& cloud = *this->input_;
  result.point_vertex.assign(cloud.size(), kOutsideIndices);
  result.angle_quantization = angle_quantization_;
  const Eigen::Affine3d pose = getSensorPose().template cast<double>();
  const Eigen::Matrix3d to_sensor = pose.linear().transpose();
  const Eigen::Vector3d origin = pose.translation();

  std::vector<detail::ProjectedPoint> projected;
  projected.reserve(this->indices_->size());
  for (const auto i : *this->indices_) {
    const PointT& p = cloud[i];
    if (!pcl::isXYZFinite(p)) {
      result.point_vertex[i] = kNonFinite;
      continue;
    }
    const Eigen::Vector3d s =
        to_sensor * (p.getVector3fMap().template cast<double>() - origin);
    if (!(s.z() > 0.0)) {
      result.point_vertex[i] = kBehindSensor;
      continue;
    }
    // eq. 1; both angles lie in (-pi/2, pi/2) because z > 0.
    const QuantizedPoint q{static_cast<std::int32_t>(std::lround(
                               std::atan2(s.x(), s.z()) / angle_quantization_)),
                           static_cast<std::int32_t>(std::lround(
                               std::atan2(s.y(), s.z()) / angle_quantization_))};
    projected.push_back({q, s.squaredNorm(), p.getVector3fMap(), s.cast<float>(), i});
  }
  std::sort(projected.begin(), projected.end());

  result.vertex_point.clear();
  result.vertex_angles.clear();
  result.vertex_positions.clear();
  for (std::size_t k = 0; k < projected.size(); ++k) {
    if (k == 0 || projected[k].angles != projected[k - 1].angles) {
      result.vertex_point.push_back(projected[k].index);
      result.vertex_angles.push_back(projected[k].angles);
      result.vertex_positions.push_back(projected[k].sensor_xyz);
    }
    result.point_vertex[projected[k].index] =
        static_cast<pcl::index_t>(result.vertex_point.size() - 1);
  }
  for (const auto v : result.point_vertex) {
    result.num_outside_indices += (v == kOutsideIndices);
    result.num_non_finite += (v == kNonFinite);
    result.num_behind_sensor += (v == kBehindSensor);
  }
}

template <typename PointT>
bool
SphericalDelaunay<PointT>::triangulateVertices()
{
  std::string why;
  if (!delaunay2d(
          triangulation_.vertex_angles, backend_, triangulation_.triangles, &why)) {
    PCL_ERROR("[pcl::selective_seg::%s::triangulate] %s\n",
              getClassName().c_str(),
              why.c_str());
    return false;
  }
  computeTriangleNeighbours(triangulation_.triangles,
                            triangulation_.vertex_angles.size(),
                            triangulation_.neighbours);
  return true;
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
  if (!this->initCompute())
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

#define PCL_INSTANTIATE_SphericalDelaunay(T)                                           \
  template class PCL_EXPORTS pcl::selective_seg::SphericalDelaunay<T>;
