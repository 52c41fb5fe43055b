/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/impl/parallel_exceptions.hpp>
#include <pcl_selective_seg/mesh_normals.h>
#include <pcl_selective_seg/region_merging.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include "mesh_checks.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>

namespace pcl {
namespace selective_seg {

namespace {

using detail::threadCount;

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

/** A triangle's smallest height h = 2 A / L_max, in units of FLT_EPSILON * M (M the
 * largest |corner|), at or below which its normal is not determined by its float
 * corners. Rounding a coordinate to float moves it by at most FLT_EPSILON / 2 of its
 * magnitude, so a corner by at most FLT_EPSILON / 2 * M; three collinear points so
 * rounded form a triangle of height at most FLT_EPSILON * M (the apex and the foot of
 * its height on the longest edge each move by at most half of that). A posed cloud's
 * sensor-frame positions are rounded twice (the input, then the transform): twice
 * that. A triangle this flat is consistent with three collinear points, so any normal
 * about its longest edge fits its corners: it is degenerate. Above it, the normal's
 * error from rounding is at most atan(kFlatHeight * FLT_EPSILON * M / h). */
constexpr double kFlatHeight = 2.0;

/** Normal (oriented toward the eye) and area of one triangle; the normal stays NaN
 * when the triangle is degenerate: zero or non-finite area, or flat at float precision
 * (kFlatHeight; its area is still given). Then false; otherwise \a centroid is set. */
inline bool
triangleNormal(const Vector3fVector& positions,
               const Triangle& triangle,
               const Eigen::Vector3d& eye,
               Eigen::Vector3f& normal,
               double& area,
               Eigen::Vector3d& centroid)
{
  const Eigen::Vector3d a = positions[triangle[0]].cast<double>();
  const Eigen::Vector3d b = positions[triangle[1]].cast<double>();
  const Eigen::Vector3d c = positions[triangle[2]].cast<double>();
  const Eigen::Vector3d ab = b - a, ac = c - a; // exact: differences of floats
  Eigen::Vector3d n = ab.cross(ac);
  const double twice_area_squared = n.squaredNorm();
  const double twice_area = std::sqrt(twice_area_squared); // as n.norm()
  area = 0.5 * twice_area;
  if (!(twice_area > 0.0) || !std::isfinite(twice_area))
    return false;
  // h <= k eps M, squared and times L_max^2: (2 A)^2 <= (k eps)^2 M^2 L_max^2. First
  // against a bound of M^2 L_max^2 from two edges and one corner (with s = |ab|^2 +
  // |ac|^2, L_max^2 <= 2 s and M^2 <= 2 |a|^2 + 2 s): most triangles pass it.
  constexpr double k_eps =
      kFlatHeight * static_cast<double>(std::numeric_limits<float>::epsilon());
  constexpr double k_eps_squared = k_eps * k_eps;
  const double ab_squared = ab.squaredNorm(), ac_squared = ac.squaredNorm();
  const double s = ab_squared + ac_squared;
  if (!(twice_area_squared > k_eps_squared * 4.0 * s * (a.squaredNorm() + s))) {
    const double longest_squared =
        std::max(std::max(ab_squared, ac_squared), (c - b).squaredNorm());
    const double farthest_squared =
        std::max(std::max(a.squaredNorm(), b.squaredNorm()), c.squaredNorm());
    if (twice_area_squared <= k_eps_squared * farthest_squared * longest_squared)
      return false;
  }
  n /= twice_area;
  centroid = (a + b + c) / 3.0;
  if (n.dot(centroid - eye) > 0.0)
    n = -n;
  normal = n.cast<float>();
  return true;
}

inline void
triangleNormal(const Vector3fVector& positions,
               const Triangle& triangle,
               const Eigen::Vector3d& eye,
               Eigen::Vector3f& normal,
               double& area)
{
  Eigen::Vector3d centroid;
  triangleNormal(positions, triangle, eye, normal, area, centroid);
}

/** Whether a triangle of this normal and centroid is seen edge-on
 * (markEdgeOnTriangles()). */
inline std::uint8_t
isEdgeOn(const Eigen::Vector3f& normal,
         const Eigen::Vector3d& centroid,
         const Eigen::Vector3d& eye,
         double min_cos)
{
  if (!normal.allFinite())
    return 1;
  const Eigen::Vector3d sight = (centroid - eye).normalized();
  return std::abs(sight.dot(normal.cast<double>())) < min_cos;
}

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
  return isEdgeOn(normal, centroid, eye, min_cos);
}

/** Normal, area and edge-on flag of one triangle, as computeTriangleNormalsAndEdgeOn()
 * gives them (the normal NaN for a degenerate triangle), its corners read and its
 * centroid computed once (the same expressions as the two functions above, so the same
 * values). */
inline void
triangleNormalAndEdgeOn(const Vector3fVector& positions,
                        const Triangle& triangle,
                        const Eigen::Vector3d& eye,
                        double min_cos,
                        Eigen::Vector3f& normal,
                        double& area,
                        std::uint8_t& edge_on)
{
  normal = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  Eigen::Vector3d centroid;
  edge_on = triangleNormal(positions, triangle, eye, normal, area, centroid)
                ? isEdgeOn(normal, centroid, eye, min_cos)
                : 1;
}

/** eq. 2-3 at one vertex over its triangles [begin, end), in that order. */
void
vertexNormal(const pcl::index_t* begin,
             const pcl::index_t* end,
             const Vector3fVector& normals,
             const std::vector<double>& areas,
             Eigen::Vector3f& vertex_normal,
             double& vertex_area)
{
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  vertex_area = 0.0;
  for (const pcl::index_t* it = begin; it != end; ++it) {
    const auto t = *it;
    if (std::isfinite(areas[t]))
      vertex_area += areas[t];                                // eq. 3
    const double weight = normalWeight(areas[t], normals[t]); // eq. 2
    if (weight > 0.0) // degenerate triangles are skipped (NaN normals)
      sum += weight * normals[t].cast<double>();
  }
  vertex_normal = normalizedOrNaN(sum);
}

/** cos of the largest incidence of a surface triangle; 0 disables the test. */
double
minIncidenceCos(double max_incidence)
{
  return max_incidence >= M_PI / 2.0 ? 0.0 : std::cos(max_incidence);
}

/** Whether an incidence angle is usable (>= 0; NaN is not); a PCL_ERROR otherwise. */
bool
incidenceUsable(double max_incidence, const char* where)
{
  if (max_incidence >= 0.0)
    return true;
  PCL_ERROR("[pcl::selective_seg::%s] max_incidence is %g rad: give an angle >= 0 "
            "(pi/2 or more flags only degenerate triangles)\n",
            where,
            max_incidence);
  return false;
}

/** Whether a ring count is usable (>= 1); a PCL_ERROR otherwise. */
bool
ringsUsable(int rings, const char* where)
{
  if (rings >= 1)
    return true;
  PCL_ERROR(
      "[pcl::selective_seg::%s] rings is %d: give 1 (eq. 2) or more\n", where, rings);
  return false;
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
  // The ids and sizes the passes below index with (mesh_checks.h).
  if (!detail::idsBelow(triangles,
                        positions.size(),
                        false,
                        "computeTriangleNormals",
                        "the triangles",
                        num_threads)) {
    normals.clear();
    areas.clear();
    return;
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  detail::assignLarge(normals, triangles.size(), Eigen::Vector3f::Constant(nan));
  detail::assignLarge(areas, triangles.size(), 0.0);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  const auto n_tri = static_cast<std::ptrdiff_t>(triangles.size());
#pragma omp parallel for num_threads(threadCount(num_threads)) schedule(static)
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
  // The ids and sizes the passes below index with (mesh_checks.h).
  const char* where = "computeTriangleNormalsAndEdgeOn";
  if (!detail::idsBelow(
          triangles, positions.size(), false, where, "the triangles", num_threads) ||
      !incidenceUsable(max_incidence, where)) {
    normals.clear();
    areas.clear();
    edge_on.clear();
    return;
  }
  // Every entry is written below.
  detail::resizeLarge(normals, triangles.size());
  detail::resizeLarge(areas, triangles.size());
  detail::resizeLarge(edge_on, triangles.size());
  const double min_cos = minIncidenceCos(max_incidence);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  const auto n_tri = static_cast<std::ptrdiff_t>(triangles.size());
#pragma omp parallel for num_threads(threadCount(num_threads)) schedule(dynamic, 1024)
  for (std::ptrdiff_t t = 0; t < n_tri; ++t)
    triangleNormalAndEdgeOn(
        positions, triangles[t], eye, min_cos, normals[t], areas[t], edge_on[t]);
}

void
updateTriangleNormalsAndEdgeOn(const Vector3fVector& positions,
                               const std::vector<Triangle>& triangles,
                               const Eigen::Vector3f& viewpoint,
                               double max_incidence,
                               const std::vector<pcl::index_t>& old_to_new,
                               const std::vector<pcl::index_t>& changed,
                               Vector3fVector& normals,
                               std::vector<double>& areas,
                               std::vector<std::uint8_t>& edge_on,
                               int num_threads)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  const char* where = "updateTriangleNormalsAndEdgeOn";
  if (!detail::idsBelow(
          triangles, positions.size(), false, where, "the triangles", num_threads) ||
      !detail::idsBelow(
          old_to_new, triangles.size(), true, where, "old_to_new", num_threads) ||
      !detail::idsBelow(
          changed, triangles.size(), false, where, "changed", num_threads))
    return; // the arrays as they were
  // The old arrays: one entry per old triangle.
  const std::size_t n_old_triangles = old_to_new.size();
  if (!incidenceUsable(max_incidence, where) ||
      !detail::sizeIs(normals.size(), n_old_triangles, where, "the old normals") ||
      !detail::sizeIs(areas.size(), n_old_triangles, where, "the old areas") ||
      !detail::sizeIs(edge_on.size(), n_old_triangles, where, "the old edge-on flags"))
    return; // the arrays as they were
  const std::size_t n_new = triangles.size();
  Vector3fVector new_normals(n_new);
  std::vector<double> new_areas(n_new);
  std::vector<std::uint8_t> new_edge_on(n_new);
  const auto n_old = static_cast<std::ptrdiff_t>(old_to_new.size());
#pragma omp parallel for num_threads(threadCount(num_threads))                         \
    schedule(static) if (old_to_new.size() >= detail::kMinParallelItems)
  for (std::ptrdiff_t k = 0; k < n_old; ++k) {
    const pcl::index_t t = old_to_new[k];
    if (t < 0)
      continue;
    new_normals[t] = normals[k];
    new_areas[t] = areas[k];
    new_edge_on[t] = edge_on[k];
  }
  const double min_cos = minIncidenceCos(max_incidence);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  const auto n_changed = static_cast<std::ptrdiff_t>(changed.size());
#pragma omp parallel for num_threads(threadCount(num_threads))                         \
    schedule(dynamic, 1024) if (changed.size() >= detail::kMinParallelItems)
  for (std::ptrdiff_t k = 0; k < n_changed; ++k) {
    const pcl::index_t t = changed[k];
    triangleNormalAndEdgeOn(positions,
                            triangles[t],
                            eye,
                            min_cos,
                            new_normals[t],
                            new_areas[t],
                            new_edge_on[t]);
  }
  normals.swap(new_normals);
  areas.swap(new_areas);
  edge_on.swap(new_edge_on);
}

namespace {

/** Smallest vertex of a triangle. */
inline pcl::index_t
lowestVertex(const Triangle& t)
{
  return std::min(t[0], std::min(t[1], t[2]));
}

void
starOf(pcl::index_t v,
       pcl::index_t first,
       const std::vector<Triangle>& triangles,
       const std::vector<Triangle>& neighbours,
       std::vector<pcl::index_t>& star);

/** Eq. 2-3 at each of the distinct \a vertices over all its triangles, found by one
 * pass over the mesh and each listed once per corner at the vertex, in increasing order
 * (as the gather of computeVertexNormals() sums them): \a out_normals[k] and \a
 * out_areas[k] are those of vertices[k]. */
void
vertexNormalsOverTheMesh(const std::vector<pcl::index_t>& vertices,
                         std::size_t num_vertices,
                         const std::vector<Triangle>& triangles,
                         const Vector3fVector& normals,
                         const std::vector<double>& areas,
                         Vector3fVector& out_normals,
                         std::vector<double>& out_areas)
{
  std::vector<pcl::index_t> slot(num_vertices, -1);
  for (std::size_t k = 0; k < vertices.size(); ++k)
    slot[vertices[k]] = static_cast<pcl::index_t>(k);
  std::vector<std::vector<pcl::index_t>> lists(vertices.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const auto v : triangles[t])
      if (slot[v] >= 0)
        lists[slot[v]].push_back(static_cast<pcl::index_t>(t));
  out_normals.resize(vertices.size());
  out_areas.resize(vertices.size());
  for (std::size_t k = 0; k < vertices.size(); ++k)
    vertexNormal(lists[k].data(),
                 lists[k].data() + lists[k].size(),
                 normals,
                 areas,
                 out_normals[k],
                 out_areas[k]);
}

/** Eq. 2-3 again at each vertex of \a seeds ((vertex, one of its triangles) pairs, a
 * vertex possibly listed several times), summed over its star in increasing order as
 * computeVertexNormals() sums it. With \a incidence (the number of triangle corners at
 * each seed vertex), a vertex whose walked star holds fewer triangles (a vertex where
 * separate fans meet, or a triangle with a repeated corner) is summed over its
 * triangles found by one pass over the mesh instead. */
void
recomputeOverStars(std::vector<std::pair<pcl::index_t, pcl::index_t>>& seeds,
                   const std::vector<Triangle>& triangles,
                   const std::vector<Triangle>& neighbours,
                   const Vector3fVector& normals,
                   const std::vector<double>& areas,
                   Vector3fVector& vertex_normals,
                   std::vector<double>& vertex_areas,
                   int num_threads,
                   const std::vector<pcl::index_t>* incidence = nullptr)
{
  // Each vertex once, with the first triangle listed for it: the star and its sum do
  // not depend on the triangle the walk starts from (starOf() sorts the star).
  {
    std::vector<std::uint8_t> listed(vertex_normals.size(), 0);
    std::size_t kept = 0;
    for (const auto& seed : seeds)
      if (!listed[seed.first]) {
        listed[seed.first] = 1;
        seeds[kept++] = seed;
      }
    seeds.resize(kept);
  }
  const auto num_seeds = static_cast<std::ptrdiff_t>(seeds.size());
  std::vector<std::uint8_t> partial(incidence ? seeds.size() : 0, 0);
  detail::ParallelExceptions errors;
#pragma omp parallel num_threads(num_threads)
  {
    std::vector<pcl::index_t> star;
#pragma omp for schedule(static)
    for (std::ptrdiff_t k = 0; k < num_seeds; ++k)
      errors.run([&] {
        const pcl::index_t v = seeds[k].first;
        starOf(v, seeds[k].second, triangles, neighbours, star);
        if (incidence && static_cast<std::size_t>((*incidence)[v]) != star.size()) {
          partial[k] = 1;
          return;
        }
        vertexNormal(star.data(),
                     star.data() + star.size(),
                     normals,
                     areas,
                     vertex_normals[v],
                     vertex_areas[v]);
      });
  }
  errors.rethrow();
  if (std::find(partial.begin(), partial.end(), 1) == partial.end())
    return;
  // The vertices the walk did not get around, over their triangles from the mesh.
  std::vector<pcl::index_t> unwalked;
  for (std::size_t k = 0; k < seeds.size(); ++k)
    if (partial[k])
      unwalked.push_back(seeds[k].first);
  Vector3fVector sums;
  std::vector<double> sum_areas;
  vertexNormalsOverTheMesh(
      unwalked, vertex_normals.size(), triangles, normals, areas, sums, sum_areas);
  for (std::size_t k = 0; k < unwalked.size(); ++k) {
    vertex_normals[unwalked[k]] = sums[k];
    vertex_areas[unwalked[k]] = sum_areas[k];
  }
}

/** computeVertexNormals() by adding each triangle's terms (eq. 2-3) to its vertices, in
 * increasing triangle order: the same sums, in the same order, as the gather over each
 * vertex's triangles. On one thread that holds for any triangle order. With the
 * adjacency, the triangles are split into one run per thread: each thread adds straight
 * to the vertices it alone reaches, and a vertex that an earlier run also reaches is
 * left for the end, when its sum is redone over its whole star, in increasing order
 * (over all its triangles when its star misses some: separate fans meeting at the
 * vertex).
 *
 * Run c starts at triangle b_c with smallest vertex m_c. If every triangle of runs c >=
 * 1 has its smallest vertex at least m_c and m_1 <= m_2 <= ... (true of delaunay2d()'s
 * canonical order), run c adds directly to the vertices below m_(c+1), which no later
 * run reaches, and defers the others; a vertex at or above m_c that an earlier run
 * reaches is deferred by that run. False, with the outputs unspecified, if the
 * triangles break that condition or a large mesh comes without its adjacency (then the
 * gather does the work on all threads). */
bool
scatterVertexNormals(std::size_t num_vertices,
                     const std::vector<Triangle>& triangles,
                     const std::vector<Triangle>* neighbours,
                     const Vector3fVector& normals,
                     const std::vector<double>& areas,
                     Vector3fVector& vertex_normals,
                     std::vector<double>& vertex_areas,
                     int num_threads)
{
  const std::size_t num_triangles = triangles.size();
  const bool parallel = num_threads > 1 && num_triangles >= detail::kMinParallelItems;
  if (parallel && !neighbours)
    return false; // the gather runs on all threads
  const auto runs = static_cast<std::size_t>(parallel ? num_threads : 1);
  // Only the bounds between runs are read: a mesh without triangles (one run) has no
  // triangle to look at.
  std::vector<pcl::index_t> run_lowest(runs + 1, 0);
  for (std::size_t c = 1; c < runs; ++c)
    run_lowest[c] = lowestVertex(triangles[c * num_triangles / runs]);
  run_lowest[runs] = static_cast<pcl::index_t>(num_vertices);
  for (std::size_t c = 2; c < runs; ++c)
    if (run_lowest[c] < run_lowest[c - 1])
      return false;
  std::vector<Eigen::Vector3d> sums;
  detail::assignLarge(sums, num_vertices, Eigen::Vector3d::Zero());
  detail::assignLarge(vertex_areas, num_vertices, 0.0);
  std::vector<std::vector<std::pair<pcl::index_t, pcl::index_t>>> deferred(runs);
  // With several runs, the corners each vertex gets directly; with its deferred corners
  // they tell whether the walk around a deferred vertex finds all its triangles.
  std::vector<pcl::index_t> corners;
  detail::assignLarge(corners, runs > 1 ? num_vertices : 0, 0);
  pcl::index_t* const direct = runs > 1 ? corners.data() : nullptr;
  std::vector<char> out_of_order(runs, 0);
  detail::ParallelExceptions errors;
#pragma omp parallel for num_threads(static_cast<int>(runs)) schedule(static, 1)
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(runs); ++c)
    errors.run([&] {
      const pcl::index_t upper = run_lowest[c + 1];
      for (std::size_t t = c * num_triangles / runs; t < (c + 1) * num_triangles / runs;
           ++t) {
        if (c > 0 && lowestVertex(triangles[t]) < run_lowest[c]) {
          out_of_order[c] = 1;
          return;
        }
        const bool finite_area = std::isfinite(areas[t]);
        const double weight = normalWeight(areas[t], normals[t]);
        const Eigen::Vector3d term = weight * normals[t].cast<double>();
        for (const auto v : triangles[t]) {
          if (v >= upper) {
            deferred[c].emplace_back(v, static_cast<pcl::index_t>(t));
            continue;
          }
          if (finite_area)
            vertex_areas[v] += areas[t];
          if (weight > 0.0)
            sums[v] += term;
          if (direct)
            ++direct[v];
        }
      }
    });
  errors.rethrow();
  if (std::find(out_of_order.begin(), out_of_order.end(), 1) != out_of_order.end())
    return false;
  detail::resizeLarge(vertex_normals, num_vertices);
#pragma omp parallel for num_threads(static_cast<int>(runs)) schedule(static)
  for (std::ptrdiff_t v = 0; v < static_cast<std::ptrdiff_t>(num_vertices); ++v)
    vertex_normals[v] = normalizedOrNaN(sums[v]);
  // The deferred vertices, each once, over their stars (none with one run).
  std::vector<std::pair<pcl::index_t, pcl::index_t>> redo;
  for (const auto& run : deferred)
    redo.insert(redo.end(), run.begin(), run.end());
  for (const auto& seed : redo)
    ++corners[seed.first];
  if (!redo.empty())
    recomputeOverStars(redo,
                       triangles,
                       *neighbours,
                       normals,
                       areas,
                       vertex_normals,
                       vertex_areas,
                       static_cast<int>(runs),
                       &corners);
  return true;
}

} // namespace

void
computeVertexNormals(std::size_t num_vertices,
                     const std::vector<Triangle>& triangles,
                     const Vector3fVector& normals,
                     const std::vector<double>& areas,
                     Vector3fVector& vertex_normals,
                     std::vector<double>& vertex_areas,
                     int num_threads,
                     const std::vector<Triangle>* neighbours)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  const char* where = "computeVertexNormals";
  if (!detail::trianglesWithValuesFit(
          triangles, num_vertices, normals.size(), areas.size(), where, num_threads) ||
      (neighbours && neighbours->size() == triangles.size() &&
       !detail::idsBelow(
           *neighbours, triangles.size(), true, where, "neighbours", num_threads))) {
    vertex_normals.clear();
    vertex_areas.clear();
    return;
  }
  const bool adjacency = neighbours && neighbours->size() == triangles.size();
  if (scatterVertexNormals(num_vertices,
                           triangles,
                           adjacency ? neighbours : nullptr,
                           normals,
                           areas,
                           vertex_normals,
                           vertex_areas,
                           threadCount(num_threads)))
    return;
  // Gathered per vertex over its triangles in increasing order: the same sums, in the
  // same order, whatever the number of threads.
  const Incidence incident =
      vertexTriangles(triangles, num_vertices, threadCount(num_threads));
  detail::assignLarge(vertex_areas, num_vertices, 0.0);
  detail::resizeLarge(vertex_normals, num_vertices);
#pragma omp parallel for num_threads(threadCount(num_threads)) schedule(static)
  for (std::ptrdiff_t v = 0; v < static_cast<std::ptrdiff_t>(num_vertices); ++v)
    vertexNormal(incident.items.data() + incident.offsets[v],
                 incident.items.data() + incident.offsets[v + 1],
                 normals,
                 areas,
                 vertex_normals[v],
                 vertex_areas[v]);
}

