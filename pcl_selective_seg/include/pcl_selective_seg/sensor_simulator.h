/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <Eigen/Core>
#include <pcl/pcl_macros.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace pcl {
namespace selective_seg {
/** \brief A simulated stereo-like range sensor with ground-truth labels.
 *
 * Frame: the sensor sits at the origin and looks along +z, x points right and y points
 * down (the PCL camera frame). A ray's angles are theta = atan2(x, z) and
 * phi = atan2(y, z), the angles of the paper's eq. 1. Lengths are in metres, angles in
 * radians. Every surface carries a ground-truth label >= 1; label 0 is never written.
 */
namespace simulation {

/** \brief A ray: the points origin + r * direction, r > 0. */
struct Ray {
  /** \brief Start of the ray [m]. */
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /** \brief Unit direction; ranges are measured along it [m]. */
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};

/** \brief The nearest surface found so far along a ray. */
struct Hit {
  /** \brief Range of the hit along the ray [m]; infinity = nothing hit yet. */
  double range = std::numeric_limits<double>::infinity();
  /** \brief Ground-truth label of the surface hit; 0 = nothing hit yet. */
  std::uint32_t label = 0;
};

/** \brief A planar parallelogram: the points origin + s * u + t * v, s, t in [0, 1].
 *
 * u and v must not be parallel. Rectangles are parallelograms with u . v = 0. Both
 * sides are surfaces.
 */
struct Parallelogram {
  /** \brief One corner [m]. */
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /** \brief First edge, from \a origin [m]. */
  Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  /** \brief Second edge, from \a origin [m]. */
  Eigen::Vector3d v = Eigen::Vector3d::UnitY();
  /** \brief Ground-truth label (>= 1). */
  std::uint32_t label = 1;
};

/** \brief A flat disk: the points p with normal . (p - centre) = 0 and
 * |p - centre| <= radius. Both sides are surfaces. */
struct Disk {
  /** \brief Centre [m]. */
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  /** \brief Normal; any non-zero length. */
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  /** \brief Radius [m], > 0. */
  double radius = 1.0;
  /** \brief Ground-truth label (>= 1). */
  std::uint32_t label = 1;
};

/** \brief The side of a finite circular cylinder, or an angular sector of it (a curved
 * panel).
 *
 * The points base + a * axis + radius * (cos(w) * e1 + sin(w) * e2) with a in
 * [0, length] and w in [angle_min, angle_max], where e1 is \a reference made
 * perpendicular to the axis and normalized, and e2 = axis x e1. The inside and the
 * outside are both surfaces; the caps are separate Disk primitives (see addCylinder()).
 */
struct CylinderPatch {
  /** \brief Centre of the end at a = 0 [m]. */
  Eigen::Vector3d base = Eigen::Vector3d::Zero();
  /** \brief Axis direction; any non-zero length (normalized internally). */
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
  /** \brief Direction of angle 0; must not be parallel to \a axis. */
  Eigen::Vector3d reference = Eigen::Vector3d::UnitX();
  /** \brief Radius [m], > 0. */
  double radius = 1.0;
  /** \brief Length along the axis [m], > 0. */
  double length = 1.0;
  /** \brief Smallest angle about the axis, from \a reference [rad], >= -pi. */
  double angle_min = -M_PI;
  /** \brief Largest angle about the axis [rad], > angle_min, <= pi. */
  double angle_max = M_PI;
  /** \brief Ground-truth label (>= 1). */
  std::uint32_t label = 1;
};

/** \brief Height above a height field's base [m] at base coordinates (s, t) in
 * [0, 1]^2; must be smooth and lie in [min_height, max_height]. */
using HeightFunction = std::function<double(double s, double t)>;

/** \brief Ground-truth label (>= 1) of a height field at base coordinates (s, t). */
using LabelFunction = std::function<std::uint32_t(double s, double t)>;

/** \brief A smooth curved panel: the points origin + s * u + t * v + height(s, t) * n
 * with s, t in [0, 1] and n = (u x v) / |u x v|.
 *
 * Rays are intersected by sampling the signed height difference along the part of the
 * ray inside the panel's bounding prism at steps of at most \a max_step (at most a
 * million steps: beyond 10^6 max_step inside the prism, 2 km at the default, the
 * steps grow to span / 10^6), then bisecting the first sign change to double
 * precision: the nearest crossing is found unless the ray enters and leaves the
 * surface within one step (a feature thinner than a step along the ray) or only
 * touches it. Different regions may carry
 * different labels (a dent in a door panel, for example).
 */
struct HeightField {
  /** \brief Corner of the base parallelogram [m]. */
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /** \brief First base edge [m]; s runs along it. */
  Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  /** \brief Second base edge [m]; t runs along it. Must not be parallel to \a u. */
  Eigen::Vector3d v = Eigen::Vector3d::UnitY();
  /** \brief Height along n [m]. */
  HeightFunction height;
  /** \brief Label of each point of the panel. */
  LabelFunction label;
  /** \brief Lower bound of \a height over the base [m]. The rays search between the
   * bounds only: a surface outside them is not seen. validateScene() checks \a height
   * and \a label (>= 1) on a 17 x 17 grid of (s, t); a hit whose label is 0 elsewhere
   * makes the simulation fail. */
  double min_height = 0.0;
  /** \brief Upper bound of \a height over the base [m], >= min_height. */
  double max_height = 0.0;
  /** \brief Longest step of the root search along a ray [m], > 0. */
  double max_step = 0.002;
};

/** \brief Surfaces to scan, each with a ground-truth label, and the labels' names.
 *
 * Rays report the nearest surface they hit, whatever its kind or order.
 */
struct PCL_EXPORTS Scene {
  /** \brief Planar parallelograms (walls, table tops, box faces). */
  std::vector<Parallelogram> parallelograms;
  /** \brief Disks (cylinder caps). */
  std::vector<Disk> disks;
  /** \brief Cylinder sides and cylindrical panels. */
  std::vector<CylinderPatch> cylinders;
  /** \brief Curved panels. */
  std::vector<HeightField> height_fields;
  /** \brief Name of every label the scene uses. */
  std::map<std::uint32_t, std::string> label_names;

