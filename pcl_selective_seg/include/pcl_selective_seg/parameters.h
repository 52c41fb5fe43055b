/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/delaunay_2d.h>

#include <pcl/pcl_macros.h>

#include <algorithm>
#include <cstddef>
#include <string>

namespace pcl {
namespace selective_seg {

/** \brief The threads a parallel stage uses when given 0 ("automatic"): the size of
 * the team OpenMP would form, that is OMP_NUM_THREADS (or omp_set_num_threads()) when
 * set, otherwise the processors this process may run on (its CPU affinity, as taskset
 * or a container's cpuset leave it); 1 when called inside a parallel region of the
 * caller's that cannot nest, or when the library was built without OpenMP. */
PCL_EXPORTS unsigned int defaultThreads();

/** \brief The default of setHugePageAdviceThreshold(): 32 MB, glibc's largest mapping
 * threshold on 64-bit systems (DEFAULT_MMAP_THRESHOLD_MAX). With glibc's default
 * settings a block this large is mapped afresh and unmapped when freed, so every run
 * faults its pages in again; smaller blocks are reused from the heap, where the advice
 * measured up to 12-14% slower at 1M points (docs/performance.md, "Huge pages"). */
constexpr std::size_t kDefaultHugePageAdviceBytes = std::size_t{32} << 20;

/** \brief Process-wide: the pipeline's arrays of at least \a bytes are advised to the
 * kernel as transparent huge pages before they are first written (Linux
 * `madvise(MADV_HUGEPAGE)` on the whole 2 MB pages inside them): one page fault per
 * 2 MB instead of per 4 KB. No result depends on it.
 *
 * The default (kDefaultHugePageAdviceBytes) suits a process that segments cloud after
 * cloud with glibc's default allocator settings. A process that segments one cloud, or
 * that keeps the memory it frees (glibc's M_MMAP_MAX = 0 and a high M_TRIM_THRESHOLD),
 * faults every page of its heap in once and gains from a lower threshold: the
 * command-line tool uses 4 MB (1M points: pipeline 1.34-1.49 s with 32 MB, 0.91-0.99 s
 * with 4 MB, the same peak memory). std::numeric_limits<std::size_t>::max() turns the
 * advice off; so does the system setting
 * /sys/kernel/mm/transparent_hugepage/enabled = never. Thread-safe; takes effect for
 * arrays sized after the call. */
PCL_EXPORTS void setHugePageAdviceThreshold(std::size_t bytes) noexcept;

/** \brief The threshold set by setHugePageAdviceThreshold(). */
PCL_EXPORTS std::size_t getHugePageAdviceThreshold() noexcept;

namespace detail {
/** \brief While one lives on a thread, the mesh functions called on that thread
 * (mesh_normals.h, region_merging.h, computeTriangleNeighbours()) skip the pass that
 * checks their ids: SelectiveSegmentation holds one during a run, whose meshes meet
 * the checks by construction (the passes together cost 2-4% at 46k points;
 * docs/reliability.md, "Review of session 36").
 * Nests; not for users' own meshes. */
class PCL_EXPORTS TrustedMeshScope {
public:
  TrustedMeshScope() noexcept;
  ~TrustedMeshScope();
  TrustedMeshScope(const TrustedMeshScope&) = delete;
  TrustedMeshScope& operator=(const TrustedMeshScope&) = delete;

private:
  bool previous_;
};

/** \brief Whether a TrustedMeshScope lives on the calling thread. */
PCL_EXPORTS bool meshTrusted() noexcept;

/** \brief Most threads any stage starts (the valid range of num_threads). */
constexpr int kMaxThreads = 1024;

/** \brief The threads of a parallel stage asked for \a requested: itself when
 * positive (at most kMaxThreads), else (0, automatic) defaultThreads(). */
inline int
threadCount(int requested)
{
  return requested > 0 ? std::min(requested, kMaxThreads)
                       : static_cast<int>(defaultThreads());
}
} // namespace detail

/** \brief Which normal of a triangle eq. 8 compares with the segment normal. */
enum class EdgeTriangleNormal : std::uint8_t {
  /** The facet normal, as in the paper. */
  Facet = 0,
  /** The normalized mean of the triangle's three point normals (eq. 2, or its k-ring
   * version): far less sensitive to range noise than a single facet. */
  VertexMean = 1
};

/** \brief The frame in which eq. 5 measures the angles of a voxel's normals. */
enum class NormalSpreadFrame : std::uint8_t {
  /** The sensor frame, as in the paper: theta = atan2(m_x, m_z), phi = atan2(m_y,
   * m_z) of each normal m (turned away from the sensor). Ill-conditioned for normals
   * nearly perpendicular to the optical axis (a floor seen by a level camera), where
   * m_z is near 0 and small noise swings the angles across (-pi, pi]. */
  Sensor = 0,
  /** The voxel's own frame, whose z axis is its mean normal (eq. 4) and whose x axis
   * is the sensor's x axis projected onto the voxel's tangent plane (the sensor's y
   * axis when x is nearly along the mean normal): eq. 5's angles then measure each
   * normal's tilt away from the mean in two directions of the tangent plane, the
   * well-conditioned case of a surface seen head-on, whatever the surface's
   * orientation. Equal to Sensor to first order for a surface facing the sensor. */
  MeanNormal = 1
};

/** \brief How eq. 7 weights the normals of the leaves that make up a segment. */
enum class SegmentNormalWeight : std::uint8_t {
  /** 1 / A_v, as in the paper: a small leaf counts for more than a large one. */
  InverseArea = 0,
  /** A_v: the segment normal is the area-weighted mean of its leaves' normals, the
   * mean normal of the surface they cover, which large, homogeneous leaves dominate. */
  Area = 1
};

/** \brief Which segments a growing segment merges with (eq. 9-10). */
enum class MergeWith : std::uint8_t {
  /** Seeds (leaves) not yet in a segment: a segment that has grown is final, and a
   * later segment that meets it across a valid edge triangle stops there. Each leaf
   * joins once. */
  Seeds = 0,
  /** Also the segments grown before it: a grown segment met at a vertex of a valid
   * edge triangle (eq. 8), whose normal is within max_merge_angle of the growing
   * segment's (eq. 9), is absorbed (eq. 10): its eq. 7 sum is added to the growing
   * segment's and its leaves become the growing segment's (not searched again: they
   * were when it grew). Runs the merge on one thread and without update()'s take-over
   * of unchanged segments (docs/pipeline.md, "Which segments merge"). */
  Segments = 1
};

/** \brief Which of a point's triangles eq. 2 sums into its normal. */
enum class PointNormalTriangles : std::uint8_t {
  /** Every triangle at the point, as in the paper. */
  All = 0,
  /** The triangles not seen edge-on (more obliquely than max_view_incidence_angle,
   * the test that already keeps them from being valid edge triangles), or all of them
   * where every one is. A triangle whose three rays lie nearly in one plane through
   * the sensor (a sliver in (theta, phi), as the straight rows of a pixel grid make
   * along a border) is edge-on by construction: its normal is that plane's, not the
   * surface's, and eq. 2's 1 / A_t gives it most of the weight. */
  NotEdgeOn = 1
};

/** \brief How stage 1 maps a point's direction in the sensor frame to the plane of the
 * triangulation. */
enum class ViewProjection : std::uint8_t {
  /** The paper's eq. 1: theta = atan2(x, z), phi = atan2(y, z), for a forward-looking
   * sensor; points at or behind the sensor plane (z <= 0) have no image. */
  Forward = 0,
  /** A panorama (a spinning lidar, a pan-tilt laser): azimuth theta = atan2(x, z) in
   * (-pi, pi] and elevation phi = atan2(y, sqrt(x^2 + z^2)) in [-pi/2, pi/2], with y
   * the spin axis. Every point but the sensor's own position has an image; the
   * triangulation is periodic in theta (delaunay2dPeriodic()), so the mesh closes
   * behind the sensor. theta and phi agree with eq. 1 in the plane x = 0. Not the
   * paper's; see docs/parameters.md. */
  Panoramic = 1
};

/** \brief Every parameter of SelectiveSegmentation, with the paper's defaults.
 *
 * Angles are in radians, lengths in metres (the cloud's unit). docs/parameters.md gives
 * each parameter's meaning, default, valid range and the stage that reads it.
 */
struct PCL_EXPORTS SelectiveSegmentationParameters {
  /** \brief Octree split threshold on the weighted standard deviation of the normal
   * angles (eq. 5), per axis [rad]. Paper: 7.6 degrees. Valid: (0, pi]. */
  double max_normal_std_dev = 7.6 * M_PI / 180.0;
  /** \brief Frame of eq. 5's normal angles. Default: the sensor frame, as in the
   * paper; MeanNormal removes the ill-conditioning of normals perpendicular to the
   * optical axis (docs/parameters.md). */
  NormalSpreadFrame normal_spread_frame = NormalSpreadFrame::Sensor;

