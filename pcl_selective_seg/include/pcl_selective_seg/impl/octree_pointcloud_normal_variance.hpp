/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/impl/parallel_exceptions.hpp>
#include <pcl_selective_seg/impl/radix_sort.hpp>
#include <pcl_selective_seg/octree_pointcloud_normal_variance.h>

#include <pcl/common/point_tests.h>
#include <pcl/octree/impl/octree_base.hpp>
#include <pcl/octree/impl/octree_pointcloud.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief Depth-first position of a finest voxel: the bits of its key interleaved as
 * PCL numbers the children (x, y, z from the most significant). */
inline std::uint64_t
mortonCode(const pcl::octree::OctreeKey& key)
{
  // Spread the low 21 bits of v to every third bit.
  const auto spread = [](std::uint64_t v) {
    v &= 0x1fffffu;
    v = (v | (v << 32)) & 0x1f00000000ffffu;
    v = (v | (v << 16)) & 0x1f0000ff0000ffu;
    v = (v | (v << 8)) & 0x100f00f00f00f00fu;
    v = (v | (v << 4)) & 0x10c30c30c30c30c3u;
    v = (v | (v << 2)) & 0x1249249249249249u;
    return v;
  };
  return (spread(key.x) << 2) | (spread(key.y) << 1) | spread(key.z);
}

/** \brief Axes u, v of the plane perpendicular to the unit vector \a z, with (u, v, z)
 * right-handed: u is the sensor's x axis projected onto that plane, or its y axis when
 * x is within about 25 degrees of \a z (then the projection is too short to be
 * well-conditioned). NaN in, NaN out. */
inline void
tangentAxes(const Eigen::Vector3d& z, Eigen::Vector3d& u, Eigen::Vector3d& v)
{
  const Eigen::Vector3d reference =
      std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  u = (reference - reference.dot(z) * z).normalized();
  v = z.cross(u);
}

/** \brief Angle difference wrapped into (-pi, pi]. */
inline double
wrapAngle(double a)
{
  if (a > M_PI)
    return a - 2.0 * M_PI;
  if (a <= -M_PI)
    return a + 2.0 * M_PI;
  return a;
}

} // namespace detail

template <typename PointT>
OctreePointCloudNormalVariance<PointT>::OctreePointCloudNormalVariance(
    double resolution)
    : OctreeT(resolution)
{
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::setInputNormals(
    const NormalCloudConstPtr& normals, const AreasConstPtr& areas)
{
  normals_ = normals;
  normal_vectors_.reset();
  areas_ = areas;
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::setInputNormals(
    const NormalVectorsConstPtr& normals, const AreasConstPtr& areas)
{
  normals_.reset();
  normal_vectors_ = normals;
  areas_ = areas;
}

template <typename PointT>
bool
OctreePointCloudNormalVariance<PointT>::isValidPoint(pcl::index_t index) const
{
  const auto i = static_cast<std::size_t>(index);
  if (i >= this->input_->size() || i >= numInputNormals() || i >= areas_->size())
    return false;
  const double area = (*areas_)[i];
  const Eigen::Vector3f normal = inputNormal(i);
  // Eq. 4 weighs a point by 1 / A_p: a subnormal area would weigh infinitely.
  return pcl::isFinite((*this->input_)[i]) && normal.allFinite() &&
         normal.squaredNorm() > 0.0f && std::isfinite(area) && area > 0.0 &&
         std::isfinite(1.0 / area);
}

template <typename PointT>
bool
OctreePointCloudNormalVariance<PointT>::checkDepth() const
{
  if (this->octree_depth_ <= kMaxDepth)
    return true;
  PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] the points' extent "
            "needs %u levels of %g voxels; at most %u are supported (a coarser "
            "resolution is needed)\n",
            static_cast<unsigned>(this->octree_depth_),
            this->resolution_,
            kMaxDepth);
  return false;
}

template <typename PointT>
bool
OctreePointCloudNormalVariance<PointT>::addPointsFromInputCloud()
{
  return insertPoints(false);
}

template <typename PointT>
bool
OctreePointCloudNormalVariance<PointT>::addPointsAndComputeAdaptiveLeaves(
    double max_std_dev, std::size_t min_points_to_split)
{
  if (!insertPoints(true))
    return false;
  computeAdaptiveLeaves(max_std_dev, min_points_to_split);
  return true;
}

