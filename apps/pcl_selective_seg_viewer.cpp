/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// pcl_selective_seg_viewer: segment a scan and show the result as the paper's figures
// do: the mesh coloured by segment with white edge triangles (Figs. 7-9) and the
// labeled multi-resolution octree (Figs. 10-12), seen from the sensor. The raw points
// and the point normals are further layers; keys toggle each of them. With
// -screenshot the picture is rendered off screen and saved instead.
//
// Exit codes: 0 = success, 1 = runtime error (unreadable input, segmentation failure,
// no X display, unwritable screenshot), 2 = usage error (bad option).

#include <pcl_selective_seg/regions_of_interest.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/visualization/pcl_visualizer.h>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkRenderingOpenGLConfigure.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "outputs.h"
#include "process_memory.h"
#include "roi_json.h"
#include "roi_options.h"
#include "scan_io.h"
#include "segment_colors.h"
#include "segmentation_options.h"

using namespace pcl::console;
using pcl::selective_seg::SegmentationResult;
using pcl::selective_seg::SelectiveSegmentationParameters;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;
constexpr double kDeg = M_PI / 180.0;

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using NormalCloud = pcl::PointCloud<pcl::Normal>;
using PolyData = vtkSmartPointer<vtkPolyData>;

/** The layers of the picture, in the order of the key legend. */
enum Layer { kMesh = 0, kOctree, kCloud, kNormals, kRegions, kNumLayers };

/** Key, name and description of each layer (keys PCLVisualizer and VTK leave free). */
struct LayerInfo {
  char key;
  const char* name;
  const char* description;
};
constexpr std::array<LayerInfo, kNumLayers> kLayers = {
    {{'t', "mesh", "mesh triangles by segment, edge triangles white"},
     {'v', "octree", "octree leaves by segment"},
     {'d', "cloud", "data points by segment"},
     {'n', "normals", "point normals (subsampled)"},
     {'r',
      "regions",
      "regions of interest: yellow transition, magenta small segment, cyan sparse"}}};

/** Every option of the tool, with its default. */
struct Options {
  std::string input;
  double unit_scale = 1.0;
  bool ignore_viewpoint = false;
  SelectiveSegmentationParameters params;
  /// Layers shown at start: -view's, else the mesh, and the regions when given.
  std::array<bool, kNumLayers> view = {true, false, false, false, false};
  bool roi = false;     ///< compute regions of interest from the segmentation
  std::string roi_json; ///< or read them from this file
  pcl::selective_seg::RegionOfInterestParameters roi_params;
  std::string screenshot;
  int width = 1280;
  int height = 960;
  int normal_step = 0; ///< 0 = about 5000 normals
  bool octree_wireframe = false;
  bool legend = true;
};

/** The segmented scan: what the layers are built from. */
struct Scene {
  Cloud::Ptr cloud;
  Eigen::Affine3f sensor_pose = Eigen::Affine3f::Identity(); ///< sensor to cloud
  SegmentationResult result;
  NormalCloud::ConstPtr normals;
  std::vector<pcl::selective_seg::RegionOfInterest> regions;
  /** Sensor to cloud frame of the regions' windows: the scan's, or the pose a regions
   * file records. */
  Eigen::Affine3f regions_pose = Eigen::Affine3f::Identity();
};

void
printHelp(const char* program)
{
  const Options d;
  print_info(
      "Segment a 3-D scan seen from one sensor and show the segments, as the\n"
      "mesh (edge triangles white) and as the labeled octree, from the sensor.\n\n"
      "Usage: %s input.{pcd,ply,xyz,txt} [options]\n\n",
      program);
  print_info("Input:\n");
  print_info("  -unit_scale X          factor applied to the coordinates and the "
             "VIEWPOINT's position, e.g. 0.001 for millimetres [-] (default %g)\n",
             d.unit_scale);
  print_info("  -ignore_viewpoint      sensor at the origin looking along +z, whatever "
             "the file's VIEWPOINT says (default off)\n");
  selseg_apps::printSegmentationHelp();
  print_info("Regions of interest (layer 'regions', key r):\n");
  print_info("  -roi                   compute them from the segmentation, with the "
             "-roi_* options below\n");
  print_info("  -roi_json FILE         read them from a file of pcl_selective_seg "
             "-roi_json (windows in the sensor frame)\n");
  selseg_apps::printRegionHelp();
  print_info("Display:\n");
  print_info("  -view LAYER[,LAYER]    layers shown at start: mesh, octree, cloud, "
             "normals, regions (default mesh, and regions when given)\n");
  print_info("  -wireframe             octree leaves as outlines, not solid cubes "
             "(default solid)\n");
  print_info("  -normal_step N         draw the normal of every N-th labeled point; "
             "0 = about 5000 normals [points] (default %d)\n",
             d.normal_step);
  print_info("  -no_legend             hide the key legend (default shown)\n");
  print_info("  -screenshot FILE.png   render off screen, save the picture, exit\n");
  print_info("  -size WxH              window or picture size [pixels] (default "
             "%dx%d)\n",
             d.width,
             d.height);
  print_info("  -h, --help             this help\n\n");
  print_info("Keys: t mesh, v octree, d data points, n normals, r regions of "
             "interest,\n      b solid/outline cubes, z back to the sensor's view, i "
             "legend; q quits.\n");
}

