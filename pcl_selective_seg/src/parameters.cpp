/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/parameters.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "parameter_checks.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl {
namespace selective_seg {

namespace detail {
namespace {
thread_local bool mesh_trusted = false;
} // namespace

TrustedMeshScope::TrustedMeshScope() noexcept
    : previous_(mesh_trusted)
{
  mesh_trusted = true;
}

TrustedMeshScope::~TrustedMeshScope()
{
  mesh_trusted = previous_;
}

bool
meshTrusted() noexcept
{
  return mesh_trusted;
}
} // namespace detail

unsigned int
defaultThreads()
{
#ifdef _OPENMP
  // Inside a caller's parallel region that cannot nest, a new team has one thread.
  if (omp_get_active_level() >= omp_get_max_active_levels())
    return 1u;
  return static_cast<unsigned int>(std::max(1, omp_get_max_threads()));
#else
  return 1u;
#endif
}

namespace {

bool
reject(std::string* why, const char* name, double value, const char* range)
{
  return detail::rejectParameter(why, name, value, range);
}

bool
inRange(double v, double lo, double hi)
{
  return std::isfinite(v) && v >= lo && v <= hi;
}

} // namespace

bool
SelectiveSegmentationParameters::validate(std::string* why) const
{
  if (!inRange(max_normal_std_dev, 0.0, M_PI) || max_normal_std_dev == 0.0)
    return reject(why, "max_normal_std_dev [rad]", max_normal_std_dev, "(0, pi]");
  if (!inRange(max_merge_angle, 0.0, M_PI))
    return reject(why, "max_merge_angle [rad]", max_merge_angle, "[0, pi]");
  if (!inRange(max_edge_triangle_angle, 0.0, M_PI))
    return reject(
        why, "max_edge_triangle_angle [rad]", max_edge_triangle_angle, "[0, pi]");
  if (!inRange(max_view_incidence_angle, 0.0, M_PI / 2.0) ||
      max_view_incidence_angle == 0.0)
    return reject(
        why, "max_view_incidence_angle [rad]", max_view_incidence_angle, "(0, pi/2]");
  if (normal_rings < 1 || normal_rings > 10)
    return reject(why, "normal_rings", normal_rings, "[1, 10]");
  if (!std::isfinite(min_voxel_size) || min_voxel_size < 0.0)
    return reject(why, "min_voxel_size [m]", min_voxel_size, "0 (automatic) or > 0");
  if (!inRange(min_voxel_size_factor, 0.5, 1000.0))
    return reject(why, "min_voxel_size_factor", min_voxel_size_factor, "[0.5, 1000]");
  if (min_points_to_split < 2)
    return reject(why, "min_points_to_split", min_points_to_split, ">= 2");
  if (max_octree_depth < 1 || max_octree_depth > 21)
    return reject(why, "max_octree_depth", max_octree_depth, "[1, 21]");
  if (!inRange(angle_quantization, 2.5e-8, 1e-2))
    return reject(
        why, "angle_quantization [rad]", angle_quantization, "[2.5e-8, 1e-2]");
  if (num_threads < 0 || num_threads > detail::kMaxThreads)
    return reject(why, "num_threads", num_threads, "[0, 1024], 0 = automatic");
  if (edge_triangle_normal != EdgeTriangleNormal::Facet &&
      edge_triangle_normal != EdgeTriangleNormal::VertexMean)
    return reject(why,
                  "edge_triangle_normal",
                  static_cast<int>(edge_triangle_normal),
                  "facet or vertex_mean (EdgeTriangleNormal 0 or 1)");
  if (segment_normal_weight != SegmentNormalWeight::InverseArea &&
      segment_normal_weight != SegmentNormalWeight::Area)
    return reject(why,
                  "segment_normal_weight",
                  static_cast<int>(segment_normal_weight),
                  "inverse_area or area (SegmentNormalWeight 0 or 1)");
  if (merge_with != MergeWith::Seeds && merge_with != MergeWith::Segments)
    return reject(why,
                  "merge_with",
                  static_cast<int>(merge_with),
                  "seeds or segments (MergeWith 0 or 1)");
  if (point_normal_triangles != PointNormalTriangles::All &&
      point_normal_triangles != PointNormalTriangles::NotEdgeOn)
    return reject(why,
                  "point_normal_triangles",
                  static_cast<int>(point_normal_triangles),
                  "all or not_edge_on (PointNormalTriangles 0 or 1)");
  if (normal_spread_frame != NormalSpreadFrame::Sensor &&
      normal_spread_frame != NormalSpreadFrame::MeanNormal)
    return reject(why,
                  "normal_spread_frame",
                  static_cast<int>(normal_spread_frame),
                  "sensor or mean_normal (NormalSpreadFrame 0 or 1)");
  if (delaunay_backend != DelaunayBackend::BoostVoronoi &&
      delaunay_backend != DelaunayBackend::Vtk &&
      delaunay_backend != DelaunayBackend::Sweep)
    return reject(why,
                  "delaunay_backend",
                  static_cast<int>(delaunay_backend),
                  isDelaunayBackendAvailable(DelaunayBackend::Vtk)
                      ? "sweep, boost or vtk (DelaunayBackend 2, 0 or 1)"
                      : "sweep, boost (DelaunayBackend 2, 0; vtk needs a build with VTK)");
  if (projection != ViewProjection::Forward && projection != ViewProjection::Panoramic)
    return reject(why,
                  "projection",
                  static_cast<int>(projection),
                  "forward or panoramic (ViewProjection 0 or 1)");
  if (projection == ViewProjection::Panoramic) {
    if (angle_quantization < 1e-7)
      return reject(why,
                    "angle_quantization [rad]",
                    angle_quantization,
                    "[1e-7, 1e-2] with the panoramic projection");
    if (normal_spread_frame != NormalSpreadFrame::MeanNormal) {
      if (why)
        *why =
            "parameter normal_spread_frame = sensor cannot go with the panoramic "
            "projection: eq. 5's sensor-frame angles are ill-conditioned for normals "
            "perpendicular to the optical axis, which a panorama's walls, floor and "
            "ceiling have all around; set normal_spread_frame = mean_normal";
      return false;
    }
    if (delaunay_backend == DelaunayBackend::Vtk) {
      if (why)
        *why = "parameter delaunay_backend = vtk cannot triangulate the panoramic "
               "projection: use sweep or boost (exact backends)";
      return false;
    }
  }
  if (!isDelaunayBackendAvailable(delaunay_backend)) {
    if (why)
      *why = std::string("parameter delaunay_backend = ") + toString(delaunay_backend) +
             " is not available in this build (the library was built without VTK)";
    return false;
  }
  return true;
}

} // namespace selective_seg
} // namespace pcl
