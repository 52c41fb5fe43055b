/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/common/time.h>
#include <pcl/console/print.h>

namespace pcl {
namespace selective_seg {

template <typename PointT>
bool
SelectiveSegmentation<PointT>::update(const PointCloud& new_points,
                                      std::vector<pcl::PointIndices>& clusters)
{
  clusters.clear();
  update_stats_ = UpdateStatistics();
  if (!input_ || !mesh_input_ || result_.segments.empty()) {
    PCL_ERROR("[pcl::selective_seg::%s::update] no result to update: call extract() "
              "first\n",
              getClassName().c_str());
    return false;
  }
  // Invalid parameters: nothing changes (not even the input).
  std::string why;
  if (!params_.validate(&why)) {
    PCL_ERROR(
        "[pcl::selective_seg::%s::update] %s\n", getClassName().c_str(), why.c_str());
    return false;
  }
  // In place only into the result of the current input and indices; else the union
  // of the current input and the new points from scratch.
  const bool in_place = meshInputUnchanged();
  const auto previous_input = input_;
  const auto previous_indices = this->fake_indices_ ? IndicesPtr() : indices_;
  const SelectiveSegmentationParameters saved = params_;
  bool ok = false;
  try {
    ok = updateUnion(new_points, in_place, clusters);
  } catch (const std::bad_alloc&) {
    std::vector<pcl::PointIndices>().swap(clusters);
    ok = failOutOfMemory("update");
  }
  params_ = saved;
  if (!ok) { // the input and indices before the call; no statistics
    update_stats_ = UpdateStatistics();
    this->setInputCloud(previous_input);
    if (previous_indices)
      this->setIndices(previous_indices);
  }
  return ok;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::updateUnion(const PointCloud& new_points,
                                           bool in_place,
                                           std::vector<pcl::PointIndices>& clusters)
{
  const detail::TrustedMeshScope trusted_mesh; // as in runExtract()
  pcl::StopWatch total;
  update_stats_.new_points = new_points.size();
  const std::size_t first_new = input_->size();
  auto merged = pcl::make_shared<PointCloud>();
  detail::reserveLarge(merged->points, first_new + new_points.size());
  merged->points.insert(merged->end(), input_->begin(), input_->end());
  merged->points.insert(merged->end(), new_points.begin(), new_points.end());
  merged->width = static_cast<std::uint32_t>(merged->points.size());
  merged->height = 1;
  merged->is_dense = input_->is_dense && new_points.is_dense;
  merged->header = input_->header;
  merged->sensor_origin_ = input_->sensor_origin_;
  merged->sensor_orientation_ = input_->sensor_orientation_;
  if (!this->fake_indices_ && indices_) {
    auto indices = pcl::make_shared<pcl::Indices>(*indices_);
    for (std::size_t i = 0; i < new_points.size(); ++i)
      indices->push_back(static_cast<pcl::index_t>(first_new + i));
    this->setInputCloud(merged);
    this->setIndices(indices);
  }
  else
    this->setInputCloud(merged);

  // The finest voxel of the result being updated is kept (see the header).
  if (!(params_.min_voxel_size > 0.0))
    params_.min_voxel_size = result_.min_voxel_size;
  bool ok = false;
  bool failed = false;
  if (in_place && updateMesh(first_new, failed)) {
    ok = segmentMesh(clusters);
    result_.timings.total = total.getTimeSeconds();
  } else if (!failed) {
    ok = extract(clusters); // no triangulation to update: from scratch on the union
  }
  return ok;
}

template <typename PointT>
bool
SelectiveSegmentation<PointT>::updateMesh(std::size_t first_new_point, bool& failed)
{
  failed = false;
  if (!initCompute()) {
    this->deinitCompute();
    failed = true;
    return false;
  }
  pcl::StopWatch watch;
  delaunay_.setInputCloud(input_);
  delaunay_.setIndices(indices_);
  // In place only with the parameters and pose the mesh was made with, and for the
  // exact backends (VTK's output is not the canonical triangulation).
  const bool same_mesh_parameters =
      params_.angle_quantization == mesh_params_.angle_quantization &&
      params_.projection == ViewProjection::Forward &&
      mesh_params_.projection == ViewProjection::Forward &&
      params_.max_view_incidence_angle == mesh_params_.max_view_incidence_angle &&
      params_.normal_rings == mesh_params_.normal_rings &&
      params_.point_normal_triangles == mesh_params_.point_normal_triangles &&
      params_.delaunay_backend != DelaunayBackend::Vtk &&
      mesh_params_.delaunay_backend != DelaunayBackend::Vtk &&
      delaunay_.getSensorPose().matrix() == mesh_pose_ &&
      result_.mesh.neighbours.size() == delaunay_.getTriangulation().triangles.size() &&
      vertex_normals_.size() == delaunay_.getTriangulation().vertex_point.size();
  DelaunayInsertion info;
  std::vector<pcl::index_t> moved;
  if (!same_mesh_parameters ||
      !delaunay_.insertPoints(first_new_point, result_.mesh.neighbours, info, moved)) {
    this->deinitCompute();
    return false;
  }
  std::vector<Triangle> adjacency;
  adjacency.swap(result_.mesh.neighbours);
  // The old triangle normals and areas, for the triangles the insertion kept.
  Vector3fVector old_normals;
  std::vector<double> old_areas;
  old_normals.swap(result_.mesh.normals);
  old_areas.swap(result_.mesh.areas);
  // The moved vertices, flagged (empty when none moved).
  std::vector<std::uint8_t> is_moved;
  if (!moved.empty()) {
    is_moved.assign(delaunay_.getTriangulation().vertex_positions.size(), 0);
    for (const auto v : moved)
      is_moved[v] = 1;
  }
  // The octree's leaves, for buildOctree() to keep where nothing changed (k-ring
  // normals change beyond the changed triangles' corners: not kept then), and the old
  // positions of the moved vertices (their old voxels lost them).
  previous_leaves_ = typename Octree::PreviousLeaves();
  if (octree_ && params_.normal_rings == 1) {
    previous_leaves_ = octree_->getPreviousLeaves();
    notePreviousSegments();
    if (!moved.empty()) {
      const auto& old_positions = *octree_->getInputCloud();
      for (std::size_t v = 0; v < info.old_to_new_point.size(); ++v)
        if (is_moved[info.old_to_new_point[v]])
          previous_leaves_.changed.push_back(old_positions[v].getVector3fMap());
    }
  }
  update_stats_.incremental = true;
  update_stats_.new_vertices = info.inserted_points.size();
  update_stats_.moved_vertices = moved.size();
  update_stats_.replaced_triangles = info.replaced_triangles;
  update_stats_.new_triangles = info.new_triangles.size();
  clearOutputs();
  result_.mesh.neighbours.swap(adjacency);
  takeTriangulationCounts();
  result_.timings.delaunay = watch.getTimeSeconds();
  watch.reset();
  updateNormals(info, is_moved, old_normals, old_areas);
  if (!publishNormals()) {
    failed = true;
    return false;
  }
  result_.timings.normals = watch.getTimeSeconds();
  mesh_params_ = params_;
  noteMeshInput();
  return true;
}

template <typename PointT>
void
SelectiveSegmentation<PointT>::updateNormals(const DelaunayInsertion& info,
                                             const std::vector<std::uint8_t>& is_moved,
                                             Vector3fVector& old_normals,
                                             std::vector<double>& old_areas)
{
  const SphericalTriangulation& tri = delaunay_.getTriangulation();
  const std::vector<Triangle>& adjacency = result_.mesh.neighbours;
  const std::size_t num_triangles = tri.triangles.size();
  const std::size_t num_vertices = tri.vertex_positions.size();
  // The changed triangles: the new ones and those at a moved vertex.
  std::vector<pcl::index_t> changed = info.new_triangles;
  if (!is_moved.empty()) {
    for (std::size_t t = 0; t < num_triangles; ++t) {
      const Triangle& c = tri.triangles[t];
      if (is_moved[c[0]] || is_moved[c[1]] || is_moved[c[2]])
        changed.push_back(static_cast<pcl::index_t>(t));
    }
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  }
  // Triangle normals, areas and edge-on flags: the kept triangles' from the result
  // when it holds them as computed (the sensor frame is the cloud frame: see
  // fillMeshAndLeaves()), the changed ones computed again.
  const std::size_t num_old = info.old_to_new_triangle.size();
  if (sensorToCloud() == Eigen::Matrix3f::Identity() && old_normals.size() == num_old &&
      old_areas.size() == num_old && triangle_edge_on_.size() == num_old) {
    triangle_normals_.swap(old_normals);
    triangle_areas_.swap(old_areas);
    updateTriangleNormalsAndEdgeOn(tri.vertex_positions,
                                   tri.triangles,
                                   Eigen::Vector3f::Zero(),
                                   params_.max_view_incidence_angle,
                                   info.old_to_new_triangle,
                                   changed,
                                   triangle_normals_,
                                   triangle_areas_,
                                   triangle_edge_on_,
                                   params_.num_threads);
  }
  else
    computeTriangleNormalsAndEdgeOn(tri.vertex_positions,
                                    tri.triangles,
                                    Eigen::Vector3f::Zero(),
                                    params_.max_view_incidence_angle,
                                    triangle_normals_,
                                    triangle_areas_,
                                    triangle_edge_on_,
                                    params_.num_threads);
  // Vertex normals: the old ones renumbered, recomputed at the changed triangles.
  Vector3fVector vertex_normals(num_vertices);
  auto vertex_areas = std::make_shared<std::vector<double>>(num_vertices, 0.0);
  const auto num_old_vertices = static_cast<std::ptrdiff_t>(info.old_to_new_point.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(numThreads()) schedule(static) \
    if (info.old_to_new_point.size() >= detail::kMinParallelItems)
#endif
  for (std::ptrdiff_t v = 0; v < num_old_vertices; ++v) {
    vertex_normals[info.old_to_new_point[v]] = vertex_normals_[v];
    (*vertex_areas)[info.old_to_new_point[v]] = (*vertex_areas_)[v];
  }
  // As computeNormals(): a vertex's normal depends on its own triangles (its k-ring's)
  // only, with or without the edge-on ones, so those of the changed triangles suffice.
  Vector3fVector masked;
  const Vector3fVector& eq2_normals = eq2TriangleNormals(masked);
  updateVertexNormals(tri.triangles,
                      adjacency,
                      eq2_normals,
                      triangle_areas_,
                      changed,
                      vertex_normals,
                      *vertex_areas,
                      params_.num_threads);
  if (params_.normal_rings > 1)
    updateVertexNormalsOverRings(tri.triangles,
                                 adjacency,
                                 eq2_normals,
                                 triangle_areas_,
                                 params_.normal_rings,
                                 changed,
                                 vertex_normals);
  fillEdgeOnOnlyVertices(vertex_normals);
  // The vertices of the changed triangles; their voxels changed for the octree (the new
  // vertices are corners of new triangles).
  const bool note_changes = !previous_leaves_.leaves.empty();
  std::vector<std::uint8_t> touched(num_vertices, 0);
  update_stats_.changed_vertices = 0;
  for (const auto t : changed)
    for (const auto v : tri.triangles[t])
      if (!touched[v]) {
        touched[v] = 1;
        ++update_stats_.changed_vertices;
        if (note_changes)
          previous_leaves_.changed.push_back(tri.vertex_positions[v]);
      }
  vertex_normals_.swap(vertex_normals);
  vertex_areas_ = vertex_areas;
}

} // namespace selective_seg
} // namespace pcl
