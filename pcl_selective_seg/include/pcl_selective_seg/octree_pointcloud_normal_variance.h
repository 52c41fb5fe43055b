/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/adaptive_leaf.h>
#include <pcl_selective_seg/octree_normal_variance_container.h>
#include <pcl_selective_seg/parameters.h>

#include <Eigen/Geometry>
#include <pcl/console/print.h>
#include <pcl/octree/octree_pointcloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief std::allocator whose resize() leaves new elements default-initialized (so
 * trivial ones not written), for scratch arrays that are written in full right after,
 * in parallel: the zero fill would be a sequential pass over them. */
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept
  {
  }
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value)
  {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args)
  {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/** \brief A scratch array whose resize() does not zero its elements. */
template <typename T>
using ScratchVector = std::vector<T, DefaultInitAllocator<T>>;

} // namespace detail

/** \brief Multi-resolution octree whose voxels split while their normals vary (paper,
 * Sec. III.C, eq. 3-5).
 *
 * The tree is a PCL octree built to the finest level (the resolution, i.e. the minimum
 * voxel size). computeAdaptiveLeaves() then walks it from the root and keeps as leaves
 * the highest nodes whose weighted standard deviation of the normal angles (eq. 5) is
 * at most the threshold on both axes, or that hold fewer than a minimum number of
 * points, or that are finest voxels.
 *
 * Normal angles: theta = atan2(m_x, m_z), phi = atan2(m_y, m_z) of m = -R^T n, the
 * normal n (oriented toward the sensor, as pcl::flipNormalTowardsViewpoint leaves it)
 * reversed and expressed in the sensor frame (R = sensor orientation). A surface facing
 * the sensor then sits near (0, 0) rather than at the +-pi seam. Deviations from the
 * voxel's angle are wrapped into (-pi, pi].
 *
 * The bounding box is taken from the points before insertion, so the tree, which
 * points each leaf holds, and the leaves' order do not depend on the order of the
 * points. A node's sums (eq. 3-5) run over its points in index order, so the same
 * points in another order can give other last bits of a leaf's normal, area and
 * sigmas (and, for a sigma within rounding of the threshold, another split). The
 * segmentation gives the octree its vertices in a canonical order (sorted by angle),
 * so its leaves do not depend on the order of the input cloud's points.
 *
 * Use: setInputCloud(), setInputNormals(), then addPointsFromInputCloud() and
 * computeAdaptiveLeaves() (which may run again with other thresholds), or
 * addPointsAndComputeAdaptiveLeaves(), which gives the same tree and leaves and on
 * several threads computes the normal angles while it builds the tree.
 */