/** "-size WxH": two integers in [64, 8192]. */
bool
parseSize(int argc, char** argv, Options& opt)
{
  std::string text;
  if (parse_argument(argc, argv, "-size", text) < 0)
    return true;
  // Digits only (sscanf's %d would wrap a number beyond int).
  const std::size_t x = text.find('x');
  const auto pixels = [](const std::string& digits) {
    if (digits.empty() || digits.size() > 5 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      return -1;
    return std::stoi(digits);
  };
  const int w = x == std::string::npos ? -1 : pixels(text.substr(0, x));
  const int h = x == std::string::npos ? -1 : pixels(text.substr(x + 1));
  if (w < 64 || h < 64 || w > 8192 || h > 8192) {
    print_error("Option -size needs WIDTHxHEIGHT in pixels, each 64 to 8192, e.g. "
                "1280x960.\n");
    return false;
  }
  opt.width = w;
  opt.height = h;
  return true;
}

/** "-view LAYER[,LAYER...]" with the layers mesh, octree, cloud and normals. */
bool
parseView(int argc, char** argv, Options& opt)
{
  std::string list;
  if (parse_argument(argc, argv, "-view", list) < 0)
    return true;
  opt.view.fill(false);
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    const auto info = std::find_if(
        kLayers.begin(), kLayers.end(), [&name](auto& l) { return name == l.name; });
    if (info == kLayers.end()) {
      print_error("Unknown layer '%s' in -view: use mesh, octree, cloud, normals or "
                  "regions, comma-separated.\n",
                  name.c_str());
      return false;
    }
    opt.view[info - kLayers.begin()] = true;
    begin = end + 1;
  }
  return true;
}

bool
isValueFlag(const std::string& arg)
{
  static const std::vector<std::string> flags = {
      "-unit_scale", "-view", "-normal_step", "-screenshot", "-size", "-roi_json"};
  const auto& seg = selseg_apps::segmentationFlags();
  const auto& roi = selseg_apps::regionFlags();
  return std::find(flags.begin(), flags.end(), arg) != flags.end() ||
         std::find(seg.begin(), seg.end(), arg) != seg.end() ||
         std::find(roi.begin(), roi.end(), arg) != roi.end();
}

bool
isSwitch(const std::string& arg)
{
  return arg == "-ignore_viewpoint" || arg == "-wireframe" || arg == "-no_legend" ||
         arg == "-roi" || arg == "-h" || arg == "--help";
}

/** The one input file; every other argument must be a known option. */
bool
parseInput(int argc, char** argv, Options& opt)
{
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (isValueFlag(arg)) {
      if (++i == argc) {
        print_error("Option %s needs a value (see -h).\n", arg.c_str());
        return false;
      }
      // An option where the value should be (its value forgotten): "-screenshot
      // -wireframe" wrote a file named -wireframe and switched the wireframe on.
      if (isValueFlag(argv[i]) || isSwitch(argv[i])) {
        print_error("Option %s needs a value, not the option '%s' (see -h).\n",
                    arg.c_str(),
                    argv[i]);
        return false;
      }
    } else if (!arg.empty() && arg[0] == '-' && !isSwitch(arg)) {
      print_error("Unknown option '%s' (see -h).\n", arg.c_str());
      return false;
    } else if (!isSwitch(arg))
      files.push_back(arg);
  }
  if (files.size() != 1) {
    print_error("Give exactly one input file, .pcd, .ply or .xyz (see -h).\n");
    return false;
  }
  opt.input = files[0];
  return true;
}