  /** \brief Register a new label.
   * \param[in] name human-readable name of the surface.
   * \return the new label: one more than the largest registered, 1 for the first. */
  std::uint32_t addLabel(const std::string& name);
};

/** \brief Which faces addBox() and addCylinder() add. */
enum class FaceSelection {
  /** \brief Every face. */
  All,
  /** \brief Only the faces whose outward normal points toward the sensor at the
   * origin. For a closed convex solid with the sensor outside it, the other faces can
   * never be the nearest hit, so leaving them out changes no ray, and every label
   * added can be seen. */
  FacingOrigin
};

/** \brief Intersect a ray with a parallelogram.
 * \param[in] ray the ray.
 * \param[in] face the parallelogram.
 * \param[in,out] hit nearest hit so far; replaced when \a face is hit at a range in
 *                (0, hit.range).
 * \return true when \a hit was replaced. */
PCL_EXPORTS bool intersect(const Ray& ray, const Parallelogram& face, Hit& hit);

/** \brief Intersect a ray with a disk; as intersect(const Ray&, const Parallelogram&,
 * Hit&). */
PCL_EXPORTS bool intersect(const Ray& ray, const Disk& disk, Hit& hit);

/** \brief Intersect a ray with a cylinder side or panel (nearest of the up to two
 * crossings inside the patch); as intersect(const Ray&, const Parallelogram&, Hit&). */
PCL_EXPORTS bool intersect(const Ray& ray, const CylinderPatch& patch, Hit& hit);

/** \brief Intersect a ray with a height field (root search, see HeightField); as
 * intersect(const Ray&, const Parallelogram&, Hit&). The label is field.label at the
 * crossing. */
PCL_EXPORTS bool intersect(const Ray& ray, const HeightField& field, Hit& hit);

/** \brief Nearest surface of a scene along a ray.
 * \param[in] scene surfaces to test.
 * \param[in] ray the ray.
 * \param[out] hit the nearest hit at a positive range; reset when nothing is hit.
 * \return true when a surface was hit. */
PCL_EXPORTS bool castRay(const Scene& scene, const Ray& ray, Hit& hit);

/** \brief Append the faces of a box as parallelograms, each with its own new label.
 *
 * The box has edges 2 * half_sizes along the columns of \a rotation. Faces, in the
 * order of the result and named "<name> <face>" in box axes: top (-y, since y points
 * down), bottom (+y), left (-x), right (+x), front (-z), back (+z). Each face's normal
 * u x v points out of the box.
 *
 * \param[in,out] scene scene to extend.
 * \param[in] centre box centre [m].
 * \param[in] half_sizes half the edge lengths along the box axes [m], > 0.
 * \param[in] rotation box axes in the sensor frame (a rotation matrix).
 * \param[in] name prefix of the faces' label names.
 * \param[in] selection which faces to add.
 * \return the label of each face in the order above; 0 for a face left out. */
PCL_EXPORTS std::array<std::uint32_t, 6>
addBox(Scene& scene,
       const Eigen::Vector3d& centre,
       const Eigen::Vector3d& half_sizes,
       const Eigen::Matrix3d& rotation,
       const std::string& name,
       FaceSelection selection = FaceSelection::All);

/** \brief Append a closed finite cylinder: its side and its two caps, each with its own
 * new label ("<name> side", "<name> base cap", "<name> end cap").
 *
 * \param[in,out] scene scene to extend.
 * \param[in] base centre of the base cap [m].
 * \param[in] axis from the base cap's centre to the end cap's centre [m]; its length
 *            is the cylinder's length.
 * \param[in] radius radius [m], > 0.
 * \param[in] name prefix of the label names.
 * \param[in] selection which surfaces to add (the side counts as facing the origin
 *            unless the origin lies inside the infinite cylinder).
 * \return the labels of the side, the base cap and the end cap; 0 for one left out. */
PCL_EXPORTS std::array<std::uint32_t, 3>
addCylinder(Scene& scene,
            const Eigen::Vector3d& base,
            const Eigen::Vector3d& axis,
            double radius,
            const std::string& name,
            FaceSelection selection = FaceSelection::All);

/** \brief Check every primitive of a scene: labels >= 1, non-degenerate shapes,
 * finite numbers, height fields with both functions set and ordered bounds.
 * \param[in] scene the scene.
 * \param[out] why when invalid and non-null: which primitive and what is wrong.
 * \return true when the scene is valid. */
PCL_EXPORTS bool validateScene(const Scene& scene, std::string* why = nullptr);

/** \brief The sensor model of SensorSimulator.
 *
 * Rays are drawn on a jittered grid over the view window and kept with a probability
 * given by a smooth random "texture" field (stereo matching finds more points where
 * the scene is textured), so the angular density varies smoothly by density_ratio
 * across the view. Kept rays are then lost to random dropouts and to a few elliptic
 * holes in the view (regions with no returns); the range of each hit gets normal noise
 * of standard deviation range_noise * r^2.
 */
struct PCL_EXPORTS SensorParameters {
  /** \brief Smallest horizontal angle theta = atan2(x, z) of the view [rad], in
   * (-pi/2, theta_max). */
  double theta_min = -0.5;
  /** \brief Largest horizontal angle [rad], in (theta_min, pi/2). */
  double theta_max = 0.5;
  /** \brief Smallest vertical angle phi = atan2(y, z) [rad], in (-pi/2, phi_max). */
  double phi_min = -0.4;
  /** \brief Largest vertical angle [rad], in (phi_min, pi/2). */
  double phi_max = 0.4;
  /** \brief Expected number of rays cast over the window, before dropouts and holes.
   * Valid: [1, 1e8]. */
  std::size_t num_rays = 10000;
  /** \brief Densest over sparsest angular sampling density across the view.
   * Valid: [1, 100]. */
  double density_ratio = 4.0;
  /** \brief Spatial frequency of the texture field: about this many density
   * oscillations across the window [1/window]. Valid: (0, 20]. */
  double texture_cycles = 2.0;
  /** \brief Jitter of each ray inside its grid cell, as a fraction of the cell
   * (0 = regular grid, 1 = uniform over the cell). Valid: [0, 1]. */
  double jitter = 1.0;
  /** \brief Probability that a ray returns nothing, independently per ray.
   * Valid: [0, 1). */
  double dropout = 0.05;
  /** \brief Number of elliptic holes (view regions without returns). Valid: [0, 1000].
   */
  int num_holes = 3;
  /** \brief Mean semi-axis of a hole [rad]; each semi-axis is drawn uniformly in
   * [0.5, 1.5] times this. Valid: [0, 1]. */
  double hole_radius = 0.03;
  /** \brief Noise factor k [1/m]: the range r [m] of a hit gets normal noise of
   * standard deviation k * r^2 [m]. Valid: [0, 1]. */
  double range_noise = 0.001;
  /** \brief Hits measured nearer than this give no point [m]. Valid: >= 0. */
  double min_range = 0.1;
  /** \brief Hits measured farther than this give no point [m], in (min_range, 1e30]. */
  double max_range = 10.0;
  /** \brief Seed of every random draw; equal parameters give identical clouds. */
  std::uint32_t seed = 42;