namespace {

/** The k-ring normal of eq. 2, vertex by vertex: triangles met breadth first, ring by
 * ring, each vertex's triangles taken in increasing order (incident(v, list) fills
 * them), so the sum has the same order however the incidence is obtained. Stamps mark
 * the vertices and triangles already met for the current vertex p (stamp p + 1). */
class RingNormals {
public:
  RingNormals(const std::vector<Triangle>& triangles,
              const Vector3fVector& normals,
              const std::vector<double>& areas,
              std::size_t num_vertices,
              int rings)
  : triangles_(triangles)
  , normals_(normals)
  , areas_(areas)
  , rings_(rings)
  , vertex_stamp_(num_vertices, 0)
  , triangle_stamp_(triangles.size(), 0)
  {}

  template <typename Incident>
  Eigen::Vector3f at(pcl::index_t p, Incident incident)
  {
    const std::size_t stamp = static_cast<std::size_t>(p) + 1;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    frontier_.assign(1, p);
    vertex_stamp_[p] = stamp;
    for (int ring = 0; ring < rings_ && !frontier_.empty(); ++ring) {
      next_.clear();
      for (const auto v : frontier_) {
        incident(v, around_);
        for (const auto t : around_) {
          if (triangle_stamp_[t] == stamp)
            continue;
          triangle_stamp_[t] = stamp;
          const double weight = normalWeight(areas_[t], normals_[t]);
          if (weight > 0.0)
            sum += weight * normals_[t].cast<double>();
          for (const auto u : triangles_[t])
            if (vertex_stamp_[u] != stamp) {
              vertex_stamp_[u] = stamp;
              next_.push_back(u);
            }
        }
      }
      frontier_.swap(next_);
    }
    return normalizedOrNaN(sum);
  }

private:
  const std::vector<Triangle>& triangles_;
  const Vector3fVector& normals_;
  const std::vector<double>& areas_;
  int rings_;
  std::vector<std::size_t> vertex_stamp_, triangle_stamp_;
  std::vector<pcl::index_t> frontier_, next_, around_;
};

/** The triangles around vertex v, in increasing order, found by walking the adjacency
 * from one of them (\a first) both ways. */
void
starOf(pcl::index_t v,
       pcl::index_t first,
       const std::vector<Triangle>& triangles,
       const std::vector<Triangle>& neighbours,
       std::vector<pcl::index_t>& star)
{
  star.assign(1, first);
  for (int way = 1; way <= 2; ++way) {
    pcl::index_t t = first;
    for (std::size_t guard = 0; guard < triangles.size(); ++guard) {
      const Triangle& tri = triangles[t];
      const int j = tri[0] == v ? 0 : (tri[1] == v ? 1 : 2);
      t = neighbours[t][(j + way) % 3];
      if (t < 0 || t == first)
        break;
      star.push_back(t);
    }
    if (t == first)
      break; // around an interior vertex: one way is enough
  }
  std::sort(star.begin(), star.end());
  // Around a non-manifold edge the two walks can meet the same triangle.
  star.erase(std::unique(star.begin(), star.end()), star.end());
}

} // namespace