/** \return 0 on success, else the exit code. */
int
parseOptions(int argc, char** argv, Options& opt)
{
  if (!parseInput(argc, argv, opt) ||
      !selseg_apps::optionsGivenOnce(argc, argv, isValueFlag))
    return kUsageError;
  auto& p = opt.params;
  if (!selseg_apps::parseNumber(argc, argv, "-unit_scale", opt.unit_scale) ||
      !selseg_apps::parseSegmentationOptions(argc, argv, p) ||
      !selseg_apps::parseRegionOptions(argc, argv, opt.roi_params) ||
      !selseg_apps::parseNumber(argc, argv, "-normal_step", opt.normal_step) ||
      !parseSize(argc, argv, opt) || !parseView(argc, argv, opt))
    return kUsageError;
  if (!selseg_apps::unitScaleUsable(opt.unit_scale))
    return kUsageError;
  if (opt.normal_step < 0) {
    print_error("Option -normal_step must be 0 (automatic) or positive.\n");
    return kUsageError;
  }
  for (const auto& [flag, value] : {std::make_pair("-screenshot", &opt.screenshot),
                                    std::make_pair("-roi_json", &opt.roi_json)})
    if (parse_argument(argc, argv, flag, *value) >= 0 && value->empty()) {
      print_error("Option %s needs a file name (see -h).\n", flag);
      return kUsageError;
    }
  // The picture would replace the scan or the regions file it shows.
  for (const auto& [flag, read] : {std::make_pair("the input file", opt.input),
                                   std::make_pair("the -roi_json file", opt.roi_json)})
    if (!opt.screenshot.empty() && !read.empty() &&
        selseg_apps::samePath(opt.screenshot, read)) {
      print_error("Option -screenshot names %s '%s': give another output name.\n",
                  flag,
                  read.c_str());
      return kUsageError;
    }
  // The picture is a PNG, whatever the name says (a .jpg held PNG bytes).
  if (!opt.screenshot.empty() &&
      selseg_apps::lowerExtension(opt.screenshot) != ".png") {
    print_error("Option -screenshot writes a PNG picture: give a name ending in .png "
                "('%s').\n",
                opt.screenshot.c_str());
    return kUsageError;
  }
  opt.roi = find_switch(argc, argv, "-roi");
  if (opt.roi && !opt.roi_json.empty()) {
    print_error("Give -roi or -roi_json, not both.\n");
    return kUsageError;
  }
  if (find_argument(argc, argv, "-view") < 0)
    opt.view[kRegions] = opt.roi || !opt.roi_json.empty();
  // The -roi_* settings choose the windows -roi computes; a -roi_json file's windows
  // are drawn as they are.
  if (!opt.roi)
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg.rfind("-roi_", 0) == 0 && arg != "-roi_json") {
        print_error("Option %s applies with -roi (windows computed here); a -roi_json "
                    "file's windows are drawn as they were written.\n",
                    arg.c_str());
        return kUsageError;
      }
      if (isValueFlag(arg))
        ++i; // skip the value
    }
  opt.ignore_viewpoint = find_switch(argc, argv, "-ignore_viewpoint");
  opt.octree_wireframe = find_switch(argc, argv, "-wireframe");
  opt.legend = !find_switch(argc, argv, "-no_legend");
  return 0;
}

/** Read the scan. \return false, with a message, on failure. */
bool
loadInput(const Options& opt, Scene& scene)
{
  TicToc timer;
  timer.tic();
  scene.cloud = pcl::make_shared<Cloud>();
  std::string error;
  if (!selseg_apps::loadScan(opt.input, opt.unit_scale, *scene.cloud, error)) {
    print_error("%s\n", error.c_str());
    return false;
  }
  if (!opt.ignore_viewpoint) {
    scene.sensor_pose.translation() = scene.cloud->sensor_origin_.head<3>();
    scene.sensor_pose.linear() =
        scene.cloud->sensor_orientation_.normalized().toRotationMatrix();
  }
  print_info("Loaded '%s' [done, %g ms : %zu points]\n",
             opt.input.c_str(),
             timer.toc(),
             scene.cloud->size());
  return true;
}

