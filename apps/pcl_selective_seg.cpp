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

#include <pcl_selective_seg/parameters.h>
#include <pcl_selective_seg/regions_of_interest.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "outputs.h"
#include "process_memory.h"
#include "roi_json.h"
#include "roi_options.h"
#include "scan_io.h"
#include "segmentation_options.h"

using namespace pcl::console;
using pcl::selective_seg::SelectiveSegmentationParameters;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;
/** Heap reserved per point of the scan (reserveHeapInHugePages()): the tool's peak is
 * about 300 bytes a point at 1M points, the libraries included, and reserving more
 * costs only address space. */
constexpr std::size_t kHeapBytesPerPoint = 400;

struct Options {
  std::string input;
  double unit_scale = 1.0;
  std::string labels, mesh_ply, mesh_vtk, leaves, json, roi_json;
  SelectiveSegmentationParameters params;
  pcl::selective_seg::RegionOfInterestParameters roi;
  bool ignore_viewpoint = false;
  std::vector<double> sensor_origin;      ///< x y z [m], empty = from the file
  std::vector<double> sensor_orientation; ///< qw qx qy qz, empty = from the file
};

/** The tool's own flags that take a value (besides the segmentation flags). */
const std::vector<std::string> kValueFlags = {"-o",
                                              "-mesh_ply",
                                              "-mesh_vtk",
                                              "-leaves",
                                              "-json",
                                              "-roi_json",
                                              "-unit_scale",
                                              "-sensor_origin",
                                              "-sensor_orientation"};
const std::vector<std::string> kSwitches = {"-ignore_viewpoint", "-h", "--help"};

void
printHelp(const char* program)
{
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
             "normals\n"
             "  -roi_json FILE.json      regions of interest for a finer scan: angular "
             "windows (sensor frame),\n"
             "                           3-D boxes (cloud frame), priorities, steps; "
             "budget flags below\n\n");
  print_info("Input and sensor:\n"
             "  -unit_scale X            multiply coordinates (and the VIEWPOINT's "
             "position) by X, e.g. 0.01 for centimetres (default 1)\n"
             "  -sensor_origin X,Y,Z     sensor position in the cloud frame [m] "
             "(default: the file's VIEWPOINT)\n"
             "  -sensor_orientation W,X,Y,Z  sensor orientation quaternion (default: "
             "the file's VIEWPOINT)\n"
             "  -ignore_viewpoint        sensor at the origin looking along +z, "
             "whatever the file says\n\n");
  selseg_apps::printSegmentationHelp();
  selseg_apps::printRegionHelp();
  print_info("  -h, --help             this help\n\n");
  print_info(
      "Memory: the tool keeps the memory it frees for its later allocations\n"
      "(glibc; the same peak, fewer page faults), unless the environment sets\n"
      "glibc's malloc options: GLIBC_TUNABLES with glibc.malloc.*, or one of\n ");
  for (const char* name : selseg_apps::kMallocOptionVariables)
    print_info(" %s", name);
  print_info(".\n");
}

/** 1: a flag with a value, 0: a switch, -1: unknown. */
int
optionKind(const std::string& arg)
{
  const auto& seg = selseg_apps::segmentationFlags();
  const auto in = [&](const std::vector<std::string>& v) {
    return std::find(v.begin(), v.end(), arg) != v.end();
  };
  if (in(kValueFlags) || in(seg) || in(selseg_apps::regionFlags()))
    return 1;
  return in(kSwitches) ? 0 : -1;
}