void
computeVertexNormalsOverRings(std::size_t num_vertices,
                              const std::vector<Triangle>& triangles,
                              const Vector3fVector& normals,
                              const std::vector<double>& areas,
                              int rings,
                              Vector3fVector& vertex_normals)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  const char* where = "computeVertexNormalsOverRings";
  if (!detail::trianglesWithValuesFit(
          triangles, num_vertices, normals.size(), areas.size(), where) ||
      !ringsUsable(rings, where)) {
    vertex_normals.clear();
    return;
  }
  const Incidence incident = vertexTriangles(triangles, num_vertices);
  const auto list = [&](pcl::index_t v, std::vector<pcl::index_t>& out) {
    out.assign(incident.items.begin() + incident.offsets[v],
               incident.items.begin() + incident.offsets[v + 1]);
  };
  RingNormals ring_normals(triangles, normals, areas, num_vertices, rings);
  vertex_normals.resize(num_vertices);
  for (std::size_t p = 0; p < num_vertices; ++p)
    vertex_normals[p] = ring_normals.at(static_cast<pcl::index_t>(p), list);
}

void
updateVertexNormalsOverRings(const std::vector<Triangle>& triangles,
                             const std::vector<Triangle>& neighbours,
                             const Vector3fVector& normals,
                             const std::vector<double>& areas,
                             int rings,
                             const std::vector<pcl::index_t>& changed_triangles,
                             Vector3fVector& vertex_normals)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  const char* where = "updateVertexNormalsOverRings";
  if (!detail::trianglesWithValuesFit(
          triangles, vertex_normals.size(), normals.size(), areas.size(), where) ||
      !detail::sizeIs(neighbours.size(), triangles.size(), where, "neighbours") ||
      !detail::idsBelow(neighbours, triangles.size(), true, where, "neighbours") ||
      !detail::idsBelow(
          changed_triangles, triangles.size(), false, where, "changed_triangles"))
    return; // the normals as they were
  if (!ringsUsable(rings, where))
    return; // the normals as they were
  // One triangle at each vertex met, for the walks around it.
  const std::size_t num_vertices = vertex_normals.size();
  std::vector<pcl::index_t> some_triangle(num_vertices, -1);
  std::vector<pcl::index_t> affected, frontier, next, star;
  for (const auto t : changed_triangles)
    for (const auto v : triangles[t])
      if (some_triangle[v] < 0) {
        some_triangle[v] = t;
        frontier.push_back(v);
      }
  affected = frontier;
  // A vertex's k-ring normal sums the triangles at its (k - 1)-ring: those within k - 1
  // rings of a changed triangle's corner are affected.
  for (int ring = 1; ring < rings && !frontier.empty(); ++ring) {
    next.clear();
    for (const auto v : frontier) {
      starOf(v, some_triangle[v], triangles, neighbours, star);
      for (const auto t : star)
        for (const auto u : triangles[t])
          if (some_triangle[u] < 0) {
            some_triangle[u] = t;
            next.push_back(u);
          }
    }
    affected.insert(affected.end(), next.begin(), next.end());
    frontier.swap(next);
  }
  // The walks reach one ring beyond the affected vertices: remember a triangle there.
  const auto list = [&](pcl::index_t v, std::vector<pcl::index_t>& out) {
    starOf(v, some_triangle[v], triangles, neighbours, out);
    for (const auto t : out)
      for (const auto u : triangles[t])
        if (some_triangle[u] < 0)
          some_triangle[u] = t;
  };
  RingNormals ring_normals(triangles, normals, areas, num_vertices, rings);
  std::sort(affected.begin(), affected.end());
  for (const auto p : affected)
    vertex_normals[p] = ring_normals.at(p, list);
}

