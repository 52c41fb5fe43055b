/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/spherical_delaunay.h>
// detail::kExcludedKey, detail::keyAngles (non-dependent names: needed at definition)
#include <pcl_selective_seg/impl/spherical_delaunay.hpp>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>

namespace pcl {
namespace selective_seg {

template <typename PointT>
bool
SphericalDelaunay<PointT>::insertPoints(std::size_t first_new_point,
                                        std::vector<Triangle>& neighbours,
                                        DelaunayInsertion& info,
                                        std::vector<pcl::index_t>& moved_vertices)
{
  moved_vertices.clear();
  SphericalTriangulation& tri = triangulation_;
  if (!this->input_ || tri.triangles.empty() ||
      neighbours.size() != tri.triangles.size() ||
      tri.point_vertex.size() != first_new_point ||
      first_new_point > this->input_->size() ||
      tri.angle_quantization != angle_quantization_ || !sensorPoseIsRigid() ||
      tri.projection != ViewProjection::Forward ||
      projection_ != ViewProjection::Forward)
    return false;
  if (!this->initCompute() || !wholeCloudIndices())
    return false;
  const auto& cloud = *this->input_;
  const auto& indices = *this->indices_;
  const auto n = static_cast<pcl::index_t>(cloud.size());
  const Eigen::Affine3d pose = getSensorPose().template cast<double>();

  // The new points' angles, computed in parallel.
  std::vector<pcl::index_t> fresh_points;
  for (const pcl::index_t i : indices) {
    if (i < 0 || i >= n) {
      this->deinitCompute();
      return false;
    }
    if (static_cast<std::size_t>(i) >= first_new_point)
      fresh_points.push_back(i);
  }
  std::vector<std::pair<std::uint64_t, pcl::index_t>> projected(fresh_points.size());
  const auto num_fresh = static_cast<std::ptrdiff_t>(fresh_points.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(dynamic, 1024) \
    if (fresh_points.size() >= detail::kMinParallelItems)
#endif
  for (std::ptrdiff_t k = 0; k < num_fresh; ++k)
    projected[k] = projectPoint(pose, fresh_points[k]);
  std::vector<std::pair<std::uint64_t, pcl::index_t>> keyed;
  std::vector<std::pair<pcl::index_t, pcl::index_t>> excluded; // (point, status)
  keyed.reserve(projected.size());
  for (std::size_t k = 0; k < projected.size(); ++k) {
    if (projected[k].first == detail::kExcludedKey)
      excluded.emplace_back(fresh_points[k], projected[k].second);
    else
      keyed.push_back(projected[k]);
  }
  std::sort(keyed.begin(), keyed.end());

  // Runs of equal angles: an existing vertex (its representative may change) or a new
  // vertex.
  std::vector<QuantizedPoint> new_angles;
  std::vector<pcl::index_t> new_representative;
  std::vector<std::pair<pcl::index_t, pcl::index_t>> point_to_old; // (point, old v)
  std::vector<std::pair<pcl::index_t, pcl::index_t>> point_to_new; // (point, new k)
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin + 1;
    while (end < keyed.size() && keyed[end].first == keyed[begin].first)
      ++end;
    const QuantizedPoint q = detail::keyAngles(keyed[begin].first);
    const auto it = std::lower_bound(tri.vertex_angles.begin(), tri.vertex_angles.end(), q);
    const pcl::index_t best = representative(keyed, begin, end, pose);
    if (it != tri.vertex_angles.end() && *it == q) {
      const auto v = static_cast<pcl::index_t>(it - tri.vertex_angles.begin());
      for (std::size_t k = begin; k < end; ++k)
        point_to_old.emplace_back(keyed[k].second, v);
      if (isCloserRepresentative(pose, best, tri.vertex_point[v]))
        point_to_old.emplace_back(-1 - best, v); // marks the new representative
    }
    else {
      const auto k_new = static_cast<pcl::index_t>(new_angles.size());
      new_angles.push_back(q);
      new_representative.push_back(best);
      for (std::size_t k = begin; k < end; ++k)
        point_to_new.emplace_back(keyed[k].second, k_new);
    }
    begin = end;
  }

  // The insertion changes its arguments only when it succeeds.
  std::string why;
  if (!insertDelaunayPoints(
          tri.vertex_angles, tri.triangles, neighbours, new_angles, info, &why,
          num_threads_)) {
    PCL_DEBUG("[pcl::selective_seg::%s::insertPoints] %s: triangulating again\n",
              getClassName().c_str(),
              why.c_str());
    this->deinitCompute();
    return false;
  }

  // Renumber the vertex arrays and the point map.
  const std::size_t num_vertices = tri.vertex_angles.size();
  pcl::Indices vertex_point;
  detail::resizeLarge(vertex_point, num_vertices);
  std::vector<Eigen::Vector3f> positions;
  detail::resizeLarge(positions, num_vertices);
  const auto num_old = static_cast<std::ptrdiff_t>(tri.vertex_point.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(static) \
    if (tri.vertex_point.size() >= detail::kMinParallelItems)
#endif
  for (std::ptrdiff_t v = 0; v < num_old; ++v) {
    vertex_point[info.old_to_new_point[v]] = tri.vertex_point[v];
    positions[info.old_to_new_point[v]] = tri.vertex_positions[v];
  }
  for (std::size_t k = 0; k < new_angles.size(); ++k) {
    const pcl::index_t v = info.inserted_points[k];
    vertex_point[v] = new_representative[k];
    positions[v] = toSensorFrame(pose, new_representative[k]).template cast<float>();
  }
  for (const auto& entry : point_to_old)
    if (entry.first < 0) { // a new representative
      const pcl::index_t v = info.old_to_new_point[entry.second];
      const pcl::index_t best = -1 - entry.first;
      vertex_point[v] = best;
      positions[v] = toSensorFrame(pose, best).template cast<float>();
      moved_vertices.push_back(v);
    }
  std::vector<pcl::index_t> point_vertex;
  detail::assignLarge(point_vertex, cloud.size(), kOutsideIndices);
  const auto num_old_points = static_cast<std::ptrdiff_t>(first_new_point);
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(static) \
    if (first_new_point >= detail::kMinParallelItems)
#endif
  for (std::ptrdiff_t i = 0; i < num_old_points; ++i) {
    const pcl::index_t v = tri.point_vertex[i];
    point_vertex[i] = v >= 0 ? info.old_to_new_point[v] : v;
  }
  for (const auto& entry : excluded)
    point_vertex[entry.first] = entry.second;
  for (const auto& entry : point_to_old)
    if (entry.first >= 0)
      point_vertex[entry.first] = info.old_to_new_point[entry.second];
  for (const auto& entry : point_to_new)
    point_vertex[entry.first] = info.inserted_points[entry.second];

  tri.point_vertex.swap(point_vertex);
  tri.vertex_point.swap(vertex_point);
  tri.vertex_positions.swap(positions);
  if (compute_neighbours_)
    tri.neighbours = neighbours;
  else
    tri.neighbours.clear();
  countExcluded(tri);
  this->deinitCompute();
  return true;
}

} // namespace selective_seg
} // namespace pcl
