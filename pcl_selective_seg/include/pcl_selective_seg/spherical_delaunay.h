/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/delaunay_2d_update.h>
#include <pcl_selective_seg/parameters.h>

#include <Eigen/Geometry>
#include <pcl/surface/reconstruction.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace pcl {
namespace selective_seg {

namespace detail {

/** \brief std::lround(std::atan2(y, x) / step), the quantized angle of eq. 1, bit for
 * bit, for x > 0, finite y and step > 0, about twice as fast: atan(|y| / x) from a
 * table of atan(i / 8) and a short series (within 1e-15 rad), and the exact expression
 * only when the quotient lies so near a half-integer (within 1e-13 rad / step) that
 * the two could round apart. */
PCL_EXPORTS long
quantizedAngle(double y, double x, double step);

} // namespace detail

/** \brief Why a point has no mesh vertex (values of
 * SphericalTriangulation::point_vertex). */
enum PointStatus : pcl::index_t {
  kOutsideIndices = -1, ///< not in the indices
  kNonFinite = -2,      ///< NaN or Inf coordinate
  kBehindSensor = -3    ///< z <= 0 in the sensor frame (ViewProjection::Forward), or
                        ///< at the sensor's own position (ViewProjection::Panoramic)
};

/** \brief The triangulation of a cloud in spherical space (paper, eq. 1 and Sec.
 * III.A).
 *
 * Mesh vertices are the distinct quantized angle pairs, numbered in increasing
 * (theta, phi) order, so the numbering depends on the point set only. */
struct SphericalTriangulation {
  /** \#N per input point: its vertex id, or a negative PointStatus. */
  std::vector<pcl::index_t> point_vertex;
  /** \#V the input point that represents each vertex: among the points sharing its
   * angles, the nearest to the sensor (ties: smallest x, y, z). */
  pcl::Indices vertex_point;
  /** \#V quantized (theta, phi) of each vertex: angle / angle_quantization, rounded.
   * With the panoramic projection theta lies in [-period / 2, period / 2), period =
   * 2 lround(pi / angle_quantization) (panoramicPeriod()). */
  std::vector<QuantizedPoint> vertex_angles;
  /** \#V position of each vertex's representative point in the sensor frame [m]. */
  std::vector<Eigen::Vector3f> vertex_positions;
  /** \#T triangles over vertex ids, counter-clockwise in (theta, phi). */
  std::vector<Triangle> triangles;
  /** \#T triangle across the edge opposite each vertex, -1 on the boundary (empty when
   * SphericalDelaunay::setComputeNeighbours(false)). */
  std::vector<Triangle> neighbours;
  std::size_t num_outside_indices = 0;
  std::size_t num_non_finite = 0;
  std::size_t num_behind_sensor = 0;
  double angle_quantization = 0.0; ///< [rad]
  /** How the angles were made. */
  ViewProjection projection = ViewProjection::Forward;
  /** Panoramic only: whether the triangles close the mesh around the sensor
   * (delaunay2dPeriodic()'s \a closed). */
  bool seam_closed = false;
};

/** \brief The period of the panoramic theta in quantization steps: 2 lround(pi /
 * angle_quantization). */
inline std::int32_t
panoramicPeriod(double angle_quantization)
{
  return static_cast<std::int32_t>(2 * std::lround(M_PI / angle_quantization));
}

/** \brief Delaunay triangulation of a cloud in the sensor's spherical space (theta,
 * phi).
 *
 * Points are mapped to the sensor frame (the cloud's sensor_origin_ and
 * sensor_orientation_ unless setSensorPose() overrides them), then to theta =
 * atan2(x, z), phi = atan2(y, z) (eq. 1), quantized on a fine grid and triangulated
 * exactly in that plane. The resulting mesh over the input points keeps the sensor's
 * view: occluded surfaces do not interleave with occluding ones.
 *
 * Points that are not finite or lie at or behind the sensor plane (z <= 0) get no
 * vertex. Points with equal quantized angles share one vertex.
 *
 * setProjection(ViewProjection::Panoramic) maps the directions to azimuth and
 * elevation instead, for a sensor that sees all around; the triangulation is then
 * periodic in the azimuth and closes behind the sensor (delaunay2dPeriodic()).
 *
 * Use it as any pcl::MeshConstruction: reconstruct(pcl::PolygonMesh&) gives the mesh
 * over the input cloud; getTriangulation() the vertex map and triangle adjacency.
 */
template <typename PointT>
class SphericalDelaunay : public pcl::MeshConstruction<PointT> {
public:
  using Ptr = pcl::shared_ptr<SphericalDelaunay<PointT>>;
  using ConstPtr = pcl::shared_ptr<const SphericalDelaunay<PointT>>;
  using PointCloudConstPtr = typename pcl::PointCloud<PointT>::ConstPtr;
  using pcl::MeshConstruction<PointT>::reconstruct;