void
maskEdgeOnNormals(const Vector3fVector& normals,
                  const std::vector<std::uint8_t>& edge_on,
                  Vector3fVector& masked,
                  int num_threads)
{
  if (!detail::sizeIs(edge_on.size(), normals.size(), "maskEdgeOnNormals", "edge_on")) {
    masked.clear();
    return;
  }
  const Eigen::Vector3f nan =
      Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  detail::resizeLarge(masked, normals.size());
  const auto n_tri = static_cast<std::ptrdiff_t>(normals.size());
#pragma omp parallel for num_threads(threadCount(num_threads))                         \
    schedule(static) if (normals.size() >= detail::kMinParallelItems)
  for (std::ptrdiff_t t = 0; t < n_tri; ++t)
    masked[t] = edge_on[t] ? nan : normals[t];
}

std::size_t
fillMissingVertexNormals(const std::vector<Triangle>& triangles,
                         const Vector3fVector& normals,
                         const std::vector<double>& areas,
                         int rings,
                         Vector3fVector& vertex_normals,
                         int num_threads)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  const char* where = "fillMissingVertexNormals";
  if (!detail::trianglesWithValuesFit(triangles,
                                      vertex_normals.size(),
                                      normals.size(),
                                      areas.size(),
                                      where,
                                      num_threads))
    return 0; // the normals as they were
  if (!ringsUsable(rings, where))
    return 0; // the normals as they were
  const std::size_t num_vertices = vertex_normals.size();
  std::vector<pcl::index_t> missing;
  for (std::size_t v = 0; v < num_vertices; ++v)
    if (!vertex_normals[v].allFinite())
      missing.push_back(static_cast<pcl::index_t>(v));
  if (missing.empty())
    return 0;
  std::size_t filled = 0;
  const auto give = [&](pcl::index_t v, const Eigen::Vector3f& normal) {
    if (normal.allFinite()) {
      vertex_normals[v] = normal;
      ++filled;
    }
  };
  if (rings > 1) {
    // The k-ring sums walk beyond the missing vertices: the whole incidence.
    const Incidence incident =
        vertexTriangles(triangles, num_vertices, threadCount(num_threads));
    const auto list = [&](pcl::index_t v, std::vector<pcl::index_t>& out) {
      out.assign(incident.items.begin() + incident.offsets[v],
                 incident.items.begin() + incident.offsets[v + 1]);
    };
    RingNormals ring_normals(triangles, normals, areas, num_vertices, rings);
    for (const auto v : missing)
      give(v, ring_normals.at(v, list));
    return filled;
  }
  // One ring: the missing vertices' own triangles, from one pass over the mesh.
  Vector3fVector sums;
  std::vector<double> sum_areas;
  vertexNormalsOverTheMesh(
      missing, num_vertices, triangles, normals, areas, sums, sum_areas);
  for (std::size_t k = 0; k < missing.size(); ++k)
    give(missing[k], sums[k]);
  return filled;
}

