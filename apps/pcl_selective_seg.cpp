/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// pcl_selective_seg: segment a scan (PCD, PLY or "x y z" text), print the per-stage
// timing table (the paper's Table I columns) and the segment counts, and write any of:
// the labeled cloud, the segmented mesh (PLY, VTK), the octree leaves, a JSON summary.
//
// Exit codes: 0 = success, 1 = runtime error (unreadable input, no usable point,
// unwritable output), 2 = usage error (unknown option, bad value). Outputs are written
// under temporary names and renamed only when all succeeded.

#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "outputs.h"
#include "scan_io.h"

using namespace pcl::console;
using pcl::selective_seg::DelaunayBackend;
using pcl::selective_seg::SelectiveSegmentationParameters;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;
constexpr double kDeg = M_PI / 180.0;

struct Options {
  std::string input;
  double unit_scale = 1.0;
  std::string labels, mesh_ply, mesh_vtk, leaves, json;
  SelectiveSegmentationParameters params;
  bool ignore_viewpoint = false;
  std::vector<double> sensor_origin;      ///< x y z [m], empty = from the file
  std::vector<double> sensor_orientation; ///< qw qx qy qz, empty = from the file
};

/** Every option: its name, whether it takes a value, and its help line. */
struct OptionSpec {
  const char* name;
  bool takes_value;
};
const OptionSpec kOptions[] = {{"-o", true},
                               {"-mesh_ply", true},
                               {"-mesh_vtk", true},
                               {"-leaves", true},
                               {"-json", true},
                               {"-unit_scale", true},
                               {"-split_deg", true},
                               {"-merge_deg", true},
                               {"-edge_deg", true},
                               {"-incidence_deg", true},
                               {"-min_voxel_m", true},
                               {"-voxel_factor", true},
                               {"-min_split_points", true},
                               {"-normal_rings", true},
                               {"-edge_normal", true},
                               {"-max_depth", true},
                               {"-angle_step_rad", true},
                               {"-backend", true},
                               {"-sensor_origin", true},
                               {"-sensor_orientation", true},
                               {"-ignore_viewpoint", false},
                               {"-h", false},
                               {"--help", false}};

void
printHelp(const char* program)
{
  const SelectiveSegmentationParameters d;
  print_info(
      "Segment a 3-D scan seen from one sensor viewpoint into surface segments.\n\n"
      "Usage: %s INPUT [options]\n"
      "  INPUT is .pcd or .ply (any point type with x y z) or text with "
      "'x y z' per line.\n\n",
      program);
  print_info("Outputs (each optional; written only if the whole run succeeds):\n"
             "  -o FILE.pcd              labeled cloud (x y z label; input order and "
             "layout; 0 = unlabeled)\n"
             "  -mesh_ply FILE.ply       segmented mesh, per-face colour (segment hue, "
             "edge triangles white), label, class\n"
             "  -mesh_vtk FILE.vtk       the same mesh as legacy VTK polydata\n"
             "  -leaves FILE.pcd         octree leaves: centre, size, depth, label, "
             "normal, sigma_theta, sigma_phi\n"
             "  -json FILE.json          summary: counts, timings, segment sizes and "
             "normals\n\n");
  print_info("Input and sensor:\n"
             "  -unit_scale X            multiply coordinates by X, e.g. 0.01 for "
             "centimetres (default 1)\n"
             "  -sensor_origin X,Y,Z     sensor position in the cloud frame [m] "
             "(default: the file's VIEWPOINT)\n"
             "  -sensor_orientation W,X,Y,Z  sensor orientation quaternion (default: "
             "the file's VIEWPOINT)\n"
             "  -ignore_viewpoint        sensor at the origin looking along +z, "
             "whatever the file says\n\n");
  print_info("Algorithm (defaults are the paper's where it gives one):\n");
  print_info("  -split_deg X             octree split threshold on the normals' std "
             "dev [deg] (default %g)\n",
             d.max_normal_std_dev / kDeg);
  print_info("  -merge_deg X             max angle between merged segment normals "
             "[deg] (default %g)\n",
             d.max_merge_angle / kDeg);
  print_info("  -edge_deg X              max angle between a valid edge triangle and "
             "the segment [deg] (default %g)\n",
             d.max_edge_triangle_angle / kDeg);
  print_info("  -incidence_deg X         max view incidence of a valid edge triangle "
             "[deg]; 90 = paper (default %g)\n",
             d.max_view_incidence_angle / kDeg);
  print_info("  -min_voxel_m X           smallest octree voxel [m]; 0 = automatic "
             "(default %g)\n",
             d.min_voxel_size);
  print_info("  -voxel_factor X          automatic smallest voxel in median point "
             "spacings (default %g)\n",
             d.min_voxel_size_factor);
  print_info("  -min_split_points N      voxels with fewer points are not split "
             "(default %d)\n",
             d.min_points_to_split);
  print_info("  -normal_rings N          point normals over the N-ring of mesh "
             "triangles; 1 = paper's eq. 2 (default %d)\n",
             d.normal_rings);
  print_info("  -edge_normal NAME        normal tested by eq. 8: facet (paper) or "
             "vertex_mean (noise-robust) (default facet)\n");
  print_info("  -max_depth N             deepest octree level (default %d)\n",
             d.max_octree_depth);
  print_info("  -angle_step_rad X        angle quantization step [rad] (default %g)\n",
             d.angle_quantization);
  print_info("  -backend NAME            Delaunay backend: boost or vtk (default "
             "boost)\n"
             "  -h, --help               this help\n");
}