/** Segment the scan. \return false, with a message, on failure. */
bool
segment(const Options& opt, Scene& scene)
{
  TicToc timer;
  timer.tic();
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setParameters(opt.params);
  seg.setSensorPose(scene.sensor_pose);
  seg.setInputCloud(scene.cloud);
  std::vector<pcl::PointIndices> segments;
  if (!seg.extract(segments)) {
    print_error("Segmentation failed (reason above); if every point lies behind the "
                "file's VIEWPOINT, pass -ignore_viewpoint.\n");
    return false;
  }
  scene.result = seg.getResult();
  scene.normals = seg.getPointNormals();
  scene.regions_pose = scene.sensor_pose;
  if (opt.roi) {
    pcl::selective_seg::RegionOfInterestStats stats;
    pcl::selective_seg::RegionOfInterestParameters roi_params = opt.roi_params;
    roi_params.num_threads = opt.params.num_threads; // -threads
    if (!pcl::selective_seg::computeRegionsOfInterest(scene.result,
                                                      seg.getTriangulation(),
                                                      scene.sensor_pose,
                                                      roi_params,
                                                      scene.regions,
                                                      &stats)) {
      print_error("Computing the regions of interest failed (reason above).\n");
      return false;
    }
    print_info("Regions of interest: %zu chosen of %zu candidates\n",
               stats.selected,
               stats.candidates);
  } else if (!opt.roi_json.empty()) {
    std::string error;
    Eigen::Affine3f pose;
    bool has_pose = false;
    if (!selseg_apps::readRegionsJson(
            opt.roi_json, scene.regions, pose, has_pose, error)) {
      print_error("%s\n", error.c_str());
      return false;
    }
    // The windows are drawn from the sensor pose they were computed with.
    if (has_pose) {
      if (!pose.matrix().isApprox(scene.sensor_pose.matrix(), 1e-5f))
        print_warn(
            "The regions file's sensor pose is not the scan's: its windows are "
            "drawn from the file's pose, the scan's segments from the scan's.\n");
      scene.regions_pose = pose;
    }
    print_info("Read %zu regions of interest from '%s'\n",
               scene.regions.size(),
               opt.roi_json.c_str());
  }
  print_info("Segmented [done, %g ms : %zu segments, %zu octree leaves, %zu "
             "triangles]\n",
             timer.toc(),
             scene.result.segments.size(),
             scene.result.leaves.size(),
             scene.result.mesh.triangles.size());
  return true;
}

/** VTK's X11 render windows abort without an X display: say what to do instead.
 * \return false, with a message, when rendering cannot work. */
bool
checkDisplay()
{
#if defined(VTK_USE_X) && !defined(VTK_OPENGL_HAS_EGL) &&                              \
    !defined(VTK_OPENGL_HAS_OSMESA)
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    print_error("No X display (DISPLAY is not set): run it in a desktop session, or "
                "for -screenshot under xvfb-run -a -s \"-screen 0 1280x1024x24\".\n");
    return false;
  }
#endif
  return true;
}

/** A 3-component colour array for cell or point scalars. */
vtkSmartPointer<vtkUnsignedCharArray>
newColors(vtkIdType count)
{
  auto colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
  colors->SetName("colors");
  colors->SetNumberOfComponents(3);
  colors->SetNumberOfTuples(count);
  return colors;
}

/** The segmented mesh: one triangle cell per mesh triangle, coloured by
 * selseg_apps::triangleColor (segment hue, edge triangles white). Only the points
 * used by triangles become vertices, so that non-finite points never reach VTK. */
PolyData
buildMesh(const Scene& scene)
{
  const auto& mesh = scene.result.mesh;
  std::vector<vtkIdType> vertex(scene.cloud->size(), -1);
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  auto colors = newColors(static_cast<vtkIdType>(mesh.triangles.size()));
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    std::array<vtkIdType, 3> ids;
    for (int k = 0; k < 3; ++k) {
      const auto i = mesh.triangles[t][k];
      if (vertex[i] < 0)
        vertex[i] = points->InsertNextPoint((*scene.cloud)[i].data);
      ids[k] = vertex[i];
    }
    cells->InsertNextCell(3, ids.data());
    const auto rgb = selseg_apps::triangleColor(mesh.labels[t], mesh.classes[t]);
    colors->SetTypedTuple(static_cast<vtkIdType>(t), rgb.data());
  }
  auto data = PolyData::New();
  data->SetPoints(points);
  data->SetPolys(cells);
  data->GetCellData()->SetScalars(colors);
  return data;
}

/** The octree leaves as cubes (six quads each) coloured by segment. The voxels'
 * axes are the sensor's axes, so every cube is rotated by the sensor orientation. */