/** The one positional argument; unknown options are usage errors. */
bool
findInput(int argc, char** argv, std::string& input)
{
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] == '-' && argv[i][1] != '\0' && !std::isdigit(argv[i][1])) {
      const int kind = optionKind(argv[i]);
      if (kind < 0) {
        print_error("Unknown option '%s' (see -h).\n", argv[i]);
        return false;
      }
      if (kind == 1 && ++i >= argc) {
        print_error("Option %s needs a value (see -h).\n", argv[i - 1]);
        return false;
      }
      // A value that is one of the options was most likely forgotten (-json -o F).
      if (kind == 1 && argv[i][0] == '-' && optionKind(argv[i]) >= 0) {
        print_error("Option %s needs a value, not the option '%s' (see -h).\n",
                    argv[i - 1],
                    argv[i]);
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

/** A quaternion of norm 0 has no rotation to normalize to (Eigen returns it as it is,
 * and a zero rotation matrix ends in a misleading runtime error), nor does one whose
 * norm overflows. */
bool
orientationUsable(const std::vector<double>& q)
{
  if (q.empty())
    return true;
  double squares = 0.0;
  for (const double x : q)
    squares += x * x;
  const double norm = std::sqrt(squares);
  if (norm > 0.0 && std::isfinite(norm))
    return true;
  print_error("Option -sensor_orientation needs a quaternion W,X,Y,Z whose norm is "
              "neither 0 nor too large to compute (got %g); it is normalized, so "
              "1,0,0,0 is the identity.\n",
              norm);
  return false;
}

/** Each output option with its file name (empty when not given), of \a opt (const or
 * not). */
template <typename OptionsT>
auto
outputFiles(OptionsT& opt)
{
  return std::array{std::pair{"-o", &opt.labels},
                    std::pair{"-mesh_ply", &opt.mesh_ply},
                    std::pair{"-mesh_vtk", &opt.mesh_vtk},
                    std::pair{"-leaves", &opt.leaves},
                    std::pair{"-json", &opt.json},
                    std::pair{"-roi_json", &opt.roi_json}};
}

/** Two outputs naming one file would silently keep only the last one; an output naming
 * the input would replace the scan. */
bool
outputsDistinct(const Options& opt)
{
  const auto outputs = outputFiles(opt);
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].second->empty())
      continue;
    if (selseg_apps::samePath(*outputs[i].second, opt.input)) {
      print_error("Option %s names the input file '%s': give another output name.\n",
                  outputs[i].first,
                  opt.input.c_str());
      return false;
    }
    for (std::size_t j = i + 1; j < outputs.size(); ++j)
      if (!outputs[j].second->empty() &&
          selseg_apps::samePath(*outputs[i].second, *outputs[j].second)) {
        print_error("Options %s and %s name the same file '%s': give each output its "
                    "own name.\n",
                    outputs[i].first,
                    outputs[j].first,
                    outputs[i].second->c_str());
        return false;
      }
  }
  return true;
}

/** \return 0 on success, else the exit code. */
int
parseOptions(int argc, char** argv, Options& opt)
{
  if (!findInput(argc, argv, opt.input) ||
      !selseg_apps::optionsGivenOnce(
          argc, argv, [](const std::string& arg) { return optionKind(arg) == 1; }))
    return kUsageError;
  for (const auto& [flag, name] : outputFiles(opt))
    if (!selseg_apps::parseFileName(argc, argv, flag, *name))
      return kUsageError;
  opt.ignore_viewpoint = find_switch(argc, argv, "-ignore_viewpoint");
  if (!outputsDistinct(opt))
    return kUsageError;
  if (!selseg_apps::parseNumber(argc, argv, "-unit_scale", opt.unit_scale) ||
      !selseg_apps::unitScaleUsable(opt.unit_scale) ||
      !selseg_apps::parseNumberList(
          argc, argv, "-sensor_origin", 3, opt.sensor_origin) ||
      !selseg_apps::parseNumberList(
          argc, argv, "-sensor_orientation", 4, opt.sensor_orientation) ||
      !orientationUsable(opt.sensor_orientation))
    return kUsageError;
  for (const double x : opt.sensor_origin)
    if (!(std::abs(x) <= std::numeric_limits<float>::max())) {
      print_error("Option -sensor_origin needs coordinates within float's range "
                  "(+-3.4e38).\n");
      return kUsageError;
    }
  if (opt.ignore_viewpoint &&
      (!opt.sensor_origin.empty() || !opt.sensor_orientation.empty())) {
    print_error(
        "-ignore_viewpoint puts the sensor at the origin looking along +z: give "
        "it or -sensor_origin / -sensor_orientation, not both.\n");
    return kUsageError;
  }
  if (!selseg_apps::parseSegmentationOptions(argc, argv, opt.params) ||
      !selseg_apps::parseRegionOptions(argc, argv, opt.roi))
    return kUsageError;
  return 0;
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
    // Normalized in double: the parts may not fit in a float before.
    pose.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3])
                        .normalized()
                        .cast<float>()
                        .toRotationMatrix();
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
printSummary(const pcl::selective_seg::SegmentationResult& r,
             pcl::selective_seg::ViewProjection projection,
             bool seam_closed)
{
  const bool panoramic = projection == pcl::selective_seg::ViewProjection::Panoramic;
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
             "%s, %zu without a normal\n",
             c.labeled,
             c.shared_vertex,
             c.non_finite,
             c.behind_sensor,
             panoramic ? "at the sensor's position" : "behind the sensor",
             c.without_normal);
  if (panoramic)
    print_info("Mesh: %s\n",
               seam_closed ? "closed around the sensor"
                           : "open at the seam theta = +-pi (the points leave a gap of "
                             "half a turn or more, or are too few around it to close)");
  if (!panoramic && c.behind_sensor >= c.labeled / 10 && c.behind_sensor > 0)
    print_info("%zu points lie behind the sensor and are left unlabeled: for a sensor "
               "that sees all around (a spinning lidar), use -projection panoramic.\n",
               c.behind_sensor);
}