template <typename PointT>
bool
OctreePointCloudNormalVariance<PointT>::insertPoints(bool with_angles)
{
  angles_ready_ = false;
  if (!this->input_)
    return false; // PCL's octree inserts nothing without a cloud either
  if (!hasNormalsAndAreas() || numInputNormals() != this->input_->size() ||
      areas_->size() != this->input_->size()) {
    PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] %zu points, but "
              "%zu normals and %zu areas: give one of each per point of the input "
              "cloud with setInputNormals()\n",
              static_cast<std::size_t>(this->input_->size()),
              hasNormalsAndAreas() ? numInputNormals() : std::size_t{0},
              areas_ ? areas_->size() : std::size_t{0});
    return false;
  }
  if (!(this->resolution_ > 0.0) || !std::isfinite(this->resolution_)) {
    PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] the resolution "
              "(smallest voxel) is %g: it must be positive and finite\n",
              this->resolution_);
    return false;
  }
  // Which points are valid, and their box, in parallel (a flag per candidate, then one
  // compaction in increasing order; min and max do not depend on the order).
  const auto num_candidates = static_cast<std::ptrdiff_t>(
      this->indices_ ? this->indices_->size() : this->input_->size());
  const auto candidate = [&](std::ptrdiff_t k) {
    return this->indices_ ? (*this->indices_)[k] : static_cast<pcl::index_t>(k);
  };
  std::vector<std::uint8_t> is_valid;
  detail::resizeLarge(is_valid, static_cast<std::size_t>(num_candidates));
  Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<double>::max());
  Eigen::Array3d hi = -lo;
  std::size_t beyond_cloud = 0; // indices that name no point of the cloud
#ifdef _OPENMP
#pragma omp parallel num_threads(num_threads_) reduction(+ : beyond_cloud)           \
    if (static_cast<std::size_t>(num_candidates) >= detail::kMinParallelItems)
