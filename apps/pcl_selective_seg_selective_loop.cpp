/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// pcl_selective_seg_selective_loop: the simulated coarse-to-fine loop of selective
// sensing on the paper's scenes, against uniform scans of the same scenes
// (docs/selective_sensing.md). For each scene: a noise-free reference scan gives the
// ground-truth boundaries; uniform scans at several steps and the selective loop
// (coarse scan, regions of interest under a point budget, finer scans, update) are
// segmented and scored. Writes OUT/table.md, OUT/<scene>.dat (gnuplot), the clouds and
// windows for the pictures (OUT/<scene>_*.pcd, *.json) and OUT/<scene>_min_voxel.txt.
// Every file is written under a temporary name and renamed into place only when the
// whole run succeeded: a failed run leaves OUT as it was (a folder it made, removed;
// a run ended by a signal removes its temporaries but leaves such a folder, empty).
//
// Exit codes: 0 = success, 1 = runtime error, 2 = usage error.

#include <pcl_selective_seg/selective_loop.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "outputs.h"
#include "process_memory.h"
#include "roi_json.h"
#include "roi_options.h"
#include "segmentation_options.h"

using namespace pcl::console;
namespace sim = pcl::selective_seg::simulation;
using pcl::selective_seg::RegionOfInterest;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;
// -step_scale's range: the scans' points, memory and time grow as 1 / S^2 (the cube at
// 0.25: about 30 s and 0.4 GB; at 0.1 it took 3 min and 2.4 GB, the door far more),
// and from about 100 up a scan has too few points to segment.
constexpr double kMinStepScale = 0.25;
constexpr double kMaxStepScale = 100.0;

struct Options {
  std::vector<std::string> scenes = {"cube", "chair", "door"};
  std::string out;
  int iterations = 3;
  double coarse_factor = 3.0;
  double budget_fraction = 0.3;
  double range_noise = 0.0005;
  double min_voxel_factor = 2.0;
  double step_scale = 1.0;
  double window_steps = 1.0;
  double progressive = 1.0;
  double seed = -1.0; ///< < 0: the scenes' own seeds
  pcl::selective_seg::RegionOfInterestParameters regions;
  pcl::selective_seg::SelectiveSegmentationParameters segmentation;
};

/** Finest step of each scene [rad]: about four times the paper's point count. */
double
fineStep(const std::string& scene)
{
  if (scene == "cube")
    return 0.0036;
  if (scene == "chair")
    return 0.0032;
  return 0.0016; // door
}

void
printHelp(const char* program)
{
  const Options defaults; // the help shows the values the tool starts from
  print_info(
      "The simulated coarse-to-fine loop of selective sensing against uniform "
      "scans.\n\n"
      "Usage: %s -out FOLDER [options]\n"
      "  -out FOLDER            where table.md, <scene>.dat, clouds and windows go "
      "(made if missing)\n"
      "  -scenes a,b            scenes among cube, chair, door (default all three)\n"
      "  -iterations N          refinement rounds, in [0, 100] (default %d)\n"
      "  -coarse_factor X       coarse step = X times the fine step, in [1, 100] "
      "(default %g)\n"
      "  -budget_fraction F     selective point budget, fraction of the finest uniform "
      "scan's points, coarse scan\n"
      "                         included: in (0, 1], at least 1 / coarse_factor^2 "
      "(default %g)\n"
      "  -range_noise K         range noise sigma = K r^2 [1/m], in [0, 1] (default "
      "%g, "
      "level A)\n"
      "  -min_voxel_factor X    finest voxel = X fine steps at the median range, in "
      "[0, 1000]; 0 = automatic\n"
      "                         from the coarse scan (default %g)\n"
      "  -progressive 0|1       1: each round a step finer, the last at the fine "
      "step; 0: every round at the fine step (default %g)\n"
      "  -window_steps X        evidence tiles of X coarse steps, in [0.01, 1000]; 0 = "
      "-roi_max_window_deg (default %g)\n"
      "  -step_scale S          multiply every step by S, in [0.25, 100]: points, "
      "memory and time grow\n"
      "                         as 1 / S^2 (S > 1: a quicker, coarser run; default "
      "%g)\n"
      "  -seed N                the sensor's random seed (rays, dropouts, noise) for "
      "every scan, in\n"
      "                         [0, 4294967295]; default: the scene's own\n\n"
      "The loop sets the windows' point budget (-budget_fraction, shared among the "
      "rounds), step (a step\nfiner each round with -progressive 1, the fine step in "
      "the last) and yield: -roi_max_points,\n-roi_max_sr, -roi_max_regions, "
      "-roi_yield, -roi_step_deg and -roi_refine are refused, and\n"
      "-roi_max_window_deg applies only with -window_steps 0. The loop's own defaults "
      "differ from\nthose listed below: -roi_margin_spacings 0.5 -roi_valid_edges 1 "
      "-roi_edge_on 1 -roi_side_deg 25\n-roi_side_confidence 0.95 "
      "-roi_sparse_by_area 1.\n",
      program,
      defaults.iterations,
      defaults.coarse_factor,
      defaults.budget_fraction,
      defaults.range_noise,
      defaults.min_voxel_factor,
      defaults.progressive,
      defaults.window_steps,
      defaults.step_scale);
  selseg_apps::printRegionHelp(true);
  print_info("The segmentation options apply to both strategies.\n");
  selseg_apps::printSegmentationHelp();
}

