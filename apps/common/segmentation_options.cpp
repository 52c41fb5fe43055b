/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "segmentation_options.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>

namespace selseg_apps {
namespace {

using pcl::console::print_error;
using pcl::console::print_info;
using pcl::selective_seg::DelaunayBackend;
using pcl::selective_seg::EdgeTriangleNormal;
using pcl::selective_seg::MergeWith;
using pcl::selective_seg::NormalSpreadFrame;
using pcl::selective_seg::PointNormalTriangles;
using pcl::selective_seg::SegmentNormalWeight;
using pcl::selective_seg::SelectiveSegmentationParameters;
using pcl::selective_seg::ViewProjection;

constexpr double kDeg = M_PI / 180.0;

bool
parseDegrees(int argc, char** argv, const char* flag, double& radians)
{
  double degrees = radians / kDeg;
  if (!parseNumber(argc, argv, flag, degrees))
    return false;
  radians = degrees * kDeg;
  return true;
}

template <typename Enum> using Choices = std::vector<std::pair<std::string, Enum>>;

// The command-line names of the enum options' values, read by the parser and written
// by choiceName() (the JSON summary).
const Choices<SegmentNormalWeight> kSegmentWeights = {
    {"inverse_area", SegmentNormalWeight::InverseArea},
    {"area", SegmentNormalWeight::Area}};
const Choices<MergeWith> kMergeWith = {{"seeds", MergeWith::Seeds},
                                       {"segments", MergeWith::Segments}};
const Choices<NormalSpreadFrame> kSpreadFrames = {
    {"sensor", NormalSpreadFrame::Sensor},
    {"mean_normal", NormalSpreadFrame::MeanNormal}};
const Choices<PointNormalTriangles> kNormalTriangles = {
    {"all", PointNormalTriangles::All},
    {"not_edge_on", PointNormalTriangles::NotEdgeOn}};
const Choices<ViewProjection> kProjections = {{"forward", ViewProjection::Forward},
                                              {"panoramic", ViewProjection::Panoramic}};
const Choices<EdgeTriangleNormal> kEdgeNormals = {
    {"facet", EdgeTriangleNormal::Facet},
    {"vertex_mean", EdgeTriangleNormal::VertexMean}};

template <typename Enum>
std::string
nameIn(const Choices<Enum>& choices, Enum value)
{
  for (const auto& c : choices)
    if (c.second == value)
      return c.first;
  return std::to_string(static_cast<int>(value));
}

/** A named choice: absent keeps \a value; an unknown name is an error. */
template <typename Enum>
bool
parseChoice(
    int argc, char** argv, const char* flag, const Choices<Enum>& choices, Enum& value)
{
  std::string name;
  if (pcl::console::parse_argument(argc, argv, flag, name) < 0)
    return true;
  for (const auto& c : choices)
    if (c.first == name) {
      value = c.second;
      return true;
    }
  print_error("Unknown %s '%s' (see -h).\n", flag, name.c_str());
  return false;
}

/** Whether strtod() reads all of \a text, and not nothing, as \a value (errno set
 * as strtod() leaves it: ERANGE beyond a double's range or towards 0). */
bool
wholeNumber(const char* text, double& value)
{
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text, &end);
  return end != text && *end == '\0';
}

} // namespace

std::string
choiceName(SegmentNormalWeight value)
{
  return nameIn(kSegmentWeights, value);
}

std::string
choiceName(MergeWith value)
{
  return nameIn(kMergeWith, value);
}

std::string
choiceName(NormalSpreadFrame value)
{
  return nameIn(kSpreadFrames, value);
}

std::string
choiceName(PointNormalTriangles value)
{
  return nameIn(kNormalTriangles, value);
}

std::string
choiceName(EdgeTriangleNormal value)
{
  return nameIn(kEdgeNormals, value);
}

std::string
choiceName(ViewProjection value)
{
  return nameIn(kProjections, value);
}

bool
readOptionNumber(const char* flag,
                 const char* text,
                 bool whole,
                 double lowest,
                 double highest,
                 double& value)
{
  if (!text || text[0] == '\0') {
    print_error("Option %s needs a value (see -h).\n", flag);
    return false;
  }
  double v = 0.0;
  if (!wholeNumber(text, v) || std::isnan(v)) {
    print_error("Option %s needs a number, not '%s' (see -h).\n", flag, text);
    return false;
  }
  if ((errno == ERANGE && std::isinf(v)) || !(v >= lowest && v <= highest)) {
    if (highest < std::numeric_limits<double>::max())
      print_error("Option %s %s is out of range: give a number in [%.15g, %.15g] (see "
                  "-h).\n",
                  flag,
                  text,
                  lowest,
                  highest);
    else
      print_error("Option %s %s is beyond a double's range (see -h).\n", flag, text);
    return false;
  }
  if (whole && v != std::floor(v)) {
    print_error("Option %s needs a whole number, not '%s' (see -h).\n", flag, text);
    return false;
  }
  value = v; // a denormal (strtod's ERANGE towards 0) is a number like any other
  return true;
}