void
computeTriangleNormalsFromVertices(const std::vector<Triangle>& triangles,
                                   const Vector3fVector& vertex_normals,
                                   Vector3fVector& normals)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  if (!detail::idsBelow(triangles,
                        vertex_normals.size(),
                        false,
                        "computeTriangleNormalsFromVertices",
                        "the triangles")) {
    normals.clear();
    return;
  }
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
  // The ids and sizes the passes below index with (mesh_checks.h).
  if (!detail::idsBelow(triangles,
                        positions.size(),
                        false,
                        "markEdgeOnTriangles",
                        "the triangles",
                        num_threads) ||
      !detail::sizeIs(
          normals.size(), triangles.size(), "markEdgeOnTriangles", "normals") ||
      !incidenceUsable(max_incidence, "markEdgeOnTriangles")) {
    edge_on.clear();
    return;
  }
  detail::assignLarge(edge_on, triangles.size(), 0);
  const double min_cos = minIncidenceCos(max_incidence);
  const Eigen::Vector3d eye = viewpoint.cast<double>();
  const auto n_tri = static_cast<std::ptrdiff_t>(triangles.size());
#pragma omp parallel for num_threads(threadCount(num_threads)) schedule(static)
  for (std::ptrdiff_t t = 0; t < n_tri; ++t)
    edge_on[t] = isEdgeOn(positions, triangles[t], normals[t], eye, min_cos);
}

