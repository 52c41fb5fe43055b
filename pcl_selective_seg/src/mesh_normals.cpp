/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/mesh_normals.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl {
namespace selective_seg {

void
computeTriangleNormals(const Vector3fVector& positions,
                       const std::vector<Triangle>& triangles,
                       const Eigen::Vector3f& viewpoint,
                       Vector3fVector& normals,
                       std::vector<double>& areas)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  normals.assign(triangles.size(), Eigen::Vector3f::Constant(nan));
  areas.assign(triangles.size(), 0.0);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3d a = positions[triangles[t][0]].cast<double>();
    const Eigen::Vector3d b = positions[triangles[t][1]].cast<double>();
    const Eigen::Vector3d c = positions[triangles[t][2]].cast<double>();
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double twice_area = n.norm();
    areas[t] = 0.5 * twice_area;
    if (!(twice_area > 0.0) || !std::isfinite(twice_area))
      continue;
    n /= twice_area;
    if (n.dot((a + b + c) / 3.0 - eye) > 0.0)
      n = -n;
    normals[t] = n.cast<float>();
  }
}

void
computeVertexNormals(std::size_t num_vertices,
                     const std::vector<Triangle>& triangles,
                     const Vector3fVector& normals,
                     const std::vector<double>& areas,
                     Vector3fVector& vertex_normals,
                     std::vector<double>& vertex_areas)
{
  std::vector<Eigen::Vector3d> sums(num_vertices, Eigen::Vector3d::Zero());
  vertex_areas.assign(num_vertices, 0.0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const double area = areas[t];
    const double weight = 1.0 / area; // eq. 2
    const bool usable = std::isfinite(area) && area > 0.0 && std::isfinite(weight) &&
                        normals[t].allFinite();
    for (const auto v : triangles[t]) {
      if (std::isfinite(area))
        vertex_areas[v] += area; // eq. 3
      if (usable)
        sums[v] += weight * normals[t].cast<double>();
    }
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  vertex_normals.assign(num_vertices, Eigen::Vector3f::Constant(nan));
  for (std::size_t v = 0; v < num_vertices; ++v) {
    const double norm = sums[v].norm();
    if (norm > 0.0 && std::isfinite(norm))
      vertex_normals[v] = (sums[v] / norm).cast<float>();
  }
}

void
markEdgeOnTriangles(const Vector3fVector& positions,
                    const std::vector<Triangle>& triangles,
                    const Vector3fVector& normals,
                    const Eigen::Vector3f& viewpoint,
                    double max_incidence,
                    std::vector<std::uint8_t>& edge_on)
{
  edge_on.assign(triangles.size(), 0);
  const double min_cos = max_incidence >= M_PI / 2.0 ? 0.0 : std::cos(max_incidence);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (!normals[t].allFinite()) {
      edge_on[t] = 1;
      continue;
    }
    const Eigen::Vector3d centroid = (positions[triangles[t][0]].cast<double>() +
                                      positions[triangles[t][1]].cast<double>() +
                                      positions[triangles[t][2]].cast<double>()) /
                                     3.0;
    const Eigen::Vector3d sight = (centroid - eye).normalized();
    edge_on[t] = std::abs(sight.dot(normals[t].cast<double>())) < min_cos;
  }
}

double
medianEdgeLength(const Vector3fVector& positions,
                 const std::vector<Triangle>& triangles)
{
  if (triangles.empty())
    return 0.0;
  std::vector<double> lengths;
  lengths.reserve(3 * triangles.size());
  for (const auto& t : triangles)
    for (int i = 0; i < 3; ++i)
      lengths.push_back(
          (positions[t[i]].cast<double>() - positions[t[(i + 1) % 3]].cast<double>())
              .norm());
  auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
  std::nth_element(lengths.begin(), middle, lengths.end());
  return *middle;
}

} // namespace selective_seg
} // namespace pcl
