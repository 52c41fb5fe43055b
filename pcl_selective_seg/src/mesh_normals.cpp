/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/mesh_normals.h>
#include <pcl_selective_seg/region_merging.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl {
namespace selective_seg {

namespace {

/** OpenMP thread count: 0 = all cores. */
int
threads(int requested)
{
  return requested > 0 ? requested : static_cast<int>(defaultThreads());
}

/** The weight of a triangle in eq. 2, or 0 when it is degenerate. */
double
normalWeight(double area, const Eigen::Vector3f& normal)
{
  const double w = 1.0 / area;
  return std::isfinite(area) && area > 0.0 && std::isfinite(w) && normal.allFinite()
             ? w
             : 0.0;
}

Eigen::Vector3f
normalizedOrNaN(const Eigen::Vector3d& sum)
{
  const double norm = sum.norm();
  if (norm > 0.0 && std::isfinite(norm))
    return (sum / norm).cast<float>();
  return Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
}

/** Normal (oriented toward the eye) and area of one triangle; the normal stays NaN
 * when the triangle is degenerate. */
inline void
triangleNormal(const Vector3fVector& positions,
               const Triangle& triangle,
               const Eigen::Vector3d& eye,
               Eigen::Vector3f& normal,
               double& area)
{
  const Eigen::Vector3d a = positions[triangle[0]].cast<double>();
  const Eigen::Vector3d b = positions[triangle[1]].cast<double>();
  const Eigen::Vector3d c = positions[triangle[2]].cast<double>();
  Eigen::Vector3d n = (b - a).cross(c - a);
  const double twice_area = n.norm();
  area = 0.5 * twice_area;
  if (!(twice_area > 0.0) || !std::isfinite(twice_area))
    return;
  n /= twice_area;
  if (n.dot((a + b + c) / 3.0 - eye) > 0.0)
    n = -n;
  normal = n.cast<float>();
}

/** Whether one triangle is seen edge-on (markEdgeOnTriangles()). */
inline std::uint8_t
isEdgeOn(const Vector3fVector& positions,
         const Triangle& triangle,
         const Eigen::Vector3f& normal,
         const Eigen::Vector3d& eye,
         double min_cos)
{
  if (!normal.allFinite())
    return 1;
  const Eigen::Vector3d centroid = (positions[triangle[0]].cast<double>() +
                                    positions[triangle[1]].cast<double>() +
                                    positions[triangle[2]].cast<double>()) /
                                   3.0;
  const Eigen::Vector3d sight = (centroid - eye).normalized();
  return std::abs(sight.dot(normal.cast<double>())) < min_cos;
}

/** cos of the largest incidence of a surface triangle; 0 disables the test. */
double
minIncidenceCos(double max_incidence)
{
  return max_incidence >= M_PI / 2.0 ? 0.0 : std::cos(max_incidence);
}

} // namespace

void
computeTriangleNormals(const Vector3fVector& positions,
                       const std::vector<Triangle>& triangles,
                       const Eigen::Vector3f& viewpoint,
                       Vector3fVector& normals,
                       std::vector<double>& areas,
                       int num_threads)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  normals.assign(triangles.size(), Eigen::Vector3f::Constant(nan));
  areas.assign(triangles.size(), 0.0);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  const auto n_tri = static_cast<std::ptrdiff_t>(triangles.size());
#pragma omp parallel for num_threads(threads(num_threads)) schedule(static)
  for (std::ptrdiff_t t = 0; t < n_tri; ++t)
    triangleNormal(positions, triangles[t], eye, normals[t], areas[t]);
}

void
computeTriangleNormalsAndEdgeOn(const Vector3fVector& positions,
                                const std::vector<Triangle>& triangles,
                                const Eigen::Vector3f& viewpoint,
                                double max_incidence,
                                Vector3fVector& normals,
                                std::vector<double>& areas,
                                std::vector<std::uint8_t>& edge_on,
                                int num_threads)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  normals.assign(triangles.size(), Eigen::Vector3f::Constant(nan));
  areas.assign(triangles.size(), 0.0);
  edge_on.assign(triangles.size(), 0);
  const double min_cos = minIncidenceCos(max_incidence);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  const auto n_tri = static_cast<std::ptrdiff_t>(triangles.size());
#pragma omp parallel for num_threads(threads(num_threads)) schedule(static)
  for (std::ptrdiff_t t = 0; t < n_tri; ++t) {
    triangleNormal(positions, triangles[t], eye, normals[t], areas[t]);
    edge_on[t] = isEdgeOn(positions, triangles[t], normals[t], eye, min_cos);
  }
}