void
updateVertexNormals(const std::vector<Triangle>& triangles,
                    const std::vector<Triangle>& neighbours,
                    const Vector3fVector& normals,
                    const std::vector<double>& areas,
                    const std::vector<pcl::index_t>& changed_triangles,
                    Vector3fVector& vertex_normals,
                    std::vector<double>& vertex_areas,
                    int num_threads)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  const char* where = "updateVertexNormals";
  if (!detail::trianglesWithValuesFit(triangles,
                                      vertex_normals.size(),
                                      normals.size(),
                                      areas.size(),
                                      where,
                                      num_threads) ||
      !detail::sizeIs(
          vertex_areas.size(), vertex_normals.size(), where, "vertex_areas") ||
      !detail::sizeIs(neighbours.size(), triangles.size(), where, "neighbours") ||
      !detail::idsBelow(
          neighbours, triangles.size(), true, where, "neighbours", num_threads) ||
      !detail::idsBelow(
          changed_triangles, triangles.size(), false, where, "changed_triangles"))
    return; // the normals as they were
  // The vertices of the changed triangles, each with one of them.
  std::vector<std::pair<pcl::index_t, pcl::index_t>> touched; // (vertex, triangle)
  touched.reserve(3 * changed_triangles.size());
  for (const auto t : changed_triangles)
    for (const auto v : triangles[t])
      touched.emplace_back(v, t);
  recomputeOverStars(touched,
                     triangles,
                     neighbours,
                     normals,
                     areas,
                     vertex_normals,
                     vertex_areas,
                     threadCount(num_threads));
}