  /** \brief Check every parameter.
   * \param[out] why when invalid and non-null: which parameter, its value and its
   *             valid range.
   * \return true when all parameters are valid. */
  bool validate(std::string* why = nullptr) const;
};

/** \brief An elliptic region of the view with no returns. */
struct EllipticHole {
  /** \brief Centre, horizontal angle [rad]. */
  double theta = 0.0;
  /** \brief Centre, vertical angle [rad]. */
  double phi = 0.0;
  /** \brief First semi-axis [rad]. */
  double semi_axis_a = 0.0;
  /** \brief Second semi-axis [rad]. */
  double semi_axis_b = 0.0;
  /** \brief Angle of the first semi-axis from the theta axis toward the phi axis
   * [rad]. */
  double orientation = 0.0;
};

/** \brief What happened to the rays of one SensorSimulator::simulate() call. */
struct SimulationDetails {
  /** \brief Grid cells drawn (candidate rays before the texture thinning). */
  std::size_t candidates = 0;
  /** \brief Rays kept by the texture field. */
  std::size_t rays = 0;
  /** \brief Rays inside a hole. */
  std::size_t in_holes = 0;
  /** \brief Rays outside the holes lost to dropouts. */
  std::size_t dropped = 0;
  /** \brief Remaining rays that hit no surface. */
  std::size_t missed = 0;
  /** \brief Hits whose measured range fell outside [min_range, max_range]. */
  std::size_t out_of_range = 0;
  /** \brief Hits on a height field whose label function gave 0 there (a broken
   * scene: the call then fails and returns no point). */
  std::size_t unlabeled_hits = 0;
  /** \brief Noise-free range of each output point [m], in cloud order. */
  std::vector<double> exact_ranges;
};

/** \brief An angular window of the view scanned at a chosen angular step (selective
 * sensing: a finer acquisition of a region of interest). Angles as in eq. 1 [rad]. */
struct PCL_EXPORTS ScanWindow {
  /** \brief Smallest horizontal angle [rad], in (-pi/2, theta_max). */
  double theta_min = -0.1;
  /** \brief Largest horizontal angle [rad], in (theta_min, pi/2). */
  double theta_max = 0.1;
  /** \brief Smallest vertical angle [rad], in (-pi/2, phi_max). */
  double phi_min = -0.1;
  /** \brief Largest vertical angle [rad], in (phi_min, pi/2). */
  double phi_max = 0.1;
  /** \brief Spacing of the candidate ray grid in both angles [rad], > 0; the grid has
   * at most 1e8 cells. The window is cut into round(width / step) columns and
   * round(height / step) rows (at least one each), so the spacing is the window's
   * width or height divided evenly: within a factor 1.5 of \a step for a window of
   * at least one step, closer for a window of many. */
  double step = 0.01;
  /** \brief Mixed into the seed of the window's grid, dropout and noise streams, so
   * that repeated scans of one window (or overlapping windows) draw new rays; equal
   * windows with equal ids give identical clouds. */
  std::uint32_t scan_id = 0;

