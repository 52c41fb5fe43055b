/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// pcl_selective_seg: segment a PCD scan, print the per-stage timing table (the paper's
// Table I columns) and write the labeled cloud.
//
// Exit codes: 0 = success, 1 = runtime error (unreadable input, no usable point,
// unwritable output), 2 = usage error (bad option).

#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/io/pcd_io.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace pcl::console;
using pcl::selective_seg::DelaunayBackend;
using pcl::selective_seg::SelectiveSegmentationParameters;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;
constexpr double kDeg = M_PI / 180.0;

struct Options {
  std::string input;
  std::string output;
  SelectiveSegmentationParameters params;
  bool ignore_viewpoint = false;
};

void
printHelp(const char* program)
{
  const SelectiveSegmentationParameters d;
  print_info(
      "Segment a 3-D scan seen from one sensor viewpoint into surface segments.\n\n"
      "Usage: %s input.pcd [options]\n\n",
      program);
  print_info("Options (defaults are the paper's where it gives one):\n");
  print_info(
      "  -o FILE.pcd            labeled cloud (x y z label, input order and layout)\n");
  print_info("  -split_deg X           octree split threshold on the normals' std dev "
             "[deg] (default %.1f)\n",
             d.max_normal_std_dev / kDeg);
  print_info("  -merge_deg X           max angle between merged segment normals [deg] "
             "(default %.1f)\n",
             d.max_merge_angle / kDeg);
  print_info("  -edge_deg X            max angle of a valid edge triangle [deg] "
             "(default %.1f)\n",
             d.max_edge_triangle_angle / kDeg);
  print_info(
      "  -incidence_deg X       max view incidence of a valid edge triangle [deg]; "
      "90 = off (default %.1f)\n",
      d.max_view_incidence_angle / kDeg);
  print_info("  -min_voxel_m X         smallest octree voxel [m]; 0 = %.1f x median "
             "point spacing (default %g)\n",
             d.min_voxel_size_factor,
             d.min_voxel_size);
  print_info("  -min_split_points N    voxels with fewer points are not split "
             "(default %d)\n",
             d.min_points_to_split);
  print_info(
      "  -backend NAME          Delaunay backend: boost or vtk (default boost)\n");
  print_info("  -ignore_viewpoint      take the sensor at the origin looking along +z, "
             "whatever the file's VIEWPOINT says\n");
  print_info("  -h, --help             this help\n");
}

/** A checked numeric option: absent is fine, present and unparsable is a usage error.
 */
template <typename T>
bool
parseChecked(int argc, char** argv, const char* flag, T& value)
{
  if (find_argument(argc, argv, flag) < 0)
    return true;
  if (parse_argument(argc, argv, flag, value) < 0 || !std::isfinite(double(value))) {
    print_error("Option %s needs a number.\n", flag);
    return false;
  }
  return true;
}

bool
parseDegrees(int argc, char** argv, const char* flag, double& radians)
{
  double degrees = radians / kDeg;
  if (!parseChecked(argc, argv, flag, degrees))
    return false;
  radians = degrees * kDeg;
  return true;
}

/** \return 0 on success, else the exit code. */
int
parseOptions(int argc, char** argv, Options& opt)
{
  // .pcd arguments, except the value of -o.
  std::vector<int> files;
  for (const int i : parse_file_extension_argument(argc, argv, ".pcd"))
    if (i == 0 || std::strcmp(argv[i - 1], "-o") != 0)
      files.push_back(i);
  if (files.size() != 1) {
    print_error("Give exactly one input .pcd file (see %s -h).\n", argv[0]);
    return kUsageError;
  }
  opt.input = argv[files[0]];
  parse_argument(argc, argv, "-o", opt.output);
  auto& p = opt.params;
  if (!parseDegrees(argc, argv, "-split_deg", p.max_normal_std_dev) ||
      !parseDegrees(argc, argv, "-merge_deg", p.max_merge_angle) ||
      !parseDegrees(argc, argv, "-edge_deg", p.max_edge_triangle_angle) ||
      !parseDegrees(argc, argv, "-incidence_deg", p.max_view_incidence_angle) ||
      !parseChecked(argc, argv, "-min_voxel_m", p.min_voxel_size) ||
      !parseChecked(argc, argv, "-min_split_points", p.min_points_to_split))
    return kUsageError;
  std::string backend = "boost";
  parse_argument(argc, argv, "-backend", backend);
  if (backend == "vtk")
    p.delaunay_backend = DelaunayBackend::Vtk;
  else if (backend != "boost") {
    print_error("Unknown -backend '%s': use boost or vtk.\n", backend.c_str());
    return kUsageError;
  }
  opt.ignore_viewpoint = find_switch(argc, argv, "-ignore_viewpoint");
  std::string why;
  if (!p.validate(&why)) {
    print_error("%s\n", why.c_str());
    return kUsageError;
  }
  return 0;
}

void
printTimings(const pcl::selective_seg::SegmentationResult& r, std::size_t points)
{
  const auto& t = r.timings;
  print_info("\n  %-10s %9s %12s %13s %11s %13s %9s\n",
             "",
             "# Points",
             "Delaunay (s)",
             "Normals (s)",
             "Octree (s)",
             "Merge (s)",
             "Total (s)");
  print_info("  %-10s %9zu %12.4f %13.4f %11.4f %13.4f %9.4f\n\n",
             "this scan",
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

/** Write to a temporary name, then rename: no partial file is ever left behind. */
bool
saveLabeled(const std::string& path, const pcl::PointCloud<pcl::PointXYZL>& cloud)
{
  const std::string tmp = path + ".tmp";
  if (pcl::io::savePCDFileBinaryCompressed(tmp, cloud) != 0) {
    std::remove(tmp.c_str());
    print_error("Cannot write '%s': check that the folder exists and is writable.\n",
                path.c_str());
    return false;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    print_error("Cannot rename '%s' to '%s': %s\n",
                tmp.c_str(),
                path.c_str(),
                std::strerror(errno));
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 2 || find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help")) {
    printHelp(argv[0]);
    return argc < 2 ? kUsageError : 0;
  }
  Options opt;
  if (const int rc = parseOptions(argc, argv, opt))
    return rc;

  TicToc timer;
  timer.tic();
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  if (pcl::io::loadPCDFile(opt.input, *cloud) != 0) {
    print_error("Cannot read '%s' as a PCD file with x y z fields.\n",
                opt.input.c_str());
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
  if (opt.ignore_viewpoint)
    seg.setSensorPose(Eigen::Affine3f::Identity());
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  if (!seg.extract(segments)) {
    const auto& c = seg.getResult().counts;
    if (c.behind_sensor > 0 && c.behind_sensor + c.non_finite == cloud->size())
      print_error(
          "Every point lies behind the sensor pose given by the file's VIEWPOINT; "
          "if the cloud is in the camera frame (z forward), pass "
          "-ignore_viewpoint.\n");
    print_error("Segmentation failed (reason above).\n");
    return kRuntimeError;
  }
  printTimings(seg.getResult(), cloud->size());
  printSummary(seg.getResult());

  if (!opt.output.empty()) {
    timer.tic();
    if (!saveLabeled(opt.output, *seg.getLabeledCloud()))
      return kRuntimeError;
    print_info("Wrote '%s' [done, %g ms : %zu points]\n",
               opt.output.c_str(),
               timer.toc(),
               cloud->size());
  }
  return 0;
}
