/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/sensor_simulator.h>

#include <Eigen/Geometry>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <utility>

namespace pcl {
namespace selective_seg {
namespace simulation {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

/** Independent random streams of one seed (see SensorSimulator). */
enum RandomStream : std::uint32_t {
  kTextureStream = 1,
  kHoleStream = 2,
  kGridStream = 3,
  kDropoutStream = 4,
  kNoiseStream = 5
};

/** Grid on which the texture field is normalized and its mean taken, per axis. */
constexpr int kTextureGrid = 65;

/** Padding of a height field's height slab: this many metres, plus this fraction of
 * its largest height bound. */
constexpr double kSlabPadding = 1e-9;

/** Largest max_range [m]: beyond it a hit's float coordinates could overflow. */
constexpr double kMaxSimulatedRange = 1e30;

/** Samples per side of the grid on which validateScene() checks a height field's
 * functions against its bounds and labels. */
constexpr int kFieldCheckGrid = 17;

/** Plane waves summed into the texture field. */
constexpr int kTextureWaves = 6;

std::mt19937
makeEngine(std::uint32_t seed, std::uint32_t stream)
{
  std::seed_seq sequence{seed, stream};
  return std::mt19937(sequence);
}

/** Uniform deviate in (0, 1) from the engine's 32-bit output only. */
double
uniform01(std::mt19937& engine)
{
  return (static_cast<double>(engine()) + 0.5) / 4294967296.0;
}

/** Standard normal deviate (Box-Muller, one value per two uniforms). */
double
standardNormal(std::mt19937& engine)
{
  const double radius = std::sqrt(-2.0 * std::log(uniform01(engine)));
  return radius * std::cos(2.0 * kPi * uniform01(engine));
}

/** The jittered grid every scan samples: rows x columns cells from (theta_min,
 * phi_min), each shifted by up to jitter / 2 of a cell in both angles and given an
 * acceptance draw, all three from \a engine in that order; f(theta, phi, accept) per
 * cell, row by row. */
template <typename F>
void
forEachJitteredCell(double theta_min,
                    double phi_min,
                    double cell_width,
                    double cell_height,
                    long rows,
                    long columns,
                    double jitter,
                    std::mt19937& engine,
                    F f)
{
  for (long row = 0; row < rows; ++row)
    for (long column = 0; column < columns; ++column) {
      const double du = jitter * (uniform01(engine) - 0.5);
      const double dv = jitter * (uniform01(engine) - 0.5);
      const double accept = uniform01(engine);
      f(theta_min + (column + 0.5 + du) * cell_width,
        phi_min + (row + 0.5 + dv) * cell_height,
        accept);
    }
}

bool
isFinite(const Eigen::Vector3d& v)
{
  return v.allFinite();
}

/** Coordinates (s, t) of an in-plane offset in the basis (u, v). */
void
planeCoordinates(const Eigen::Vector3d& u,
                 const Eigen::Vector3d& v,
                 const Eigen::Vector3d& offset,
                 double& s,
                 double& t)
{
  const double uu = u.squaredNorm();
  const double uv = u.dot(v);
  const double vv = v.squaredNorm();
  const double ou = offset.dot(u);
  const double ov = offset.dot(v);
  const double determinant = uu * vv - uv * uv;
  s = (vv * ou - uv * ov) / determinant;
  t = (uu * ov - uv * ou) / determinant;
}

/** Range in (0, hit.range) at which the ray meets the plane normal . (p - point) = 0,
 * or a negative value when it does not. */
double
planeRange(const Ray& ray,
           const Eigen::Vector3d& point,
           const Eigen::Vector3d& normal,
           const Hit& hit)
{
  const double denominator = normal.dot(ray.direction);
  if (denominator == 0.0)
    return -1.0;
  const double range = normal.dot(point - ray.origin) / denominator;
  return range > 0.0 && range < hit.range ? range : -1.0;
}

/** Restrict [r_min, r_max] to the ranges where c0 + r * c1 lies in [lo, hi].
 * \return false when nothing is left. */
bool
clipRange(double c0, double c1, double lo, double hi, double& r_min, double& r_max)
{
  if (c1 == 0.0)
    return c0 >= lo && c0 <= hi;
  double enter = (lo - c0) / c1;
  double leave = (hi - c0) / c1;
  if (enter > leave)
    std::swap(enter, leave);
  r_min = std::max(r_min, enter);
  r_max = std::min(r_max, leave);
  return r_min <= r_max;
}

/** A height field's coordinates (s, t, h) along a ray, each c0 + r * c1. */
struct FieldCoordinates {
  Eigen::Vector3d at_origin;
  Eigen::Vector3d per_metre;