  /** \brief Check every field; \a why as SensorParameters::validate(). */
  bool validate(std::string* why = nullptr) const;
};

/** \brief Simulated stereo-like range sensor at the origin (identity orientation).
 *
 * \code
 * auto setup = pcl::selective_seg::simulation::makeCubeScene();
 * pcl::selective_seg::simulation::SensorSimulator sensor;
 * pcl::PointCloud<pcl::PointXYZL> cloud;
 * if (sensor.setParameters(setup.sensor) && sensor.simulate(setup.scene, cloud)) {
 *   // cloud: x y z [m] and the ground-truth label of the surface hit
 * }
 * \endcode
 *
 * Random numbers come from std::mt19937 engines seeded with std::seed_seq{seed, stream}
 * (one stream each for the texture, the holes, the ray grid, the dropouts and the
 * noise), turned into uniform and normal deviates without the standard library's
 * distributions, so a seed gives the same cloud with every standard library. Each ray
 * draws its dropout and noise deviates whether or not it is used: clouds that differ
 * only in dropout, holes or noise come from the same rays.
 */
class PCL_EXPORTS SensorSimulator {
public:
  /** \brief A simulator with the default SensorParameters. */
  SensorSimulator();

  /** \brief Set the sensor model; draws the texture field and the holes.
   * \param[in] params the parameters.
   * \return false (and keeps the previous parameters) when \a params is invalid. */
  bool setParameters(const SensorParameters& params);

