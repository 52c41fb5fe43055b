/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// pcl_selective_seg_simulate: simulate a stereo-like scan of one of the paper's scenes
// (cube, chair, door) with ground-truth labels, print the per-label point counts and
// write the labeled cloud.
//
// Exit codes: 0 = success, 1 = runtime error (unwritable output, out of memory),
// 2 = usage error (bad option).

#include <pcl_selective_seg/sensor_simulator.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <set>
#include <string>

#include "outputs.h"
#include "process_memory.h"
#include "segmentation_options.h"

using namespace pcl::console;
namespace sim = pcl::selective_seg::simulation;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;
constexpr double kDeg = M_PI / 180.0;

/** Command-line options; the sensor defaults are SensorParameters' defaults. */
struct Options {
  sim::PaperScene scene = sim::PaperScene::Cube;
  double density = 1.0;
  sim::SensorParameters sensor;
  std::string output;
};

void
printHelp(const char* program)
{
  const sim::SensorParameters d;
  print_info("Simulate a stereo-like scan of one of the paper's scenes, with "
             "ground-truth labels.\n\nUsage: %s [options]\n\nOptions:\n",
             program);
  print_info("  -scene NAME          cube, chair or door (default cube)\n");
  print_info("  -density X           multiplier of the ray count [-], > 0; 1 gives "
             "about the paper's point count (default 1)\n");
  print_info("  -noise K             range noise factor [1/m]: std dev K * r^2 [m] at "
             "range r [m], in [0, 1] (default %g)\n",
             d.range_noise);
  print_info("  -density_ratio X     densest / sparsest angular density [-], in "
             "[1, 100] (default %g)\n",
             d.density_ratio);
  print_info(
      "  -jitter X            jitter of each ray in its grid cell [-], in [0, 1]: "
      "0 = a regular grid, as a depth camera's pixels (default %g)\n",
      d.jitter);
  print_info("  -dropout P           probability that a ray returns nothing [-], in "
             "[0, 1) (default %g)\n",
             d.dropout);
  print_info("  -holes N             number of elliptic holes without returns, in "
             "[0, 1000] (default %d)\n",
             d.num_holes);
  print_info("  -hole_radius_deg X   mean semi-axis of a hole [deg], in [0, 57.29] "
             "(default %g)\n",
             d.hole_radius / kDeg);
  print_info("  -seed S              random seed, integer in [0, 4294967295] "
             "(default %u)\n",
             d.seed);
  print_info("  -o FILE.pcd          write the cloud (x y z label [m]); without it, "
             "only the counts are printed\n");
  print_info("  -h, --help           this help\n");
}

/** A checked integer option in [lo, hi]. */
bool
parseInteger(
    int argc, char** argv, const char* flag, double lo, double hi, double& value)
{
  if (!selseg_apps::parseNumber(argc, argv, flag, value))
    return false;
  if (value != std::floor(value) || value < lo || value > hi) {
    print_error("Option %s needs an integer in [%.0f, %.0f].\n", flag, lo, hi);
    return false;
  }
  return true;
}

/** Every argument is a known option followed by its value. */
bool
checkArguments(int argc, char** argv)
{
  static const char* const flags[] = {"-scene",
                                      "-density",
                                      "-noise",
                                      "-density_ratio",
                                      "-jitter",
                                      "-dropout",
                                      "-holes",
                                      "-hole_radius_deg",
                                      "-seed",
                                      "-o"};
  std::set<std::string> seen;
  for (int i = 1; i < argc; i += 2) {
    const std::string arg = argv[i];
    if (std::find(std::begin(flags), std::end(flags), arg) == std::end(flags)) {
      print_error("Unknown argument '%s' (see %s -h).\n", argv[i], argv[0]);
      return false;
    }
    // pcl::console's parsers would use the first value and ignore the others.
    if (!seen.insert(arg).second) {
      print_error("Option %s is given more than once: give it once (see -h).\n",
                  argv[i]);
      return false;
    }
    if (i + 1 >= argc) {
      print_error("Option %s needs a value.\n", argv[i]);
      return false;
    }
  }
  return true;
}

