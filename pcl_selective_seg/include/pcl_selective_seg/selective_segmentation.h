/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/mesh_normals.h>
#include <pcl_selective_seg/octree_pointcloud_normal_variance.h>
#include <pcl_selective_seg/parameters.h>
#include <pcl_selective_seg/segmentation_result.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <pcl/PointIndices.h>
#include <pcl/PolygonMesh.h>
#include <pcl/pcl_base.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <mutex>
#include <vector>

namespace pcl {
namespace selective_seg {

namespace detail {
/** \brief A value built on demand by const getters, under a mutex: readers on several
 * threads build it once, and a copy of its owner (a const operation too) reads it
 * under the same lock and gets a mutex of its own. */
template <typename T> class LockedCache {
public:
  LockedCache() = default;
  LockedCache(const LockedCache& other)
      : value_(other.get())
  {
  }
  LockedCache& operator=(const LockedCache& other)
  {
    if (this != &other) {
      T value = other.get();
      const std::lock_guard<std::mutex> lock(mutex_);
      value_ = std::move(value);
    }
    return *this;
  }
  T get() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return value_;
  }
  void reset()
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    value_ = T();
  }
  /** \brief The value; when empty, first make() under the lock. */
  template <typename Make> T getOrMake(const Make& make) const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!value_)
      value_ = make();
    return value_;
  }

private:
  mutable std::mutex mutex_;
  mutable T value_{};
};
} // namespace detail

struct MergeReplay; // region_merging.h

/** \brief What the last SelectiveSegmentation::update() changed. */
struct UpdateStatistics {
  /** The mesh and normals were updated in place; false: the pipeline ran from scratch
   * on the union, because the input cloud or the indices were set again since the run
   * being updated, the sensor pose or a parameter of stages 1-3 changed
   * (angle_quantization, max_view_incidence_angle, normal_rings,
   * point_normal_triangles), the projection is panoramic, VTK's backend made or
   * would make the mesh, or the local insertion failed its own checks
   * (docs/incremental_update.md, "When it runs from scratch"). Other parameters
   * (merge and split angles, weights, ...) may change between the calls: the update
   * stays in place and applies them. */
  bool incremental = false;
  std::size_t new_points = 0;     ///< points given to update()
  std::size_t new_vertices = 0;   ///< mesh vertices they added
  std::size_t moved_vertices = 0; ///< vertices now represented by a nearer new point
  std::size_t replaced_triangles = 0; ///< old triangles the insertion replaced
  std::size_t new_triangles = 0;      ///< triangles not in the old mesh
  /// Corners of the new triangles and of the old ones at a moved vertex: the vertices
  /// whose one-ring changed (with normal_rings > 1 the normals of the vertices up to
  /// normal_rings - 1 rings around them are recomputed too, and not counted here).
  std::size_t changed_vertices = 0;
  /** Octree leaves kept from the previous result: those under nodes whose finest
   * voxels hold no new, moved or changed vertex (the rest are computed again). */
  std::size_t kept_leaves = 0;
  /** Segments taken over from the previous merge instead of grown again: those whose
   * leaves were all kept and whose neighbourhood is in the state it was when they grew
   * (MergeReplay). */
  std::size_t replayed_segments = 0;
};