  /** \brief The current sensor model. */
  const SensorParameters& getParameters() const { return params_; }

  /** \brief Relative angular sampling density at a view direction.
   * \param[in] theta horizontal angle [rad].
   * \param[in] phi vertical angle [rad].
   * \return density relative to the densest regions, in [1 / density_ratio, 1]. */
  double getRelativeDensity(double theta, double phi) const;

  /** \brief Whether a view direction lies in one of the holes.
   * \param[in] theta horizontal angle [rad].
   * \param[in] phi vertical angle [rad]. */
  bool isInHole(double theta, double phi) const;

  /** \brief The holes drawn for the current parameters. */
  const std::vector<EllipticHole>& getHoles() const { return holes_; }

  /** \brief Scan a scene.
   * \param[in] scene surfaces to scan.
   * \param[out] cloud one point per return: x y z [m] (float) and the label of the
   *             surface hit; unorganized (height 1), dense, sensor at the origin with
   *             identity orientation; in scan order (phi rows, theta within a row).
   * \param[out] details if non-null: ray counts and noise-free ranges.
   * \return false (empty cloud) when the scene is invalid. */
  bool simulate(const Scene& scene,
                pcl::PointCloud<pcl::PointXYZL>& cloud,
                SimulationDetails* details = nullptr) const;

  /** \brief Scan one angular window at a chosen angular step.
   *
   * The same sensor as simulate() (texture field and holes of the current parameters,
   * which stay fixed in the view whatever the window; dropouts; range noise; range
   * limits), but the candidate rays lie on a jittered grid of \a window.step over the
   * window instead of num_rays over the view window of the parameters. The texture
   * field then keeps a fraction of them, as in simulate(). simulate() is unchanged.
   * \param[in] scene surfaces to scan.
   * \param[in] window the window, step and scan id.
   * \param[out] cloud as simulate().
   * \param[out] details as simulate().
   * \return false (empty cloud, with a PCL_ERROR saying why) when the scene or the
   *         window is invalid. */
  bool simulateWindow(const Scene& scene,
                      const ScanWindow& window,
                      pcl::PointCloud<pcl::PointXYZL>& cloud,
                      SimulationDetails* details = nullptr) const;

private:
  /** \brief One plane wave of the texture field, in window-normalized coordinates. */
  struct TextureWave {
    double frequency_a;
    double frequency_b;
    double phase;
  };