#endif
  {
    Eigen::Array3d my_lo = lo, my_hi = hi;
#ifdef _OPENMP
#pragma omp for schedule(static)
#endif
    for (std::ptrdiff_t k = 0; k < num_candidates; ++k) {
      const pcl::index_t i = candidate(k);
      beyond_cloud += static_cast<std::size_t>(i) >= this->input_->size();
      is_valid[k] = isValidPoint(i);
      if (is_valid[k]) {
        const Eigen::Array3d p =
            (*this->input_)[i].getVector3fMap().template cast<double>();
        my_lo = my_lo.min(p);
        my_hi = my_hi.max(p);
      }
    }
#ifdef _OPENMP
#pragma omp critical(selseg_octree_box)
#endif
    {
      lo = lo.min(my_lo);
      hi = hi.max(my_hi);
    }
  }
  pcl::Indices valid;
  detail::reserveLarge(valid,
                       static_cast<std::size_t>(std::count(
                           is_valid.begin(), is_valid.end(), std::uint8_t{1})));
  for (std::ptrdiff_t k = 0; k < num_candidates; ++k)
    if (is_valid[k])
      valid.push_back(candidate(k));
  std::vector<std::uint8_t>().swap(is_valid);
  if (beyond_cloud != 0) {
    PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] %zu of the %zu "
              "indices name no point of the cloud (%zu points): nothing was inserted\n",
              beyond_cloud,
              static_cast<std::size_t>(num_candidates),
              static_cast<std::size_t>(this->input_->size()));
    return false;
  }
  if (valid.empty())
    return false;
  if (!std::is_sorted(valid.begin(), valid.end()))
    std::sort(valid.begin(), valid.end());
  if (this->leaf_count_ != 0) {
    // A tree that already holds points keeps its box: PCL's insertion, point by point
    // (it grows the box as PCL's octree does, a level at a time). Refused before it
    // starts when the grown box would need more than kMaxDepth levels: PCL would add
    // levels until its memory or its 32-bit depth arithmetic gave out.
    double box[6];
    this->getBoundingBox(box[0], box[1], box[2], box[3], box[4], box[5]);
    const Eigen::Array3d box_lo(box[0], box[1], box[2]), box_hi(box[3], box[4], box[5]);
    const double reach = (hi.max(box_hi) - lo.min(box_lo)).maxCoeff();
    if (!(reach <= std::ldexp(this->resolution_, static_cast<int>(kMaxDepth)))) {
      PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] the new points "
                "and the tree span %g m, more than %u levels of %g voxels; at most %u "
                "are supported: nothing was inserted (a coarser resolution is "
                "needed)\n",
                reach,
                kMaxDepth,
                this->resolution_,
                kMaxDepth);
      return false;
    }
    for (const auto i : valid)
      this->addPointIdx(i);
    return checkDepth();
  }
  // PCL's octree subtracts FLT_EPSILON (absolute) from each side of the box before
  // counting voxels: a narrower side (a scene smaller than 0.1 micrometre, or flat
  // along an axis with voxels under 12 micrometres) gave a negative count cast to an
  // unsigned integer. Make every side at least 2 FLT_EPSILON wide, and wide enough to
  // differ from its low end (far from the origin FLT_EPSILON is below a double's ulp).
  const Eigen::Array3d top = hi; // the points' largest coordinates
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] - lo[a] >= 2.0 * std::numeric_limits<float>::epsilon()))
      hi[a] = std::max(lo[a] + 2.0 * std::numeric_limits<float>::epsilon(),
                       std::nextafter(std::nextafter(lo[a], HUGE_VAL), HUGE_VAL));
  // Pad the top so that no point sits exactly on the box's upper faces.
  hi += 0.01 * this->resolution_;
  // With voxels far below FLT_EPSILON, PCL's subtraction can leave the box short of
  // the points, their keys beyond the tree's depth: then once more with the box
  // widened by what PCL subtracts. The keys grow with the coordinates, so the largest
  // point's decide (PCL's key formula); for voxels above about 12 micrometres the
  // padding above covers the subtraction and the first box is always used.
  unsigned depth = 0;
  bool keys_fit = false;
  for (int attempt = 0; attempt < 2 && !keys_fit; ++attempt) {
    const double widen =
        static_cast<double>(attempt) * std::numeric_limits<float>::epsilon();
    this->defineBoundingBox(
        lo.x(), lo.y(), lo.z(), hi.x() + widen, hi.y() + widen, hi.z() + widen);
    depth = static_cast<unsigned>(this->octree_depth_);
    if (!checkDepth())
      return false;
    Eigen::Array3d box_min, box_max;
    this->getBoundingBox(
        box_min.x(), box_min.y(), box_min.z(), box_max.x(), box_max.y(), box_max.z());
    keys_fit = (((top - box_min) / this->resolution_) < std::ldexp(1.0, depth)).all();
  }
  if (!keys_fit) {
    PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] the points' box "
              "(%g x %g x %g) does not fit %u levels of %g voxels\n",
              top.x() - lo.x(),
              top.y() - lo.y(),
              top.z() - lo.z(),
              depth,
              this->resolution_);
    return false;
  }
  // Finest voxels in depth-first (Morton) order, points by increasing index within
  // each (a stable radix sort of the codes of the points in increasing index order).
  std::vector<std::pair<std::uint64_t, pcl::index_t>> order;
  detail::resizeLarge(order, valid.size());
  // The passes over the points below take microseconds on small clouds: less than
  // starting a team of threads.
  [[maybe_unused]] const bool parallel = valid.size() >= detail::kMinParallelItems;
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(static) if (parallel)
#endif
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(valid.size()); ++k) {
    pcl::octree::OctreeKey key;
    this->genOctreeKeyforPoint((*this->input_)[valid[k]], key);
    order[k] = {detail::mortonCode(key), valid[k]};
  }
  pcl::Indices().swap(valid);
  detail::radixSortByKey(order, static_cast<int>(3 * depth), num_threads_);
  // The leaves' indices, in one array that each leaf container views: with_angles, the
  // ordered points themselves (the sorted codes are the depth-first order of the tree:
  // PCL numbers a node's children by the same bits).
  const std::size_t n = order.size();
  leaves_view_ordered_ = with_angles; // the tree is empty: no container views either
  pcl::Indices& leaf_indices = with_angles ? ordered_indices_ : voxel_indices_;
  detail::resizeLarge(leaf_indices, n);
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(static) if (parallel)
#endif
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(n); ++k)
    leaf_indices[k] = order[k].second;
  // The first entry of each leaf; the points' codes are freed before the scratch of the
  // angles is allocated (the peak of memory).
  const auto starts_voxel = [&](std::size_t k) {
    return k == 0 || order[k].first != order[k - 1].first;
  };
  std::size_t num_voxels = 0;
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(static) \
    reduction(+ : num_voxels) if (parallel)