/** \return 0 on success, else the exit code. */
int
parseOptions(int argc, char** argv, Options& opt)
{
  if (!checkArguments(argc, argv))
    return kUsageError;
  std::string scene = "cube";
  parse_argument(argc, argv, "-scene", scene);
  if (!sim::parsePaperScene(scene, opt.scene)) {
    print_error("Unknown -scene '%s': use cube, chair or door.\n", scene.c_str());
    return kUsageError;
  }
  auto& s = opt.sensor;
  double holes = s.num_holes;
  double seed = s.seed;
  double hole_radius_deg = s.hole_radius / kDeg;
  using selseg_apps::parseNumber;
  if (!parseNumber(argc, argv, "-density", opt.density) ||
      !parseNumber(argc, argv, "-noise", s.range_noise) ||
      !parseNumber(argc, argv, "-density_ratio", s.density_ratio) ||
      !parseNumber(argc, argv, "-jitter", s.jitter) ||
      !parseNumber(argc, argv, "-dropout", s.dropout) ||
      !parseInteger(argc, argv, "-holes", 0.0, 1000.0, holes) ||
      !parseNumber(argc, argv, "-hole_radius_deg", hole_radius_deg) ||
      !parseInteger(argc, argv, "-seed", 0.0, 4294967295.0, seed))
    return kUsageError;
  if (!(opt.density > 0.0)) {
    print_error("Option -density needs a value > 0.\n");
    return kUsageError;
  }
  // The simulator takes radians, at most 1: checked here so that the message names
  // the option and its unit.
  if (!(hole_radius_deg >= 0.0 && hole_radius_deg * kDeg <= 1.0)) {
    print_error("Option -hole_radius_deg needs a value in [0, %.2f] (1 rad).\n",
                std::floor(100.0 / kDeg) / 100.0);
    return kUsageError;
  }
  // makePaperScene() caps the rays at the simulator's limit, num_rays <= 1e8: a larger
  // density would silently give the cap (and about a minute and 6 GB for it).
  constexpr double kMaxRays = 1e8;
  const double rays =
      static_cast<double>(sim::makePaperScene(opt.scene).sensor.num_rays);
  if (std::round(rays * opt.density) < 1.0) {
    print_error("Option -density %.10g asks for %.10g rays on the %s scene, fewer than "
                "one: use -density %.3g or more.\n",
                opt.density,
                rays * opt.density,
                scene.c_str(),
                1.0 / rays);
    return kUsageError;
  }
  if (std::round(rays * opt.density) > kMaxRays) {
    print_error(
        "Option -density %.10g asks for %.10g rays on the %s scene; the simulator "
        "casts at most %.0f: use -density %.2f or less.\n",
        opt.density,
        rays * opt.density,
        scene.c_str(),
        kMaxRays,
        std::floor(kMaxRays / rays * 100.0) / 100.0);
    return kUsageError;
  }
  s.num_holes = static_cast<int>(holes);
  s.seed = static_cast<std::uint32_t>(seed);
  s.hole_radius = hole_radius_deg * kDeg;
  parse_argument(argc, argv, "-o", opt.output);
  if (find_argument(argc, argv, "-o") >= 0 && opt.output.empty()) {
    print_error("Option -o needs a file name (without -o, only the counts are "
                "printed).\n");
    return kUsageError;
  }
  if (opt.output.size() > 1 && opt.output[0] == '-') {
    print_error("Option -o needs a file name, not an option ('%s'); a file whose name "
                "starts with '-' is given as ./%s.\n",
                opt.output.c_str(),
                opt.output.c_str());
    return kUsageError;
  }
  return 0;
}

/** The scene's sensor window and ray count with the options' sensor model. */
bool
makeSensor(const Options& opt,
           const sim::SimulationSetup& setup,
           sim::SensorParameters& sensor)
{
  sensor = opt.sensor;
  sensor.theta_min = setup.sensor.theta_min;
  sensor.theta_max = setup.sensor.theta_max;
  sensor.phi_min = setup.sensor.phi_min;
  sensor.phi_max = setup.sensor.phi_max;
  sensor.num_rays = setup.sensor.num_rays;
  std::string why;
  if (!sensor.validate(&why)) {
    print_error("%s\n", why.c_str());
    return false;
  }
  return true;
}