bool
parseNumberList(
    int argc, char** argv, const char* flag, std::size_t n, std::vector<double>& values)
{
  const int at = pcl::console::find_argument(argc, argv, flag);
  if (at < 0)
    return true;
  const std::string text = at + 1 < argc ? argv[at + 1] : "";
  std::vector<double> read;
  bool numbers = true;
  for (std::size_t begin = 0; numbers && begin <= text.size();) {
    const std::size_t end = std::min(text.find(',', begin), text.size());
    const std::string item = text.substr(begin, end - begin);
    double value = 0.0;
    // A denormal is a number.
    numbers = wholeNumber(item.c_str(), value) && std::isfinite(value);
    read.push_back(value);
    begin = end + 1;
  }
  if (!numbers || read.size() != n) {
    print_error("Option %s needs %zu comma-separated finite numbers, not '%s' (see "
                "-h).\n",
                flag,
                n,
                text.c_str());
    return false;
  }
  values = read;
  return true;
}

bool
parseFileName(int argc, char** argv, const char* flag, std::string& name)
{
  const int at = pcl::console::find_argument(argc, argv, flag);
  if (at < 0)
    return true;
  const std::string text = at + 1 < argc ? argv[at + 1] : "";
  if (text.empty()) {
    print_error("Option %s needs a file name (see -h).\n", flag);
    return false;
  }
  if (text.size() > 1 && text[0] == '-' &&
      (std::isalpha(static_cast<unsigned char>(text[1])) || text[1] == '-')) {
    print_error("Option %s needs a file name, not the option '%s'; a file whose name "
                "starts with '-' is given as ./%s.\n",
                flag,
                text.c_str(),
                text.c_str());
    return false;
  }
  name = text;
  return true;
}

bool
helpAsked(int argc, char** argv)
{
  for (int i = 1; i < argc; i += 2)
    if (std::string(argv[i]) == "-h" || std::string(argv[i]) == "--help")
      return true;
  return false;
}

bool
optionsGivenOnce(int argc,
                 char** argv,
                 const std::function<bool(const std::string&)>& takes_value)
{
  std::set<std::string> seen;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-' ||
        !std::isalpha(static_cast<unsigned char>(arg[arg[1] == '-' ? 2 : 1])))
      continue;
    if (!seen.insert(arg).second) {
      print_error("Option %s is given more than once: give it once (see -h).\n",
                  arg.c_str());
      return false;
    }
    if (takes_value(arg))
      ++i;
  }
  return true;
}

const std::vector<std::string>&
segmentationFlags()
{
  static const std::vector<std::string> flags = {"-split_deg",
                                                 "-spread_frame",
                                                 "-merge_deg",
                                                 "-segment_weight",
                                                 "-merge_with",
                                                 "-edge_deg",
                                                 "-incidence_deg",
                                                 "-normal_rings",
                                                 "-normal_triangles",
                                                 "-edge_normal",
                                                 "-min_voxel_m",
                                                 "-voxel_factor",
                                                 "-max_depth",
                                                 "-angle_step_rad",
                                                 "-min_split_points",
                                                 "-backend",
                                                 "-projection",
                                                 "-threads"};
  return flags;
}

void
printSegmentationHelp()
{
  const SelectiveSegmentationParameters d;
  print_info("Segmentation (defaults are the paper's where it gives one; "
             "docs/parameters.md):\n");
  print_info("  -split_deg X           octree split threshold on the normals' std dev "
             "[deg] (default %g)\n",
             d.max_normal_std_dev / kDeg);
  print_info("  -spread_frame NAME     frame of the split test's normal angles: sensor "
             "(paper) or mean_normal (default sensor)\n");
  print_info("  -merge_deg X           max angle between merged segment normals [deg] "
             "(default %g)\n",
             d.max_merge_angle / kDeg);
  print_info("  -segment_weight NAME   weight of a leaf normal in its segment's (eq. 7): "
             "inverse_area (paper) or area (default inverse_area)\n");
  print_info("  -merge_with NAME       what a growing segment merges with (eq. 9-10): "
             "seeds (not yet in a segment) or segments (also those grown before it; "
             "one thread) (default seeds)\n");
  print_info("  -edge_deg X            max angle between a valid edge triangle and the "
             "segment [deg] (default %g)\n",
             d.max_edge_triangle_angle / kDeg);
  print_info("  -incidence_deg X       max view incidence of a valid edge triangle "
             "[deg]; 90 = paper (default %g)\n",
             d.max_view_incidence_angle / kDeg);
  print_info("  -normal_rings N        point normals over the N-ring of triangles; 1 = "
             "paper's eq. 2 (default %d)\n",
             d.normal_rings);
  print_info("  -normal_triangles NAME triangles summed into a point normal (eq. 2): "
             "all (paper) or not_edge_on (only those seen within -incidence_deg of "
             "head-on; all where none is) (default all)\n");
  print_info("  -edge_normal NAME      normal tested by eq. 8: facet (paper) or "
             "vertex_mean (noise-robust) (default facet)\n");
  print_info("  -min_voxel_m X         smallest octree voxel [m]; 0 = automatic "
             "(default %g)\n",
             d.min_voxel_size);
  print_info("  -voxel_factor X        automatic smallest voxel in median point "
             "spacings (default %g)\n",
             d.min_voxel_size_factor);
  print_info("  -min_split_points N    voxels with fewer points are not split "
             "(default %d)\n",
             d.min_points_to_split);
  print_info("  -max_depth N           deepest octree level (default %d)\n",
             d.max_octree_depth);
  print_info("  -angle_step_rad X      angle quantization step [rad] (default %g)\n",
             d.angle_quantization);
  print_info(
      "  -backend NAME          Delaunay backend: sweep, boost or vtk (default sweep)\n");
  print_info("  -projection NAME       directions to angles: forward (paper's eq. 1; "
             "points behind the sensor are left out) or panoramic (azimuth and "
             "elevation, the mesh closed around the sensor: a spinning lidar; implies "
             "-spread_frame mean_normal) (default forward)\n");
  print_info("  -threads N             threads of the parallel stages; 0 = automatic: "
             "OMP_NUM_THREADS, else the CPUs the process may use (default %d; the "
             "result does not depend on it)\n",
             d.num_threads);
}

