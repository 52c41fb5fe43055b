/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/impl/spherical_delaunay.hpp>
#include <pcl_selective_seg/region_merging.h>
#include <pcl_selective_seg/segment_colors.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/common/time.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>
#include <numeric>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl {
namespace selective_seg {

template <typename PointT>
bool
SelectiveSegmentation<PointT>::initCompute()
{
  if (!input_) {
    PCL_ERROR("[pcl::selective_seg::%s::extract] no input cloud: call setInputCloud() "
              "first\n",
              getClassName().c_str());
    return false;
  }
  if (!pcl::PCLBase<PointT>::initCompute())
    return false;
  // PCLBase::initCompute() reports a failed allocation of the indices that stand for
  // the whole cloud but goes on with the old ones (fewer points than the cloud's).
  if (this->fake_indices_ && indices_->size() != input_->size())
    throw std::bad_alloc();
  std::string why;
  if (!params_.validate(&why)) {
    PCL_ERROR(
        "[pcl::selective_seg::%s::extract] %s\n", getClassName().c_str(), why.c_str());
    return false;
  }
  return true;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::fail(const char* stage, const std::string& why)
{
  PCL_ERROR(
      "[pcl::selective_seg::%s::%s] %s\n", getClassName().c_str(), stage, why.c_str());
  const PointCounts counts = result_.counts;
  result_.clear();
  result_.counts = counts;
  octree_.reset();
  normals_.reset();
  forgetRun();
  this->deinitCompute();
  return false;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::failOutOfMemory(const char* stage)
{
  const std::size_t points = input_ ? input_->size() : 0;
  clearOutputs();
  previous_leaves_ = typename Octree::PreviousLeaves();
  previous_merge_ = PreviousMerge();
  mesh_input_.reset();
  forgetRun();
  PCL_ERROR("[pcl::selective_seg::%s::%s] out of memory with %zu input points: "
            "segment fewer (setIndices(), a voxel grid filter) or give the process "
            "more memory\n",
            getClassName().c_str(),
            stage,
            points);
  this->deinitCompute();
  return false;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::forgetRun()
{
  delaunay_.clearTriangulation();
  mesh_pose_.setZero();
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::clearOutputs()
{
  result_.clear();
  octree_.reset();
  normals_.reset();
  vertex_mean_normals_.clear();
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::takeTriangulationCounts()
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  result_.counts.outside_indices = tri.num_outside_indices;
  result_.counts.non_finite = tri.num_non_finite;
  result_.counts.behind_sensor = tri.num_behind_sensor;
  result_.num_vertices = tri.vertex_point.size();
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::triangulate()
{
  delaunay_.setInputCloud(input_);
  delaunay_.setIndices(indices_);
  delaunay_.setBackend(params_.delaunay_backend);
  delaunay_.setAngleQuantization(params_.angle_quantization);
  delaunay_.setProjection(params_.projection);
  delaunay_.setNumberOfThreads(static_cast<unsigned int>(params_.num_threads));
  // The adjacency comes with the triangles (the sweep reads it off its half-edges) and
  // moves into the result; update() keeps it there, not in the triangulation.
  delaunay_.setComputeNeighbours(true);
  const bool triangulated = delaunay_.triangulate();
  delaunay_.takeNeighbours(result_.mesh.neighbours);
  delaunay_.setComputeNeighbours(false);
  if (!triangulated)
    return fail("extract", "the spherical triangulation failed (reason above)");
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  takeTriangulationCounts();
  if (tri.vertex_point.empty())
    return fail("extract",
                "no usable point among " + std::to_string(input_->size()) + ": " +
                    std::to_string(tri.num_non_finite) + " non-finite, " +
                    std::to_string(tri.num_behind_sensor) +
                    (tri.projection == ViewProjection::Panoramic
                         ? " at the sensor's position, "
                         : " at or behind the sensor plane (z <= 0 in the sensor "
                           "frame; check sensor_origin_/sensor_orientation_ or "
                           "setSensorPose(), or use the panoramic projection), ") +
                    std::to_string(tri.num_outside_indices) + " outside the indices");
  if (tri.triangles.empty())
    return fail("extract",
                "the " + std::to_string(tri.vertex_point.size()) +
                    " distinct viewing directions are fewer than three or all on one "
                    "line in (theta, phi): there is no surface to triangulate");
  // Points on one 3-D line that misses the sensor have distinct directions and are
  // triangulated, but their triangles' areas are float rounding: any segment would be
  // noise. The line through vertex 0 and the vertex farthest from it must leave some
  // vertex by more than a few float roundings of the coordinates. (An exact test:
  // a far outlier cannot make a surface look like a line, as a principal axis would.)
  const auto& pos = tri.vertex_positions;
  const Eigen::Vector3d a = pos[0].template cast<double>();
  std::size_t far = 0;
  double far_distance = 0.0;
  for (std::size_t v = 1; v < pos.size(); ++v) {
    const double d = (pos[v].template cast<double>() - a).squaredNorm();
    if (d > far_distance) {
      far = v;
      far_distance = d;
    }
  }
  const Eigen::Vector3d b = pos[far].template cast<double>();
  const double length = std::sqrt(far_distance);
  const Eigen::Vector3d axis = (b - a) / length;
  const double tolerance = 16.0 * std::numeric_limits<float>::epsilon();
  bool on_line = far_distance > 0.0;
  for (std::size_t v = 1; on_line && v < pos.size(); ++v) {
    const Eigen::Vector3d p = pos[v].template cast<double>();
    const Eigen::Vector3d off = (p - a) - axis * axis.dot(p - a);
    // The rounding of p, and that of a and b carried to p along the line.
    const double rounding =
        p.norm() + (a.norm() * (p - b).norm() + b.norm() * (p - a).norm()) / length;
    on_line = off.norm() <= tolerance * rounding;
  }
  if (on_line)
    return fail("extract",
                "the " + std::to_string(pos.size()) +
                    " distinct points lie on one line in 3-D (to float precision): "
                    "there is no surface to segment");
  return true;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::computeNormals()
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  const auto& positions = tri.vertex_positions; // sensor frame: the viewpoint is 0
  const Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();
  computeTriangleNormalsAndEdgeOn(positions,
                                  tri.triangles,
                                  viewpoint,
                                  params_.max_view_incidence_angle,
                                  triangle_normals_,
                                  triangle_areas_,
                                  triangle_edge_on_,
                                  params_.num_threads);
  vertex_areas_ = std::make_shared<std::vector<double>>();
  // Eq. 2 over the triangles not seen edge-on, when asked, then over all of them where
  // that leaves no normal.
  Vector3fVector masked;
  const Vector3fVector& eq2_normals = eq2TriangleNormals(masked);
  computeVertexNormals(positions.size(),
                       tri.triangles,
                       eq2_normals,
                       triangle_areas_,
                       vertex_normals_,
                       *vertex_areas_,
                       params_.num_threads,
                       &result_.mesh.neighbours);
  if (params_.normal_rings > 1)
    computeVertexNormalsOverRings(positions.size(),
                                  tri.triangles,
                                  eq2_normals,
                                  triangle_areas_,
                                  params_.normal_rings,
                                  vertex_normals_);
  fillEdgeOnOnlyVertices(vertex_normals_);
  return publishNormals();
}

template <typename PointT>
const Vector3fVector&
SelectiveSegmentation<PointT>::eq2TriangleNormals(Vector3fVector& masked) const
{
  if (params_.point_normal_triangles != PointNormalTriangles::NotEdgeOn)
    return triangle_normals_;
  maskEdgeOnNormals(triangle_normals_, triangle_edge_on_, masked, params_.num_threads);
  return masked;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::fillEdgeOnOnlyVertices(
    Vector3fVector& vertex_normals) const
{
  if (params_.point_normal_triangles == PointNormalTriangles::NotEdgeOn)
    fillMissingVertexNormals(delaunay_.getTriangulation().triangles,
                             triangle_normals_,
                             triangle_areas_,
                             params_.normal_rings,
                             vertex_normals,
                             params_.num_threads);
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::publishNormals()
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  const auto& positions = tri.vertex_positions;
  // Every vertex represents at least one point: a point has a normal if a vertex has;
  // the point normals themselves are built on the first getPointNormals().
  normals_.reset();
  const bool any = std::any_of(vertex_normals_.begin(),
                               vertex_normals_.end(),
                               [](const Eigen::Vector3f& n) { return n.allFinite(); });
  result_.median_spacing =
      medianEdgeLength(positions, tri.triangles, params_.num_threads);
  if (!any)
    return fail("extract",
                "every triangle is degenerate (zero 3-D area): the points give no "
                "surface normal");
  return true;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::buildOctree()
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  const std::size_t num_vertices = tri.vertex_positions.size();
  auto vertices = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  detail::reserveLarge(vertices->points, num_vertices);
  vertices->resize(num_vertices);
  // The box of the vertices with a normal: per-thread minima and maxima, combined (the
  // same for any thread count).
  const int threads = num_vertices >= detail::kMinParallelItems ? numThreads() : 1;
  const float big = std::numeric_limits<float>::max();
  std::vector<Eigen::Array3f> los(static_cast<std::size_t>(threads),
                                  Eigen::Array3f::Constant(big));
  std::vector<Eigen::Array3f> his(static_cast<std::size_t>(threads),
                                  Eigen::Array3f::Constant(-big));
#ifdef _OPENMP
#pragma omp parallel num_threads(threads)
#endif
  {
#ifdef _OPENMP
    const auto mine = static_cast<std::size_t>(omp_get_thread_num());
#else
    const std::size_t mine = 0;
#endif
    Eigen::Array3f my_lo = los[mine], my_hi = his[mine]; // no shared cache line
#ifdef _OPENMP
#pragma omp for schedule(static)
#endif
    for (std::ptrdiff_t v = 0; v < static_cast<std::ptrdiff_t>(num_vertices); ++v) {
      (*vertices)[v].getVector3fMap() = tri.vertex_positions[v];
      if (vertex_normals_[v].allFinite()) {
        my_lo = my_lo.min(tri.vertex_positions[v].array());
        my_hi = my_hi.max(tri.vertex_positions[v].array());
      }
    }
    los[mine] = my_lo;
    his[mine] = my_hi;
  }
  Eigen::Array3f lo = los[0], hi = his[0];
  for (std::size_t t = 1; t < los.size(); ++t) {
    lo = lo.min(los[t]);
    hi = hi.max(his[t]);
  }
  // The finest voxel: the parameter, or a multiple of the point spacing, but never so
  // small that the tree would exceed its maximum depth.
  // In double: the difference of two floats near float's limits overflows float.
  const double extent =
      (hi.template cast<double>() - lo.template cast<double>()).maxCoeff();
  double resolution = params_.min_voxel_size > 0.0
                          ? params_.min_voxel_size
                          : params_.min_voxel_size_factor * result_.median_spacing;
  // 2^depth - 1 voxels: the octree pads its box by a hundredth of a voxel, which must
  // not take it one level deeper than max_octree_depth. The box is at least 2 float
  // epsilons wide (OctreePointCloudNormalVariance: PCL's octree subtracts one).
  const double box = std::max(extent, 2.0 * std::numeric_limits<float>::epsilon());
  resolution =
      std::max(resolution, box / (std::ldexp(1.0, params_.max_octree_depth) - 1.0));
  if (!(resolution > 0.0) || !std::isfinite(resolution))
    resolution = extent > 0.0 && std::isfinite(extent) ? extent : 1.0;
  result_.min_voxel_size = resolution;

  octree_ = pcl::make_shared<Octree>(resolution);
  octree_->setInputCloud(vertices);
  // The vertex normals are lent to the octree, not copied into a pcl::Normal cloud
  // (32 bytes per vertex, at the pipeline's peak of memory), and taken back once the
  // leaves are made: the octree is only handed out const, so it never reads them again.
  const typename Octree::NormalVectorsConstPtr lent(
      std::shared_ptr<const Vector3fVector>(), &vertex_normals_);
  octree_->setInputNormals(lent, vertex_areas_);
  octree_->setNumberOfThreads(static_cast<unsigned int>(params_.num_threads));
  octree_->setNormalSpreadFrame(params_.normal_spread_frame);
  // update(): the previous leaves where nothing changed.
  const bool keeping = !previous_leaves_.leaves.empty();
  if (keeping)
    octree_->keepLeavesFrom(std::move(previous_leaves_));
  previous_leaves_ = typename Octree::PreviousLeaves();
  const bool inserted = octree_->addPointsAndComputeAdaptiveLeaves(
      params_.max_normal_std_dev, static_cast<std::size_t>(params_.min_points_to_split));
  if (keeping)
    update_stats_.kept_leaves = octree_->getNumKeptLeaves();
  octree_->setInputNormals(typename Octree::NormalVectorsConstPtr(), vertex_areas_);
  if (!inserted)
    return fail("extract",
                "the octree holds no point: no point has a normal, or the octree "
                "refused the points' extent (reason above)");
  // The leaves' sizes and centres are floats (OctreeLeaf): near float's limits, a
  // large leaf may not fit one.
  const auto leaf_fits = [&](const AdaptiveLeaf& leaf) {
    return octree_->getVoxelSideLength(leaf.depth) <=
               std::numeric_limits<float>::max() &&
           (delaunay_.getSensorPose() * octree_->getVoxelCentre(leaf)).allFinite();
  };
  // Checked only where some could not: a leaf's centre is within its points' largest
  // coordinate plus the octree's box (at most twice the extent or the finest voxel)
  // in each axis, moved by the pose.
  const double largest = std::max(lo.abs().maxCoeff(), hi.abs().maxCoeff());
  const double reach = std::sqrt(3.0) * (largest + 2.0 * (extent + resolution)) +
                       delaunay_.getSensorPose().translation().norm();
  const auto& fitting = octree_->getAdaptiveLeaves();
  if (!(reach < 0.5 * std::numeric_limits<float>::max()) &&
      !std::all_of(fitting.begin(), fitting.end(), leaf_fits)) {
    char span[32];
    std::snprintf(span, sizeof(span), "%.3g", extent);
    return fail("extract",
                std::string("the points span ") + span +
                    " m, more than the octree's float voxels hold: scale the cloud "
                    "down (e.g. give it in kilometres)");
  }

  detail::assignLarge(vertex_leaf_, num_vertices, -1);
  const auto& leaves = octree_->getAdaptiveLeaves();
  const auto& ordered = octree_->getOrderedIndices();
  // Each vertex is in one leaf at most: the leaves can be split among the threads.
  const auto num_leaves = static_cast<std::ptrdiff_t>(leaves.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static)
#endif
  for (std::ptrdiff_t l = 0; l < num_leaves; ++l)
    for (std::size_t k = leaves[l].begin; k < leaves[l].end; ++k)
      vertex_leaf_[ordered[k]] = static_cast<pcl::index_t>(l);
  return true;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::rankSegments(
    const std::vector<pcl::index_t>& vertex_segment,
    const Vector3fVector& segment_normals,
    std::vector<std::uint32_t>& segment_label)
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  const std::size_t num_segments = segment_normals.size();
  // Points per segment: counted per thread (the counts allocated here, on the calling
  // thread), then added up.
  const int threads = numThreads();
  std::vector<std::vector<std::size_t>> counts(
      static_cast<std::size_t>(threads), std::vector<std::size_t>(num_segments, 0));
  const auto num_mapped = static_cast<std::ptrdiff_t>(tri.point_vertex.size());
#ifdef _OPENMP
#pragma omp parallel num_threads(threads)
#endif
  {
#ifdef _OPENMP
    std::vector<std::size_t>& mine =
        counts[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
#else
    std::vector<std::size_t>& mine = counts[0];
#endif
    for (std::ptrdiff_t i = 0; i < num_mapped; ++i) {
      const pcl::index_t v = tri.point_vertex[i];
      if (v >= 0 && vertex_segment[v] >= 0)
        ++mine[static_cast<std::size_t>(vertex_segment[v])];
    }
  }
  std::vector<std::size_t> sizes = std::move(counts[0]);
  for (std::size_t t = 1; t < counts.size(); ++t)
    for (std::size_t k = 0; k < num_segments; ++k)
      sizes[k] += counts[t][k];
  // Largest first; ties keep the (data-determined) creation order.
  std::vector<std::size_t> order(num_segments);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return sizes[a] > sizes[b];
  });
  segment_label.assign(num_segments, 0);
  result_.segments.resize(num_segments);
  const Eigen::Matrix3f to_cloud = sensorToCloud();
  for (std::size_t r = 0; r < num_segments; ++r) {
    segment_label[order[r]] = static_cast<std::uint32_t>(r + 1);
    result_.segments[r].label = static_cast<std::uint32_t>(r + 1);
    result_.segments[r].num_points = sizes[order[r]];
    result_.segments[r].normal = to_cloud * segment_normals[order[r]];
    result_.segments[r].sensor_normal = segment_normals[order[r]];
  }
  // Per-point labels and the counts of labeled, shared-vertex and normal-less points.
  detail::resizeLarge(result_.labels, input_->size());
  std::size_t without_normal = 0, labeled = 0, shared_vertex = 0;
  const auto num_points = static_cast<std::ptrdiff_t>(input_->size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(numThreads()) schedule(static)                  \
    reduction(+ : without_normal, labeled, shared_vertex)
#endif
  for (std::ptrdiff_t i = 0; i < num_points; ++i) {
    const pcl::index_t v = tri.point_vertex[i];
    result_.labels[i] =
        v >= 0 && vertex_segment[v] >= 0 ? segment_label[vertex_segment[v]] : 0;
    if (v < 0)
      continue;
    if (result_.labels[i] == 0)
      ++without_normal;
    else {
      ++labeled;
      shared_vertex += (tri.vertex_point[v] != static_cast<pcl::index_t>(i));
    }
  }
  result_.counts.without_normal += without_normal;
  result_.counts.labeled += labeled;
  result_.counts.shared_vertex += shared_vertex;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::fillMeshAndLeaves(
    const std::vector<std::uint32_t>& vertex_labels,
    const std::vector<pcl::index_t>& leaf_segment,
    const std::vector<std::uint32_t>& segment_label)
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  SegmentedMesh& mesh = result_.mesh;
  const auto num_triangles = static_cast<std::ptrdiff_t>(tri.triangles.size());
  const Eigen::Matrix3f to_cloud = sensorToCloud();
  Vector3fVector label_normals; // sensor frame, like the triangle normals
  label_normals.reserve(result_.segments.size());
  for (const auto& s : result_.segments)
    label_normals.push_back(to_cloud.transpose() * s.normal);
  classifyTriangles(tri.triangles,
                    edgeTestNormals(),
                    &triangle_edge_on_,
                    vertex_labels,
                    label_normals,
                    params_.max_edge_triangle_angle,
                    mesh.labels,
                    mesh.classes,
                    params_.num_threads);
  // The triangles over input points; the triangle normals and areas move into the
  // result (the normals turned to the cloud frame): the run needs them no more, and
  // they are the largest arrays. When the frames coincide the normals are moved as
  // they are, and update() can take them back for the triangles it keeps.
  detail::resizeLarge(mesh.triangles, tri.triangles.size());
  const bool turn = to_cloud != Eigen::Matrix3f::Identity();
#ifdef _OPENMP
#pragma omp parallel for num_threads(numThreads()) schedule(static)
#endif
  for (std::ptrdiff_t t = 0; t < num_triangles; ++t) {
    for (int i = 0; i < 3; ++i)
      mesh.triangles[t][i] = tri.vertex_point[tri.triangles[t][i]];
    if (turn)
      triangle_normals_[t] = to_cloud * triangle_normals_[t];
  }
  mesh.normals = std::move(triangle_normals_);
  mesh.areas = std::move(triangle_areas_);
  triangle_normals_.clear();
  triangle_areas_.clear();

  const auto& leaves = octree_->getAdaptiveLeaves();
  const Eigen::Affine3f sensor_pose = delaunay_.getSensorPose();
  result_.leaves.resize(leaves.size());
  const auto num_leaves = static_cast<std::ptrdiff_t>(leaves.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(numThreads()) schedule(static)
#endif
  for (std::ptrdiff_t l = 0; l < num_leaves; ++l) {
    OctreeLeaf& out = result_.leaves[l];
    out.centre = sensor_pose * octree_->getVoxelCentre(leaves[l]);
    out.size = static_cast<float>(octree_->getVoxelSideLength(leaves[l].depth));
    out.depth = leaves[l].depth;
    out.label = segment_label[leaf_segment[l]];
    out.normal = to_cloud * leaves[l].normal;
    out.sigma_theta = leaves[l].sigma_theta;
    out.sigma_phi = leaves[l].sigma_phi;
    out.area = leaves[l].area;
    out.num_points = static_cast<std::uint32_t>(leaves[l].end - leaves[l].begin);
  }
  // Segment areas summed in leaf order, whatever the thread count.
  for (const OctreeLeaf& out : result_.leaves) {
    result_.segments[out.label - 1].area += out.area;
    ++result_.segments[out.label - 1].num_leaves;
  }
}

template <typename PointT>
const Vector3fVector&
SelectiveSegmentation<PointT>::edgeTestNormals()
{
  if (params_.edge_triangle_normal == EdgeTriangleNormal::Facet)
    return triangle_normals_;
  if (vertex_mean_normals_.size() != triangle_normals_.size())
    computeTriangleNormalsFromVertices(
        delaunay_.getTriangulation().triangles, vertex_normals_, vertex_mean_normals_);
  return vertex_mean_normals_;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::mergeAndLabel()
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  MergeInput in;
  in.leaves = &octree_->getAdaptiveLeaves();
  in.vertex_leaf = &vertex_leaf_;
  in.triangles = &tri.triangles;
  in.triangle_normals = &edgeTestNormals();
  in.triangle_edge_on = &triangle_edge_on_;
  in.max_merge_angle = params_.max_merge_angle;
  in.segment_normal_weight = params_.segment_normal_weight;
  in.max_edge_triangle_angle = params_.max_edge_triangle_angle;
  in.merge_with = params_.merge_with;
  in.num_threads = numThreads();
  MergeReplay replay;
  std::vector<pcl::index_t> replay_leaf_segment, replay_seed;
  if (prepareReplay(replay, replay_leaf_segment, replay_seed))
    in.replay = &replay;
  std::vector<pcl::index_t> leaf_segment;
  Vector3fVector segment_normals;
  mergeSeedSegments(in, leaf_segment, segment_normals);
  if (in.replay)
    update_stats_.replayed_segments = replay.num_replayed;
  std::vector<pcl::index_t>().swap(replay_leaf_segment);
  std::vector<pcl::index_t>().swap(replay_seed);
  previous_merge_ = PreviousMerge();

  const auto num_vertices = static_cast<std::ptrdiff_t>(vertex_leaf_.size());
  std::vector<pcl::index_t> vertex_segment;
  detail::resizeLarge(vertex_segment, vertex_leaf_.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(numThreads()) schedule(static)
#endif
  for (std::ptrdiff_t v = 0; v < num_vertices; ++v)
    vertex_segment[v] = vertex_leaf_[v] >= 0 ? leaf_segment[vertex_leaf_[v]] : -1;
  std::vector<std::uint32_t> segment_label;
  rankSegments(vertex_segment, segment_normals, segment_label);
  std::vector<std::uint32_t> vertex_labels;
  detail::resizeLarge(vertex_labels, vertex_segment.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(numThreads()) schedule(static)
#endif
  for (std::ptrdiff_t v = 0; v < num_vertices; ++v)
    vertex_labels[v] = vertex_segment[v] >= 0 ? segment_label[vertex_segment[v]] : 0;
  fillMeshAndLeaves(vertex_labels, leaf_segment, segment_label);
  // For update(): the merge's parameters; the rest of it is read from the result when
  // it is needed (notePreviousSegments()).
  previous_merge_.params = params_;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::notePreviousSegments()
{
  // The result's leaves (their labels) and the vertex leaves are still the previous
  // run's. The merge numbered its segments in the order they grew: a segment grew from
  // its leaf that comes first in the seed order, so walking that order, each label met
  // for the first time is the next segment, grown from that leaf.
  PreviousMerge& previous = previous_merge_;
  previous.leaf_segment.clear();
  previous.segment_seed.clear();
  previous.segment_normals.clear();
  const std::size_t num_leaves = result_.leaves.size();
  const std::size_t num_segments = result_.segments.size();
  if (num_leaves == 0 || previous_leaves_.leaves.size() != num_leaves)
    return;
  std::vector<pcl::index_t> label_segment(num_segments + 1, -1);
  previous.leaf_segment.resize(num_leaves);
  previous.segment_seed.reserve(num_segments);
  for (const pcl::index_t l : seedOrder(vertex_leaf_, num_leaves)) {
    const std::uint32_t label = result_.leaves[l].label;
    if (label == 0 || label > num_segments) { // not a merge's result: no replay
      previous = PreviousMerge();
      return;
    }
    if (label_segment[label] < 0) {
      label_segment[label] = static_cast<pcl::index_t>(previous.segment_seed.size());
      previous.segment_seed.push_back(l);
      previous.segment_normals.push_back(result_.segments[label - 1].sensor_normal);
    }
    previous.leaf_segment[l] = label_segment[label];
  }
  if (previous.segment_seed.size() != num_segments)
    previous = PreviousMerge();
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::prepareReplay(
    MergeReplay& replay,
    std::vector<pcl::index_t>& leaf_segment,
    std::vector<pcl::index_t>& segment_seed) const
{
  // A kept leaf holds the same vertices, with the same normals and areas, as the
  // previous leaf it was kept from, and no corner of a new or changed triangle (those
  // are among the positions the octree was told changed): every triangle at its
  // vertices is an old one, with its facet normal and edge-on flag, in the same
  // relative order (the canonical order over vertex numbers that keep their order).
  // A vertex-mean edge normal would change with a neighbour's vertex normal.
  const PreviousMerge& previous = previous_merge_;
  const SelectiveSegmentationParameters& was = previous.params;
  // With MergeWith::Segments a segment can change after it has grown: none is taken
  // over.
  if (octree_->getNumKeptLeaves() == 0 || previous.leaf_segment.empty() ||
      params_.merge_with != MergeWith::Seeds || was.merge_with != MergeWith::Seeds ||
      params_.edge_triangle_normal != EdgeTriangleNormal::Facet ||
      was.edge_triangle_normal != EdgeTriangleNormal::Facet ||
      was.max_merge_angle != params_.max_merge_angle ||
      was.max_edge_triangle_angle != params_.max_edge_triangle_angle ||
      was.segment_normal_weight != params_.segment_normal_weight)
    return false;
  const auto& leaves = octree_->getAdaptiveLeaves();
  const std::size_t num_previous = previous.leaf_segment.size();
  // Each previous leaf's number now, -1 when it was not kept.
  std::vector<pcl::index_t> now(num_previous, -1);
  leaf_segment.assign(leaves.size(), -1);
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    const std::int32_t k = leaves[l].kept_from;
    if (k < 0 || static_cast<std::size_t>(k) >= num_previous)
      continue;
    now[k] = static_cast<pcl::index_t>(l);
    leaf_segment[l] = previous.leaf_segment[k];
  }
  // A previous segment can be taken over only when all its leaves were kept.
  segment_seed.resize(previous.segment_seed.size());
  for (std::size_t s = 0; s < segment_seed.size(); ++s)
    segment_seed[s] = now[previous.segment_seed[s]];
  for (std::size_t k = 0; k < num_previous; ++k)
    if (now[k] < 0)
      segment_seed[previous.leaf_segment[k]] = -1;
  replay.leaf_segment = &leaf_segment;
  replay.segment_seed = &segment_seed;
  replay.segment_normals = &previous.segment_normals;
  return true;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::extract(std::vector<pcl::PointIndices>& clusters)
{
  try {
    return runExtract(clusters);
  } catch (const std::bad_alloc&) {
    std::vector<pcl::PointIndices>().swap(clusters);
    return failOutOfMemory("extract");
  }
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::runExtract(std::vector<pcl::PointIndices>& clusters)
{
  // The meshes of this run are the triangulation's own: the mesh functions need not
  // check their ids (the input is checked by initCompute() and the triangulation).
  const detail::TrustedMeshScope trusted_mesh;
  clusters.clear();
  clearOutputs();
  previous_leaves_ = typename Octree::PreviousLeaves(); // from scratch
  previous_merge_ = PreviousMerge();
  mesh_input_.reset();
  pcl::StopWatch total;
  if (!initCompute()) {
    forgetRun();
    this->deinitCompute();
    return false;
  }
  pcl::StopWatch watch;
  if (!triangulate())
    return false;
  result_.timings.delaunay = watch.getTimeSeconds();
  watch.reset();
  if (!computeNormals())
    return false;
  result_.timings.normals = watch.getTimeSeconds();
  mesh_params_ = params_;
  mesh_pose_ = delaunay_.getSensorPose().matrix();
  noteMeshInput();
  if (!segmentMesh(clusters))
    return false;
  result_.timings.total = total.getTimeSeconds();
  return true;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::noteMeshInput()
{
  mesh_input_ = input_;
  mesh_all_points_ = this->fake_indices_ || !indices_;
  if (mesh_all_points_)
    pcl::Indices().swap(mesh_indices_);
  else
    mesh_indices_ = *indices_;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::meshInputUnchanged() const
{
  if (!input_ || input_ != mesh_input_ || result_.labels.size() != input_->size())
    return false;
  const bool all_points = this->fake_indices_ || !indices_;
  return all_points == mesh_all_points_ && (all_points || *indices_ == mesh_indices_);
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::segmentMesh(std::vector<pcl::PointIndices>& clusters)
{
  pcl::StopWatch watch;
  if (!buildOctree())
    return false;
  result_.timings.octree = watch.getTimeSeconds();
  watch.reset();
  mergeAndLabel();
  // Each cluster lists its points in increasing order, for any thread count.
  clustersFromLabels(result_.labels, result_.segments.size(), clusters, numThreads());
  for (auto& c : clusters)
    c.header = input_->header;
  result_.timings.merge = watch.getTimeSeconds();
  if (result_.segments.empty())
    PCL_WARN("[pcl::selective_seg::%s::extract] no segment found\n",
             getClassName().c_str());
  this->deinitCompute();
  return true;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::runLayoutIsItsSize() const
{
  const PointCloud& run = *mesh_input_;
  return static_cast<std::size_t>(run.width) * run.height == run.size();
}

template <typename PointT>
template <typename CloudT>
pcl::shared_ptr<CloudT>
SelectiveSegmentation<PointT>::cloudShapedLikeTheRun(
    const typename CloudT::PointType& fill) const
{
  const PointCloud& run = *mesh_input_;
  auto out = pcl::make_shared<CloudT>();
  if (runLayoutIsItsSize())
    *out = CloudT(run.width, run.height, fill);
  else
    out->resize(static_cast<pcl::index_t>(run.size()), fill);
  out->header = run.header;
  return out;
}

template <typename PointT>
typename SelectiveSegmentation<PointT>::NormalCloud::ConstPtr
SelectiveSegmentation<PointT>::getPointNormals() const
{
  // Built once, whichever thread comes first.
  return normals_.getOrMake([this]() -> typename NormalCloud::ConstPtr {
    const SphericalTriangulation& tri = delaunay_.getTriangulation();
    if (!mesh_input_ || result_.labels.size() != mesh_input_->size() ||
        tri.point_vertex.size() != mesh_input_->size() || vertex_normals_.empty())
      return nullptr;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    auto normals = cloudShapedLikeTheRun<NormalCloud>(pcl::Normal(nan, nan, nan, nan));
    normals->is_dense = false;
    // The orientation of the run, whatever the pose is now.
    const Eigen::Matrix3f to_cloud = mesh_pose_.template topLeftCorner<3, 3>();
    for (std::size_t i = 0; i < mesh_input_->size(); ++i) {
      const pcl::index_t v = tri.point_vertex[i];
      if (v < 0 || !vertex_normals_[v].allFinite())
        continue;
      (*normals)[i].getNormalVector3fMap() = to_cloud * vertex_normals_[v];
      (*normals)[i].curvature = 0.0f;
    }
    return normals;
  });
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::hasRunOutputs() const
{
  // A successful run has at least one segment.
  return mesh_input_ && !result_.segments.empty() &&
         result_.labels.size() == mesh_input_->size();
}

template <typename PointT>
template <typename CloudT, typename Fill>
pcl::shared_ptr<CloudT>
SelectiveSegmentation<PointT>::runPointsCloud(const Fill& fill) const
{
  if (!hasRunOutputs())
    return nullptr;
  const PointCloud& run = *mesh_input_;
  auto out = cloudShapedLikeTheRun<CloudT>(typename CloudT::PointType());
  out->is_dense = run.is_dense;
  out->sensor_origin_ = run.sensor_origin_;
  out->sensor_orientation_ = run.sensor_orientation_;
  for (std::size_t i = 0; i < run.size(); ++i) {
    auto& p = (*out)[i];
    p.getVector3fMap() = run[i].getVector3fMap();
    fill(p, result_.labels[i]);
  }
  return out;
}

template <typename PointT>
typename SelectiveSegmentation<PointT>::LabeledCloud::Ptr
SelectiveSegmentation<PointT>::getLabeledCloud() const
{
  return runPointsCloud<LabeledCloud>(
      [](pcl::PointXYZL& p, std::uint32_t label) { p.label = label; });
}

template <typename PointT>
template <typename CloudT>
pcl::shared_ptr<CloudT>
SelectiveSegmentation<PointT>::coloredCloud() const
{
  // The labels are 0 .. #segments.
  const std::vector<Rgb> colors =
      segmentColors(static_cast<std::uint32_t>(result_.segments.size()));
  return runPointsCloud<CloudT>(
      [&](typename CloudT::PointType& p, std::uint32_t label) {
        const Rgb& c = colors[label];
        p.r = c[0];
        p.g = c[1];
        p.b = c[2];
        p.a = 255;
      });
}

template <typename PointT>
typename SelectiveSegmentation<PointT>::ColoredCloud::Ptr
SelectiveSegmentation<PointT>::getColoredCloud() const
{
  return coloredCloud<ColoredCloud>();
}

template <typename PointT>
typename SelectiveSegmentation<PointT>::ColoredCloudRGBA::Ptr
SelectiveSegmentation<PointT>::getColoredCloudRGBA() const
{
  return coloredCloud<ColoredCloudRGBA>();
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::getPolygonMesh(pcl::PolygonMesh& mesh) const
{
  mesh = pcl::PolygonMesh();
  if (!hasRunOutputs())
    return;
  pcl::toPCLPointCloud2(*mesh_input_, mesh.cloud);
  // A declared layout that is not the cloud's size would make a blob whose rows
  // describe more or fewer bytes than it holds: one row then, as the other getters.
  if (!runLayoutIsItsSize()) {
    mesh.cloud.width = static_cast<std::uint32_t>(mesh_input_->size());
    mesh.cloud.height = 1;
    mesh.cloud.row_step = mesh.cloud.point_step * mesh.cloud.width;
  }
  mesh.header = mesh_input_->header;
  mesh.polygons.resize(result_.mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.polygons.size(); ++t) {
    const Triangle& tri = result_.mesh.triangles[t];
    mesh.polygons[t].vertices.assign(tri.begin(), tri.end());
  }
}

} // namespace selective_seg
} // namespace pcl

#include <pcl_selective_seg/impl/selective_segmentation_update.hpp>

#define PCL_INSTANTIATE_SelectiveSegmentation(T)                                       \
  template class PCL_EXPORTS pcl::selective_seg::SelectiveSegmentation<T>;