void
printCounts(const sim::Scene& scene,
            const pcl::PointCloud<pcl::PointXYZL>& cloud,
            const sim::SimulationDetails& details)
{
  std::map<std::uint32_t, std::size_t> counts;
  for (const auto& point : cloud)
    ++counts[point.label];
  print_info("Rays: %zu cast, %zu in holes, %zu dropped, %zu missed, %zu out of "
             "range\n",
             details.rays,
             details.in_holes,
             details.dropped,
             details.missed,
             details.out_of_range);
  for (const auto& [label, name] : scene.label_names)
    print_info("  label %2u  %-28s %8zu points\n", label, name.c_str(), counts[label]);
}

/** Written under a temporary name and renamed into place (OutputTransaction: no
 * partial file is left behind, by a failure or by SIGTERM, SIGINT or SIGHUP; a
 * symbolic link stays one). */
bool
saveCloud(const std::string& path, const pcl::PointCloud<pcl::PointXYZL>& cloud)
{
  selseg_apps::OutputTransaction output;
  bool written = false;
  try {
    written = pcl::io::savePCDFileBinary(output.stage(path), cloud) == 0;
  } catch (const pcl::PCLException&) {
    written = false;
  }
  std::string error;
  if (!written) {
    print_error("Cannot write '%s': check the free space and that the folder is "
                "writable.\n",
                path.c_str());
    return false;
  }
  if (!output.commit(error)) {
    print_error("%s\n", error.c_str());
    return false;
  }
  return true;
}

int
run(int argc, char** argv)
{
  if (selseg_apps::helpAsked(argc, argv)) {
    printHelp(argv[0]);
    return 0;
  }
  Options opt;
  if (const int code = parseOptions(argc, argv, opt))
    return code;
  // The output is checked before the work that makes it.
  std::string error;
  if (!opt.output.empty() && !selseg_apps::outputWritable(opt.output, error)) {
    print_error("%s\n", error.c_str());
    return kRuntimeError;
  }
  const sim::SimulationSetup setup = sim::makePaperScene(opt.scene, opt.density);
  sim::SensorSimulator simulator;
  sim::SensorParameters sensor;
  if (!makeSensor(opt, setup, sensor) || !simulator.setParameters(sensor))
    return kUsageError;
  // About 63 bytes of peak memory per ray (measured at 1e8 rays: 6.3 GB).
  if (setup.sensor.num_rays >= 10000000)
    print_info("Casting %zu rays: this takes minutes and about %.1f GB of memory.\n",
               static_cast<std::size_t>(setup.sensor.num_rays),
               63e-9 * static_cast<double>(setup.sensor.num_rays));
  TicToc timer;
  timer.tic();
  print_highlight("Simulating the %s scene ",
                  sim::getPaperSceneName(opt.scene).c_str());
  pcl::PointCloud<pcl::PointXYZL> cloud;
  sim::SimulationDetails details;
  if (!simulator.simulate(setup.scene, cloud, &details))
    return kRuntimeError;
  print_info("[done, %g ms : %zu points]\n", timer.toc(), cloud.size());
  printCounts(setup.scene, cloud, details);
  if (cloud.empty() && !opt.output.empty()) { // a file no tool reads
    print_error("No ray returned a point: lower -dropout or -holes / -hole_radius_deg "
                "(nothing written).\n");
    return kRuntimeError;
  }
  if (!opt.output.empty() && !saveCloud(opt.output, cloud))
    return kRuntimeError;
  if (!opt.output.empty())
    print_info("Wrote %s (%zu points)\n", opt.output.c_str(), cloud.size());
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  return selseg_apps::runReportingOutOfMemory(
      [&] { return run(argc, argv); }, "use a smaller -density.", kRuntimeError);
}
