/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <Eigen/Core>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <cstdint>
#include <vector>

/** \brief Ray-casting generator of labelled synthetic scans for the test suite.
 *
 * Frame: the sensor sits at the origin and looks along +z, x points right and y points
 * down (the PCL/Kinect camera frame). All lengths are in metres, all angles in radians.
 */
namespace selseg_test {

/** \brief A planar parallelogram: the points origin + s * u + t * v, s, t in [0, 1].
 *
 * u and v must not be parallel. The face normal is u x v; faces built by addBox() have
 * it pointing out of the box.
 */
struct Face {
  /** \brief One corner [m]. */
  Eigen::Vector3d origin;
  /** \brief First edge, from \a origin [m]. */
  Eigen::Vector3d u;
  /** \brief Second edge, from \a origin [m]. */
  Eigen::Vector3d v;
  /** \brief Ground-truth label written to every point on this face (>= 1). */
  std::uint32_t label;
};

/** \brief A set of faces; rays report the nearest face they hit. */
struct Scene {
  /** \brief The faces, in no particular order. */
  std::vector<Face> faces;
};

/** \brief Append the six faces of a box, all with outward normals.
 *
 * The box is axis-aligned in its own frame, which is rotated by \a yaw about the
 * vertical (y) axis. Labels, in box axes: first_label + 0 the -y face (the top, since y
 * points down), + 1 the +y face (bottom), + 2 the -x face, + 3 the +x face, + 4 the -z
 * face, + 5 the +z face.
 *
 * \param[in,out] scene scene to extend.
 * \param[in] centre box centre [m].
 * \param[in] half_sizes half the edge lengths along the box's x, y and z axes [m].
 * \param[in] yaw rotation of the box about the y axis (right-handed) [rad].
 * \param[in] first_label label of the first face (>= 1).
 * \return the next unused label, first_label + 6.
 */
std::uint32_t addBox(Scene& scene,
                     const Eigen::Vector3d& centre,
                     const Eigen::Vector3d& half_sizes,
                     double yaw,
                     std::uint32_t first_label);

/** \brief How scan() draws its rays.
 *
 * A ray's direction is (tan theta, tan phi, 1) normalized, so theta = atan2(x, z) and
 * phi = atan2(y, z) of every point on it. Directions are drawn at random inside the
 * view window with the relative density given by relativeDensity().
 */
struct SamplingParams {
  /** \brief Smallest horizontal angle theta = atan2(x, z) [rad], > -pi/2. */
  double theta_min = -0.5;
  /** \brief Largest horizontal angle [rad], > theta_min, < pi/2. */
  double theta_max = 0.5;
  /** \brief Smallest vertical angle phi = atan2(y, z) [rad], > -pi/2. */
  double phi_min = -0.4;
  /** \brief Largest vertical angle [rad], > phi_min, < pi/2. */
  double phi_max = 0.4;
  /** \brief Number of rays cast; the number of points when every ray hits a face. */
  std::size_t num_rays = 5000;
  /** \brief Densest over sparsest angular sampling density across the window (>= 1). */
  double density_ratio = 10.0;
  /** \brief Relative range noise [1/m]: a hit at range r [m] moves along its ray by
   * a normal deviate of standard deviation range_noise * r^2 [m] (>= 0). */
  double range_noise = 0.0;
  /** \brief Seed of the std::mt19937 engine; equal seeds give identical scans. */
  unsigned seed = 42;
};

/** \brief Relative angular sampling density of scan() at (theta, phi).
 *
 * With a = (theta - theta_min) / (theta_max - theta_min) and b the same for phi, both
 * clamped to [0, 1], and w = (a + b) / 2, the density is density_ratio^(3 w^2 - 2 w^3):
 * 1 at the (theta_min, phi_min) corner, density_ratio at the (theta_max, phi_max)
 * corner, smooth in between.
 *
 * \param[in] params sampling parameters (only the window and density_ratio are used).
 * \param[in] theta horizontal angle [rad].
 * \param[in] phi vertical angle [rad].
 * \return density relative to the sparsest corner, in [1, density_ratio].
 */
double relativeDensity(const SamplingParams& params, double theta, double phi);

/** \brief Cast rays from the origin into a scene.
 *
 * Draws params.num_rays directions by rejection sampling of relativeDensity() and
 * intersects each with every face exactly; the nearest hit at a positive range wins.
 * Rays that hit nothing produce no point.
 *
 * \param[in] scene faces to scan.
 * \param[in] params sampling window, density, noise and seed.
 * \param[out] exact_hits if not null, receives the noise-free intersection of each
 *             output point in double precision, in the same order as the cloud.
 * \return an unorganized (height 1), dense cloud; label = label of the face hit.
 * \throws std::invalid_argument when \a params is out of its documented ranges.
 */
pcl::PointCloud<pcl::PointXYZL>
scan(const Scene& scene,
     const SamplingParams& params,
     std::vector<Eigen::Vector3d>* exact_hits = nullptr);

/** \brief The cube-on-a-table scene of the paper's Fig. 4.
 *
 * A wall z = 2.2 (label 1) behind a table top y = 0.8 (label 2), 0.8 m below the
 * sensor, and a 0.3 m cube (labels 3 to 8, in the order of addBox(); 3 is its top)
 * resting on the table at x = 0, z = 0.9, turned 35 degrees about the vertical axis.
 * Seen through makeCubeOnTableView(), the sensor sees the wall, the table top and
 * exactly three cube faces: the top (3), the +x face (6) and the -z face (7).
 */
Scene makeCubeOnTableScene();

/** \brief A view window framing makeCubeOnTableScene() (other fields at defaults).
 *
 * \param[in] num_rays number of rays to cast.
 */
SamplingParams makeCubeOnTableView(std::size_t num_rays = 5000);

} // namespace selseg_test