/** \a fraction rounded up to three significant digits. */
double
roundUp3(double fraction)
{
  const double unit = std::pow(10.0, std::floor(std::log10(fraction)) - 2.0);
  return std::ceil(fraction / unit - 1e-9) * unit;
}

/** What to give when the budget cannot hold a coarse scan of \a coarse_share of the
 * finest uniform scan's points: a fraction with a quarter to spare, or, where that
 * would exceed the whole scan, a coarser coarse scan. */
std::string
budgetAdvice(double coarse_share)
{
  char text[160];
  const double fraction = roundUp3(1.25 * coarse_share);
  if (fraction <= 1.0)
    std::snprintf(text, sizeof text, "give -budget_fraction %.3g or more", fraction);
  else
    std::snprintf(text,
                  sizeof text,
                  "give -coarse_factor 1.12 or more (a coarse scan of at most 80%% of "
                  "the points leaves some for the windows)");
  return text;
}

bool
parseOptions(int argc, char** argv, Options& opt)
{
  // Every option takes a value.
  for (int i = 1; i < argc; i += 2) {
    const std::string a = argv[i];
    const bool known = a == "-out" || a == "-scenes" || a == "-iterations" ||
                       a == "-coarse_factor" || a == "-budget_fraction" ||
                       a == "-range_noise" || a == "-min_voxel_factor" ||
                       a == "-step_scale" || a == "-window_steps" ||
                       a == "-progressive" || a == "-seed" ||
                       std::find(selseg_apps::segmentationFlags().begin(),
                                 selseg_apps::segmentationFlags().end(),
                                 a) != selseg_apps::segmentationFlags().end() ||
                       std::find(selseg_apps::regionFlags().begin(),
                                 selseg_apps::regionFlags().end(),
                                 a) != selseg_apps::regionFlags().end();
    if (!known || i + 1 >= argc) {
      print_error("%s '%s' (see -h).\n",
                  known ? "Missing value of" : "Unknown argument",
                  a.c_str());
      return false;
    }
  }
  if (!selseg_apps::optionsGivenOnce(
          argc, argv, [](const std::string&) { return true; }))
    return false;
  parse_argument(argc, argv, "-out", opt.out);
  if (opt.out.empty()) {
    print_error("Give -out FOLDER.\n");
    return false;
  }
  std::string scenes;
  if (parse_argument(argc, argv, "-scenes", scenes) >= 0) {
    opt.scenes.clear();
    std::stringstream list(scenes);
    std::string name;
    if (!scenes.empty() && scenes.back() == ',') {
      print_error("-scenes '%s' ends with a comma: list scenes as a,b.\n",
                  scenes.c_str());
      return false;
    }
    while (std::getline(list, name, ',')) {
      sim::PaperScene scene;
      if (!sim::parsePaperScene(name, scene)) {
        print_error("Unknown scene '%s': use cube, chair or door.\n", name.c_str());
        return false;
      }
      if (std::find(opt.scenes.begin(), opt.scenes.end(), name) != opt.scenes.end()) {
        print_error("Scene '%s' is listed twice in -scenes.\n", name.c_str());
        return false;
      }
      opt.scenes.push_back(name);
    }
    if (opt.scenes.empty()) {
      print_error("-scenes needs at least one of cube, chair, door.\n");
      return false;
    }
  }
  // The loop sets these region parameters itself, every round: a value given for them
  // would change nothing (and be written into the windows' files as if it had).
  for (const std::string& flag : selseg_apps::loopSetRegionFlags())
    if (find_argument(argc, argv, flag.c_str()) >= 0) {
      print_error("%s does not apply here: the loop sets the windows' point budget "
                  "(-budget_fraction of the finest uniform scan's points, shared "
                  "among the rounds), step and yield itself.\n",
                  flag.c_str());
      return false;
    }
  using selseg_apps::parseNumber;
  double iterations = opt.iterations;
  const bool seed_given = find_argument(argc, argv, "-seed") >= 0;
  if (!parseNumber(argc, argv, "-iterations", iterations) ||
      !parseNumber(argc, argv, "-coarse_factor", opt.coarse_factor) ||
      !parseNumber(argc, argv, "-budget_fraction", opt.budget_fraction) ||
      !parseNumber(argc, argv, "-range_noise", opt.range_noise) ||
      !parseNumber(argc, argv, "-min_voxel_factor", opt.min_voxel_factor) ||
      !parseNumber(argc, argv, "-step_scale", opt.step_scale) ||
      !parseNumber(argc, argv, "-window_steps", opt.window_steps) ||
      !parseNumber(argc, argv, "-progressive", opt.progressive) ||
      !parseNumber(argc, argv, "-seed", opt.seed) ||
      !selseg_apps::parseRegionOptions(argc, argv, opt.regions) ||
      !selseg_apps::parseSegmentationOptions(argc, argv, opt.segmentation))
    return false;
  if (opt.segmentation.projection != pcl::selective_seg::ViewProjection::Forward) {
    print_error("-projection panoramic does not apply here: the simulated sensor looks "
                "forward and the regions of interest are windows of eq. 1's angles.\n");
    return false;
  }
  if (opt.segmentation.min_voxel_size > 0.0) {
    print_error("-min_voxel_m does not apply here: the loop sets the voxel with "
                "-min_voxel_factor, the uniform scans choose theirs.\n");
    return false;
  }
  // Each option's range, named with the option (the first one out of range is
  // reported).
  const bool whole_iterations = iterations == std::floor(iterations);
  const struct {
    const char* flag;
    bool ok;
    const char* range;
  } ranges[] = {
      {"-iterations",
       whole_iterations && iterations >= 0 && iterations <= 100,
       "a whole number in [0, 100]"},
      {"-coarse_factor",
       opt.coarse_factor >= 1.0 && opt.coarse_factor <= 100.0,
       "a value in [1, 100]"},
      {"-budget_fraction",
       opt.budget_fraction > 0.0 && opt.budget_fraction <= 1.0,
       "a value in (0, 1]"},
      {"-range_noise",
       opt.range_noise >= 0.0 && opt.range_noise <= 1.0,
       "a value in [0, 1]"},
      {"-min_voxel_factor",
       opt.min_voxel_factor >= 0.0 && opt.min_voxel_factor <= 1000.0,
       "0 or a value in (0, 1000]"},
      {"-step_scale",
       opt.step_scale >= kMinStepScale && opt.step_scale <= kMaxStepScale,
       "a value in [0.25, 100] (the scans' points grow as 1 / S^2)"},
      {"-window_steps",
       opt.window_steps == 0.0 ||
           (opt.window_steps >= 0.01 && opt.window_steps <= 1000.0),
       "0 or a value in [0.01, 1000]"},
      {"-progressive", opt.progressive == 0.0 || opt.progressive == 1.0, "0 or 1"},
      {"-seed",
       !seed_given || (opt.seed >= 0.0 && opt.seed <= 4294967295.0 &&
                       opt.seed == std::floor(opt.seed)),
       "a whole number in [0, 4294967295]"},
  };
  for (const auto& r : ranges)
    if (!r.ok) {
      print_error("Option %s needs %s.\n", r.flag, r.range);
      return false;
    }
  opt.iterations = static_cast<int>(iterations);
  if (!seed_given)
    opt.seed = -1.0;
  if (opt.window_steps > 0.0 && find_argument(argc, argv, "-roi_max_window_deg") >= 0) {
    print_error("-roi_max_window_deg applies only with -window_steps 0: otherwise the "
                "evidence tiles, -window_steps coarse steps, bound the windows.\n");
    return false;
  }
  // The budget includes the coarse scan, about 1 / coarse_factor^2 of the finest
  // uniform scan's points: a smaller fraction cannot hold it, whatever the scene.
  const double coarse_share = 1.0 / (opt.coarse_factor * opt.coarse_factor);
  if (opt.budget_fraction < coarse_share) {
    print_error(
        "-budget_fraction %g is less than the coarse scan's share of the finest "
        "uniform scan's points, about 1 / coarse_factor^2 = %.3g: %s.\n",
        opt.budget_fraction,
        coarse_share,
        budgetAdvice(coarse_share).c_str());
    return false;
  }
  return true;
}