  SphericalDelaunay() { this->check_tree_ = false; }

  /** \brief Triangulation backend (default: DelaunayBackend::Sweep). */
  void setBackend(DelaunayBackend backend) { backend_ = backend; }
  DelaunayBackend getBackend() const { return backend_; }

  /** \brief Whether triangulate() also fills SphericalTriangulation::neighbours
   * (default true). */
  void setComputeNeighbours(bool compute) { compute_neighbours_ = compute; }
  bool getComputeNeighbours() const { return compute_neighbours_; }

  /** \brief Moves SphericalTriangulation::neighbours into \a neighbours, leaving the
   * triangulation's list empty (for a caller that keeps the adjacency elsewhere). */
  void takeNeighbours(std::vector<Triangle>& neighbours)
  {
    neighbours.swap(triangulation_.neighbours);
    triangulation_.neighbours.clear();
  }

  /** \brief Stage 1's mapping (default ViewProjection::Forward, eq. 1). */
  void setProjection(ViewProjection projection) { projection_ = projection; }
  ViewProjection getProjection() const { return projection_; }

  /** \brief Grid step of the angle quantization [rad], in [2.5e-8, 1e-2] ([1e-7,
   * 1e-2] with the panoramic projection). */
  void setAngleQuantization(double step) { angle_quantization_ = step; }
  double getAngleQuantization() const { return angle_quantization_; }

  /** \brief Threads for the projection and the triangulation (0: defaultThreads();
   * at most 1024, as SelectiveSegmentationParameters::num_threads: libgomp fails on
   * teams of tens of thousands). The result does not depend on it. */
  void setNumberOfThreads(unsigned int threads)
  {
    num_threads_ = threads
                       ? std::min(threads, static_cast<unsigned>(detail::kMaxThreads))
                       : defaultThreads();
  }

  /** \brief Sensor pose in the cloud frame, overriding the cloud's sensor_origin_ /
   * sensor_orientation_. The sensor looks along its +z axis. */
  void setSensorPose(const Eigen::Affine3f& sensor_to_cloud)
  {
    sensor_pose_ = sensor_to_cloud;
    has_sensor_pose_ = true;
  }
  /** \brief Use the cloud's own sensor_origin_ / sensor_orientation_ again. */
  void resetSensorPose() { has_sensor_pose_ = false; }
  /** \brief The pose in use: the override, or the input cloud's (identity if none). */
  Eigen::Affine3f getSensorPose() const;
  /** \brief Whether the pose in use is a finite rotation (within 1e-4) and
   * translation; triangulate() refuses any other. \param[out] why the reason when
   * not, if non-null. */
  bool sensorPoseIsRigid(std::string* why = nullptr) const;

  /** \brief Guarded: the base class dereferences a missing input. */
  void reconstruct(pcl::PolygonMesh& output) override;

  /** \brief Project, quantize and triangulate; getTriangulation() gives the result.
   * \return false (with a PCL_ERROR saying why) on a missing input, a bad parameter or
   *         a backend failure. Fewer than three distinct non-collinear positions is not
   *         a failure: the result then has no triangle. */
  bool triangulate();

  /** \brief Fold the input points from \a first_new_point on into the triangulation of
   * the last triangulate() call, whose input was the points before them (same sensor
   * pose and quantization). The result equals triangulate() on the whole input; only
   * the new points are projected, and the triangulation changes only where they fall
   * (insertDelaunayPoints()).
   * \param[in] first_new_point the old input's size; the indices must be the old ones
   *            followed by indices of new points
   * \param[in,out] neighbours the triangle adjacency of the current triangulation
   *                (computeTriangleNeighbours()); on success that of the new one (also
   *                stored in the triangulation when setComputeNeighbours(true))
   * \param[out] info the renumbering of the vertices and triangles
   * \param[out] moved_vertices vertices (new ids) whose representative point changed to
   *             a new point nearer to the sensor
   * \return false when the update is impossible (no previous triangulation with
   *         triangles, a panoramic one, inconsistent input); the triangulation is then
   * unchanged and triangulate() should run instead. */
  bool insertPoints(std::size_t first_new_point,
                    std::vector<Triangle>& neighbours,
                    DelaunayInsertion& info,
                    std::vector<pcl::index_t>& moved_vertices);