  Eigen::Vector3d at(double range) const { return at_origin + range * per_metre; }
};

FieldCoordinates
fieldCoordinates(const Ray& ray, const HeightField& field)
{
  const double uu = field.u.squaredNorm();
  const double uv = field.u.dot(field.v);
  const double vv = field.v.squaredNorm();
  const double determinant = uu * vv - uv * uv;
  const Eigen::Vector3d s_gradient = (vv * field.u - uv * field.v) / determinant;
  const Eigen::Vector3d t_gradient = (uu * field.v - uv * field.u) / determinant;
  const Eigen::Vector3d normal = field.u.cross(field.v).normalized();
  const Eigen::Vector3d offset = ray.origin - field.origin;
  FieldCoordinates c;
  c.at_origin << s_gradient.dot(offset), t_gradient.dot(offset), normal.dot(offset);
  c.per_metre << s_gradient.dot(ray.direction), t_gradient.dot(ray.direction),
      normal.dot(ray.direction);
  return c;
}

/** Height of the ray above the surface at a range [m]. */
double
heightAbove(const HeightField& field, const FieldCoordinates& c, double range)
{
  const Eigen::Vector3d p = c.at(range);
  return p.z() - field.height(std::clamp(p.x(), 0.0, 1.0), std::clamp(p.y(), 0.0, 1.0));
}

/** Bisect a sign change of heightAbove() in [lo, hi] to double precision. */
double
bisectCrossing(const HeightField& field,
               const FieldCoordinates& c,
               double lo,
               double hi,
               bool lo_above)
{
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (!(mid > lo && mid < hi))
      break;
    if ((heightAbove(field, c, mid) > 0.0) == lo_above)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

/** Nearest crossing of the surface in [r_min, r_max], or a negative value. */
double
searchCrossing(const HeightField& field,
               const FieldCoordinates& c,
               double r_min,
               double r_max)
{
  const double span = r_max - r_min;
  const double steps = std::clamp(std::ceil(span / field.max_step), 1.0, 1e6);
  const int num_steps = static_cast<int>(steps);
  double previous = heightAbove(field, c, r_min);
  if (previous == 0.0)
    return r_min;
  for (int i = 1; i <= num_steps; ++i) {
    const double r = i == num_steps ? r_max : r_min + span * i / num_steps;
    const double current = heightAbove(field, c, r);
    if (current == 0.0)
      return r;
    if ((current > 0.0) != (previous > 0.0))
      return bisectCrossing(
          field, c, r_min + span * (i - 1) / num_steps, r, previous > 0.0);
    previous = current;
  }
  return -1.0;
}

/** Append a parallelogram with a new label named \a name. */
std::uint32_t
addFace(Scene& scene,
        const Eigen::Vector3d& origin,
        const Eigen::Vector3d& u,
        const Eigen::Vector3d& v,
        const std::string& name)
{
  Parallelogram face;
  face.origin = origin;
  face.u = u;
  face.v = v;
  face.label = scene.addLabel(name);
  scene.parallelograms.push_back(face);
  return face.label;
}

/** Whether a plane with outward \a normal through \a point faces the origin. */
bool
facesOrigin(const Eigen::Vector3d& point, const Eigen::Vector3d& normal)
{
  return normal.dot(point) < 0.0;
}

} // namespace

std::uint32_t
Scene::addLabel(const std::string& name)
{
  const std::uint32_t label = label_names.empty() ? 1 : label_names.rbegin()->first + 1;
  label_names[label] = name;
  return label;
}

bool
intersect(const Ray& ray, const Parallelogram& face, Hit& hit)
{
  const double range = planeRange(ray, face.origin, face.u.cross(face.v), hit);
  if (!(range > 0.0))
    return false;
  double s = 0.0;
  double t = 0.0;
  planeCoordinates(
      face.u, face.v, ray.origin + range * ray.direction - face.origin, s, t);
  if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0)
    return false;
  hit.range = range;
  hit.label = face.label;
  return true;
}

bool
intersect(const Ray& ray, const Disk& disk, Hit& hit)
{
  const double range = planeRange(ray, disk.centre, disk.normal, hit);
  if (!(range > 0.0))
    return false;
  const Eigen::Vector3d offset = ray.origin + range * ray.direction - disk.centre;
  if (offset.squaredNorm() > disk.radius * disk.radius)
    return false;
  hit.range = range;
  hit.label = disk.label;
  return true;
}

bool
intersect(const Ray& ray, const CylinderPatch& patch, Hit& hit)
{
  const Eigen::Vector3d axis = patch.axis.normalized();
  const Eigen::Vector3d e1 =
      (patch.reference - patch.reference.dot(axis) * axis).normalized();
  const Eigen::Vector3d e2 = axis.cross(e1);
  const Eigen::Vector3d w = ray.origin - patch.base;
  const Eigen::Vector3d w_perp = w - w.dot(axis) * axis;
  const Eigen::Vector3d d_perp = ray.direction - ray.direction.dot(axis) * axis;
  const double a = d_perp.squaredNorm();
  const double b = 2.0 * w_perp.dot(d_perp);
  const double c = w_perp.squaredNorm() - patch.radius * patch.radius;
  const double discriminant = b * b - 4.0 * a * c;
  if (a == 0.0 || discriminant < 0.0)
    return false;
  const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
  double roots[2] = {q / a, q != 0.0 ? c / q : q / a};
  if (roots[0] > roots[1])
    std::swap(roots[0], roots[1]);
  for (const double range : roots) {
    if (!(range > 0.0 && range < hit.range))
      continue;
    const Eigen::Vector3d p = w + range * ray.direction;
    const double along = p.dot(axis);
    const double angle = std::atan2(p.dot(e2), p.dot(e1));
    if (along < 0.0 || along > patch.length || angle < patch.angle_min ||
        angle > patch.angle_max)
      continue;
    hit.range = range;
    hit.label = patch.label;
    return true;
  }
  return false;
}

bool
intersect(const Ray& ray, const HeightField& field, Hit& hit)
{
  const FieldCoordinates c = fieldCoordinates(ray, field);
  double r_min = 0.0;
  double r_max = hit.range;
  // The height slab is padded so that a surface lying on its bounds (a flat field)
  // still shows a sign change inside it.
  const double pad = kSlabPadding * (1.0 + std::max(std::abs(field.min_height),
                                                    std::abs(field.max_height)));
  if (!clipRange(c.at_origin.x(), c.per_metre.x(), 0.0, 1.0, r_min, r_max) ||
      !clipRange(c.at_origin.y(), c.per_metre.y(), 0.0, 1.0, r_min, r_max) ||
      !clipRange(c.at_origin.z(),
                 c.per_metre.z(),
                 field.min_height - pad,
                 field.max_height + pad,
                 r_min,
                 r_max) ||
      !std::isfinite(r_max))
    return false;
  const double range = searchCrossing(field, c, r_min, r_max);
  if (!(range > 0.0 && range < hit.range))
    return false;
  const Eigen::Vector3d st = c.at(range);
  hit.range = range;
  hit.label = field.label(std::clamp(st.x(), 0.0, 1.0), std::clamp(st.y(), 0.0, 1.0));
  return true;
}

bool
castRay(const Scene& scene, const Ray& ray, Hit& hit)
{
  hit = Hit();
  bool found = false;
  for (const auto& face : scene.parallelograms)
    found |= intersect(ray, face, hit);
  for (const auto& disk : scene.disks)
    found |= intersect(ray, disk, hit);
  for (const auto& patch : scene.cylinders)
    found |= intersect(ray, patch, hit);
  for (const auto& field : scene.height_fields)
    found |= intersect(ray, field, hit);
  return found;
}

std::array<std::uint32_t, 6>
addBox(Scene& scene,
       const Eigen::Vector3d& centre,
       const Eigen::Vector3d& half_sizes,
       const Eigen::Matrix3d& rotation,
       const std::string& name,
       FaceSelection selection)
{
  const Eigen::Vector3d ex = 2.0 * half_sizes.x() * rotation.col(0);
  const Eigen::Vector3d ey = 2.0 * half_sizes.y() * rotation.col(1);
  const Eigen::Vector3d ez = 2.0 * half_sizes.z() * rotation.col(2);
  // Per face: the edge from the opposite face to it (along its outward normal), and
  // its two edges u, v with u x v along that normal.
  const Eigen::Vector3d across[6] = {-ey, ey, -ex, ex, -ez, ez};
  const Eigen::Vector3d edges[6][2] = {
      {ex, ez}, {ez, ex}, {ez, ey}, {ey, ez}, {ey, ex}, {ex, ey}};
  const char* face_names[6] = {"top", "bottom", "left", "right", "front", "back"};
  std::array<std::uint32_t, 6> labels{};
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d face_centre = centre + 0.5 * across[i];
    if (selection == FaceSelection::FacingOrigin &&
        !facesOrigin(face_centre, across[i]))
      continue;
    const Eigen::Vector3d& u = edges[i][0];
    const Eigen::Vector3d& v = edges[i][1];
    labels[i] =
        addFace(scene, face_centre - 0.5 * (u + v), u, v, name + " " + face_names[i]);
  }
  return labels;
}

std::array<std::uint32_t, 3>
addCylinder(Scene& scene,
            const Eigen::Vector3d& base,
            const Eigen::Vector3d& axis,
            double radius,
            const std::string& name,
            FaceSelection selection)
{
  const bool facing_only = selection == FaceSelection::FacingOrigin;
  const Eigen::Vector3d unit = axis.normalized();
  const Eigen::Vector3d base_to_origin = -base;
  const bool origin_inside =
      (base_to_origin - base_to_origin.dot(unit) * unit).norm() <= radius;
  std::array<std::uint32_t, 3> labels{};
  if (!facing_only || !origin_inside) {
    CylinderPatch side;
    side.base = base;
    side.axis = unit;
    side.reference = unit.unitOrthogonal();
    side.radius = radius;
    side.length = axis.norm();
    side.label = labels[0] = scene.addLabel(name + " side");
    scene.cylinders.push_back(side);
  }
  const Eigen::Vector3d centres[2] = {base, base + axis};
  const Eigen::Vector3d normals[2] = {-unit, unit};
  const char* cap_names[2] = {" base cap", " end cap"};
  for (int i = 0; i < 2; ++i) {
    if (facing_only && !facesOrigin(centres[i], normals[i]))
      continue;
    Disk cap;
    cap.centre = centres[i];
    cap.normal = normals[i];
    cap.radius = radius;
    cap.label = labels[i + 1] = scene.addLabel(name + cap_names[i]);
    scene.disks.push_back(cap);
  }
  return labels;
}

namespace {

bool
fail(std::string* why, const std::string& message)
{
  if (why)
    *why = message;
  return false;
}

std::string
describe(const char* kind, std::size_t index, const char* problem)
{
  std::ostringstream s;
  s << kind << " " << index << ": " << problem;
  return s.str();
}

bool
validatePlanar(const Scene& scene, std::string* why)
{
  for (std::size_t i = 0; i < scene.parallelograms.size(); ++i) {
    const auto& f = scene.parallelograms[i];
    if (f.label == 0)
      return fail(why, describe("parallelogram", i, "label 0 (labels are >= 1)"));
    if (!isFinite(f.origin) || !(f.u.cross(f.v).norm() > 0.0) ||
        !std::isfinite(f.u.cross(f.v).norm()))
      return fail(why, describe("parallelogram", i, "degenerate or not finite"));
  }
  for (std::size_t i = 0; i < scene.disks.size(); ++i) {
    const auto& d = scene.disks[i];
    if (d.label == 0)
      return fail(why, describe("disk", i, "label 0 (labels are >= 1)"));
    if (!isFinite(d.centre) || !isFinite(d.normal) || !(d.normal.norm() > 0.0) ||
        !(d.radius > 0.0) || !std::isfinite(d.radius))
      return fail(why, describe("disk", i, "degenerate or not finite"));
  }
  return true;
}

bool
validateCurved(const Scene& scene, std::string* why)
{
  for (std::size_t i = 0; i < scene.cylinders.size(); ++i) {
    const auto& c = scene.cylinders[i];
    const Eigen::Vector3d axis = c.axis.normalized();
    const bool ok = isFinite(c.base) && isFinite(axis) && c.axis.norm() > 0.0 &&
                    (c.reference - c.reference.dot(axis) * axis).norm() > 0.0 &&
                    c.radius > 0.0 && std::isfinite(c.radius) && c.length > 0.0 &&
                    std::isfinite(c.length) && c.angle_min >= -kPi &&
                    c.angle_max <= kPi && c.angle_min < c.angle_max;
    if (c.label == 0)
      return fail(why, describe("cylinder", i, "label 0 (labels are >= 1)"));
    if (!ok)
      return fail(why, describe("cylinder", i, "degenerate, not finite or bad angles"));
  }
  for (std::size_t i = 0; i < scene.height_fields.size(); ++i) {
    const auto& h = scene.height_fields[i];
    const double area = h.u.cross(h.v).norm();
    if (!h.height || !h.label)
      return fail(why, describe("height field", i, "height or label function unset"));
    if (!isFinite(h.origin) || !(area > 0.0) || !std::isfinite(area) ||
        !std::isfinite(h.min_height) || !std::isfinite(h.max_height) ||
        h.min_height > h.max_height || !(h.max_step > 0.0))
      return fail(why, describe("height field", i, "degenerate or bad bounds/step"));
    // The functions are the caller's: spot-check them on a grid. A height outside the
    // bounds would be missed by the rays (they search between the bounds only), and a
    // label 0 would be written as a point without a surface.
    const double pad =
        kSlabPadding * (1.0 + std::max(std::abs(h.min_height), std::abs(h.max_height)));
    for (int a = 0; a < kFieldCheckGrid; ++a)
      for (int b = 0; b < kFieldCheckGrid; ++b) {
        const double fs = static_cast<double>(a) / (kFieldCheckGrid - 1);
        const double ft = static_cast<double>(b) / (kFieldCheckGrid - 1);
        const double z = h.height(fs, ft);
        if (!(z >= h.min_height - pad && z <= h.max_height + pad)) {
          std::ostringstream m;
          m << std::setprecision(17) << "height(" << fs << ", " << ft << ") = " << z
            << " outside [min_height, max_height] = [" << h.min_height << ", "
            << h.max_height << "]";
          return fail(why, describe("height field", i, m.str().c_str()));
        }
        if (h.label(fs, ft) == 0) {
          std::ostringstream m;
          m << "label(" << fs << ", " << ft << ") = 0 (labels are >= 1)";
          return fail(why, describe("height field", i, m.str().c_str()));
        }
      }
  }
  return true;
}

} // namespace

bool
validateScene(const Scene& scene, std::string* why)
{
  return validatePlanar(scene, why) && validateCurved(scene, why);
}

namespace {

/** "parameter NAME = VALUE is invalid: valid range RANGE", with \a bound after the
 * range when it names another parameter's value. */
bool
reject(std::string* why,
       const char* name,
       double value,
       const char* range,
       double bound = std::numeric_limits<double>::quiet_NaN())
{
  std::ostringstream s;
  s << std::setprecision(12) << "parameter " << name << " = " << value
    << " is invalid: valid range " << range;
  if (!std::isnan(bound))
    s << " = " << bound;
  return fail(why, s.str());
}

bool
inRange(double value, double lo, double hi)
{
  return std::isfinite(value) && value >= lo && value <= hi;
}

bool
validateWindow(const SensorParameters& p, std::string* why)
{
  const double limit = 0.5 * kPi;
  if (!(p.theta_min > -limit && p.theta_min < limit))
    return reject(why, "theta_min [rad]", p.theta_min, "(-pi/2, pi/2)");
  if (!(p.theta_max > -limit && p.theta_max < limit))
    return reject(why, "theta_max [rad]", p.theta_max, "(-pi/2, pi/2)");
  if (!(p.theta_min < p.theta_max))
    return reject(why, "theta_max [rad]", p.theta_max, "above theta_min", p.theta_min);
  if (!(p.phi_min > -limit && p.phi_min < limit))
    return reject(why, "phi_min [rad]", p.phi_min, "(-pi/2, pi/2)");
  if (!(p.phi_max > -limit && p.phi_max < limit))
    return reject(why, "phi_max [rad]", p.phi_max, "(-pi/2, pi/2)");
  if (!(p.phi_min < p.phi_max))
    return reject(why, "phi_max [rad]", p.phi_max, "above phi_min", p.phi_min);
  return true;
}

} // namespace

bool
SensorParameters::validate(std::string* why) const
{
  if (!validateWindow(*this, why))
    return false;
  if (num_rays < 1 || num_rays > 100000000)
    return reject(why, "num_rays", static_cast<double>(num_rays), "[1, 100000000]");
  if (!inRange(density_ratio, 1.0, 100.0))
    return reject(why, "density_ratio", density_ratio, "[1, 100]");
  if (!inRange(texture_cycles, 0.0, 20.0) || texture_cycles == 0.0)
    return reject(why, "texture_cycles [1/window]", texture_cycles, "(0, 20]");
  if (!inRange(jitter, 0.0, 1.0))
    return reject(why, "jitter [cell]", jitter, "[0, 1]");
  if (!inRange(dropout, 0.0, 1.0) || dropout == 1.0)
    return reject(why, "dropout", dropout, "[0, 1)");
  if (num_holes < 0 || num_holes > 1000)
    return reject(why, "num_holes", num_holes, "[0, 1000]");
  if (!inRange(hole_radius, 0.0, 1.0))
    return reject(why, "hole_radius [rad]", hole_radius, "[0, 1]");
  if (!inRange(range_noise, 0.0, 1.0))
    return reject(why, "range_noise [1/m]", range_noise, "[0, 1]");
  if (!std::isfinite(min_range) || min_range < 0.0)
    return reject(why, "min_range [m]", min_range, ">= 0");
  if (!(max_range > min_range && max_range <= kMaxSimulatedRange))
    return reject(why, "max_range [m]", max_range, "(min_range, 1e30]");
  return true;
}

SensorSimulator::SensorSimulator()
{
  drawTexture();
  drawHoles();
}

bool
SensorSimulator::setParameters(const SensorParameters& params)
{
  std::string why;
  if (!params.validate(&why)) {
    PCL_ERROR("[pcl::selective_seg::simulation::SensorSimulator::setParameters] %s\n",
              why.c_str());
    return false;
  }
  params_ = params;
  drawTexture();
  drawHoles();
  return true;
}

double
SensorSimulator::textureValue(double a, double b) const
{
  double value = 0.0;
  for (const auto& wave : waves_)
    value += std::cos(2.0 * kPi * (wave.frequency_a * a + wave.frequency_b * b) +
                      wave.phase);
  return value;
}

void
SensorSimulator::drawTexture()
{
  std::mt19937 engine = makeEngine(params_.seed, kTextureStream);
  waves_.clear();
  for (int i = 0; i < kTextureWaves; ++i) {
    const double frequency = params_.texture_cycles * (0.5 + 0.5 * uniform01(engine));
    const double direction = 2.0 * kPi * uniform01(engine);
    const double phase = 2.0 * kPi * uniform01(engine);
    waves_.push_back(
        {frequency * std::cos(direction), frequency * std::sin(direction), phase});
  }
  const double step = 1.0 / (kTextureGrid - 1);
  texture_min_ = kInfinity;
  texture_max_ = -kInfinity;
  for (int i = 0; i < kTextureGrid; ++i)
    for (int j = 0; j < kTextureGrid; ++j) {
      const double value = textureValue(i * step, j * step);
      texture_min_ = std::min(texture_min_, value);
      texture_max_ = std::max(texture_max_, value);
    }
  const double width = params_.theta_max - params_.theta_min;
  const double height = params_.phi_max - params_.phi_min;
  double sum = 0.0;
  for (int i = 0; i < kTextureGrid; ++i)
    for (int j = 0; j < kTextureGrid; ++j)
      sum += getRelativeDensity(params_.theta_min + i * step * width,
                                params_.phi_min + j * step * height);
  mean_density_ = sum / (kTextureGrid * kTextureGrid);
}

void
SensorSimulator::drawHoles()
{
  std::mt19937 engine = makeEngine(params_.seed, kHoleStream);
  holes_.clear();
  for (int i = 0; i < params_.num_holes; ++i) {
    EllipticHole hole;
    hole.theta =
        params_.theta_min + (params_.theta_max - params_.theta_min) * uniform01(engine);
    hole.phi =
        params_.phi_min + (params_.phi_max - params_.phi_min) * uniform01(engine);
    hole.semi_axis_a = params_.hole_radius * (0.5 + uniform01(engine));
    hole.semi_axis_b = params_.hole_radius * (0.5 + uniform01(engine));
    hole.orientation = kPi * uniform01(engine);
    holes_.push_back(hole);
  }
}

double
SensorSimulator::getRelativeDensity(double theta, double phi) const
{
  const double a =
      (theta - params_.theta_min) / (params_.theta_max - params_.theta_min);
  const double b = (phi - params_.phi_min) / (params_.phi_max - params_.phi_min);
  const double spread = texture_max_ - texture_min_;
  const double g =
      spread > 0.0 ? std::clamp((textureValue(a, b) - texture_min_) / spread, 0.0, 1.0)
                   : 1.0;
  return std::pow(params_.density_ratio, g * g * (3.0 - 2.0 * g) - 1.0);
}

bool
SensorSimulator::isInHole(double theta, double phi) const
{
  for (const auto& hole : holes_) {
    const double dt = theta - hole.theta;
    const double dp = phi - hole.phi;
    // A point of the ellipse lies within its larger semi-axis of the centre: a ray
    // farther in either angle is outside, without the rotation's cosine and sine
    // (most rays, for most holes). The margin keeps the exact test's answer wherever
    // its rounding could differ.
    const double reach = std::max(hole.semi_axis_a, hole.semi_axis_b) * (1.0 + 1e-9);
    if (std::abs(dt) > reach || std::abs(dp) > reach)
      continue;
    const double c = std::cos(hole.orientation);
    const double s = std::sin(hole.orientation);
    const double x = (c * dt + s * dp) / hole.semi_axis_a;
    const double y = (c * dp - s * dt) / hole.semi_axis_b;
    if (x * x + y * y <= 1.0)
      return true;
  }
  return false;
}

std::vector<std::array<double, 2>>
SensorSimulator::sampleDirections(SimulationDetails& details) const
{
  const double width = params_.theta_max - params_.theta_min;
  const double height = params_.phi_max - params_.phi_min;
  const double cells = static_cast<double>(params_.num_rays) / mean_density_;
  // About sqrt(cells) columns and rows in the window's aspect ratio. A window much
  // wider than tall (or the reverse) has fewer rows than one: the columns are then
  // capped at the cells, and when rounding the rows misses the cells by more than 5%
  // (a window a row or two high) the columns are made again from the rows, so that
  // there are always about num_rays / mean density candidates.
  const long most = std::max(1L, std::lround(cells));
  long columns = std::clamp(std::lround(std::sqrt(cells * width / height)), 1L, most);
  const long rows =
      std::clamp(std::lround(cells / static_cast<double>(columns)), 1L, most);
  if (std::abs(static_cast<double>(rows * columns) - cells) > 0.05 * cells)
    columns = std::clamp(std::lround(cells / static_cast<double>(rows)), 1L, most);
  const double cell_width = width / columns;
  const double cell_height = height / rows;
  std::mt19937 engine = makeEngine(params_.seed, kGridStream);
  std::vector<std::array<double, 2>> kept;
  kept.reserve(params_.num_rays + params_.num_rays / 4);
  forEachJitteredCell(params_.theta_min,
                      params_.phi_min,
                      cell_width,
                      cell_height,
                      rows,
                      columns,
                      params_.jitter,
                      engine,
                      [&](double theta, double phi, double accept) {
                        if (accept < getRelativeDensity(theta, phi))
                          kept.push_back({theta, phi});
                      });
  details.candidates = static_cast<std::size_t>(rows * columns);
  details.rays = kept.size();
  return kept;
}

void
SensorSimulator::castOne(const Scene& scene,
                         const std::array<double, 2>& angles,
                         double noise_deviate,
                         pcl::PointCloud<pcl::PointXYZL>& cloud,
                         SimulationDetails& details) const
{
  Ray ray;
  ray.direction =
      Eigen::Vector3d(std::tan(angles[0]), std::tan(angles[1]), 1.0).normalized();
  Hit hit;
  if (!castRay(scene, ray, hit)) {
    ++details.missed;
    return;
  }
  if (hit.label == 0) { // a height field's label function broke its contract
    ++details.unlabeled_hits;
    return;
  }
  const double sigma = params_.range_noise * hit.range * hit.range;
  const double measured = hit.range + sigma * noise_deviate;
  if (!(measured >= params_.min_range && measured <= params_.max_range)) {
    ++details.out_of_range;
    return;
  }
  const Eigen::Vector3f position = (measured * ray.direction).cast<float>();
  pcl::PointXYZL point;
  point.x = position.x();
  point.y = position.y();
  point.z = position.z();
  point.label = hit.label;
  cloud.push_back(point);
  details.exact_ranges.push_back(hit.range);
}

namespace {

/** True when no hit had label 0; otherwise an error, and the cloud emptied. */
bool
unlabeledHitsRefused(SimulationDetails& d,
                     pcl::PointCloud<pcl::PointXYZL>& cloud,
                     const char* method)
{
  if (d.unlabeled_hits == 0)
    return true;
  PCL_ERROR(
      "[pcl::selective_seg::simulation::SensorSimulator::%s] %zu hits on a height "
      "field whose label function gave 0 (labels are >= 1): no point returned\n",
      method,
      d.unlabeled_hits);
  cloud.clear();
  cloud.width = 0;
  cloud.height = 1;
  std::vector<double>().swap(d.exact_ranges); // one per point returned: none
  return false;
}

} // namespace

bool
SensorSimulator::simulate(const Scene& scene,
                          pcl::PointCloud<pcl::PointXYZL>& cloud,
                          SimulationDetails* details) const
{
  cloud.clear();
  cloud.height = 1;
  SimulationDetails local;
  SimulationDetails& d = details ? *details : local;
  d = SimulationDetails();
  std::string why;
  if (!validateScene(scene, &why)) {
    PCL_ERROR("[pcl::selective_seg::simulation::SensorSimulator::simulate] invalid "
              "scene: %s\n",
              why.c_str());
    return false;
  }
  std::mt19937 dropout_engine = makeEngine(params_.seed, kDropoutStream);
  std::mt19937 noise_engine = makeEngine(params_.seed, kNoiseStream);
  for (const auto& angles : sampleDirections(d)) {
    const bool dropped = uniform01(dropout_engine) < params_.dropout;
    const double deviate = standardNormal(noise_engine);
    if (isInHole(angles[0], angles[1]))
      ++d.in_holes;
    else if (dropped)
      ++d.dropped;
    else
      castOne(scene, angles, deviate, cloud, d);
  }
  if (!unlabeledHitsRefused(d, cloud, "simulate"))
    return false;
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  cloud.sensor_origin_ = Eigen::Vector4f::Zero();
  cloud.sensor_orientation_ = Eigen::Quaternionf::Identity();
  return true;
}

bool
ScanWindow::validate(std::string* why) const
{
  const double limit = 0.5 * kPi;
  const auto bounds = [&](const char* name, double lo, double hi) {
    std::ostringstream s;
    s << std::setprecision(17) << "scan window " << name << "_min " << lo << ", "
      << name << "_max " << hi << ": need -pi/2 < " << name << "_min < " << name
      << "_max < pi/2 [rad]";
    return fail(why, s.str());
  };
  if (!(theta_min > -limit && theta_min < theta_max && theta_max < limit))
    return bounds("theta", theta_min, theta_max);
  if (!(phi_min > -limit && phi_min < phi_max && phi_max < limit))
    return bounds("phi", phi_min, phi_max);
  if (!(step > 0.0) || !std::isfinite(step))
    return reject(why, "scan window step", step, "(0, inf) [rad]");
  const double cells = std::ceil((theta_max - theta_min) / step + 0.5) *
                       std::ceil((phi_max - phi_min) / step + 0.5);
  if (!(cells <= 1e8))
    return reject(why,
                  "scan window step",
                  step,
                  "large enough for at most 1e8 grid cells over the window [rad]");
  return true;
}

bool
SensorSimulator::simulateWindow(const Scene& scene,
                                const ScanWindow& window,
                                pcl::PointCloud<pcl::PointXYZL>& cloud,
                                SimulationDetails* details) const
{
  cloud.clear();
  cloud.height = 1;
  cloud.width = 0;
  SimulationDetails local;
  SimulationDetails& d = details ? *details : local;
  d = SimulationDetails();
  std::string why;
  if (!validateScene(scene, &why) || !window.validate(&why)) {
    PCL_ERROR("[pcl::selective_seg::simulation::SensorSimulator::simulateWindow] %s\n",
              why.c_str());
    return false;
  }
  // Streams of their own, seeded with the window's id: a window scan never repeats
  // the rays of simulate() or of another id.
  const auto engine = [&](std::uint32_t stream) {
    std::seed_seq sequence{params_.seed, stream, window.scan_id, 0x57696e64u};
    return std::mt19937(sequence);
  };
  std::mt19937 grid_engine = engine(kGridStream);
  std::mt19937 dropout_engine = engine(kDropoutStream);
  std::mt19937 noise_engine = engine(kNoiseStream);
  const double width = window.theta_max - window.theta_min;
  const double height = window.phi_max - window.phi_min;
  const long columns = std::max(1L, std::lround(width / window.step));
  const long rows = std::max(1L, std::lround(height / window.step));
  const double cell_width = width / columns;
  const double cell_height = height / rows;
  forEachJitteredCell(window.theta_min,
                      window.phi_min,
                      cell_width,
                      cell_height,
                      rows,
                      columns,
                      params_.jitter,
                      grid_engine,
                      [&](double theta, double phi, double accept) {
                        const bool dropped = uniform01(dropout_engine) < params_.dropout;
                        const double deviate = standardNormal(noise_engine);
                        if (!(accept < getRelativeDensity(theta, phi)))
                          return;
                        ++d.rays;
                        if (isInHole(theta, phi))
                          ++d.in_holes;
                        else if (dropped)
                          ++d.dropped;
                        else
                          castOne(scene, {theta, phi}, deviate, cloud, d);
                      });
  d.candidates = static_cast<std::size_t>(rows * columns);
  if (!unlabeledHitsRefused(d, cloud, "simulateWindow"))
    return false;
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  cloud.sensor_origin_ = Eigen::Vector4f::Zero();
  cloud.sensor_orientation_ = Eigen::Quaternionf::Identity();
  return true;
}

namespace {

/** Expected rays of each paper scene at density 1: the paper's point count divided by
 * the fraction of rays that return a point with the default sensor model (dropouts,
 * holes and, for the chair, rays that miss it), measured with the default seed. */
constexpr double kCubeRays = 5800.0;
constexpr double kChairRays = 2030.0;
constexpr double kDoorRays = 49400.0;

SensorParameters
viewWindow(double theta_min,
           double theta_max,
           double phi_min,
           double phi_max,
           double rays,
           double density)
{
  SensorParameters sensor;
  sensor.theta_min = theta_min;
  sensor.theta_max = theta_max;
  sensor.phi_min = phi_min;
  sensor.phi_max = phi_max;
  const double count = std::round(rays * (density > 0.0 ? density : 0.0));
  sensor.num_rays = static_cast<std::size_t>(std::clamp(count, 1.0, 1e8));
  if (!(count >= 1.0 && count <= 1e8))
    PCL_WARN("[pcl::selective_seg::simulation] scene density %g asks for %g rays; the "
             "sensor casts %zu (the simulator's range is [1, 1e8])\n",
             density,
             rays * density,
             sensor.num_rays);
  return sensor;
}

double
smoothStep(double x)
{
  const double c = std::clamp(x, 0.0, 1.0);
  return c * c * (3.0 - 2.0 * c);
}

/** Shift of the door to the right of the sensor [m]: the door is seen a little from
 * its left, so that the handle's end cap faces the sensor at about 18 degrees. */
constexpr double kDoorShift = 0.15;

/** The door skin of makeDoorScene(): extent, shape and labels. */
struct DoorSkin {
  static constexpr double kWidth = 1.1;
  static constexpr double kHeight = 0.6;
  static constexpr double kShoulderT = 0.2;
  static constexpr double kShoulderDepth = 0.06;
  static constexpr double kBowAcross = 0.04;
  static constexpr double kBowDown = 0.015;
  static constexpr double kDingS = 0.3;
  static constexpr double kDingT = 0.6;
  static constexpr double kDingRadius = 0.05;
  static constexpr double kDingDepth = 0.006;