#endif
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(n); ++k)
    num_voxels += starts_voxel(static_cast<std::size_t>(k));
  std::vector<pcl::uindex_t> voxel_begin; // exactly sized: it lives beside the scratch
  detail::reserveLarge(voxel_begin, num_voxels);
  for (std::size_t k = 0; k < n; ++k)
    if (starts_voxel(k))
      voxel_begin.push_back(static_cast<pcl::uindex_t>(k));
  decltype(order)().swap(order);
  // The same tree as PCL's point-by-point insertion (addPointIdx()), built along the
  // sorted codes (computed again for each leaf's first point): consecutive voxels share
  // the branches of their common prefix, so each node is created once, from its parent.
  const auto build_tree = [&] {
    std::vector<BranchNode*> path(depth, nullptr);
    path[0] = this->root_node_;
    std::uint64_t previous = 0;
    for (std::size_t v = 0; v < num_voxels; ++v) {
      const std::size_t begin = voxel_begin[v];
      const std::size_t end = v + 1 < num_voxels ? voxel_begin[v + 1] : n;
      pcl::octree::OctreeKey key;
      this->genOctreeKeyforPoint((*this->input_)[leaf_indices[begin]], key);
      const std::uint64_t code = detail::mortonCode(key);
      // The first level whose child differs from the previous voxel's.
      unsigned level = 0;
      if (v > 0) {
        const std::uint64_t differ = code ^ previous;
        level = depth - 1 - static_cast<unsigned>(detail::bitWidth(differ) - 1) / 3;
      }
      previous = code;
      if (with_angles)
        voxel_codes_[v] = code;
      const auto child = [&](unsigned d) {
        return static_cast<unsigned char>((code >> (3 * (depth - 1 - d))) & 7u);
      };
      for (unsigned d = level; d + 1 < depth; ++d) {
        path[d + 1] = this->createBranchChild(*path[d], child(d));
        ++this->branch_count_;
      }
      LeafNode* leaf = this->createLeafChild(*path[depth - 1], child(depth - 1));
      ++this->leaf_count_;
      auto& container = leaf->getContainer();
      container.viewPointIndices(leaf_indices.data() + begin,
                                 static_cast<pcl::uindex_t>(end - begin));
      container.setFirstOrderedPoint(begin);
    }
  };
  if (!with_angles) {
    build_tree();
    return true;
  }
  // The normal angles of the ordered points (computeNormalAngles() gives the same
  // values), computed by the other threads while the calling thread builds the tree,
  // which then joins them.
  voxel_indices_ = pcl::Indices();
  detail::resizeLarge(voxel_codes_, num_voxels);
  resizeScratch(n);
  // With leaves to keep (keepLeavesFrom()), the points under kept nodes never need
  // their angles: each is computed when a statistics pass first reaches it.
  lazy_angles_ = !previous_.leaves.empty();
  const Eigen::Matrix3d to_sensor =
      sensor_orientation_.toRotationMatrix().transpose().template cast<double>();
  detail::ParallelExceptions errors; // the tree's nodes may not fit in memory