PolyData
buildOctree(const Scene& scene)
{
  static constexpr int kFaces[6][4] = {{0, 2, 3, 1},
                                       {4, 5, 7, 6},
                                       {0, 1, 5, 4},
                                       {2, 6, 7, 3},
                                       {0, 4, 6, 2},
                                       {1, 3, 7, 5}};
  const Eigen::Matrix3f rotation = scene.sensor_pose.linear();
  const auto& leaves = scene.result.leaves;
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetNumberOfPoints(static_cast<vtkIdType>(8 * leaves.size()));
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  auto colors = newColors(static_cast<vtkIdType>(6 * leaves.size()));
  vtkIdType point_id = 0, cell_id = 0;
  for (const auto& leaf : leaves) {
    const float h = 0.5f * leaf.size;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3f corner(c & 4 ? h : -h, c & 2 ? h : -h, c & 1 ? h : -h);
      const Eigen::Vector3f p = leaf.centre + rotation * corner;
      points->SetPoint(point_id + c, p.x(), p.y(), p.z());
    }
    const auto rgb = selseg_apps::segmentColor(leaf.label);
    for (const auto& face : kFaces) {
      const vtkIdType ids[4] = {point_id + face[0],
                                point_id + face[1],
                                point_id + face[2],
                                point_id + face[3]};
      cells->InsertNextCell(4, ids);
      colors->SetTypedTuple(cell_id++, rgb.data());
    }
    point_id += 8;
  }
  auto data = PolyData::New();
  data->SetPoints(points);
  data->SetPolys(cells);
  data->GetCellData()->SetScalars(colors);
  return data;
}

/** The labeled points as vertices coloured by segment. */
PolyData
buildCloud(const Scene& scene)
{
  const auto& labels = scene.result.labels;
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  auto colors = newColors(0);
  for (std::size_t i = 0; i < scene.cloud->size(); ++i) {
    if (labels[i] == 0)
      continue;
    const vtkIdType id = points->InsertNextPoint((*scene.cloud)[i].data);
    cells->InsertNextCell(1, &id);
    colors->InsertNextTypedTuple(selseg_apps::segmentColor(labels[i]).data());
  }
  auto data = PolyData::New();
  data->SetPoints(points);
  data->SetVerts(cells);
  data->GetCellData()->SetScalars(colors);
  return data;
}

/** A line along the normal of every step-th labeled point, 10 median point spacings
 * long, coloured by segment. */
PolyData
buildNormals(const Scene& scene, int step)
{
  const auto& labels = scene.result.labels;
  if (step == 0)
    step = std::max<int>(1, static_cast<int>(scene.result.counts.labeled / 5000));
  const float length = static_cast<float>(10.0 * scene.result.median_spacing);
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  auto colors = newColors(0);
  std::size_t seen = 0;
  for (std::size_t i = 0; i < scene.cloud->size(); ++i) {
    const auto& n = (*scene.normals)[i];
    if (labels[i] == 0 || !std::isfinite(n.normal_x) || seen++ % step != 0)
      continue;
    const Eigen::Vector3f p = (*scene.cloud)[i].getVector3fMap();
    const Eigen::Vector3f q = p + length * n.getNormalVector3fMap();
    const vtkIdType ids[2] = {points->InsertNextPoint(p.data()),
                              points->InsertNextPoint(q.data())};
    cells->InsertNextCell(2, ids);
    colors->InsertNextTypedTuple(selseg_apps::segmentColor(labels[i]).data());
  }
  auto data = PolyData::New();
  data->SetPoints(points);
  data->SetLines(cells);
  data->GetCellData()->SetScalars(colors);
  return data;
}

/** Each region of interest as the outline of its angular window, drawn on a plane in
 * front of the nearest labeled point (so that it is never hidden; for a panorama's
 * windows, on a sphere around the sensor inside the nearest point), coloured by its
 * first reason: yellow transition, magenta small segment, cyan sparse. */