/** \a sum / \a count metres in millimetres, two decimals; "-" for an empty group and
 * for a distance that is not a number (a scan segmented as a single segment has no
 * predicted boundary to measure to). */
std::string
meanMm(double sum, std::size_t count)
{
  const double mean = sum / static_cast<double>(count);
  if (count == 0 || !std::isfinite(mean))
    return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", 1000.0 * mean);
  return text;
}

/** One row of a .dat file. */
std::string
datRow(const sim::ScanScore& s)
{
  std::ostringstream o;
  o << std::setprecision(6) << s.points << " " << s.seconds << " " << s.accuracy.mean
    << " " << s.accuracy.p90 << " " << s.spurious.mean << " "
    << s.hoover.correct_detections << " " << s.hoover.over_segmentations << " "
    << s.hoover.under_segmentations << " " << s.hoover.missed << " " << s.hoover.noise
    << " " << s.under_segmentation << " " << s.segments << " " << s.windows << " "
    << s.scanned_solid_angle;
  return o.str();
}

/** One row of table.md. */
std::string
tableRow(const std::string& scene,
         const std::string& strategy,
         const sim::ScanScore& s,
         std::size_t dense_points)
{
  char line[512];
  std::snprintf(line,
                sizeof(line),
                "| %s | %s | %zu | %.0f%% | %.3f | %s | %s | %s | %zu | %zu/%zu/%zu/"
                "%zu/%zu | %.2f%% |\n",
                scene.c_str(),
                strategy.c_str(),
                s.points,
                100.0 * static_cast<double>(s.points) /
                    static_cast<double>(dense_points),
                s.seconds,
                meanMm(s.accuracy.mean, 1).c_str(),
                meanMm(s.accuracy.p90, 1).c_str(),
                meanMm(s.spurious.mean, 1).c_str(),
                s.segments,
                s.hoover.correct_detections,
                s.hoover.over_segmentations,
                s.hoover.under_segmentations,
                s.hoover.missed,
                s.hoover.noise,
                100.0 * s.under_segmentation);
  return line;
}