const OptionSpec*
findOption(const char* arg)
{
  for (const auto& o : kOptions)
    if (std::strcmp(o.name, arg) == 0)
      return &o;
  return nullptr;
}

/** The one positional argument; unknown options are usage errors. */
bool
findInput(int argc, char** argv, std::string& input)
{
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] == '-' && argv[i][1] != '\0' && !std::isdigit(argv[i][1])) {
      const OptionSpec* o = findOption(argv[i]);
      if (!o) {
        print_error("Unknown option '%s' (see -h).\n", argv[i]);
        return false;
      }
      if (o->takes_value && ++i >= argc) {
        print_error("Option %s needs a value (see -h).\n", o->name);
        return false;
      }
      continue;
    }
    positional.emplace_back(argv[i]);
  }
  if (positional.size() != 1) {
    print_error("Give exactly one input file (see -h); got %zu.\n", positional.size());
    return false;
  }
  input = positional.front();
  return true;
}

/** A checked number: absent is fine, present and not a finite number is an error. */
template <typename T>
bool
parseNumber(int argc, char** argv, const char* flag, T& value)
{
  if (find_argument(argc, argv, flag) < 0)
    return true;
  if (parse_argument(argc, argv, flag, value) < 0 ||
      !std::isfinite(static_cast<double>(value))) {
    print_error("Option %s needs a number.\n", flag);
    return false;
  }
  return true;
}

bool
parseDegrees(int argc, char** argv, const char* flag, double& radians)
{
  double degrees = radians / kDeg;
  if (!parseNumber(argc, argv, flag, degrees))
    return false;
  radians = degrees * kDeg;
  return true;
}

bool
parseVector(
    int argc, char** argv, const char* flag, std::size_t n, std::vector<double>& v)
{
  if (find_argument(argc, argv, flag) < 0)
    return true;
  if (parse_x_arguments(argc, argv, flag, v) < 0 || v.size() != n) {
    print_error("Option %s needs %zu comma-separated numbers.\n", flag, n);
    return false;
  }
  for (const double x : v)
    if (!std::isfinite(x)) {
      print_error("Option %s needs finite numbers.\n", flag);
      return false;
    }
  return true;
}