  /** \brief Draw the texture waves and normalize the field over the window. */
  void drawTexture();

  /** \brief Draw the holes. */
  void drawHoles();

  /** \brief Angles (theta, phi) [rad] of the rays kept by the texture field. */
  std::vector<std::array<double, 2>> sampleDirections(SimulationDetails& details) const;

  /** \brief Cast one kept ray and append its point, if any. */
  void castOne(const Scene& scene,
               const std::array<double, 2>& angles,
               double noise_deviate,
               pcl::PointCloud<pcl::PointXYZL>& cloud,
               SimulationDetails& details) const;

  /** \brief Raw texture value at window-normalized coordinates (a, b) in [0, 1]. */
  double textureValue(double a, double b) const;

  SensorParameters params_;
  std::vector<TextureWave> waves_;
  double texture_min_ = 0.0;
  double texture_max_ = 1.0;
  double mean_density_ = 1.0;
  std::vector<EllipticHole> holes_;
};

/** \brief A scene and the sensor model framing it. */
struct SimulationSetup {
  /** \brief Surfaces and label names. */
  Scene scene;
  /** \brief View window, ray count and sensor defaults for the scene. */
  SensorParameters sensor;
};

/** \brief The paper's three datasets (Sec. IV, figs. 4-6). */
enum class PaperScene {
  /** \brief A cube on a table in front of a wall (fig. 4); makeCubeScene(). */
  Cube,
  /** \brief A mock-up chair (fig. 5); makeChairScene(). */
  Chair,
  /** \brief A mock-up car door with a ding (fig. 6); makeDoorScene(). */
  Door
};

/** \brief Labels of makeCubeScene(). */
enum class CubeLabel : std::uint32_t {
  Wall = 1,  ///< "wall": the wall behind, plane z = 2.2 m
  Table = 2, ///< "table": the table top, plane y = 0.8 m (0.8 m below the sensor)
  Top = 3,   ///< "cube top"
  Right = 4, ///< "cube right": the face turned toward +x
  Front = 5  ///< "cube front": the face turned toward the sensor and -x
};

/** \brief Labels of makeChairScene() ("left" = -x, seen from the sensor). */
enum class ChairLabel : std::uint32_t {
  SeatTop = 1,        ///< "seat top"
  SeatFront = 2,      ///< "seat front"
  BackRestTop = 3,    ///< "back rest top"
  BackRestFront = 4,  ///< "back rest front"
  LeftArmTop = 5,     ///< "left arm rest top"
  LeftArmInner = 6,   ///< "left arm rest inner side" (its +x face)
  LeftArmFront = 7,   ///< "left arm rest front"
  RightArmTop = 8,    ///< "right arm rest top"
  RightArmInner = 9,  ///< "right arm rest inner side" (its -x face)
  RightArmFront = 10, ///< "right arm rest front"
};

/** \brief Labels of makeDoorScene(). */
enum class DoorLabel : std::uint32_t {
  Wall = 1,     ///< "wall": the wall behind the door, also seen through the window
  Panel = 2,    ///< "door panel": the main, gently bowed part of the door skin
  Shoulder = 3, ///< "door shoulder": the top strip curving back toward the window
  Ding = 4,     ///< "ding": a shallow dent in the panel
  Frame = 5,    ///< "window frame": four coplanar bars around the window opening
  Handle = 6,   ///< "handle": side of the cylindrical door handle
  HandleCap = 7 ///< "handle cap": the handle's end cap facing the sensor
};

/** \brief The cube dataset (fig. 4): a 0.3 m cube on a table top in front of a wall.
 *
 * The cube stands at x = 0, z = 0.9 m, turned 35 degrees about the vertical axis, so
 * that exactly three faces (top, right, front) are seen; only those are modelled
 * (FaceSelection::FacingOrigin). Labels: CubeLabel.
 *
 * \param[in] density multiplier of the ray count (> 0; one that asks for fewer than 1
 *            or more than 1e8 rays gives 1 or 1e8, with a warning); 1 gives about the
 *            paper's 5,432 points with the default sensor model.
 * \return the scene and the sensor (view window theta in [-0.35, 0.35], phi in
 *         [0.05, 0.9] rad). */
PCL_EXPORTS SimulationSetup makeCubeScene(double density = 1.0);

/** \brief The chair dataset (fig. 5): a blocky mock-up chair seen from above and in
 * front, without background.
 *
 * A solid seat block (0.5 x 0.45 x 0.45 m, seat 0.45 m above the floor), a back rest
 * board (0.5 m high, 0.08 m thick) and two arm rest blocks (0.06 m wide, 0.25 m high);
 * the sensor is 1.5 m above the floor, 1.8 m in front of the seat's centre. Only the
 * faces turned toward the sensor are modelled; each is its own label (ChairLabel).
 *
 * \param[in] density multiplier of the ray count (> 0; one that asks for fewer than 1
 *            or more than 1e8 rays gives 1 or 1e8, with a warning); 1 gives about the
 *            paper's 1,544 points with the default sensor model.
 * \return the scene and the sensor. */
PCL_EXPORTS SimulationSetup makeChairScene(double density = 1.0);

/** \brief The door dataset (fig. 6): a mock-up car door in front of a wall.
 *
 * The door skin (1.1 m wide, 0.6 m high, 1.6 m from the sensor, its centre 0.15 m to
 * the sensor's right) is a height field: bowed 4 cm toward the sensor across its width
 * and 1.5 cm over its height, with its top 0.12 m curving 6 cm back toward the window
 * (the shoulder), and a 5 cm radius, 6 mm deep dent (the ding) in its lower left part.
 * Above it, a window frame of four coplanar 5 cm bars (0.95 m wide, 0.4 m high) leans
 * back by 20 degrees; the wall 2.6 m away is seen around the door and through the
 * window. A horizontal cylindrical handle (radius 2.5 cm, 0.2 m long) stands 1.2 cm in
 * front of the skin; its cap nearer the sensor's axis is seen at about 18 degrees.
 * Labels: DoorLabel.
 *
 * \param[in] density multiplier of the ray count (> 0; one that asks for fewer than 1
 *            or more than 1e8 rays gives 1 or 1e8, with a warning); 1 gives about the
 *            paper's 46,255 points with the default sensor model.
 * \return the scene and the sensor. */
PCL_EXPORTS SimulationSetup makeDoorScene(double density = 1.0);

/** \brief One of the paper's scenes, as makeCubeScene(), makeChairScene() or
 * makeDoorScene().
 * \param[in] scene which dataset.
 * \param[in] density multiplier of the ray count (> 0). */
PCL_EXPORTS SimulationSetup makePaperScene(PaperScene scene, double density = 1.0);

/** \brief Number of points of the paper's dataset (Table I): 5,432 (cube), 1,544
 * (chair), 46,255 (door). */
PCL_EXPORTS std::size_t getPaperPointCount(PaperScene scene);

/** \brief Lower-case name of a paper scene: "cube", "chair" or "door". */
PCL_EXPORTS std::string getPaperSceneName(PaperScene scene);

/** \brief The paper scene of a name.
 * \param[in] name "cube", "chair" or "door".
 * \param[out] scene the scene, when the name is known.
 * \return false for an unknown name. */
PCL_EXPORTS bool parsePaperScene(const std::string& name, PaperScene& scene);

} // namespace simulation
} // namespace selective_seg
} // namespace pcl