double
medianEdgeLength(const Vector3fVector& positions,
                 const std::vector<Triangle>& triangles,
                 int num_threads)
{
  // The ids and sizes the passes below index with (mesh_checks.h).
  if (!detail::idsBelow(triangles,
                        positions.size(),
                        false,
                        "medianEdgeLength",
                        "the triangles",
                        num_threads))
    return std::numeric_limits<double>::quiet_NaN();
  if (triangles.empty())
    return 0.0;
  // Large meshes: every stride-th triangle (a fixed function of the canonical triangle
  // order) still gives over 300,000 edges, plenty for a median.
  const std::size_t stride = std::max<std::size_t>(1, triangles.size() / 100000);
  const std::ptrdiff_t sampled =
      static_cast<std::ptrdiff_t>((triangles.size() + stride - 1) / stride);
  // The median of the squared lengths, then one square root: sqrt is monotone and
  // correctly rounded, and Eigen's norm() is sqrt(squaredNorm()), so this is the
  // median of the lengths to the bit.
  // Every entry is written below: no zero fill.
  const std::size_t num_squares = 3 * static_cast<std::size_t>(sampled);
  const std::unique_ptr<double[]> squares(new double[num_squares]);
  detail::adviseHugePages(squares.get(), num_squares * sizeof(double));
  // Squares are non-negative, so their bit patterns order as they do: the range of the
  // patterns, then a histogram over it, finds the bucket that holds the element of rank
  // n / 2, and only that bucket is partitioned.
  const auto bits = [](double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  };
  std::uint64_t lowest = std::numeric_limits<std::uint64_t>::max(), highest = 0;
  const bool parallel = static_cast<std::size_t>(sampled) >= detail::kMinParallelItems;
  const int num_parts = parallel ? threadCount(num_threads) : 1;
#ifdef _OPENMP
  // clang-format would break the reduction clauses apart.
  // clang-format off
#pragma omp parallel for num_threads(num_parts) schedule(static) if (parallel) \
    reduction(min : lowest) reduction(max : highest)
  // clang-format on
#endif
  for (std::ptrdiff_t j = 0; j < sampled; ++j) {
    const Triangle& t = triangles[static_cast<std::size_t>(j) * stride];
    for (int i = 0; i < 3; ++i) {
      const double square =
          (positions[t[i]].cast<double>() - positions[t[(i + 1) % 3]].cast<double>())
              .squaredNorm();
      squares[3 * j + i] = square;
      lowest = std::min(lowest, bits(square));
      highest = std::max(highest, bits(square));
    }
  }
  // kBuckets buckets over [lowest, highest]; a histogram per thread, then their sum.
  constexpr std::size_t kBuckets = 4096;
  int shift = 0;
  while (((highest - lowest) >> shift) >= kBuckets)
    ++shift;
  const auto bucketOf = [&](double v) { return (bits(v) - lowest) >> shift; };
  const std::size_t rank = num_squares / 2;
  std::vector<std::uint32_t> histograms(kBuckets * static_cast<std::size_t>(num_parts),
                                        0);
#ifdef _OPENMP
#pragma omp parallel num_threads(num_parts) if (parallel)
#endif
  {
#ifdef _OPENMP
    std::uint32_t* histogram = histograms.data() + kBuckets * omp_get_thread_num();
#pragma omp for schedule(static)
#else
    std::uint32_t* histogram = histograms.data();
#endif
    for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(num_squares); ++k)
      ++histogram[bucketOf(squares[k])];
  }
  for (int p = 1; p < num_parts; ++p)
    for (std::size_t b = 0; b < kBuckets; ++b)
      histograms[b] += histograms[kBuckets * static_cast<std::size_t>(p) + b];
  std::size_t below = 0;
  std::uint64_t bucket = 0;
  while (below + histograms[bucket] <= rank)
    below += histograms[bucket++];
  // The bucket's values, in any order (the value of a rank does not depend on it).
  std::vector<double> candidates;
  candidates.reserve(histograms[bucket]); // the insertions below do not allocate
  detail::ParallelExceptions errors;
#ifdef _OPENMP
#pragma omp parallel num_threads(num_parts) if (parallel)
#endif
  {
    std::vector<double> mine;
#ifdef _OPENMP
#pragma omp for schedule(static) nowait
#endif
    for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(num_squares); ++k)
      if (bucketOf(squares[k]) == bucket)
        errors.run([&] { mine.push_back(squares[k]); });
#ifdef _OPENMP
#pragma omp critical(selseg_median_candidates)
#endif
    candidates.insert(candidates.end(), mine.begin(), mine.end());
  }
  errors.rethrow();
  const auto middle = candidates.begin() + static_cast<std::ptrdiff_t>(rank - below);
  std::nth_element(candidates.begin(), middle, candidates.end());
  return std::sqrt(*middle);
}

} // namespace selective_seg
} // namespace pcl