/** \brief Segmentation of a 3-D surface point cloud seen from one sensor viewpoint into
 * surface segments, for selective sensing.
 *
 * \note The method of "A Method to Segment a 3D Surface Point Cloud for Selective
 * Sensing in Robotic Exploration": (1) points mapped to the sensor's spherical space
 * (eq. 1), (2) Delaunay triangulation in (theta, phi), (3) point normals as the
 * 1 / area weighted mean of the incident triangle normals (eq. 2), (4) a multi-
 * resolution octree that splits voxels while the weighted standard deviation of their
 * normal angles exceeds a threshold (eq. 3-5), (5) every octree leaf a seed segment,
 * seeds merged across the mesh when their normals agree (eq. 6-10).
 *
 * Usage, as any PCL segmentation (the sensor pose is the cloud's sensor_origin_ and
 * sensor_orientation_, or setSensorPose()):
 * \code
 * pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
 * seg.setInputCloud(cloud);
 * std::vector<pcl::PointIndices> segments;  // largest first
 * if (seg.extract(segments))
 *   auto labeled = seg.getLabeledCloud();   // pcl::PointXYZL, input layout
 * \endcode
 *
 * Points outside the indices, with non-finite coordinates, at or behind the sensor
 * plane or without a normal get label 0 and are counted in getResult().counts. The
 * result depends on the point set only, not on the order of the points.
 *
 * Every stage works in the sensor frame, the paper's frame, so the segmentation does
 * not depend on where the sensor stood in the world; normals, leaf centres and the mesh
 * are reported in the cloud frame. The octree's voxels are aligned with the sensor
 * axes.
 */