void
computeVertexNormals(std::size_t num_vertices,
                     const std::vector<Triangle>& triangles,
                     const Vector3fVector& normals,
                     const std::vector<double>& areas,
                     Vector3fVector& vertex_normals,
                     std::vector<double>& vertex_areas,
                     int num_threads)
{
  // Gathered per vertex over its triangles in increasing order: the same sums, in the
  // same order, whatever the number of threads.
  const Incidence incident =
      vertexTriangles(triangles, num_vertices, threads(num_threads));
  vertex_areas.assign(num_vertices, 0.0);
  vertex_normals.resize(num_vertices);
#pragma omp parallel for num_threads(threads(num_threads)) schedule(static)
  for (std::ptrdiff_t v = 0; v < static_cast<std::ptrdiff_t>(num_vertices); ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (auto i = incident.offsets[v]; i < incident.offsets[v + 1]; ++i) {
      const auto t = incident.items[i];
      if (std::isfinite(areas[t]))
        vertex_areas[v] += areas[t];                            // eq. 3
      const double weight = normalWeight(areas[t], normals[t]); // eq. 2
      if (weight > 0.0) // degenerate triangles are skipped (NaN normals)
        sum += weight * normals[t].cast<double>();
    }
    vertex_normals[v] = normalizedOrNaN(sum);
  }
}

void
computeVertexNormalsOverRings(std::size_t num_vertices,
                              const std::vector<Triangle>& triangles,
                              const Vector3fVector& normals,
                              const std::vector<double>& areas,
                              int rings,
                              Vector3fVector& vertex_normals)
{
  const Incidence incident = vertexTriangles(triangles, num_vertices);
  // Visit stamps: a vertex or triangle is in the current neighbourhood when its stamp
  // equals the current vertex id + 1.
  std::vector<std::size_t> vertex_stamp(num_vertices, 0),
      triangle_stamp(triangles.size(), 0);
  std::vector<pcl::index_t> frontier, next;
  vertex_normals.resize(num_vertices);
  for (std::size_t p = 0; p < num_vertices; ++p) {
    const std::size_t stamp = p + 1;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    frontier.assign(1, static_cast<pcl::index_t>(p));
    vertex_stamp[p] = stamp;
    for (int ring = 0; ring < rings && !frontier.empty(); ++ring) {
      next.clear();
      for (const auto v : frontier)
        for (auto i = incident.offsets[v]; i < incident.offsets[v + 1]; ++i) {
          const auto t = incident.items[i];
          if (triangle_stamp[t] == stamp)
            continue;
          triangle_stamp[t] = stamp;
          const double weight = normalWeight(areas[t], normals[t]);
          if (weight > 0.0)
            sum += weight * normals[t].cast<double>();
          for (const auto u : triangles[t])
            if (vertex_stamp[u] != stamp) {
              vertex_stamp[u] = stamp;
              next.push_back(u);
            }
        }
      frontier.swap(next);
    }
    vertex_normals[p] = normalizedOrNaN(sum);
  }
}

void
computeTriangleNormalsFromVertices(const std::vector<Triangle>& triangles,
                                   const Vector3fVector& vertex_normals,
                                   Vector3fVector& normals)
{
  normals.resize(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto v : triangles[t])
      sum += vertex_normals[v].cast<double>(); // NaN propagates: no normal
    normals[t] =
        sum.allFinite()
            ? normalizedOrNaN(sum)
            : Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  }
}

void
markEdgeOnTriangles(const Vector3fVector& positions,
                    const std::vector<Triangle>& triangles,
                    const Vector3fVector& normals,
                    const Eigen::Vector3f& viewpoint,
                    double max_incidence,
                    std::vector<std::uint8_t>& edge_on,
                    int num_threads)
{
  edge_on.assign(triangles.size(), 0);
  const double min_cos = minIncidenceCos(max_incidence);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  const auto n_tri = static_cast<std::ptrdiff_t>(triangles.size());
#pragma omp parallel for num_threads(threads(num_threads)) schedule(static)
  for (std::ptrdiff_t t = 0; t < n_tri; ++t)
    edge_on[t] = isEdgeOn(positions, triangles[t], normals[t], eye, min_cos);
}

double
medianEdgeLength(const Vector3fVector& positions,
                 const std::vector<Triangle>& triangles)
{
  if (triangles.empty())
    return 0.0;
  // Large meshes: every stride-th triangle (a fixed function of the canonical triangle
  // order) still gives over 300,000 edges, plenty for a median.
  const std::size_t stride = std::max<std::size_t>(1, triangles.size() / 100000);
  std::vector<double> lengths;
  lengths.reserve(3 * (triangles.size() / stride + 1));
  for (std::size_t k = 0; k < triangles.size(); k += stride) {
    const Triangle& t = triangles[k];
    for (int i = 0; i < 3; ++i)
      lengths.push_back(
          (positions[t[i]].cast<double>() - positions[t[(i + 1) % 3]].cast<double>())
              .norm());
  }
  auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
  std::nth_element(lengths.begin(), middle, lengths.end());
  return *middle;
}

} // namespace selective_seg
} // namespace pcl