#ifdef _OPENMP
#pragma omp parallel num_threads(num_threads_)
#endif
  {
    // On the calling thread: memory a worker thread allocates comes from its own
    // malloc arena, which would not reuse what the earlier stages freed.
#ifdef _OPENMP
#pragma omp master
#endif
    errors.run(build_tree);
#ifdef _OPENMP
#pragma omp for schedule(dynamic, 1024) nowait
#endif
    for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(n); ++k)
      computeNormalAngle(static_cast<std::size_t>(k), to_sensor, ordered_indices_.data(), n);
  }
  errors.rethrow();
  voxel_first_ = std::move(voxel_begin);
  angles_ready_ = true;
  return true;
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::orderPoints(const pcl::octree::OctreeNode* node,
                                                    pcl::octree::OctreeKey key)
{
  if (node->getNodeType() == pcl::octree::LEAF_NODE) {
    auto& container =
        const_cast<LeafNode*>(static_cast<const LeafNode*>(node))->getContainer();
    container.setFirstOrderedPoint(ordered_indices_.size());
    voxel_codes_.push_back(detail::mortonCode(key));
    voxel_first_.push_back(static_cast<pcl::uindex_t>(ordered_indices_.size()));
    ordered_indices_.insert(ordered_indices_.end(), container.begin(), container.end());
    return;
  }
  const auto* branch = static_cast<const BranchNode*>(node);
  for (unsigned char c = 0; c < 8; ++c)
    if (const auto* child = branch->getChildPtr(c)) {
      pcl::octree::OctreeKey child_key = key;
      child_key.pushBranch(c);
      orderPoints(child, child_key);
    }
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::resizeScratch(std::size_t n)
{
  detail::resizeLarge(ordered_normals_, n);
  // The sensor-frame angles are read only in that frame (computeStatistics()).
  const std::size_t angles = spread_frame_ == NormalSpreadFrame::Sensor ? n : 0;
  detail::resizeLarge(ordered_theta_, angles);
  detail::resizeLarge(ordered_phi_, angles);
  detail::resizeLarge(ordered_weights_, n);
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::computeNormalAngle(std::size_t k,
                                                           const Eigen::Matrix3d& to_sensor,
                                                           const pcl::index_t* indices,
                                                           std::size_t n)
{
  // The points are in Morton order, their normals and areas in vertex order: ask for
  // those of a point a few iterations ahead (a hint; no effect on the values).
  if (k + 16 < n && normal_vectors_) {
    const auto ahead = static_cast<std::size_t>(indices[k + 16]);
    __builtin_prefetch((*normal_vectors_).data() + ahead);
    __builtin_prefetch((*areas_).data() + ahead);
  }
  const auto i = static_cast<std::size_t>(indices[k]);
  const Eigen::Vector3d m =
      -(to_sensor * inputNormal(i).template cast<double>()).normalized();
  ordered_normals_[k] = m;
  if (spread_frame_ == NormalSpreadFrame::Sensor) {
    if (lazy_angles_) // computeStatistics() computes them when it reaches them
      ordered_theta_[k] = ordered_phi_[k] = std::numeric_limits<double>::quiet_NaN();
    else
      sensorAngles(k);
  }
  ordered_weights_[k] = 1.0 / (*areas_)[i]; // eq. 4: weight 1 / A_p
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::sensorAngles(std::size_t k)
{
  const Eigen::Vector3d& m = ordered_normals_[k];
  ordered_theta_[k] = std::atan2(m.x(), m.z());
  ordered_phi_[k] = std::atan2(m.y(), m.z());
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::computeNormalAngles()
{
  lazy_angles_ = false;
  const std::size_t n = ordered_indices_.size();
  resizeScratch(n);
  const Eigen::Matrix3d to_sensor =
      sensor_orientation_.toRotationMatrix().transpose().template cast<double>();
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(dynamic, 1024)
#endif
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(n); ++k)
    computeNormalAngle(static_cast<std::size_t>(k), to_sensor, ordered_indices_.data(), n);
}

template <typename PointT>
typename OctreePointCloudNormalVariance<PointT>::NodeStatistics
OctreePointCloudNormalVariance<PointT>::computeStatistics(std::size_t begin,
                                                          std::size_t end,
                                                          double split_above)
{
  NodeStatistics s;
  for (std::size_t k = begin; k < end; ++k) {
    const double w = ordered_weights_[k];
    s.sum_weighted_normal += w * ordered_normals_[k];
    s.sum_weight += w;
  }
  const Eigen::Vector3d mean = s.sum_weighted_normal.normalized();
  const bool sensor_frame = spread_frame_ == NormalSpreadFrame::Sensor;
  const double theta_v = sensor_frame ? std::atan2(mean.x(), mean.z()) : 0.0;
  const double phi_v = sensor_frame ? std::atan2(mean.y(), mean.z()) : 0.0;
  // NormalSpreadFrame::MeanNormal: the voxel's frame (u, v, mean), in which the mean
  // normal has the angles (0, 0) of a surface seen head-on.
  Eigen::Vector3d u = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
  if (!sensor_frame)
    detail::tangentAxes(mean, u, v);
  double var_theta = 0.0, var_phi = 0.0;
  for (std::size_t k = begin; k < end;) {
    const std::size_t block_end = std::min(end, k + 256);
    if (sensor_frame) {
      if (lazy_angles_) // the angles of the points this pass reaches, once
        for (std::size_t j = k; j < block_end; ++j)
          if (std::isnan(ordered_theta_[j]))
            sensorAngles(j);
      for (; k < block_end; ++k) {
        const double w = ordered_weights_[k];
        const double dt = detail::wrapAngle(ordered_theta_[k] - theta_v);
        const double dp = detail::wrapAngle(ordered_phi_[k] - phi_v);
        var_theta += w * dt * dt; // eq. 5
        var_phi += w * dp * dp;
      }
    }
    else {
      for (; k < block_end; ++k) {
        const double w = ordered_weights_[k];
        const Eigen::Vector3d& m = ordered_normals_[k];
        const double c = m.dot(mean);
        const double dt = std::atan2(m.dot(u), c); // eq. 5 in the voxel's frame
        const double dp = std::atan2(m.dot(v), c);
        var_theta += w * dt * dt;
        var_phi += w * dp * dp;
      }
    }
    s.sigma_theta = std::sqrt(var_theta / s.sum_weight);
    s.sigma_phi = std::sqrt(var_phi / s.sum_weight);
    // The terms are finite and non-negative (finite weights), so the partial sums never
    // decrease: once a partial sigma exceeds the threshold the whole one does.
    if (s.sigma_theta > split_above || s.sigma_phi > split_above) {
      s.complete = k == end;
      return s;
    }
  }
  return s;
}

template <typename PointT>
AdaptiveLeaf
OctreePointCloudNormalVariance<PointT>::makeLeaf(const PendingNode& node,
                                                 const NodeStatistics& s) const
{
  AdaptiveLeaf leaf;
  leaf.key = node.key;
  leaf.depth = node.depth;
  leaf.begin = node.begin;
  leaf.end = node.end;
  const Eigen::Matrix3d to_cloud =
      sensor_orientation_.toRotationMatrix().template cast<double>();
  leaf.normal =
      (-(to_cloud * s.sum_weighted_normal)).normalized().template cast<float>();
  // eq. 6: the leaf's area, summed in the leaf's point order (only leaves need it).
  double area = 0.0;
  for (std::size_t k = node.begin; k < node.end; ++k)
    area += (*areas_)[static_cast<std::size_t>(ordered_indices_[k])];
  leaf.area = area;
  leaf.sigma_theta = static_cast<float>(s.sigma_theta);
  leaf.sigma_phi = static_cast<float>(s.sigma_phi);
  return leaf;
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::computeAdaptiveLeaves(
    double max_std_dev, std::size_t min_points_to_split)
{
  leaves_.clear();
  // keepLeavesFrom() applies to this call only.
  const PreviousLeaves previous = std::move(previous_);
  previous_ = PreviousLeaves();
  num_kept_leaves_ = 0;
  const bool angles_ready = angles_ready_;
  angles_ready_ = false;
  if (!angles_ready) {
    // The leaf containers may view ordered_indices_ (insertPoints(true)): that array
    // moves, its storage unchanged, to voxel_indices_ before the ordering is made again.
    if (leaves_view_ordered_) {
      voxel_indices_ = std::move(ordered_indices_);
      leaves_view_ordered_ = false;
    }
    ordered_indices_ = pcl::Indices();
    releaseScratch();
  }
  if (this->leaf_count_ == 0 || !this->root_node_ || !checkDepth()) {
    releaseScratch();
    return;
  }
  // The same ranges as SelectiveSegmentationParameters::validate().
  const bool threshold_ok = max_std_dev > 0.0 && max_std_dev <= M_PI;
  const bool orientation_ok = sensor_orientation_.coeffs().allFinite() &&
                              sensor_orientation_.coeffs().squaredNorm() > 0.0f;
  if (!threshold_ok || !orientation_ok) {
    if (!threshold_ok)
      PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] the split "
                "threshold is %g rad: it must lie in (0, pi]; no leaves\n",
                max_std_dev);
    else
      PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] the sensor "
                "orientation is not a finite, non-zero quaternion; no leaves\n");
    releaseScratch();
    return;
  }
  if (!angles_ready) {
    ordered_indices_.reserve(this->indices_ ? this->indices_->size()
                                            : this->input_->size());
    voxel_codes_.reserve(this->leaf_count_);
    voxel_first_.reserve(this->leaf_count_);
    orderPoints(this->root_node_, pcl::octree::OctreeKey());
    // OctreePointCloud's own insertion methods (addPointToCloud(), its
    // addPointsFromInputCloud() through a base reference) are not virtual and check
    // nothing: a point they added may have no normal or area.
    const bool all_valid = hasNormalsAndAreas() && std::all_of(ordered_indices_.begin(),
                                                               ordered_indices_.end(),
                                                               [this](pcl::index_t i) {
                                                                 return isValidPoint(i);
                                                               });
    if (!all_valid) {
      PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] the tree holds a "
                "point without a finite normal and a positive area: add the points "
                "with this class's addPointsFromInputCloud(), not OctreePointCloud's "
                "insertion methods\n");
      ordered_indices_ = pcl::Indices();
      releaseScratch();
      return;
    }
    computeNormalAngles();
  }
  const std::size_t min_points = std::max<std::size_t>(min_points_to_split, 2);
  const bool finite_weights = std::all_of(ordered_weights_.begin(),
                                          ordered_weights_.end(),
                                          [](double w) { return std::isfinite(w); });
  const double kNever = std::numeric_limits<double>::infinity();
  // Level by level from the root: the statistics of a level's nodes in parallel (each
  // node one sequential pass, so the same sums for any thread count), then the
  // decisions in order. A node splits while sigma_theta or sigma_phi > max_std_dev
  // (eq. 5) and it is a branch with at least min_points points. A node is a run of the
  // finest voxels (their codes share its prefix); a branch is a node above the leaf
  // level, and its children are the runs of the next three bits of the codes.
  const std::size_t n = ordered_indices_.size();
  const std::size_t num_voxels = voxel_codes_.size();
  const auto tree_depth = static_cast<std::uint32_t>(this->octree_depth_);
  const auto points_of = [&](const PendingNode& node) {
    return std::make_pair(static_cast<std::size_t>(voxel_first_[node.first_voxel]),
                          node.end_voxel < num_voxels
                              ? static_cast<std::size_t>(voxel_first_[node.end_voxel])
                              : n);
  };
  // Calls f(child's first voxel, its end voxel, its number) for each child of a branch,
  // in the order of their numbers (PCL's child order: the codes' order).
  const auto for_each_child = [&](const PendingNode& node, const auto& f) {
    const unsigned shift = 3 * (tree_depth - 1 - node.depth);
    for (std::size_t v = node.first_voxel; v < node.end_voxel;) {
      const std::uint64_t prefix = voxel_codes_[v] >> shift;
      const std::size_t end = static_cast<std::size_t>(
          std::lower_bound(voxel_codes_.begin() + static_cast<std::ptrdiff_t>(v),
                           voxel_codes_.begin() +
                               static_cast<std::ptrdiff_t>(node.end_voxel),
                           (prefix + 1) << shift) -
          voxel_codes_.begin());
      f(v, end, static_cast<unsigned char>(prefix & 7u));
      v = end;
    }
  };
  // Leaves kept from a previous tree (keepLeavesFrom()): the first finest-voxel code of
  // each previous leaf, and the codes of the finest voxels whose points changed.
  const bool keep =
      !previous.leaves.empty() &&
      previous.settings == leafSettings(max_std_dev, min_points_to_split) &&
      num_voxels > 0 && tree_depth <= 21; // 63-bit codes
  std::vector<std::uint64_t> previous_first, changed_codes;
  if (keep) {
    previous_first.reserve(previous.leaves.size());
    for (const AdaptiveLeaf& leaf : previous.leaves)
      previous_first.push_back(detail::mortonCode(leaf.key)
                               << (3 * (tree_depth - leaf.depth)));
    for (const Eigen::Vector3f& position : previous.changed) {
      PointT point;
      point.x = position.x();
      point.y = position.y();
      point.z = position.z();
      if (!position.allFinite() || !this->isPointWithinBoundingBox(point))
        continue; // in neither tree: the box is the same
      pcl::octree::OctreeKey key;
      this->genOctreeKeyforPoint(point, key);
      changed_codes.push_back(detail::mortonCode(key));
    }
    std::sort(changed_codes.begin(), changed_codes.end());
  }
  // The previous leaves [first, end) under a node whose finest voxels hold no changed
  // position (then it holds the same points as before, in the same order), if the
  // previous tree went down to it; (0, 0) otherwise.
  const auto kept_leaves = [&](const PendingNode& node) {
    const std::pair<std::size_t, std::size_t> none(0, 0);
    if (!keep)
      return none;
    const unsigned shift = 3 * (tree_depth - node.depth);
    const std::uint64_t lo = (voxel_codes_[node.first_voxel] >> shift) << shift;
    const std::uint64_t hi = lo + (std::uint64_t{1} << shift);
    const auto changed =
        std::lower_bound(changed_codes.begin(), changed_codes.end(), lo);
    if (changed != changed_codes.end() && *changed < hi)
      return none;
    const auto first =
        std::lower_bound(previous_first.begin(), previous_first.end(), lo);
    const auto end = std::lower_bound(first, previous_first.end(), hi);
    const auto a = static_cast<std::size_t>(first - previous_first.begin());
    const auto b = static_cast<std::size_t>(end - previous_first.begin());
    // None when the previous tree stopped above the node: a previous leaf holds it,
    // starting before it (then none starts inside) or with it (then that leaf is
    // shallower than the node, even if all of its points lie in this node).
    if (a == b || previous.leaves[a].depth < node.depth ||
        previous.leaves[b - 1].end - previous.leaves[a].begin != node.end - node.begin)
      return none;
    return std::make_pair(a, b);
  };
  std::vector<PendingNode> level(1), next;
  level[0].first_voxel = 0;
  level[0].end_voxel = num_voxels;
  std::vector<NodeStatistics> stats;
  std::vector<std::uint8_t> split;
  // A leaf's place in leaves_; a branch's number of children, then its first child's
  // place in next.
  std::vector<std::size_t> slot;
  std::vector<std::pair<std::size_t, std::size_t>> kept; // kept_leaves() of each node
  while (!level.empty()) {
    stats.resize(level.size());
    split.resize(level.size());
    slot.resize(level.size());
    kept.resize(level.size());
    // One node (the root) is one thread's work. (Read by the pragmas only.)
    [[maybe_unused]] const bool parallel = level.size() > 1;
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(dynamic, 8) if (parallel)
#endif
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(level.size()); ++i) {
      PendingNode& node = level[i];
      std::tie(node.begin, node.end) = points_of(node);
      kept[i] = kept_leaves(node);
      if (kept[i].second > kept[i].first) {
        split[i] = 0;
        slot[i] = 0;
        continue;
      }
      // A node that may split needs its sigmas only until one exceeds the threshold.
      const bool can_split =
          node.depth < tree_depth && node.end - node.begin >= min_points;
      stats[i] = computeStatistics(
          node.begin, node.end, can_split && finite_weights ? max_std_dev : kNever);
      const bool varies =
          stats[i].sigma_theta > max_std_dev || stats[i].sigma_phi > max_std_dev;
      split[i] = varies && can_split;
      std::size_t num_children = 0;
      if (split[i])
        for_each_child(
            node, [&](std::size_t, std::size_t, unsigned char) { ++num_children; });
      slot[i] = num_children;
    }
    // Places: leaves after the earlier levels' ones, children in the order of their
    // parents.
    const std::size_t first_new_leaf = leaves_.size();
    std::size_t num_new_leaves = 0, num_children = 0;
    for (std::size_t i = 0; i < level.size(); ++i) {
      if (split[i]) {
        const std::size_t count = slot[i];
        slot[i] = num_children;
        num_children += count;
      } else {
        slot[i] = first_new_leaf + num_new_leaves;
        num_new_leaves += std::max<std::size_t>(1, kept[i].second - kept[i].first);
        num_kept_leaves_ += kept[i].second - kept[i].first;
      }
    }
    next.resize(num_children);
    // Grown by exactly this level's leaves: doubling would hold three times the leaves
    // at the pipeline's peak of memory. The leaves (their areas are one pass over
    // their points) and the children are made in parallel, each into its own slot.
    leaves_.reserve(first_new_leaf + num_new_leaves);
    leaves_.resize(first_new_leaf + num_new_leaves);
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(dynamic, 64) if (parallel)
#endif
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(level.size()); ++i) {
      const PendingNode& node = level[i];
      if (!split[i]) {
        if (kept[i].second == kept[i].first) {
          leaves_[slot[i]] = makeLeaf(node, stats[i]);
          continue;
        }
        // The previous leaves, moved to the node's place in the new order.
        const std::size_t previous_begin = previous.leaves[kept[i].first].begin;
        for (std::size_t k = kept[i].first; k < kept[i].second; ++k) {
          AdaptiveLeaf leaf = previous.leaves[k];
          leaf.begin = node.begin + (leaf.begin - previous_begin);
          leaf.end = node.begin + (leaf.end - previous_begin);
          leaf.kept_from = static_cast<std::int32_t>(k);
          leaves_[slot[i] + (k - kept[i].first)] = leaf;
        }
        continue;
      }
      std::size_t place = slot[i];
      for_each_child(node, [&](std::size_t first, std::size_t end, unsigned char c) {
        PendingNode& child = next[place++];
        child.first_voxel = first;
        child.end_voxel = end;
        child.key = node.key;
        child.key.pushBranch(c);
        child.depth = node.depth + 1;
      });
    }
    // Depth-first order: the leaves' point ranges are disjoint and ordered so; each
    // level's leaves come in that order.
    std::inplace_merge(
        leaves_.begin(),
        leaves_.begin() + static_cast<std::ptrdiff_t>(first_new_leaf),
        leaves_.end(),
        [](const AdaptiveLeaf& a, const AdaptiveLeaf& b) { return a.begin < b.begin; });
    level.swap(next);
  }
  leaves_max_std_dev_ = max_std_dev;
  leaves_min_points_ = min_points_to_split;
  lazy_angles_ = false;
  // The per-point scratch is not needed any more (the leaves hold their statistics).
  releaseScratch();
}