/** The files a run writes for each scene: DIR/<scene><suffix>. runScene() names its
 * outputs through sceneFile() and the early check goes through the whole list, so an
 * output cannot be written without being checked first. */
enum SceneFile {
  kDensePcd,
  kCoarsePcd,
  kCoarseRoisJson,
  kRefinedPcd,
  kWindowsJson,
  kBoundaryErrorsDat,
  kMinVoxelTxt,
  kDat,
  kNumSceneFiles
};
constexpr const char* kSceneFileSuffix[kNumSceneFiles] = {"_dense.pcd",
                                                          "_coarse.pcd",
                                                          "_coarse_rois.json",
                                                          "_refined.pcd",
                                                          "_windows.json",
                                                          "_boundary_errors.dat",
                                                          "_min_voxel.txt",
                                                          ".dat"};

/** DIR/<scene><suffix of \a file>. */
std::string
sceneFile(const std::string& folder, const std::string& scene, SceneFile file)
{
  return folder + "/" + scene + kSceneFileSuffix[file];
}

/** Every file a run writes for \a scenes under \a folder. */
std::vector<std::string>
outputFiles(const std::string& folder, const std::vector<std::string>& scenes)
{
  std::vector<std::string> files;
  for (const auto& scene : scenes)
    for (int f = 0; f < kNumSceneFiles; ++f)
      files.push_back(sceneFile(folder, scene, static_cast<SceneFile>(f)));
  files.push_back(folder + "/table.md");
  return files;
}