  /** \brief The triangulation of the last reconstruct() or triangulate() call. */
  const SphericalTriangulation& getTriangulation() const { return triangulation_; }

  /** \brief Empty the triangulation and free its memory (a user of it whose run
   * failed). */
  void clearTriangulation() { triangulation_ = SphericalTriangulation(); }

protected:
  /** \brief After initCompute(): false, with a PCL_ERROR, when the indices standing
   * for the whole cloud are fewer than its points (PCLBase::initCompute() goes on
   * with the old ones when it cannot allocate them). */
  bool wholeCloudIndices();

  std::string getClassName() const override { return "SphericalDelaunay"; }

  void performReconstruction(pcl::PolygonMesh& output) override;

  void performReconstruction(std::vector<pcl::Vertices>& polygons) override;

  /** \brief Stage 1: angles of every input point in indices_, and the vertex map. */
  void projectAndMergeVertices(SphericalTriangulation& result) const;

  /** \brief One vertex per run of equal angle keys in \a sorted. */
  void
  mergeEqualAngles(const std::vector<std::pair<std::uint64_t, pcl::index_t>>& sorted,
                   const Eigen::Affine3d& pose,
                   SphericalTriangulation& result) const;

  /** \brief Eq. 1 for one point: (its quantized angle key, the point), or (a key that
   * sorts last, its PointStatus) when it is not finite or not in front of the sensor. */
  std::pair<std::uint64_t, pcl::index_t> projectPoint(const Eigen::Affine3d& pose,
                                                      pcl::index_t index) const;

  /** \brief projectPoint() with the panoramic projection, \a s in the sensor frame. */
  std::pair<std::uint64_t, pcl::index_t> projectPanoramic(const Eigen::Vector3d& s,
                                                          pcl::index_t index) const;

  /** \brief The representative of the points sorted[begin, end) (equal angles). */
  pcl::index_t
  representative(const std::vector<std::pair<std::uint64_t, pcl::index_t>>& sorted,
                 std::size_t begin,
                 std::size_t end,
                 const Eigen::Affine3d& pose) const;

  /** \brief The counts of points outside the indices, non-finite and behind the sensor
   * from result.point_vertex. */
  static void countExcluded(SphericalTriangulation& result);

  /** \brief Whether point a represents a shared vertex rather than point b. */
  bool isCloserRepresentative(const Eigen::Affine3d& pose,
                              pcl::index_t a,
                              pcl::index_t b) const;

  /** \brief A point in the sensor frame, in double precision. */
  Eigen::Vector3d toSensorFrame(const Eigen::Affine3d& pose, pcl::index_t index) const;

  /** \brief Triangulate the vertices of triangulation_ (stage 2). */
  bool triangulateVertices();

  /** \brief The triangles as polygons over input point indices. */
  void toPolygons(std::vector<pcl::Vertices>& polygons) const;

private:
  DelaunayBackend backend_ = DelaunayBackend::Sweep;
  double angle_quantization_ = 1e-7;
  ViewProjection projection_ = ViewProjection::Forward;
  /** Unaligned storage (as every 32- or 64-byte Eigen member of the installed classes
   * must be): Eigen aligns a 64-byte matrix to 16, 32 or 64 bytes depending on the
   * compiler's -m flags (SSE, AVX, AVX-512), so an aligned member would give this class
   * another layout in a program built with -march=native than in the library. */
  Eigen::Transform<float, 3, Eigen::Affine, Eigen::DontAlign> sensor_pose_ =
      Eigen::Transform<float, 3, Eigen::Affine, Eigen::DontAlign>::Identity();
  bool has_sensor_pose_ = false;
  SphericalTriangulation triangulation_;
  unsigned int num_threads_ = defaultThreads();
  bool compute_neighbours_ = true;
};

} // namespace selective_seg
} // namespace pcl

#ifdef PCL_NO_PRECOMPILE
#include <pcl_selective_seg/impl/spherical_delaunay.hpp>
#endif

// The library's own instantiations are used even when the bodies are visible
// (PCL_NO_PRECOMPILE): see octree_pointcloud_normal_variance.h.
#include <pcl_selective_seg/point_types.h>
PCL_SELSEG_EXTERN_TEMPLATES(pcl::selective_seg::SphericalDelaunay)