template <typename PointT>
typename OctreePointCloudNormalVariance<PointT>::PreviousLeaves
OctreePointCloudNormalVariance<PointT>::getPreviousLeaves() const
{
  PreviousLeaves p;
  p.leaves = leaves_;
  p.settings = leafSettings(leaves_max_std_dev_, leaves_min_points_);
  return p;
}

template <typename PointT>
typename OctreePointCloudNormalVariance<PointT>::LeafSettings
OctreePointCloudNormalVariance<PointT>::leafSettings(
    double max_std_dev, std::size_t min_points_to_split) const
{
  LeafSettings s;
  this->getBoundingBox(s.box_min.x(),
                       s.box_min.y(),
                       s.box_min.z(),
                       s.box_max.x(),
                       s.box_max.y(),
                       s.box_max.z());
  s.resolution = this->resolution_;
  s.depth = this->octree_depth_;
  s.max_std_dev = max_std_dev;
  s.min_points_to_split = min_points_to_split;
  s.frame = spread_frame_;
  s.orientation = sensor_orientation_;
  return s;
}

template <typename PointT>
void
OctreePointCloudNormalVariance<PointT>::releaseScratch()
{
  decltype(ordered_normals_)().swap(ordered_normals_);
  decltype(ordered_theta_)().swap(ordered_theta_);
  decltype(ordered_phi_)().swap(ordered_phi_);
  decltype(ordered_weights_)().swap(ordered_weights_);
  decltype(voxel_codes_)().swap(voxel_codes_);
  decltype(voxel_first_)().swap(voxel_first_);
}

template <typename PointT>
double
OctreePointCloudNormalVariance<PointT>::getVoxelSideLength(std::uint32_t depth) const
{
  return this->resolution_ *
         static_cast<double>(
             1ULL << (this->octree_depth_ - std::min(depth, this->octree_depth_)));
}

template <typename PointT>
Eigen::Vector3f
OctreePointCloudNormalVariance<PointT>::getVoxelCentre(const AdaptiveLeaf& leaf) const
{
  const double side = getVoxelSideLength(leaf.depth);
  return Eigen::Vector3f(static_cast<float>((leaf.key.x + 0.5) * side + this->min_x_),
                         static_cast<float>((leaf.key.y + 0.5) * side + this->min_y_),
                         static_cast<float>((leaf.key.z + 0.5) * side + this->min_z_));
}

} // namespace selective_seg
} // namespace pcl