/** Writes \a cloud to \a outputs' temporary file for \a path. */
bool
savePcd(selseg_apps::OutputTransaction& outputs,
        const std::string& path,
        const pcl::PointCloud<pcl::PointXYZL>& cloud)
{
  bool ok = false;
  try {
    ok = pcl::io::savePCDFileBinary(outputs.stage(path), cloud) == 0;
  } catch (const pcl::IOException&) {
  }
  if (!ok)
    print_error("Cannot write '%s'.\n", path.c_str());
  return ok;
}

/** With a -step_scale other than 1, a hint that it may be the cause of a failed scan.
 */
std::string
scaleHint(const Options& opt)
{
  if (opt.step_scale == 1.0)
    return "";
  char text[160];
  std::snprintf(
      text,
      sizeof text,
      " (-step_scale %g scales every step: a scan of too few points, or of too "
      "many, fails; try a value closer to 1)",
      opt.step_scale);
  return text;
}

/** Run one scene; appends its rows to \a table and stages its files in \a outputs. */
bool
runScene(const Options& opt,
         const std::string& name,
         std::string& table,
         selseg_apps::OutputTransaction& outputs)
{
  sim::PaperScene which;
  sim::parsePaperScene(name, which);
  sim::SimulationSetup setup = sim::makePaperScene(which);
  setup.sensor.range_noise = opt.range_noise;
  if (opt.seed >= 0.0)
    setup.sensor.seed = static_cast<std::uint32_t>(opt.seed);
  const double fine = fineStep(name) * opt.step_scale;
  const auto file = [&](SceneFile f) { return sceneFile(opt.out, name, f); };

  sim::ReferenceBoundary reference;
  if (!sim::makeReferenceBoundary(setup, 0.5 * fine, reference)) {
    print_error(
        "%s: the reference scan failed.%s\n", name.c_str(), scaleHint(opt).c_str());
    return false;
  }
  print_info("%s: reference scan %zu points, %zu ground-truth boundary points\n",
             name.c_str(),
             reference.scan_points,
             reference.points.size());

  const pcl::selective_seg::SelectiveSegmentationParameters& seg_params =
      opt.segmentation;
  std::vector<sim::ScanScore> uniform;
  const std::vector<double> factors = {3.0, 2.5, 2.0, 1.6, 1.3, 1.0};
  for (const double f : factors) {
    sim::ScanScore s;
    pcl::PointCloud<pcl::PointXYZL> cloud;
    if (!sim::runUniformScan(setup, f * fine, seg_params, reference, s, &cloud)) {
      print_error("%s: the uniform scan at %g rad failed.%s\n",
                  name.c_str(),
                  f * fine,
                  scaleHint(opt).c_str());
      return false;
    }
    uniform.push_back(s);
    if (f == 1.0 && !savePcd(outputs, file(kDensePcd), cloud))
      return false;
  }
  const std::size_t dense_points = uniform.back().points;

  sim::SelectiveLoopParameters loop;
  loop.fine_step = fine;
  loop.coarse_factor = opt.coarse_factor;
  loop.iterations = opt.iterations;
  loop.min_voxel_factor = opt.min_voxel_factor;
  loop.regions = opt.regions;
  loop.segmentation = opt.segmentation;
  loop.window_steps = opt.window_steps;
  loop.progressive = opt.progressive == 1.0;
  loop.point_budget =
      static_cast<std::size_t>(opt.budget_fraction * static_cast<double>(dense_points));
  // The budget includes the coarse scan, about 1 / coarse_factor^2 of the finest
  // uniform scan's points (parseOptions() refused smaller fractions; the point count's
  // rounding can still fall short of it).
  const double coarse_share = 1.0 / (opt.coarse_factor * opt.coarse_factor);
  if (static_cast<double>(loop.point_budget) <
      coarse_share * static_cast<double>(dense_points)) {
    print_error("%s: -budget_fraction %g of the finest uniform scan's %zu points is a "
                "budget of %zu points, less than the coarse scan's (about %.0f): %s.\n",
                name.c_str(),
                opt.budget_fraction,
                dense_points,
                loop.point_budget,
                coarse_share * static_cast<double>(dense_points),
                budgetAdvice(coarse_share).c_str());
    return false;
  }
  std::vector<RegionOfInterest> scanned;
  std::vector<sim::ScanScore> rounds;
  bool files_ok = true;
  double min_voxel = 0.0;
  // Where the windows go: the reference boundary points (sensor angles) inside a
  // scanned window, and the share of the windows' estimated points in windows that
  // hold one.
  std::vector<std::pair<double, double>> truth_angles;
  for (const auto& p : reference.points)
    truth_angles.emplace_back(std::atan2(p.x, p.z), std::atan2(p.y, p.z));
  std::vector<char> truth_covered(truth_angles.size(), 0);
  pcl::selective_seg::RegionOfInterestParameters last_parameters = loop.regions;
  const auto observer = [&](const sim::LoopRound& r) {
    min_voxel = r.result->min_voxel_size;
    const auto& regions = *r.regions;
    const auto& stats = r.region_stats;
    std::size_t on_edge = 0, estimated = 0;
    for (const auto& w : regions) {
      bool holds = false;
      for (std::size_t i = 0; i < truth_angles.size(); ++i) {
        const auto& a = truth_angles[i];
        if (a.first >= w.theta_min && a.first <= w.theta_max && a.second >= w.phi_min &&
            a.second <= w.phi_max) {
          truth_covered[i] = 1;
          holds = true;
        }
      }
      estimated += w.estimated_points;
      on_edge += holds ? w.estimated_points : 0;
    }
    if (estimated > 0)
      print_info("%s: round %d windows: %.0f%% of their estimated points in windows "
                 "on a true edge\n",
                 name.c_str(),
                 r.iteration,
                 100.0 * static_cast<double>(on_edge) / static_cast<double>(estimated));
    if (r.iteration == 0) {
      files_ok = files_ok && savePcd(outputs, file(kCoarsePcd), *r.cloud) &&
                 selseg_apps::writeRegionsJson(outputs.stage(file(kCoarseRoisJson)),
                                               name,
                                               r.region_parameters,
                                               stats,
                                               regions);
    }
    scanned.insert(scanned.end(), regions.begin(), regions.end());
    if (!regions.empty())
      last_parameters = r.region_parameters;
    if (regions.empty() || r.iteration == opt.iterations)
      files_ok = files_ok && savePcd(outputs, file(kRefinedPcd), *r.cloud);
    print_info("%s: round %d, %zu points, boundary accuracy %s mm; evidence "
               "%zu/%zu/%zu vertices (transition/small/sparse), %zu candidate windows, "
               "%zu already fine, %zu over budget, %zu chosen (%zu points estimated)\n",
               name.c_str(),
               r.iteration,
               r.score.points,
               meanMm(r.score.accuracy.mean, 1).c_str(),
               stats.transition_vertices,
               stats.small_segment_vertices,
               stats.sparse_vertices,
               stats.candidates,
               stats.already_fine,
               stats.over_budget,
               stats.selected,
               stats.selected_points);
  };
  if (!sim::runSelectiveLoop(setup, loop, reference, rounds, observer)) {
    print_error(
        "%s: the selective loop failed.%s\n", name.c_str(), scaleHint(opt).c_str());
    return false;
  }
  {
    double inside[2] = {0, 0}, outside[2] = {0, 0};
    std::size_t n_in = 0;
    for (std::size_t i = 0; i < truth_angles.size(); ++i) {
      const double d[2] = {uniform.back().reference_distances[i],
                           rounds.back().reference_distances[i]};
      for (int k = 0; k < 2; ++k)
        (truth_covered[i] ? inside : outside)[k] += d[k];
      n_in += truth_covered[i] != 0;
    }
    const std::size_t n_out = truth_angles.size() - n_in;
    print_info("%s: %zu of %zu true edge points (%.0f%%) inside a scanned window; mean "
               "distance there %s mm (finest uniform) / %s mm (selective), outside "
               "%s / %s mm\n",
               name.c_str(),
               n_in,
               truth_angles.size(),
               100.0 * static_cast<double>(n_in) /
                   static_cast<double>(std::max<std::size_t>(truth_angles.size(), 1)),
               meanMm(inside[0], n_in).c_str(),
               meanMm(inside[1], n_in).c_str(),
               meanMm(outside[0], n_out).c_str(),
               meanMm(outside[1], n_out).c_str());
  }
  {
    // The same by the kind of true edge (metrics::describeBoundaryPoints()): depth
    // jumps, and creases by the angle between the surfaces, against the merge angle
    // (25 deg by default) with a margin of 5 deg either side: the segmentation splits
    // creases well above it, a crease near it by the noise of the normals, and a
    // border below it (a smooth one has 0) only by noise or by the octree.
    const double merge_deg = opt.segmentation.max_merge_angle * 180.0 / M_PI;
    const double lo = merge_deg - 5.0, hi = merge_deg + 5.0;
    const char* names[5] = {"depth jumps",
                            "creases > merge + 5 deg",
                            "creases within 5 deg of merge",
                            "creases < merge - 5 deg",
                            "undetermined"};
    double sum[5][2] = {};
    std::size_t count[5] = {};
    for (std::size_t i = 0; i < reference.kinds.size(); ++i) {
      const auto& k = reference.kinds[i];
      const double deg = k.crease_angle * 180.0 / M_PI;
      const int c = k.depth_jump      ? 0
                    : std::isnan(deg) ? 4
                    : deg > hi        ? 1
                    : deg >= lo       ? 2
                                      : 3;
      sum[c][0] += uniform.back().reference_distances[i];
      sum[c][1] += rounds.back().reference_distances[i];
      ++count[c];
    }
    std::string line;
    for (int c = 0; c < 5; ++c) {
      char buffer[160];
      std::snprintf(buffer,
                    sizeof buffer,
                    "%s%s %zu, %s / %s mm",
                    c ? "; " : "",
                    names[c],
                    count[c],
                    meanMm(sum[c][0], count[c]).c_str(),
                    meanMm(sum[c][1], count[c]).c_str());
      line += buffer;
    }
    print_info("%s: true edge points by kind (merge angle %.0f deg), mean distance "
               "finest uniform / selective: %s\n",
               name.c_str(),
               merge_deg,
               line.c_str());
  }
  // Every round's windows: the budget recorded is the loop's (all rounds, the coarse
  // scan included) and the step its finest; the other parameters are the last
  // round's that chose windows.
  pcl::selective_seg::RegionOfInterestStats all;
  all.selected = scanned.size();
  pcl::selective_seg::RegionOfInterestParameters whole = last_parameters;
  whole.max_points = loop.point_budget;
  whole.target_step = loop.fine_step;
  files_ok =
      files_ok && selseg_apps::writeRegionsJson(
                      outputs.stage(file(kWindowsJson)), name, whole, all, scanned);
  // Where the error is: every reference boundary point with its distance to the
  // nearest predicted boundary, for the finest uniform scan and the last round.
  std::ofstream errors(outputs.stage(file(kBoundaryErrorsDat)));
  errors << "# theta phi (rad) distance_dense distance_selective (m) depth_jump "
            "crease_angle (deg, nan: undetermined) in_window (0/1)\n";
  for (std::size_t i = 0; i < reference.points.size(); ++i) {
    const auto& p = reference.points[i];
    errors << std::atan2(p.x, p.z) << " " << std::atan2(p.y, p.z) << " "
           << uniform.back().reference_distances[i] << " "
           << rounds.back().reference_distances[i] << " "
           << (reference.kinds[i].depth_jump ? 1 : 0) << " "
           << reference.kinds[i].crease_angle * 180.0 / M_PI << " "
           << (truth_covered[i] ? 1 : 0) << "\n";
  }
  errors.close();
  files_ok = files_ok && static_cast<bool>(errors);
  std::ofstream voxel(outputs.stage(file(kMinVoxelTxt)));
  voxel << std::setprecision(9) << min_voxel << "\n";
  std::ofstream dat(outputs.stage(file(kDat)));
  dat << "# " << name << ": fine step " << fine << " rad, coarse factor "
      << opt.coarse_factor << ", budget " << loop.point_budget << " points\n"
      << "# points seconds accuracy_mean_m accuracy_p90_m spurious_mean_m correct "
         "over under missed noise under_seg_error segments windows solid_angle_sr\n"
      << "# uniform\n";
  for (const auto& s : uniform)
    dat << datRow(s) << "\n";
  dat << "\n\n# selective\n";
  for (const auto& s : rounds)
    dat << datRow(s) << "\n";
  voxel.close();
  dat.close();
  if (!files_ok || !voxel || !dat) {
    print_error(
        "Cannot write the files of %s under '%s'.\n", name.c_str(), opt.out.c_str());
    return false;
  }
  for (std::size_t i = 0; i < uniform.size(); ++i) {
    char label[64];
    std::snprintf(
        label, sizeof(label), "uniform, step %.2f mrad", 1000.0 * factors[i] * fine);
    table += tableRow(name, label, uniform[i], dense_points);
  }
  for (std::size_t i = 0; i < rounds.size(); ++i)
    table += tableRow(name,
                      i == 0 ? "selective, coarse scan"
                             : "selective, round " + std::to_string(i),
                      rounds[i],
                      dense_points);
  return true;
}