PolyData
buildRegions(const Scene& scene)
{
  const Eigen::Affine3f to_sensor = scene.regions_pose.inverse();
  const bool panoramic =
      !scene.regions.empty() &&
      scene.regions.front().projection == pcl::selective_seg::ViewProjection::Panoramic;
  // The nearest labeled point the file's sensor sees (in front of it, for eq. 1).
  float depth = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < scene.cloud->size(); ++i)
    if (scene.result.labels[i] != 0) {
      const Eigen::Vector3f s = to_sensor * (*scene.cloud)[i].getVector3fMap();
      const float d = panoramic ? s.norm() : s.z();
      if (d > 0.0f)
        depth = std::min(depth, d);
    }
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  auto colors = newColors(0);
  static const std::vector<pcl::selective_seg::RegionOfInterest> none;
  const auto& drawn = std::isfinite(depth) ? scene.regions : none;
  if (drawn.size() != scene.regions.size())
    print_warn("The regions file's sensor sees none of the scan's labeled points (its "
               "pose is far from the scan's): its windows are not drawn.\n");
  depth *= 0.9f;
  for (const auto& r : drawn) {
    const double corners[4][2] = {{r.theta_min, r.phi_min},
                                  {r.theta_max, r.phi_min},
                                  {r.theta_max, r.phi_max},
                                  {r.theta_min, r.phi_max}};
    vtkIdType ids[5];
    for (int c = 0; c < 4; ++c) {
      // Eq. 1's windows on the plane z = depth; a panorama's on the sphere r = depth.
      const double theta = corners[c][0], phi = corners[c][1];
      const Eigen::Vector3f ray =
          r.projection == pcl::selective_seg::ViewProjection::Panoramic
              ? Eigen::Vector3f(static_cast<float>(std::cos(phi) * std::sin(theta)),
                                static_cast<float>(std::sin(phi)),
                                static_cast<float>(std::cos(phi) * std::cos(theta)))
              : Eigen::Vector3f(
                    static_cast<float>(std::tan(std::clamp(theta, -1.56, 1.56))),
                    static_cast<float>(std::tan(std::clamp(phi, -1.56, 1.56))),
                    1.0f);
      const Eigen::Vector3f p = scene.regions_pose * (depth * ray);
      ids[c] = points->InsertNextPoint(p.data());
    }
    ids[4] = ids[0];
    cells->InsertNextCell(5, ids);
    const std::array<unsigned char, 3> rgb =
        (r.reasons & pcl::selective_seg::kTransition)
            ? std::array<unsigned char, 3>{255, 230, 0}
        : (r.reasons & pcl::selective_seg::kSmallSegment)
            ? std::array<unsigned char, 3>{255, 0, 255}
            : std::array<unsigned char, 3>{0, 230, 255};
    colors->InsertNextTypedTuple(rgb.data());
  }
  auto data = PolyData::New();
  data->SetPoints(points);
  data->SetLines(cells);
  data->GetCellData()->SetScalars(colors);
  return data;
}

/** An actor drawing the data's cell colours as they are. */
vtkSmartPointer<vtkActor>
newActor(const PolyData& data)
{
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputData(data);
  mapper->SetScalarModeToUseCellData();
  mapper->SetColorModeToDirectScalars();
  mapper->ScalarVisibilityOn();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  return actor;
}

/** What the sensor's camera shows: the vertical view angle and the window centre (an
 * off-axis shift, in [-1, 1] viewport units) that frame the labeled points. */
struct SensorFrame {
  double view_angle = 60.0 * kDeg; ///< [rad]
  double centre_x = 0.0;
  double centre_y = 0.0;
};

/** The 0.5% and 99.5% quantiles of v, reordering v. */
std::pair<double, double>
robustRange(std::vector<float>& v)
{
  const auto at = [&v](double q) {
    const auto nth = v.begin() + static_cast<std::ptrdiff_t>(q * (v.size() - 1));
    std::nth_element(v.begin(), nth, v.end());
    return static_cast<double>(*nth);
  };
  return {at(0.005), at(0.995)};
}

/** Frame of a camera at the sensor, looking along its +z axis, that shows 99% of the
 * labeled points in a window of the given aspect ratio (width / height). */
SensorFrame
fitSensorFrame(const Scene& scene, double aspect)
{
  const Eigen::Affine3f to_sensor = scene.sensor_pose.inverse();
  std::vector<float> tan_x, tan_y;
  for (std::size_t i = 0; i < scene.cloud->size(); ++i) {
    if (scene.result.labels[i] == 0)
      continue;
    const Eigen::Vector3f s = to_sensor * (*scene.cloud)[i].getVector3fMap();
    tan_x.push_back(s.x() / s.z());
    tan_y.push_back(s.y() / s.z());
  }
  SensorFrame frame;
  if (tan_x.empty())
    return frame;
  const auto [x0, x1] = robustRange(tan_x);
  const auto [y0, y1] = robustRange(tan_y);
  const double half = 0.53 * std::max(y1 - y0, (x1 - x0) / aspect);
  frame.view_angle = std::clamp(2.0 * std::atan(half), 1.0 * kDeg, 150.0 * kDeg);
  const double half_tan = std::tan(0.5 * frame.view_angle);
  frame.centre_x = 0.5 * (x0 + x1) / (half_tan * aspect);
  frame.centre_y = -0.5 * (y0 + y1) / half_tan;
  return frame;
}