/** Every requested output, all or nothing. */
bool
writeOutputs(const Options& opt,
             const pcl::PointCloud<pcl::PointXYZ>& cloud,
             const pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ>& seg,
             const Eigen::Affine3f& pose)
{
  using namespace selseg_apps;
  const auto& r = seg.getResult();
  const RunInfo info{opt.input,
                     cloud.size(),
                     pcl::selective_seg::toString(opt.params.delaunay_backend),
                     opt.params,
                     seg.getTriangulation().seam_closed};
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
  std::vector<pcl::selective_seg::RegionOfInterest> regions;
  pcl::selective_seg::RegionOfInterestStats stats;
  if (!opt.roi_json.empty()) {
    TicToc roi_timer;
    roi_timer.tic();
    pcl::selective_seg::RegionOfInterestParameters roi = opt.roi;
    roi.num_threads = opt.params.num_threads; // -threads
    if (!pcl::selective_seg::computeRegionsOfInterest(
            r, seg.getTriangulation(), pose, roi, regions, &stats)) {
      print_error("Computing the regions of interest failed (reason above).\n");
      return false;
    }
    print_info(
        "Regions of interest (%.1f ms): %zu chosen (%.4f sr, %zu points "
        "estimated) of %zu candidates, %zu cut around a window chosen before; %zu "
        "already fine, %zu over the budget\n",
        roi_timer.toc(),
        stats.selected,
        stats.selected_solid_angle,
        stats.selected_points,
        stats.candidates,
        stats.cut,
        stats.already_fine,
        stats.over_budget);
  }
  // The writers use the segmentation's threads (-threads, 0 = automatic).
  const int threads = pcl::selective_seg::detail::threadCount(opt.params.num_threads);
  const bool ok =
      write(opt.labels,
            [&](const std::string& f) {
              return writeLabeledCloud(f, cloud, r.labels, threads);
            }) &&
      write(opt.mesh_ply,
            [&](const std::string& f) {
              return writeMeshPly(f, cloud, r.mesh, threads);
            }) &&
      write(opt.mesh_vtk,
            [&](const std::string& f) {
              return writeMeshVtk(f, cloud, r.mesh, threads);
            }) &&
      write(opt.leaves,
            [&](const std::string& f) { return writeLeaves(f, r.leaves, threads); }) &&
      write(opt.json,
            [&](const std::string& f) {
              return writeSummaryJson(f, info, r, threads);
            }) &&
      write(opt.roi_json, [&](const std::string& f) {
        return writeRegionsJson(
            f, opt.input, opt.roi, stats, regions, opt.params.projection, &pose);
      });
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
  // The outputs are checked before the work that makes them (a folder, a missing
  // folder, a FIFO), as the viewer and the simulator check theirs.
  for (const auto& output : outputFiles(opt))
    if (!output.second->empty() &&
        !selseg_apps::outputWritable(*output.second, error)) {
      print_error("%s\n", error.c_str());
      return kRuntimeError;
    }
  // The heap for the whole run at once, in huge pages (when the tool keeps its freed
  // memory): sized by the points a PCD or PLY header declares, before they are read,
  // or by the points read from a text file.
  bool reserved = false;
  const auto reserve = [&](std::size_t points) {
    reserved = points <= std::numeric_limits<std::size_t>::max() / kHeapBytesPerPoint &&
               selseg_apps::reserveHeapInHugePages(points * kHeapBytesPerPoint);
  };
  if (!selseg_apps::loadScan(opt.input, opt.unit_scale, *cloud, error, reserve)) {
    print_error("%s\n", error.c_str());
    return kRuntimeError;
  }
  if (!reserved)
    reserve(cloud->size());
  print_info("Loaded '%s' [done, %g ms : %zu points, %u x %u]\n",
             opt.input.c_str(),
             timer.toc(),
             cloud->size(),
             cloud->width,
             cloud->height);

  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setParameters(opt.params);
  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  if (sensorPose(opt, *cloud, pose))
    seg.setSensorPose(pose);
  else {
    pose.translation() = cloud->sensor_origin_.head<3>();
    pose.linear() = cloud->sensor_orientation_.normalized().toRotationMatrix();
  }
  if (!pose.matrix().allFinite()) {
    print_error("The sensor pose has a value that is not a finite number (the file's "
                "VIEWPOINT?): fix it, or give -sensor_origin and -sensor_orientation, "
                "or -ignore_viewpoint.\n");
    return kRuntimeError;
  }
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  if (!seg.extract(segments)) {
    const auto& c = seg.getResult().counts;
    const bool panoramic =
        opt.params.projection == pcl::selective_seg::ViewProjection::Panoramic;
    // -ignore_viewpoint is worth suggesting only where it would change the pose.
    const bool camera_frame = pose.matrix().isIdentity(0.0);
    if (c.behind_sensor > 0 && c.behind_sensor + c.non_finite == cloud->size())
      print_error(panoramic ? "Every point lies at the sensor's position; check the "
                              "sensor origin (-sensor_origin, the file's VIEWPOINT).\n"
                  : camera_frame
                      ? "Every point lies behind the sensor (z <= 0 in its frame): "
                        "give its pose (-sensor_origin, -sensor_orientation), or for a "
                        "sensor that sees all around -projection panoramic.\n"
                      : "Every point lies behind the sensor pose; if the cloud is in "
                        "the camera frame (z forward), pass -ignore_viewpoint, or for "
                        "a sensor that sees all around -projection panoramic.\n");
    else if (c.behind_sensor > 0 && !panoramic)
      print_error("%zu of the %zu points lie behind the sensor and were left out (see "
                  "-sensor_origin, -ignore_viewpoint, -projection panoramic).\n",
                  c.behind_sensor,
                  cloud->size());
    print_error("Segmentation failed (reason above).\n");
    return kRuntimeError;
  }
  // The outputs come from the result: the point lists are freed for the writers.
  std::vector<pcl::PointIndices>().swap(segments);
  printTimings(seg.getResult());
  printSummary(seg.getResult(),
               seg.getParameters().projection,
               seg.getTriangulation().seam_closed);
  timer.tic();
  if (!writeOutputs(opt, *cloud, seg, pose))
    return kRuntimeError;
  print_info("Outputs written [done, %g ms]\n", timer.toc());
  return 0;
}

/** main() but for its handling of memory running out. */
int
run(int argc, char** argv)
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

} // namespace

int
main(int argc, char** argv)
{
  // One pipeline a process: freed arrays are kept for the next stage's (same peak),
  // and, none being returned to the system, every page is faulted in once: huge pages
  // for the arrays from 4 MB on (1M points: 0.91-0.99 s instead of 1.34-1.49 s, the
  // same peak; docs/performance.md, "Huge pages").
  if (selseg_apps::keepFreedMemory())
    pcl::selective_seg::setHugePageAdviceThreshold(std::size_t{4} << 20);
  // Out of memory outside the library's own handling (the options, reading, the
  // outputs): a message, and the outputs' temporaries removed on the way out of
  // segment().
  return selseg_apps::runReportingOutOfMemory(
      [&] { return run(argc, argv); },
      "segment a smaller scan (crop or downsample it) or give the process more memory.",
      kRuntimeError);
}