int
run(int argc, char** argv)
{
  if (argc < 2) {
    printHelp(argv[0]);
    print_error("Give -out FOLDER.\n");
    return kUsageError;
  }
  if (selseg_apps::helpAsked(argc, argv)) {
    printHelp(argv[0]);
    return 0;
  }
  Options opt;
  // The loop's windows (sim::loopRegionParameters()); the flags change them.
  opt.regions = sim::loopRegionParameters();
  if (!parseOptions(argc, argv, opt))
    return kUsageError;
  // The output folder, made if missing, before any scan is simulated. The folders this
  // run makes are removed again (when empty) unless it succeeds.
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> made; // innermost first
  for (fs::path p = opt.out; !p.empty() && !fs::exists(fs::symlink_status(p, ec));
       p = p.parent_path()) {
    made.push_back(p);
    if (p == p.parent_path())
      break;
  }
  bool succeeded = false;
  struct RemoveMade {
    const std::vector<fs::path>& folders;
    const bool& keep;
    ~RemoveMade()
    {
      std::error_code ignored;
      if (!keep)
        for (const auto& f : folders)
          fs::remove(f, ignored); // only an empty folder
    }
  } remove_made{made, succeeded};
  fs::create_directories(opt.out, ec);
  if (ec || !fs::is_directory(opt.out)) {
    print_error("Cannot make the output folder '%s'%s%s: give -out a writable folder.\n",
                opt.out.c_str(),
                ec ? ": " : "",
                ec ? ec.message().c_str() : "");
    return kRuntimeError;
  }
  std::string table =
      "| scene | strategy | points | of dense | time (s) | boundary accuracy, mean "
      "(mm) "
      "| p90 (mm) | spurious, mean (mm) | segments | correct/over/under/missed/noise "
      "| under-seg. error |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  // Every output can be written, before the scans (a folder or a FIFO in its place,
  // a folder that takes no file).
  for (const auto& file : outputFiles(opt.out, opt.scenes)) {
    std::string error;
    if (!selseg_apps::outputWritable(file, error)) {
      print_error("%s\n", error.c_str());
      return kRuntimeError;
    }
  }
  // Declared after remove_made: its temporaries go before the folders.
  selseg_apps::OutputTransaction outputs;
  for (const auto& scene : opt.scenes)
    if (!runScene(opt, scene, table, outputs))
      return kRuntimeError;
  std::ofstream out(outputs.stage(opt.out + "/table.md"));
  out << table;
  out.close();
  if (!out) {
    print_error("Cannot write '%s/table.md'.\n", opt.out.c_str());
    return kRuntimeError;
  }
  std::string error;
  if (!outputs.commit(error)) {
    print_error("%s\n", error.c_str());
    return kRuntimeError;
  }
  succeeded = true;
  print_info("%s", table.c_str());
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  // Out of memory (a small -step_scale on a small machine): a message, and the
  // temporaries and the folders the run made are removed on the way out of run().
  return selseg_apps::runReportingOutOfMemory(
      [&] { return run(argc, argv); },
      "use a larger -step_scale or fewer -scenes.",
      kRuntimeError);
}