/** Owns the PCLVisualizer: one actor per layer, the key legend, the sensor camera. */
class SegmentationViewer {
public:
  /** \param[in] offscreen render without a window (for screenshots) */
  SegmentationViewer(const Scene& scene, const Options& opt, bool offscreen);

  /** Run the interactive loop until the window is closed. */
  void spin();

  /** Render once and write a PNG. \return false, with a message, on failure. */
  bool saveScreenshot(const std::string& path);

private:
  /** Layer keys toggle their layer; b, z and i as the legend says. */
  void keyboardCallback(const pcl::visualization::KeyboardEvent& event);

  /** Camera at the sensor, looking along its +z axis, its y axis pointing down. */
  void setSensorCamera();

  /** Octree leaves as outlines or as solid cubes with dark edges. */
  void setOctreeWireframe(bool wireframe);

  /** The key legend with each layer's state, or nothing when the legend is off. */
  void updateLegend();

  vtkRenderer* renderer() { return viz_.getRendererCollection()->GetFirstRenderer(); }

  pcl::visualization::PCLVisualizer viz_;
  const Scene& scene_;
  std::array<vtkSmartPointer<vtkActor>, kNumLayers> actors_;
  std::array<bool, kNumLayers> visible_{};
  std::string summary_;
  bool octree_wireframe_ = false;
  bool legend_ = true;
};

SegmentationViewer::SegmentationViewer(const Scene& scene,
                                       const Options& opt,
                                       bool offscreen)
    : viz_("pcl_selective_seg_viewer: " + opt.input, !offscreen)
    , scene_(scene)
    , legend_(opt.legend)
{
  if (offscreen)
    viz_.getRenderWindow()->SetOffScreenRendering(1);
  viz_.setSize(opt.width, opt.height);
  viz_.setBackgroundColor(0.0, 0.0, 0.0);
  viz_.setShowFPS(false);
  const std::array<PolyData, kNumLayers> data = {buildMesh(scene),
                                                 buildOctree(scene),
                                                 buildCloud(scene),
                                                 buildNormals(scene, opt.normal_step),
                                                 buildRegions(scene)};
  for (int layer = 0; layer < kNumLayers; ++layer) {
    actors_[layer] = newActor(data[layer]);
    visible_[layer] = opt.view[layer];
    actors_[layer]->SetVisibility(visible_[layer]);
    renderer()->AddActor(actors_[layer]);
  }
  for (const Layer layer : {kMesh, kOctree}) {
    actors_[layer]->GetProperty()->SetAmbient(0.35);
    actors_[layer]->GetProperty()->SetDiffuse(0.65);
  }
  actors_[kCloud]->GetProperty()->SetPointSize(2.0);
  actors_[kNormals]->GetProperty()->LightingOff();
  actors_[kRegions]->GetProperty()->LightingOff();
  actors_[kRegions]->GetProperty()->SetLineWidth(2.0f);
  actors_[kOctree]->GetProperty()->SetEdgeColor(0.1, 0.1, 0.1);
  setOctreeWireframe(opt.octree_wireframe);
  summary_ =
      std::to_string(scene.result.segments.size()) + " segments, " +
      std::to_string(scene.result.leaves.size()) + " octree leaves, " +
      std::to_string(scene.result.mesh.triangles.size()) + " triangles" +
      (scene.regions.empty() && opt.roi_json.empty() && !opt.roi
           ? std::string()
           : ", " + std::to_string(scene.regions.size()) + " regions of interest");
  updateLegend();
  setSensorCamera();
  if (!offscreen)
    viz_.registerKeyboardCallback(
        [this](const pcl::visualization::KeyboardEvent& e) { keyboardCallback(e); });
}

void
SegmentationViewer::spin()
{
  while (!viz_.wasStopped())
    viz_.spinOnce(100);
}

bool
SegmentationViewer::saveScreenshot(const std::string& path)
{
  // Written to a temporary and renamed into place: a failed run leaves no partial
  // picture, and a path that is not a regular file (a folder, a FIFO, a device) is
  // refused before anything is rendered.
  selseg_apps::OutputTransaction output;
  const std::string temporary = output.stage(path);
  std::string error;
  if (!output.check(error)) {
    print_error("%s\n", error.c_str());
    return false;
  }
  if (!std::ofstream(temporary, std::ios::binary)) {
    print_error("Cannot write '%s': check that the folder exists and is writable.\n",
                path.c_str());
    return false;
  }
  auto* window = viz_.getRenderWindow().Get();
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetCompressionLevel(9);
  writer->SetFileName(temporary.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0) {
    print_error("Cannot write the PNG '%s' (disk full?).\n", path.c_str());
    return false;
  }
  if (!output.commit(error)) {
    print_error("%s\n", error.c_str());
    return false;
  }
  print_info("Wrote '%s' [%d x %d]\n",
             path.c_str(),
             window->GetSize()[0],
             window->GetSize()[1]);
  return true;
}