  /** \brief Maximum angle between two segment normals for them to merge (eq. 9)
   * [rad]. Paper: 25 degrees. Valid: [0, pi]. */
  double max_merge_angle = 25.0 * M_PI / 180.0;
  /** \brief Weight of a leaf's normal in its segment's normal (eq. 7). Default:
   * 1 / A_v, as in the paper (docs/parameters.md). */
  SegmentNormalWeight segment_normal_weight = SegmentNormalWeight::InverseArea;
  /** \brief Which segments a growing segment merges with (eq. 9-10). Default: the
   * seeds not yet in a segment (docs/pipeline.md, "Which segments merge"). */
  MergeWith merge_with = MergeWith::Seeds;

  /** \brief Maximum angle between an edge triangle's normal and the growing segment's
   * normal for the triangle to be searched for neighbours (eq. 8) [rad]. Paper: 25
   * degrees. Valid: [0, pi]. */
  double max_edge_triangle_angle = 25.0 * M_PI / 180.0;

  /** \brief Largest angle between an edge triangle's normal and the line of sight to
   * it for the triangle to count as surface [rad]. A triangle seen more obliquely
   * spans a depth discontinuity (the "veil" between an occluding edge and the surface
   * behind it) and is never a valid edge triangle, whatever its normal. pi/2 disables
   * the test, which is the paper's literal reading. Default 85 degrees: an addition to
   * the paper, measured in docs/parameters.md. Valid: (0, pi/2]. */
  double max_view_incidence_angle = 85.0 * M_PI / 180.0;