  /** Squared distance from the ding's centre in units of its radius. */
  static double dingDistance2(double s, double t)
  {
    const double dx = (s - kDingS) * kWidth / kDingRadius;
    const double dy = (t - kDingT) * kHeight / kDingRadius;
    return dx * dx + dy * dy;
  }

  /** Height away from the sensor [m]: bows toward the sensor, the shoulder recedes. */
  static double height(double s, double t)
  {
    const double across = 1.0 - (2.0 * s - 1.0) * (2.0 * s - 1.0);
    const double down = 1.0 - (2.0 * t - 1.0) * (2.0 * t - 1.0);
    const double shoulder = std::max(0.0, (kShoulderT - t) / kShoulderT);
    const double ding = std::max(0.0, 1.0 - dingDistance2(s, t));
    return -kBowAcross * across * smoothStep(t / kShoulderT) - kBowDown * down +
           kShoulderDepth * shoulder * shoulder + kDingDepth * ding * ding;
  }

  static std::uint32_t label(double s, double t)
  {
    if (dingDistance2(s, t) < 1.0)
      return static_cast<std::uint32_t>(DoorLabel::Ding);
    if (t < kShoulderT)
      return static_cast<std::uint32_t>(DoorLabel::Shoulder);
    return static_cast<std::uint32_t>(DoorLabel::Panel);
  }
};

/** Door skin: top edge at y = 0.15 m, z = 1.66 m (where the window frame starts). */
void
addDoorSkin(Scene& scene)
{
  scene.addLabel("door panel");
  scene.addLabel("door shoulder");
  scene.addLabel("ding");
  HeightField skin;
  skin.origin = Eigen::Vector3d(kDoorShift - 0.55, 0.15, 1.6);
  skin.u = Eigen::Vector3d(DoorSkin::kWidth, 0.0, 0.0);
  skin.v = Eigen::Vector3d(0.0, DoorSkin::kHeight, 0.0);
  skin.height = &DoorSkin::height;
  skin.label = &DoorSkin::label;
  skin.min_height = -(DoorSkin::kBowAcross + DoorSkin::kBowDown);
  skin.max_height = DoorSkin::kShoulderDepth + DoorSkin::kDingDepth;
  scene.height_fields.push_back(skin);
}

/** Four coplanar bars around the window, leaning back by 20 degrees. */
void
addWindowFrame(Scene& scene)
{
  constexpr double kLean = 20.0 * kPi / 180.0;
  constexpr double kSlant = 0.4;
  constexpr double kBar = 0.05;
  constexpr double kLeft = kDoorShift - 0.5;
  constexpr double kRight = kDoorShift + 0.45;
  const Eigen::Vector3d up(0.0, -std::cos(kLean), std::sin(kLean));
  const Eigen::Vector3d start(0.0, 0.15, 1.6 + DoorSkin::kShoulderDepth);
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX();
  const auto at = [&](double x, double a) -> Eigen::Vector3d {
    return start + x * ex + a * up;
  };
  Parallelogram bar;
  bar.label = scene.addLabel("window frame");
  const Eigen::Vector3d bars[4][3] = {
      {at(kLeft, 0.0), (kRight - kLeft) * ex, kBar * up},
      {at(kLeft, kSlant - kBar), (kRight - kLeft) * ex, kBar * up},
      {at(kLeft, kBar), kBar * ex, (kSlant - 2.0 * kBar) * up},
      {at(kRight - kBar, kBar), kBar * ex, (kSlant - 2.0 * kBar) * up}};
  for (const auto& b : bars) {
    bar.origin = b[0];
    bar.u = b[1];
    bar.v = b[2];
    scene.parallelograms.push_back(bar);
  }
}

} // namespace

SimulationSetup
makeCubeScene(double density)
{
  constexpr double kTableY = 0.8;
  constexpr double kWallZ = 2.2;
  constexpr double kCubeHalf = 0.15;
  SimulationSetup setup;
  Scene& scene = setup.scene;
  addFace(scene,
          Eigen::Vector3d(-1.5, -1.2, kWallZ),
          Eigen::Vector3d(0.0, kTableY + 1.2, 0.0),
          Eigen::Vector3d(3.0, 0.0, 0.0),
          "wall");
  addFace(scene,
          Eigen::Vector3d(-1.2, kTableY, 0.5),
          Eigen::Vector3d(2.4, 0.0, 0.0),
          Eigen::Vector3d(0.0, 0.0, kWallZ - 0.5),
          "table");
  addBox(scene,
         Eigen::Vector3d(0.0, kTableY - kCubeHalf, 0.9),
         Eigen::Vector3d::Constant(kCubeHalf),
         Eigen::AngleAxisd(35.0 * kPi / 180.0, Eigen::Vector3d::UnitY())
             .toRotationMatrix(),
         "cube",
         FaceSelection::FacingOrigin);
  setup.sensor = viewWindow(-0.35, 0.35, 0.05, 0.9, kCubeRays, density);
  return setup;
}

SimulationSetup
makeChairScene(double density)
{
  // Chair frame: origin on the floor under the seat's centre, axes as the sensor's.
  const Eigen::Vector3d floor(0.0, 1.5, 1.8);
  const Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  const auto facing = FaceSelection::FacingOrigin;
  SimulationSetup setup;
  Scene& scene = setup.scene;
  addBox(scene,
         floor + Eigen::Vector3d(0.0, -0.225, 0.0),
         Eigen::Vector3d(0.25, 0.225, 0.225),
         axes,
         "seat",
         facing);
  addBox(scene,
         floor + Eigen::Vector3d(0.0, -0.7, 0.185),
         Eigen::Vector3d(0.25, 0.25, 0.04),
         axes,
         "back rest",
         facing);
  const Eigen::Vector3d arm_half(0.03, 0.125, 0.1725);
  const auto left = addBox(scene,
                           floor + Eigen::Vector3d(-0.22, -0.575, -0.0275),
                           arm_half,
                           axes,
                           "left arm rest",
                           facing);
  const auto right = addBox(scene,
                            floor + Eigen::Vector3d(0.22, -0.575, -0.0275),
                            arm_half,
                            axes,
                            "right arm rest",
                            facing);
  scene.label_names[left[3]] = "left arm rest inner side";
  scene.label_names[right[2]] = "right arm rest inner side";
  setup.sensor = viewWindow(-0.17, 0.17, 0.25, 0.78, kChairRays, density);
  return setup;
}

SimulationSetup
makeDoorScene(double density)
{
  SimulationSetup setup;
  Scene& scene = setup.scene;
  addFace(scene,
          Eigen::Vector3d(-2.0, -1.5, 2.6),
          Eigen::Vector3d(0.0, 3.5, 0.0),
          Eigen::Vector3d(4.0, 0.0, 0.0),
          "wall");
  addDoorSkin(scene);
  addWindowFrame(scene);
  const auto handle = addCylinder(scene,
                                  Eigen::Vector3d(kDoorShift + 0.33, 0.3, 1.525),
                                  Eigen::Vector3d(0.2, 0.0, 0.0),
                                  0.025,
                                  "handle",
                                  FaceSelection::FacingOrigin);
  scene.label_names[handle[0]] = "handle";
  scene.label_names[handle[1]] = "handle cap";
  setup.sensor = viewWindow(-0.285, 0.455, -0.16, 0.46, kDoorRays, density);
  return setup;
}

SimulationSetup
makePaperScene(PaperScene scene, double density)
{
  switch (scene) {
  case PaperScene::Cube:
    return makeCubeScene(density);
  case PaperScene::Chair:
    return makeChairScene(density);
  case PaperScene::Door:
    return makeDoorScene(density);
  }
  return makeCubeScene(density);
}

std::size_t
getPaperPointCount(PaperScene scene)
{
  switch (scene) {
  case PaperScene::Cube:
    return 5432;
  case PaperScene::Chair:
    return 1544;
  case PaperScene::Door:
    return 46255;
  }
  return 0;
}

std::string
getPaperSceneName(PaperScene scene)
{
  switch (scene) {
  case PaperScene::Cube:
    return "cube";
  case PaperScene::Chair:
    return "chair";
  case PaperScene::Door:
    return "door";
  }
  return "";
}

bool
parsePaperScene(const std::string& name, PaperScene& scene)
{
  for (const PaperScene s : {PaperScene::Cube, PaperScene::Chair, PaperScene::Door})
    if (name == getPaperSceneName(s)) {
      scene = s;
      return true;
    }
  return false;
}

} // namespace simulation
} // namespace selective_seg
} // namespace pcl