bool
parseAlgorithm(int argc, char** argv, SelectiveSegmentationParameters& p)
{
  if (!parseDegrees(argc, argv, "-split_deg", p.max_normal_std_dev) ||
      !parseDegrees(argc, argv, "-merge_deg", p.max_merge_angle) ||
      !parseDegrees(argc, argv, "-edge_deg", p.max_edge_triangle_angle) ||
      !parseDegrees(argc, argv, "-incidence_deg", p.max_view_incidence_angle) ||
      !parseNumber(argc, argv, "-min_voxel_m", p.min_voxel_size) ||
      !parseNumber(argc, argv, "-voxel_factor", p.min_voxel_size_factor) ||
      !parseNumber(argc, argv, "-min_split_points", p.min_points_to_split) ||
      !parseNumber(argc, argv, "-normal_rings", p.normal_rings) ||
      !parseNumber(argc, argv, "-max_depth", p.max_octree_depth) ||
      !parseNumber(argc, argv, "-angle_step_rad", p.angle_quantization))
    return false;
  std::string edge_normal = "facet";
  parse_argument(argc, argv, "-edge_normal", edge_normal);
  if (edge_normal == "vertex_mean")
    p.edge_triangle_normal = pcl::selective_seg::EdgeTriangleNormal::VertexMean;
  else if (edge_normal != "facet") {
    print_error("Unknown -edge_normal '%s': use facet or vertex_mean.\n",
                edge_normal.c_str());
    return false;
  }
  std::string backend = "boost";
  parse_argument(argc, argv, "-backend", backend);
  if (backend == "vtk")
    p.delaunay_backend = DelaunayBackend::Vtk;
  else if (backend != "boost") {
    print_error("Unknown -backend '%s': use boost or vtk.\n", backend.c_str());
    return false;
  }
  std::string why;
  if (!p.validate(&why)) {
    print_error("%s\n", why.c_str());
    return false;
  }
  return true;
}

/** \return 0 on success, else the exit code. */
int
parseOptions(int argc, char** argv, Options& opt)
{
  if (!findInput(argc, argv, opt.input))
    return kUsageError;
  parse_argument(argc, argv, "-o", opt.labels);
  parse_argument(argc, argv, "-mesh_ply", opt.mesh_ply);
  parse_argument(argc, argv, "-mesh_vtk", opt.mesh_vtk);
  parse_argument(argc, argv, "-leaves", opt.leaves);
  parse_argument(argc, argv, "-json", opt.json);
  opt.ignore_viewpoint = find_switch(argc, argv, "-ignore_viewpoint");
  if (!parseNumber(argc, argv, "-unit_scale", opt.unit_scale) ||
      !(opt.unit_scale > 0.0) ||
      !parseVector(argc, argv, "-sensor_origin", 3, opt.sensor_origin) ||
      !parseVector(argc, argv, "-sensor_orientation", 4, opt.sensor_orientation)) {
    if (!(opt.unit_scale > 0.0))
      print_error("Option -unit_scale needs a positive number.\n");
    return kUsageError;
  }
  return parseAlgorithm(argc, argv, opt.params) ? 0 : kUsageError;
}