std::string
explainDegrees(const std::string& why,
               const std::vector<std::pair<const char*, const char*>>& flags,
               int argc,
               char** argv)
{
  for (const auto& [flag, name] : flags) {
    // The library's messages name the parameter as "parameter NAME = ..." or
    // "parameter NAME [unit] = ...".
    const std::string key = std::string("parameter ") + name + " ";
    if (why.find(key) == std::string::npos)
      continue;
    std::string value = "(its default)";
    pcl::console::parse_argument(argc, argv, flag, value);
    return std::string("Option ") + flag + " " + value +
           " [deg] is out of range; in the library's radians (pi rad = 180 deg): " +
           why;
  }
  return why;
}

bool
parseSegmentationOptions(int argc, char** argv, SelectiveSegmentationParameters& p)
{
  if (!parseDegrees(argc, argv, "-split_deg", p.max_normal_std_dev) ||
      !parseDegrees(argc, argv, "-merge_deg", p.max_merge_angle) ||
      !parseDegrees(argc, argv, "-edge_deg", p.max_edge_triangle_angle) ||
      !parseDegrees(argc, argv, "-incidence_deg", p.max_view_incidence_angle) ||
      !parseNumber(argc, argv, "-normal_rings", p.normal_rings) ||
      !parseNumber(argc, argv, "-min_voxel_m", p.min_voxel_size) ||
      !parseNumber(argc, argv, "-voxel_factor", p.min_voxel_size_factor) ||
      !parseNumber(argc, argv, "-min_split_points", p.min_points_to_split) ||
      !parseNumber(argc, argv, "-max_depth", p.max_octree_depth) ||
      !parseNumber(argc, argv, "-angle_step_rad", p.angle_quantization) ||
      !parseNumber(argc, argv, "-threads", p.num_threads) ||
      !parseChoice(
          argc, argv, "-segment_weight", kSegmentWeights, p.segment_normal_weight) ||
      !parseChoice(argc, argv, "-merge_with", kMergeWith, p.merge_with) ||
      !parseChoice(argc, argv, "-spread_frame", kSpreadFrames, p.normal_spread_frame) ||
      !parseChoice(argc,
                   argv,
                   "-normal_triangles",
                   kNormalTriangles,
                   p.point_normal_triangles) ||
      !parseChoice(argc, argv, "-edge_normal", kEdgeNormals, p.edge_triangle_normal) ||
      !parseChoice(argc, argv, "-projection", kProjections, p.projection) ||
      !parseChoice(argc,
                   argv,
                   "-backend",
                   {{"boost", DelaunayBackend::BoostVoronoi},
                    {"vtk", DelaunayBackend::Vtk},
                    {"sweep", DelaunayBackend::Sweep}},
                   p.delaunay_backend))
    return false;
  // The panoramic projection needs eq. 5 in the voxel's frame (validate() says why).
  if (p.projection == ViewProjection::Panoramic &&
      pcl::console::find_argument(argc, argv, "-spread_frame") < 0)
    p.normal_spread_frame = NormalSpreadFrame::MeanNormal;
  std::string why;
  if (!p.validate(&why)) {
    print_error("%s\n",
                explainDegrees(why,
                               {{"-split_deg", "max_normal_std_dev"},
                                {"-merge_deg", "max_merge_angle"},
                                {"-edge_deg", "max_edge_triangle_angle"},
                                {"-incidence_deg", "max_view_incidence_angle"}},
                               argc,
                               argv)
                    .c_str());
    return false;
  }
  return true;
}

} // namespace selseg_apps