  /** \brief Size of the neighbourhood of the point normals, in mesh rings: 1 is the
   * paper's eq. 2 (the triangles at the point); k sums eq. 2's terms over the triangles
   * of the k-ring, which averages range noise over about k^2 times more triangles.
   * Valid: [1, 10]. See docs/parameters.md. */
  int normal_rings = 1;

  /** \brief The triangles whose normals eq. 2 (or its k-ring version) sums. Default:
   * all of them, as in the paper; NotEdgeOn leaves out those seen edge-on, which on a
   * pixel grid's borders are slivers whose normals are not the surface's
   * (docs/parameters.md). Has no effect with max_view_incidence_angle = pi/2. */
  PointNormalTriangles point_normal_triangles = PointNormalTriangles::All;

  /** \brief The triangle normal tested by eq. 8 (valid edge triangles). Default: the
   * facet normal, as in the paper. */
  EdgeTriangleNormal edge_triangle_normal = EdgeTriangleNormal::Facet;

  /** \brief Smallest octree voxel edge [m]; voxels of this size are never split.
   * 0 = automatic: min_voxel_size_factor times the median 3-D edge length of the
   * Delaunay mesh (the median point spacing; SegmentationResult::median_spacing says
   * how it is sampled on large meshes). Valid: 0 or a positive finite value. */
  double min_voxel_size = 0.0;

  /** \brief Automatic minimum voxel size in units of the median point spacing
   * (used when min_voxel_size is 0). Valid: [0.5, 1000]. */
  double min_voxel_size_factor = 2.0;

  /** \brief A voxel holding fewer mesh vertices (distinct directions: points on one
   * quantized direction count once) than this is never split. Valid: >= 2. */
  int min_points_to_split = 8;

  /** \brief Deepest octree level; bounds the tree for clouds of extreme extent, where
   * the effective minimum voxel size grows to extent / 2^max_octree_depth.
   * Valid: [1, 21]. */
  int max_octree_depth = 16;

  /** \brief Grid step on which the (theta, phi) angles are quantized for the exact
   * triangulation [rad]. Points falling on one grid position share one mesh vertex.
   * Default 1e-7 rad (0.1 micrometre at 1 m). Valid: [2.5e-8, 1e-2]. */
  double angle_quantization = 1e-7;

  /** \brief Stage 1's mapping of directions. Default: Forward, the paper's eq. 1.
   * Panoramic needs normal_spread_frame = MeanNormal (eq. 5's sensor-frame angles are
   * ill-conditioned for the normals perpendicular to the optical axis that a
   * panorama has all around), an exact backend and angle_quantization >= 1e-7 (the
   * periodic strip must fit the exact predicates' coordinate range). */
  ViewProjection projection = ViewProjection::Forward;

  /** \brief Threads for the parallel stages; 0 = automatic (defaultThreads()). The
   * result is identical for any value. Valid: [0, 1024]. */
  int num_threads = 0;

  /** \brief Triangulation backend. Default: Sweep, our exact scan-order triangulator
   * (identical triangles to BoostVoronoi, tested on every test and real cloud). */
  DelaunayBackend delaunay_backend = DelaunayBackend::Sweep;

  /** \brief Check every parameter.
   * \param[out] why when invalid and non-null: which parameter, its value and its
   *             valid range.
   * \return true when all parameters are valid. */
  bool validate(std::string* why = nullptr) const;
};

} // namespace selective_seg
} // namespace pcl