/** The sensor pose from the options, or false to keep the file's. */
bool
sensorPose(const Options& opt,
           const pcl::PointCloud<pcl::PointXYZ>& cloud,
           Eigen::Affine3f& pose)
{
  if (opt.ignore_viewpoint) {
    pose = Eigen::Affine3f::Identity();
    return true;
  }
  if (opt.sensor_origin.empty() && opt.sensor_orientation.empty())
    return false;
  pose = Eigen::Affine3f::Identity();
  pose.translation() = cloud.sensor_origin_.head<3>();
  pose.linear() = cloud.sensor_orientation_.normalized().toRotationMatrix();
  if (!opt.sensor_origin.empty())
    pose.translation() = Eigen::Vector3d(opt.sensor_origin.data()).cast<float>();
  if (!opt.sensor_orientation.empty()) {
    const auto& q = opt.sensor_orientation;
    pose.linear() =
        Eigen::Quaternionf(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  }
  return true;
}

void
printTimings(const pcl::selective_seg::SegmentationResult& r)
{
  const auto& t = r.timings;
  const std::size_t points = r.counts.labeled + r.counts.without_normal;
  // The columns of the paper's Table I.
  print_info("\n  %9s %12s %16s %15s %16s %9s\n",
             "# Points",
             "Delaunay (s)",
             "Normal Calc. (s)",
             "Octree Gen. (s)",
             "Merge Voxels (s)",
             "Total (s)");
  print_info("  %9zu %12.4f %16.4f %15.4f %16.4f %9.4f\n\n",
             points,
             t.delaunay,
             t.normals,
             t.octree,
             t.merge,
             t.total);
}

void
printSummary(const pcl::selective_seg::SegmentationResult& r)
{
  const auto& c = r.counts;
  std::size_t large = 0;
  for (const auto& s : r.segments)
    large += s.num_points >= 0.01 * c.labeled;
  print_info("Segments: %zu (%zu with at least 1%% of the labeled points); octree "
             "leaves: %zu; triangles: %zu\n",
             r.segments.size(),
             large,
             r.leaves.size(),
             r.mesh.triangles.size());
  print_info("Points: %zu labeled (%zu sharing a mesh vertex), %zu non-finite, %zu "
             "behind the sensor, %zu without a normal\n",
             c.labeled,
             c.shared_vertex,
             c.non_finite,
             c.behind_sensor,
             c.without_normal);
}

/** Every requested output, all or nothing. */
bool
writeOutputs(const Options& opt,
             const pcl::PointCloud<pcl::PointXYZ>& cloud,
             const pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ>& seg)
{
  using namespace selseg_apps;
  const auto& r = seg.getResult();
  const RunInfo info{opt.input,
                     cloud.size(),
                     pcl::selective_seg::toString(opt.params.delaunay_backend),
                     opt.params};
  OutputTransaction outputs;
  const auto write = [&](const std::string& path, const auto& writer) {
    if (path.empty() || writer(outputs.stage(path)))
      return true;
    print_error("Cannot write '%s': check that the folder exists, is writable and has "
                "free space.\n",
                path.c_str());
    return false;
  };
  std::string error;
  const bool ok =
      write(opt.labels,
            [&](const std::string& f) {
              return writeLabeledCloud(f, *seg.getLabeledCloud());
            }) &&
      write(opt.mesh_ply,
            [&](const std::string& f) { return writeMeshPly(f, cloud, r.mesh); }) &&
      write(opt.mesh_vtk,
            [&](const std::string& f) { return writeMeshVtk(f, cloud, r.mesh); }) &&
      write(opt.leaves,
            [&](const std::string& f) { return writeLeaves(f, r.leaves); }) &&
      write(opt.json,
            [&](const std::string& f) { return writeSummaryJson(f, info, r); });
  if (ok && !outputs.commit(error)) {
    print_error("%s\n", error.c_str());
    return false;
  }
  return ok;
}

int
segment(const Options& opt)
{
  TicToc timer;
  timer.tic();
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  std::string error;
  if (!selseg_apps::loadScan(opt.input, opt.unit_scale, *cloud, error)) {
    print_error("%s\n", error.c_str());
    return kRuntimeError;
  }
  print_info("Loaded '%s' [done, %g ms : %zu points, %u x %u]\n",
             opt.input.c_str(),
             timer.toc(),
             cloud->size(),
             cloud->width,
             cloud->height);

  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setParameters(opt.params);
  Eigen::Affine3f pose;
  if (sensorPose(opt, *cloud, pose))
    seg.setSensorPose(pose);
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  if (!seg.extract(segments)) {
    const auto& c = seg.getResult().counts;
    if (c.behind_sensor > 0 && c.behind_sensor + c.non_finite == cloud->size())
      print_error("Every point lies behind the sensor pose; if the cloud is in the "
                  "camera frame (z forward), pass -ignore_viewpoint.\n");
    print_error("Segmentation failed (reason above).\n");
    return kRuntimeError;
  }
  printTimings(seg.getResult());
  printSummary(seg.getResult());
  timer.tic();
  if (!writeOutputs(opt, *cloud, seg))
    return kRuntimeError;
  print_info("Outputs written [done, %g ms]\n", timer.toc());
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 2) {
    printHelp(argv[0]);
    return kUsageError;
  }
  if (find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help")) {
    printHelp(argv[0]);
    return 0;
  }
  Options opt;
  if (const int rc = parseOptions(argc, argv, opt))
    return rc;
  return segment(opt);
}