void
SegmentationViewer::keyboardCallback(const pcl::visualization::KeyboardEvent& event)
{
  if (!event.keyDown())
    return;
  const char key = event.getKeyCode();
  for (int layer = 0; layer < kNumLayers; ++layer)
    if (key == kLayers[layer].key) {
      visible_[layer] = !visible_[layer];
      actors_[layer]->SetVisibility(visible_[layer]);
      renderer()->ResetCameraClippingRange();
    }
  if (key == 'b')
    setOctreeWireframe(!octree_wireframe_);
  else if (key == 'z')
    setSensorCamera();
  else if (key == 'i')
    legend_ = !legend_;
  updateLegend();
  viz_.getRenderWindow()->Render();
}

void
SegmentationViewer::setSensorCamera()
{
  const auto& pose = scene_.sensor_pose;
  const Eigen::Vector3f eye = pose.translation();
  const Eigen::Vector3f focal = pose * Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f up = pose.linear() * -Eigen::Vector3f::UnitY();
  viz_.setCameraPosition(eye.x(),
                         eye.y(),
                         eye.z(),
                         focal.x(),
                         focal.y(),
                         focal.z(),
                         up.x(),
                         up.y(),
                         up.z());
  const int* size = viz_.getRenderWindow()->GetSize();
  const SensorFrame frame = fitSensorFrame(scene_, double(size[0]) / size[1]);
  viz_.setCameraFieldOfView(frame.view_angle);
  renderer()->GetActiveCamera()->SetWindowCenter(frame.centre_x, frame.centre_y);
  renderer()->ResetCameraClippingRange();
}

void
SegmentationViewer::setOctreeWireframe(bool wireframe)
{
  octree_wireframe_ = wireframe;
  auto* property = actors_[kOctree]->GetProperty();
  if (wireframe) {
    property->SetRepresentationToWireframe();
    property->EdgeVisibilityOff();
    property->LightingOff();
  } else {
    property->SetRepresentationToSurface();
    property->EdgeVisibilityOn();
    property->LightingOn();
  }
}

void
SegmentationViewer::updateLegend()
{
  std::vector<std::string> lines = {summary_};
  for (int layer = 0; layer < kNumLayers; ++layer)
    lines.push_back(std::string(1, kLayers[layer].key) + "  " +
                    kLayers[layer].description + (visible_[layer] ? "  [on]" : ""));
  lines.push_back(std::string("b  octree as ") +
                  (octree_wireframe_ ? "outlines" : "solid cubes"));
  lines.push_back("z  sensor's view   i  legend   q  quit");
  const int font = 12, step = 16;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const std::string id = "legend" + std::to_string(k);
    const int y = 8 + step * static_cast<int>(lines.size() - 1 - k);
    const std::string text = legend_ ? lines[k] : "";
    if (!viz_.updateText(text, 8, y, font, 1.0, 1.0, 1.0, id))
      viz_.addText(text, 8, y, font, 1.0, 1.0, 1.0, id);
  }
}

/** main() but for its handling of memory running out. */
int
run(int argc, char** argv)
{
  if (argc < 2 || find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help")) {
    printHelp(argv[0]);
    return argc < 2 ? kUsageError : 0;
  }
  Options opt;
  if (const int rc = parseOptions(argc, argv, opt))
    return rc;
  // A screenshot path that is not a regular file (a folder, a FIFO, a device), or in a
  // folder that does not exist or cannot be written, is refused before the scan is
  // read or a window opened.
  std::string error;
  if (!opt.screenshot.empty() && !selseg_apps::outputWritable(opt.screenshot, error)) {
    print_error("%s\n", error.c_str());
    return kRuntimeError;
  }
  Scene scene;
  if (!loadInput(opt, scene) || !checkDisplay() || !segment(opt, scene))
    return kRuntimeError;
  const bool offscreen = !opt.screenshot.empty();
  SegmentationViewer viewer(scene, opt, offscreen);
  if (offscreen)
    return viewer.saveScreenshot(opt.screenshot) ? 0 : kRuntimeError;
  viewer.spin();
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  return selseg_apps::runReportingOutOfMemory(
      [&] { return run(argc, argv); },
      "view a smaller scan (crop or downsample it).",
      kRuntimeError);
}