template <typename PointT> class SelectiveSegmentation : public pcl::PCLBase<PointT> {
public:
  using Ptr = pcl::shared_ptr<SelectiveSegmentation<PointT>>;
  using ConstPtr = pcl::shared_ptr<const SelectiveSegmentation<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using LabeledCloud = pcl::PointCloud<pcl::PointXYZL>;
  using ColoredCloud = pcl::PointCloud<pcl::PointXYZRGB>;
  using ColoredCloudRGBA = pcl::PointCloud<pcl::PointXYZRGBA>;
  using NormalCloud = pcl::PointCloud<pcl::Normal>;
  /** The octree over the mesh vertices in the sensor frame (point i = vertex i). */
  using Octree = OctreePointCloudNormalVariance<pcl::PointXYZ>;

  SelectiveSegmentation() = default;

  /** \brief All parameters at once (checked by extract()). */
  void setParameters(const SelectiveSegmentationParameters& parameters)
  {
    params_ = parameters;
  }
  const SelectiveSegmentationParameters& getParameters() const { return params_; }

  /** \brief Octree split threshold on the normal angles' standard deviation [rad]. */
  void setMaxNormalStdDev(double angle) { params_.max_normal_std_dev = angle; }
  double getMaxNormalStdDev() const { return params_.max_normal_std_dev; }

  /** \brief Frame of eq. 5's normal angles; default the sensor frame (the paper). */
  void setNormalSpreadFrame(NormalSpreadFrame frame)
  {
    params_.normal_spread_frame = frame;
  }
  NormalSpreadFrame getNormalSpreadFrame() const { return params_.normal_spread_frame; }

  /** \brief Weight of a leaf's normal in its segment's normal (eq. 7); default
   * 1 / A_v (the paper). */
  void setSegmentNormalWeight(SegmentNormalWeight weight)
  {
    params_.segment_normal_weight = weight;
  }
  SegmentNormalWeight getSegmentNormalWeight() const
  {
    return params_.segment_normal_weight;
  }

  /** \brief Largest angle between segment normals that still merge (eq. 9) [rad]. */
  void setMaxMergeAngle(double angle) { params_.max_merge_angle = angle; }
  double getMaxMergeAngle() const { return params_.max_merge_angle; }

  /** \brief Largest angle between an edge triangle and a segment for the triangle to
   * be searched (eq. 8) [rad]. */
  void setMaxEdgeTriangleAngle(double angle)
  {
    params_.max_edge_triangle_angle = angle;
  }
  double getMaxEdgeTriangleAngle() const { return params_.max_edge_triangle_angle; }

  /** \brief Most oblique view of an edge triangle that still counts as surface [rad];
   * pi/2 (the paper) disables the test. */
  void setMaxViewIncidenceAngle(double angle)
  {
    params_.max_view_incidence_angle = angle;
  }
  double getMaxViewIncidenceAngle() const { return params_.max_view_incidence_angle; }

  /** \brief Neighbourhood of the point normals in mesh rings; 1 = the paper's eq. 2. */
  void setNormalRings(int rings) { params_.normal_rings = rings; }
  int getNormalRings() const { return params_.normal_rings; }

  /** \brief The triangles eq. 2 sums into a point normal; default all of them (the
   * paper). */
  void setPointNormalTriangles(PointNormalTriangles which)
  {
    params_.point_normal_triangles = which;
  }
  PointNormalTriangles getPointNormalTriangles() const
  {
    return params_.point_normal_triangles;
  }

  /** \brief Smallest voxel edge [m]; 0 = automatic (see the parameters). */
  void setMinVoxelSize(double size) { params_.min_voxel_size = size; }
  double getMinVoxelSize() const { return params_.min_voxel_size; }

  /** \brief Triangulation backend. */
  void setDelaunayBackend(DelaunayBackend backend)
  {
    params_.delaunay_backend = backend;
  }
  DelaunayBackend getDelaunayBackend() const { return params_.delaunay_backend; }

  /** \brief Threads of the parallel stages, as PCL's OpenMP classes take them: 0 =
   * automatic (defaultThreads(): OMP_NUM_THREADS, else the CPUs the process may use).
   * The result does not depend on it; extract() refuses more than 1,024. */
  void setNumberOfThreads(unsigned int nr_threads = 0)
  {
    params_.num_threads = static_cast<int>(std::min(nr_threads, 1u << 30));
  }
  unsigned int getNumberOfThreads() const
  {
    return static_cast<unsigned int>(params_.num_threads);
  }

  /** \brief Sensor pose in the cloud frame (the sensor looks along its +z axis),
   * overriding the cloud's sensor_origin_ / sensor_orientation_. */
  void setSensorPose(const Eigen::Affine3f& sensor_to_cloud)
  {
    delaunay_.setSensorPose(sensor_to_cloud);
  }
  /** \brief Use the input cloud's sensor_origin_ / sensor_orientation_ again. */
  void resetSensorPose() { delaunay_.resetSensorPose(); }
  /** \brief The sensor pose of the last run (setSensorPose()'s, or the cloud's), which
   * its results are in; before any run and after a failed one, the pose in use. */
  Eigen::Affine3f getSensorPose() const
  {
    return mesh_pose_.isZero() ? delaunay_.getSensorPose()
                               : Eigen::Affine3f(Eigen::Matrix4f(mesh_pose_));
  }

  /** \brief Run the whole pipeline.
   * \param[out] clusters the segments' point indices, largest first (segment i has
   *             label i + 1)
   * \return false, with a PCL_ERROR saying why and empty outputs, on a missing or
   *         unusable input or an invalid parameter, and when memory runs out
   *         (std::bad_alloc is caught, on every thread of the parallel stages too;
   *         the result is cleared; docs/reliability.md, "Out of memory"). After a
   *         failure the run's outputs are empty (getResult(), the clouds, the mesh,
   *         the octree, the triangulation), but for getResult().counts, which keep
   *         the points the triangulation set aside and why, as far as it got (the
   *         others are 0); getUpdateStatistics() describes the last update() call. */
  bool extract(std::vector<pcl::PointIndices>& clusters);

  /** \brief Fold more points of the same scene, seen from the same sensor pose, into
   * the result of the last successful extract() or update() (selective sensing: a
   * finer scan of some regions of interest).
   *
   * The input becomes a new cloud: the previous input followed by \a new_points
   * (given in the same frame as the input; unorganized, height 1). With indices set,
   * the new points' indices are appended to them. The finest voxel size of the run
   * being updated is kept (unless setMinVoxelSize() set a positive size, which is
   * then used), so the result is that of extract() on the union with
   * setMinVoxelSize(getResult().min_voxel_size), bit for bit
   * (docs/incremental_update.md: what is recomputed, and when it runs from scratch).
   * If the input cloud or the indices were set again since that run, the union of the
   * current input and \a new_points is segmented from scratch. The input cloud must
   * not be modified in place between the calls.
   * \param[in] new_points the points to add
   * \param[out] clusters as extract(), over the union
   * \return as extract(); false also when there is no result to update. On failure
   *         the input cloud and indices are those before the call, and so are the
   *         parameters; the result is kept when nothing ran (invalid parameters),
   *         cleared when a stage failed or memory ran out. */
  bool update(const PointCloud& new_points, std::vector<pcl::PointIndices>& clusters);

  /** \brief What the last update() changed: all zero (and not incremental) when that
   * call failed or was refused. */
  const UpdateStatistics& getUpdateStatistics() const { return update_stats_; }

  /** \brief Labels, segments, leaves, mesh, counts and timings of the last extract()
   * or update(). */
  const SegmentationResult& getResult() const { return result_; }

  /** \brief The points of the last run's input cloud with their labels (0 =
   * unlabeled); same size, order and layout (width, height) as that cloud (one row
   * when its width x height is not its size). Null before a successful extract().
   * The getters describe the last extract() or update(), whatever the input, pose or
   * parameters set since. As in PCL's other classes, the run's cloud is not copied:
   * this getter and getPolygonMesh() read its points through the pointer given to
   * setInputCloud(), so call them before refilling that cloud in place for the next
   * frame (a cloud of another size gives null and an empty mesh). The const getters
   * may be called from several threads at once. */
  LabeledCloud::Ptr getLabeledCloud() const;

  /** \brief getLabeledCloud() with a colour per segment instead of the label, as
   * pcl::RegionGrowing::getColoredCloud() gives, for a look at the result: each point
   * has segmentColor() of its label (segment_colors.h: one hue per label, the same in
   * every run and as the tool's meshes and the viewer; unlabeled points dark grey).
   * Same size, order, layout and sensor pose as getLabeledCloud(); null when it is. */
  ColoredCloud::Ptr getColoredCloud() const;

  /** \brief getColoredCloud() as pcl::PointXYZRGBA, alpha 255. */
  ColoredCloudRGBA::Ptr getColoredCloudRGBA() const;

  /** \brief Point normals (eq. 2) in the cloud frame of the last run (its sensor
   * pose), oriented toward the sensor; same size and layout as getLabeledCloud(); NaN
   * where a point has no normal. Null before a successful extract(). Built from the
   * vertex normals on the first call after a run (the pipeline itself needs only the
   * vertex normals), then kept: every call after a run gives the same cloud. */
  NormalCloud::ConstPtr getPointNormals() const;

  /** \brief The segmented mesh over the last run's input cloud (labels and classes
   * per triangle are in getResult().mesh); empty before a successful extract(). */
  void getPolygonMesh(pcl::PolygonMesh& mesh) const;

  /** \brief The triangulation of the last extract() or update(): the vertex of every
   * input point, the vertices' representative points, angles and sensor-frame
   * positions; empty after a failed run. Its neighbours are left empty: the triangle
   * adjacency is getResult().mesh.neighbours (same triangle order), stored once. */
  const SphericalTriangulation& getTriangulation() const
  {
    return delaunay_.getTriangulation();
  }

  /** \brief The multi-resolution octree of the last extract() or update(), over the
   * mesh vertices in the sensor frame (its point i is vertex i of getTriangulation()).
   */
  typename Octree::ConstPtr getOctree() const { return octree_; }

protected:
  using pcl::PCLBase<PointT>::input_;
  using pcl::PCLBase<PointT>::indices_;

  /** \brief The base checks plus parameters and indices. */
  bool initCompute();

  std::string getClassName() const { return "SelectiveSegmentation"; }

  /** \brief Empty result, octree, point normals and edge-test normals. */
  void clearOutputs();

  /** \brief The point counts and the vertex count of the triangulation, into the
   * result. */
  void takeTriangulationCounts();

  /** \brief Stage 1-2: spherical projection and Delaunay triangulation. */
  bool triangulate();

  /** \brief Stage 3: triangle and point normals and areas (eq. 2-3). */
  bool computeNormals();

  /** \brief The point normals cloud and the median spacing from the vertex normals;
   * false when no point has a normal. */
  bool publishNormals();

  /** \brief Stages 4-5 and the clusters, after the mesh and its normals. */
  bool segmentMesh(std::vector<pcl::PointIndices>& clusters);

  /** \brief Note the input and indices the mesh is made from (mesh_input_). */
  void noteMeshInput();
  /** \brief Whether the input and indices are those the mesh was made from. */
  bool meshInputUnchanged() const;

  /** \brief update(): stages 1-3 for the new points only; false when they must run
   * from scratch (the state is then unchanged), or set \a failed (reported). */
  bool updateMesh(std::size_t first_new_point, bool& failed);

  /** \brief update(): triangle and vertex normals where the mesh changed, reusing the
   * previous result's triangle normals and areas (taken from \a old_normals and
   * \a old_areas) where it can; \a is_moved flags the moved vertices (empty: none). */
  void updateNormals(const DelaunayInsertion& info,
                     const std::vector<std::uint8_t>& is_moved,
                     Vector3fVector& old_normals,
                     std::vector<double>& old_areas);

  /** \brief Stage 4: the multi-resolution octree (eq. 4-5). */
  bool buildOctree();

  /** \brief Stage 5: seed merging (eq. 6-10) and the labeled outputs. */
  void mergeAndLabel();

  /** \brief Labels ranked by segment size, per-point labels, segments, and the counts
   * of labeled, shared-vertex and normal-less points. */
  void rankSegments(const std::vector<pcl::index_t>& vertex_segment,
                    const Vector3fVector& segment_normals,
                    std::vector<std::uint32_t>& segment_label);

  /** \brief The triangle normals eq. 8 tests (parameter edge_triangle_normal). */
  const Vector3fVector& edgeTestNormals();

  /** \brief Threads of the parallel loops (parameter num_threads, 0 =
   * defaultThreads()). */
  int numThreads() const { return detail::threadCount(params_.num_threads); }

  /** \brief Rotation from the sensor frame to the cloud frame. */
  Eigen::Matrix3f sensorToCloud() const { return delaunay_.getSensorPose().rotation(); }

  /** \brief Mesh, leaves and counts of the result from the final labels. */
  void fillMeshAndLeaves(const std::vector<std::uint32_t>& vertex_labels,
                         const std::vector<pcl::index_t>& leaf_segment,
                         const std::vector<std::uint32_t>& segment_label);

  /** \brief Fail: report, clear the outputs, keep the point counts. */
  bool fail(const char* stage, const std::string& why);
  /** \brief Fail after std::bad_alloc: report, clear the outputs and what update()
   * would fold into. */
  bool failOutOfMemory(const char* stage);
  /** \brief After a failed run: the triangulation emptied and the run's pose
   * forgotten, so that no getter describes an earlier run. */
  void forgetRun();
  /** \brief extract() but for its handling of std::bad_alloc. */
  bool runExtract(std::vector<pcl::PointIndices>& clusters);
  /** \brief update() from the union of the input and \a new_points on, but for its
   * handling of std::bad_alloc and its restoring of the parameters and input. */
  bool updateUnion(const PointCloud& new_points,
                   bool in_place,
                   std::vector<pcl::PointIndices>& clusters);

  /** \brief The triangle normals eq. 2 sums: triangle_normals_, or with
   * PointNormalTriangles::NotEdgeOn a copy in \a masked without the edge-on ones
   * (maskEdgeOnNormals(); follow with fillEdgeOnOnlyVertices()). */
  const Vector3fVector& eq2TriangleNormals(Vector3fVector& masked) const;

  /** \brief With PointNormalTriangles::NotEdgeOn, the vertices whose triangles are all
   * edge-on (no normal from eq2TriangleNormals()) get eq. 2 over all of them
   * (fillMissingVertexNormals()); otherwise nothing. */
  void fillEdgeOnOnlyVertices(Vector3fVector& vertex_normals) const;

  /** \brief Whether the last run's cloud declares a layout (width x height) that is
   * its size; a cloud whose points were pushed after it was loaded may not. The
   * getters give such a cloud's outputs one row. */
  bool runLayoutIsItsSize() const;

  /** \brief An output cloud of the last run's size, layout and header, every point
   * \a fill. */
  template <typename CloudT>
  pcl::shared_ptr<CloudT>
  cloudShapedLikeTheRun(const typename CloudT::PointType& fill) const;

  /** \brief Whether the last run succeeded on the cloud it kept (the getters' outputs
   * exist). */
  bool hasRunOutputs() const;

  /** \brief Null unless hasRunOutputs(); otherwise the run's points in a cloud shaped
   * like it (size, layout, header, density, sensor pose), fill(point, label) setting
   * each point's other fields from its label. */
  template <typename CloudT, typename Fill>
  pcl::shared_ptr<CloudT> runPointsCloud(const Fill& fill) const;

  /** \brief getColoredCloud() for any PCL point type with x, y, z and r, g, b, a. */
  template <typename CloudT> pcl::shared_ptr<CloudT> coloredCloud() const;

private:
  SelectiveSegmentationParameters params_;
  SphericalDelaunay<PointT> delaunay_;
  typename Octree::Ptr octree_;
  detail::LockedCache<NormalCloud::ConstPtr> normals_; ///< built by getPointNormals()
  Vector3fVector vertex_normals_;         ///< sensor frame
  std::shared_ptr<std::vector<double>> vertex_areas_;
  Vector3fVector triangle_normals_;
  std::vector<double> triangle_areas_;
  std::vector<std::uint8_t> triangle_edge_on_;
  Vector3fVector
      vertex_mean_normals_; ///< per triangle, for EdgeTriangleNormal::VertexMean
  std::vector<pcl::index_t> vertex_leaf_;
  SegmentationResult result_;
  /** Parameters and sensor pose the current mesh and normals were computed with. */
  SelectiveSegmentationParameters mesh_params_;
  /** Unaligned: the layout must not depend on the user's -march (see
   * SphericalDelaunay::sensor_pose_). */
  Eigen::Matrix<float, 4, 4, Eigen::DontAlign> mesh_pose_ =
      Eigen::Matrix<float, 4, 4, Eigen::DontAlign>::Zero();
  /** The cloud and indices the current mesh was made from (noteMeshInput()): update()
   * folds new points into the result in place only while they are still the input. */
  typename PointCloud::ConstPtr mesh_input_;
  bool mesh_all_points_ = true; ///< no indices were set
  pcl::Indices mesh_indices_;   ///< a copy of the indices, when set
  UpdateStatistics update_stats_;
  /** update(): the previous octree's leaves and the positions changed since, for
   * buildOctree() to keep what did not change; empty otherwise. */
  typename Octree::PreviousLeaves previous_leaves_;
  /** The last merge, for update() to take over the segments whose leaves the octree
   * kept (MergeReplay): its parameters, kept from the merge, and during update() the
   * segment of each previous leaf, the seeds and the segment normals in the order the
   * segments grew (notePreviousSegments()). */
  struct PreviousMerge {
    std::vector<pcl::index_t> leaf_segment;
    std::vector<pcl::index_t> segment_seed;
    Vector3fVector segment_normals;
    SelectiveSegmentationParameters params;
  };
  PreviousMerge previous_merge_;

  /** \brief update(): the previous merge's segment of each previous leaf, their seeds
   * and normals, from the result's leaves and segments and the seed order; left empty
   * when the result does not tell. */
  void notePreviousSegments();

  /** \brief The replay of previous_merge_ over the current octree's leaves, when it
   * kept some and the merge parameters are the same; false otherwise. */
  bool prepareReplay(MergeReplay& replay,
                     std::vector<pcl::index_t>& leaf_segment,
                     std::vector<pcl::index_t>& segment_seed) const;
};

} // namespace selective_seg
} // namespace pcl

#ifdef PCL_NO_PRECOMPILE
#include <pcl_selective_seg/impl/selective_segmentation.hpp>
#endif

// The library's own instantiations are used even when the bodies are visible
// (PCL_NO_PRECOMPILE): see octree_pointcloud_normal_variance.h.
#include <pcl_selective_seg/point_types.h>
PCL_SELSEG_EXTERN_TEMPLATES(pcl::selective_seg::SelectiveSegmentation)