template <typename PointT>
class OctreePointCloudNormalVariance
    : public pcl::octree::OctreePointCloud<PointT,
                                           OctreeNormalVarianceContainer,
                                           pcl::octree::OctreeContainerEmpty> {
public:
  using Ptr = pcl::shared_ptr<OctreePointCloudNormalVariance<PointT>>;
  using ConstPtr = pcl::shared_ptr<const OctreePointCloudNormalVariance<PointT>>;
  using OctreeT = pcl::octree::OctreePointCloud<PointT,
                                                OctreeNormalVarianceContainer,
                                                pcl::octree::OctreeContainerEmpty>;
  using NormalCloud = pcl::PointCloud<pcl::Normal>;
  using NormalCloudConstPtr = typename NormalCloud::ConstPtr;
  using AreasConstPtr = std::shared_ptr<const std::vector<double>>;
  using NormalVectors = std::vector<Eigen::Vector3f>;
  using NormalVectorsConstPtr = std::shared_ptr<const NormalVectors>;

  /** \param[in] resolution finest voxel edge [m], > 0 */
  explicit OctreePointCloudNormalVariance(double resolution);

  /** \brief Per-point normals and point areas A_p (eq. 3), one of each per point of
   * the input cloud (the insertion refuses other counts). Points whose normal is not
   * finite or is zero, or whose area is not positive (or so small that eq. 4's weight
   * 1 / A_p overflows), are skipped by addPointsFromInputCloud(). */
  void setInputNormals(const NormalCloudConstPtr& normals, const AreasConstPtr& areas);

  /** \brief The same with the normals as plain 3-vectors (12 bytes per point instead of
   * pcl::Normal's 32): no copy is needed when they are kept that way. */
  void setInputNormals(const NormalVectorsConstPtr& normals,
                       const AreasConstPtr& areas);

  /** \brief Threads for the per-point work (0: defaultThreads(); at most 1,024); the
   * result does not depend on it. */
  void setNumberOfThreads(unsigned int threads)
  {
    num_threads_ = threads
                       ? std::min(threads, static_cast<unsigned>(detail::kMaxThreads))
                       : defaultThreads();
  }

  /** \brief Orientation of the sensor in the cloud frame (the angles of eq. 5 are
   * measured in the sensor frame), a unit quaternion. Default: identity. One that is
   * not finite or is zero gives no leaves (computeAdaptiveLeaves()). */
  void setSensorOrientation(const Eigen::Quaternionf& orientation)
  {
    sensor_orientation_ = orientation;
  }

  /** \brief Frame of eq. 5's normal angles (NormalSpreadFrame). Default: Sensor,
   * the paper's. */
  void setNormalSpreadFrame(NormalSpreadFrame frame) { spread_frame_ = frame; }
  NormalSpreadFrame getNormalSpreadFrame() const { return spread_frame_; }

  /** Deepest tree supported: a finest voxel's depth-first code interleaves 21 bits
   * of each key in 64 bits. */
  static constexpr unsigned kMaxDepth = 21;

  /** \brief Fit the bounding box to the valid points and insert them. Replaces
   * OctreePointCloud::addPointsFromInputCloud (which ignores normals and grows the
   * box in insertion order); into a tree that already holds points they are inserted
   * as PCL's octree does, its box kept or grown. A point is valid when it is finite,
   * its normal finite and not zero, and its area positive with a finite inverse (eq.
   * 4's weight). \return false, with a PCL_ERROR, when the resolution is not positive
   * and finite, the normals or areas are missing or not one per point, an index names
   * no point of the cloud, or the points need more than kMaxDepth levels of the
   * resolution (into a tree that holds points: nothing is inserted when the grown box
   * would need more); false when no point is valid or no cloud is set. */
  bool addPointsFromInputCloud();

  /** \brief Split from the root while sigma_theta or sigma_phi > max_std_dev [rad]
   * and the node holds at least min_points_to_split points (eq. 4-5). No leaves, with
   * a PCL_ERROR, when max_std_dev is not in (0, pi] (SelectiveSegmentationParameters'
   * range), the sensor orientation is not finite or is zero, or the tree holds a
   * point without a finite, non-zero normal and a positive area (one added by
   * OctreePointCloud's own insertion methods). */
  void computeAdaptiveLeaves(double max_std_dev, std::size_t min_points_to_split);

  /** \brief addPointsFromInputCloud() then computeAdaptiveLeaves(): the same tree and
   * leaves, faster on several threads (the normal angles of eq. 5 are computed while
   * the tree is built). \return false when no point could be inserted. */
  bool addPointsAndComputeAdaptiveLeaves(double max_std_dev,
                                         std::size_t min_points_to_split);

  /** \brief The leaves, in depth-first (Morton) order. */
  const std::vector<AdaptiveLeaf>& getAdaptiveLeaves() const { return leaves_; }

  /** \brief OctreePointCloud::setResolution() for a positive, finite \a resolution
   * [m]; any other is refused with a PCL_ERROR and the resolution kept (PCL's own
   * converts it to voxel counts out of range). */
  void setResolution(double resolution)
  {
    if (!(resolution > 0.0) || !std::isfinite(resolution)) {
      PCL_ERROR("[pcl::selective_seg::OctreePointCloudNormalVariance] resolution %g "
                "refused: it must be positive and finite\n",
                resolution);
      return;
    }
    OctreeT::setResolution(resolution);
  }

  /** \brief OctreePointCloud::deleteTree(), and the adaptive leaves and ordered
   * indices with it. (Called through a reference to the base class, PCL's alone runs:
   * the leaves then stay until the next computeAdaptiveLeaves().) */
  void deleteTree()
  {
    OctreeT::deleteTree();
    leaves_.clear();
    ordered_indices_ = pcl::Indices();
    voxel_indices_ = pcl::Indices();
    leaves_view_ordered_ = false;
    angles_ready_ = false;
    num_kept_leaves_ = 0;
    releaseScratch();
  }

  /** \brief What a tree's leaves depend on besides its points: the box, finest
   * voxel and depth, the thresholds, the frame of eq. 5's angles and the sensor
   * orientation. */
  struct LeafSettings {
    Eigen::Vector3d box_min = Eigen::Vector3d::Zero();
    Eigen::Vector3d box_max = Eigen::Vector3d::Zero();
    double resolution = 0.0;
    unsigned int depth = 0;
    double max_std_dev = 0.0;
    std::size_t min_points_to_split = 0;
    NormalSpreadFrame frame = NormalSpreadFrame::Sensor;
    Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();

    bool operator==(const LeafSettings& other) const
    {
      return box_min == other.box_min && box_max == other.box_max &&
             resolution == other.resolution && depth == other.depth &&
             max_std_dev == other.max_std_dev &&
             min_points_to_split == other.min_points_to_split && frame == other.frame &&
             orientation.coeffs() == other.orientation.coeffs();
    }
  };

  /** \brief What the next computeAdaptiveLeaves() of another tree may keep from this
   * one (SelectiveSegmentation::update()): its leaves and what they were made with. */
  struct PreviousLeaves {
    std::vector<AdaptiveLeaf> leaves; ///< depth-first order
    LeafSettings settings;
    /** Positions whose voxel's points changed since: points added or removed, moved
     * (the old and the new position), or whose normal or area changed. */
    std::vector<Eigen::Vector3f> changed;
  };

  /** \brief This tree's leaves and what they were made with (PreviousLeaves::changed
   * empty); no leaves before computeAdaptiveLeaves(). */
  PreviousLeaves getPreviousLeaves() const;

  /** \brief Lets the next computeAdaptiveLeaves() keep the leaves of \a previous under
   * every node whose finest voxels hold no changed position, when the two trees have
   * the same box, resolution and depth and the leaves were made with the same
   * thresholds, frame and orientation. Such a node holds the same points, normals and
   * areas in the same order, so its statistics, its splits and its leaves would be the
   * same: the leaves are the ones computeAdaptiveLeaves() would make, bit for bit. */
  void keepLeavesFrom(PreviousLeaves previous) { previous_ = std::move(previous); }

  /** \brief Leaves the last computeAdaptiveLeaves() kept from keepLeavesFrom(). */
  std::size_t getNumKeptLeaves() const { return num_kept_leaves_; }

  /** \brief Input point indices in depth-first order; each leaf owns a range. */
  const pcl::Indices& getOrderedIndices() const { return ordered_indices_; }

  /** \brief Edge length of a node at the given depth [m]. */
  double getVoxelSideLength(std::uint32_t depth) const;

  /** \brief Centre of a node [m], cloud frame. */
  Eigen::Vector3f getVoxelCentre(const AdaptiveLeaf& leaf) const;

protected:
  using BranchNode = typename OctreeT::BranchNode;
  using LeafNode = typename OctreeT::LeafNode;

  struct NodeStatistics {
    Eigen::Vector3d sum_weighted_normal = Eigen::Vector3d::Zero();
    double sum_weight = 0.0;
    double sigma_theta = 0.0;
    double sigma_phi = 0.0;
    bool complete = true; ///< false: sigmas of a prefix only (computeStatistics())
  };

  bool isValidPoint(pcl::index_t index) const;

  /** \brief Order the points depth first, and list the finest voxels (leaf nodes) in
   * that order; \a key is the key of \a node. */
  void orderPoints(const pcl::octree::OctreeNode* node, pcl::octree::OctreeKey key);

  /** \brief Normals, angles and areas of the ordered points (in parallel). */
  void computeNormalAngles();

  /** \brief The scratch of computeNormalAngles() for the ordered point \a k, of index
   * indices[k] (n points). */
  void computeNormalAngle(std::size_t k,
                          const Eigen::Matrix3d& to_sensor,
                          const pcl::index_t* indices,
                          std::size_t n);

  void resizeScratch(std::size_t n);

  /** \brief Inserts the valid points; with_angles: also orders them and computes their
   * normal angles for the next computeAdaptiveLeaves() (bulk insertion only). */
  bool insertPoints(bool with_angles);
  /** \brief Whether the tree's depth is at most kMaxDepth; else a PCL_ERROR. */
  bool checkDepth() const;

  /** \brief Frees the per-point normals, angles and weights (computeNormalAngles()),
   * needed only while computeAdaptiveLeaves() runs. */
  void releaseScratch();

  /** \brief eq. 4-6 over ordered points [begin, end). With \a split_above finite,
   * stops as soon as a sigma over a prefix of the points exceeds it (then the node's
   * sigma does too: the node splits and needs no more). */
  NodeStatistics
  computeStatistics(std::size_t begin,
                    std::size_t end,
                    double split_above = std::numeric_limits<double>::infinity());

  /** \brief The sensor-frame angles of ordered point \a k from its normal. */
  void sensorAngles(std::size_t k);

  /** \brief A node met while descending from the root: its finest voxels
   * [first_voxel, end_voxel) (a run of voxel_codes_) and its point range. */
  struct PendingNode {
    std::size_t first_voxel = 0;
    std::size_t end_voxel = 0;
    pcl::octree::OctreeKey key;
    std::uint32_t depth = 0;
    std::size_t begin = 0;
    std::size_t end = 0;
  };

  /** \brief A node kept as a leaf, with its statistics. */
  AdaptiveLeaf makeLeaf(const PendingNode& node, const NodeStatistics& s) const;

  /** \brief This tree's LeafSettings with these thresholds. */
  LeafSettings leafSettings(double max_std_dev, std::size_t min_points_to_split) const;

private:
  /** Whether normals (in either form) and areas were given. */
  bool hasNormalsAndAreas() const { return (normals_ || normal_vectors_) && areas_; }

  /** The input normal of point \a i, from whichever form was given. */
  Eigen::Vector3f inputNormal(std::size_t i) const
  {
    return normals_ ? Eigen::Vector3f((*normals_)[i].getNormalVector3fMap())
                    : (*normal_vectors_)[i];
  }
  std::size_t numInputNormals() const
  {
    return normals_ ? normals_->size() : normal_vectors_ ? normal_vectors_->size() : 0;
  }

  NormalCloudConstPtr normals_;
  NormalVectorsConstPtr normal_vectors_;
  AreasConstPtr areas_;
  Eigen::Quaternionf sensor_orientation_ = Eigen::Quaternionf::Identity();
  NormalSpreadFrame spread_frame_ = NormalSpreadFrame::Sensor;
  /** The indices of the leaves built by addPointsFromInputCloud(), leaf after leaf;
   * their containers view them. Assigned only while the tree is empty
   * (addPointsAndComputeAdaptiveLeaves() stores them in ordered_indices_). */
  pcl::Indices voxel_indices_;
  pcl::Indices ordered_indices_;
  /** The finest voxels (the tree's leaf nodes) in depth-first order: their Morton codes
   * (increasing) and the first of their points in ordered_indices_. A node of the tree
   * is a run of them (its code prefix), so computeAdaptiveLeaves() finds a node's
   * points and children without walking the tree. Kept while computeAdaptiveLeaves()
   * needs them, like the scratch. */
  std::vector<std::uint64_t> voxel_codes_;
  std::vector<pcl::uindex_t> voxel_first_;
  /** ordered_indices_ and the scratch were made by insertPoints(true) for the next
   * computeAdaptiveLeaves(). */
  bool angles_ready_ = false;
  /** The leaf containers view ordered_indices_ (insertPoints(true)), not voxel_indices_.
   */
  bool leaves_view_ordered_ = false;
  detail::ScratchVector<Eigen::Vector3d> ordered_normals_; ///< sensor frame, reversed
  /** Sensor-frame angles of ordered_normals_ [rad] (NormalSpreadFrame::Sensor only) */
  detail::ScratchVector<double> ordered_theta_;
  detail::ScratchVector<double> ordered_phi_;
  detail::ScratchVector<double> ordered_weights_; ///< 1 / A_p (eq. 4)
  std::vector<AdaptiveLeaf> leaves_;
  /** The thresholds the leaves were made with (getPreviousLeaves()). */
  double leaves_max_std_dev_ = 0.0;
  std::size_t leaves_min_points_ = 0;
  PreviousLeaves previous_; ///< keepLeavesFrom(), used once
  /** The sensor-frame angles are computed when a statistics pass reaches them (NaN
   * until then), not all in advance: insertPoints() with leaves to keep. */
  bool lazy_angles_ = false;
  std::size_t num_kept_leaves_ = 0;
  unsigned int num_threads_ = defaultThreads();
};

} // namespace selective_seg
} // namespace pcl

// The octree always compiles its bodies, like PCL's own octrees with custom containers.
#include <pcl_selective_seg/impl/octree_pointcloud_normal_variance.hpp>

// The library's instantiations (point_types.h) are used as they are: a program's own
// copies of them (implicit instantiations, weak symbols) would take their place at
// load time, compiled with that program's flags (without OpenMP: the stages on one
// thread) and recompiled in every file that uses them. Declared whether or not
// PCL_NO_PRECOMPILE is defined: the library always holds them, and a program that
// defines it for its own point type must not replace them.
#include <pcl_selective_seg/point_types.h>
PCL_SELSEG_EXTERN_TEMPLATES(pcl::selective_seg::OctreePointCloudNormalVariance)
