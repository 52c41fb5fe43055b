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
// whole run succeeded: a failed run leaves OUT as it was (a folder it made, removed).
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
#include "roi_json.h"
#include "roi_options.h"
#include "segmentation_options.h"

using namespace pcl::console;
namespace sim = pcl::selective_seg::simulation;
using pcl::selective_seg::RegionOfInterest;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;

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
      "  -iterations N          refinement rounds (default %d)\n"
      "  -coarse_factor X       coarse step = X times the fine step, in [1, 100] "
      "(default %g)\n"
      "  -budget_fraction F     selective point budget, fraction of the finest uniform "
      "scan's points (default %g)\n"
      "  -range_noise K         range noise sigma = K r^2 [1/m] (default %g, "
      "level A)\n"
      "  -min_voxel_factor X    finest voxel = X fine steps at the median range; 0 = "
      "automatic from the coarse scan (default %g)\n"
      "  -progressive 0|1       1: each round a step finer, the last at the fine "
      "step; 0: every round at the fine step (default %g)\n"
      "  -window_steps X        evidence tiles of X coarse steps, in [0.01, 1000]; 0 = "
      "-roi_max_window_deg (default %g)\n"
      "  -step_scale S          multiply every step by S (S > 1: a quicker, coarser "
      "run; default %g)\n"
      "  -seed N                the sensor's random seed (rays, dropouts, noise) for "
      "every scan; default: the scene's own\n\n"
      "The loop sets the regions' step (the fine step), point budget and yield; the "
      "other\nregion options apply (the budget flags -roi_max_points, -roi_max_sr and "
      "-roi_max_regions\nare refused: -budget_fraction sets the budget). The loop's "
      "own "
      "defaults differ from those\nlisted below: -roi_margin_spacings 0.5 "
      "-roi_valid_edges 1 -roi_edge_on 1 -roi_side_deg 25 -roi_side_confidence 0.95\n"
      "-roi_sparse_by_area 1:\n",
      program,
      defaults.iterations,
      defaults.coarse_factor,
      defaults.budget_fraction,
      defaults.range_noise,
      defaults.min_voxel_factor,
      defaults.progressive,
      defaults.window_steps,
      defaults.step_scale);
  selseg_apps::printRegionHelp();
  print_info("Segmentation (both strategies):\n");
  selseg_apps::printSegmentationHelp();
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
  for (const char* flag : {"-roi_max_points", "-roi_max_sr", "-roi_max_regions"})
    if (find_argument(argc, argv, flag) >= 0) {
      print_error(
          "%s does not apply here: the loop's budget is -budget_fraction of the "
          "finest uniform scan's points.\n",
          flag);
      return false;
    }
  using selseg_apps::parseNumber;
  if (!parseNumber(argc, argv, "-iterations", opt.iterations) ||
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
  if (opt.iterations < 0 || opt.iterations > 100 ||
      !(opt.coarse_factor >= 1.0 && opt.coarse_factor <= 100.0) ||
      !(opt.budget_fraction > 0.0 && opt.budget_fraction <= 1.0) ||
      !(opt.range_noise >= 0.0 && opt.range_noise <= 1.0) ||
      !(opt.min_voxel_factor >= 0.0) || !(opt.step_scale > 0.0) ||
      !(opt.window_steps == 0.0 ||
        (opt.window_steps >= 0.01 && opt.window_steps <= 1000.0)) ||
      (opt.progressive != 0.0 && opt.progressive != 1.0) ||
      !(opt.seed < 0.0 ||
        (opt.seed <= 4294967295.0 && opt.seed == std::floor(opt.seed)))) {
    print_error(
        "Need 0 <= iterations <= 100, 1 <= coarse_factor <= 100, 0 < "
        "budget_fraction <= 1, 0 <= range_noise <= 1, min_voxel_factor >= 0, "
        "step_scale > 0, window_steps 0 or in [0.01, 1000], progressive 0 or 1, "
        "seed a whole number < 2^32.\n");
    return false;
  }
  return true;
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
  std::snprintf(
      line,
      sizeof(line),
      "| %s | %s | %zu | %.0f%% | %.3f | %.2f | %.2f | %.2f | %zu | %zu/%zu/%zu/"
      "%zu/%zu | %.2f%% |\n",
      scene.c_str(),
      strategy.c_str(),
      s.points,
      100.0 * static_cast<double>(s.points) / static_cast<double>(dense_points),
      s.seconds,
      1000.0 * s.accuracy.mean,
      1000.0 * s.accuracy.p90,
      1000.0 * s.spurious.mean,
      s.segments,
      s.hoover.correct_detections,
      s.hoover.over_segmentations,
      s.hoover.under_segmentations,
      s.hoover.missed,
      s.hoover.noise,
      100.0 * s.under_segmentation);
  return line;
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

/** \a fraction rounded up to three significant digits. */
double
roundUp3(double fraction)
{
  const double unit = std::pow(10.0, std::floor(std::log10(fraction)) - 2.0);
  return std::ceil(fraction / unit - 1e-9) * unit;
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
  const std::string base = opt.out + "/" + name;

  sim::ReferenceBoundary reference;
  if (!sim::makeReferenceBoundary(setup, 0.5 * fine, reference)) {
    print_error("%s: the reference scan failed.\n", name.c_str());
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
      print_error("%s: the uniform scan at %g rad failed.\n", name.c_str(), f * fine);
      return false;
    }
    uniform.push_back(s);
    if (f == 1.0 && !savePcd(outputs, base + "_dense.pcd", cloud))
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
  // uniform scan's points (whether a fraction is too small depends on the scene).
  const double coarse_share = 1.0 / (opt.coarse_factor * opt.coarse_factor);
  if (static_cast<double>(loop.point_budget) <
      coarse_share * static_cast<double>(dense_points)) {
    print_error("%s: -budget_fraction %g of the finest uniform scan's %zu points is a "
                "budget of %zu points, less than the coarse scan's (about %.0f): give "
                "-budget_fraction %.3g or more.\n",
                name.c_str(),
                opt.budget_fraction,
                dense_points,
                loop.point_budget,
                coarse_share * static_cast<double>(dense_points),
                roundUp3(1.25 * coarse_share));
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
      files_ok =
          files_ok && savePcd(outputs, base + "_coarse.pcd", *r.cloud) &&
          selseg_apps::writeRegionsJson(outputs.stage(base + "_coarse_rois.json"),
                                        name,
                                        loop.regions,
                                        stats,
                                        regions);
    }
    scanned.insert(scanned.end(), regions.begin(), regions.end());
    if (regions.empty() || r.iteration == opt.iterations)
      files_ok = files_ok && savePcd(outputs, base + "_refined.pcd", *r.cloud);
    print_info("%s: round %d, %zu points, boundary accuracy %.2f mm; evidence "
               "%zu/%zu/%zu vertices (transition/small/sparse), %zu candidate windows, "
               "%zu already fine, %zu over budget, %zu chosen (%zu points estimated)\n",
               name.c_str(),
               r.iteration,
               r.score.points,
               1000.0 * r.score.accuracy.mean,
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
    print_error("%s: the selective loop failed.\n", name.c_str());
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
    print_info(
        "%s: %zu of %zu true edge points (%.0f%%) inside a scanned window; mean "
        "distance there %.2f mm (finest uniform) / %.2f mm (selective), outside "
        "%.2f / %.2f mm\n",
        name.c_str(),
        n_in,
        truth_angles.size(),
        100.0 * static_cast<double>(n_in) /
            static_cast<double>(std::max<std::size_t>(truth_angles.size(), 1)),
        1000.0 * inside[0] / static_cast<double>(std::max<std::size_t>(n_in, 1)),
        1000.0 * inside[1] / static_cast<double>(std::max<std::size_t>(n_in, 1)),
        1000.0 * outside[0] / static_cast<double>(std::max<std::size_t>(n_out, 1)),
        1000.0 * outside[1] / static_cast<double>(std::max<std::size_t>(n_out, 1)));
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
      const double n = static_cast<double>(std::max<std::size_t>(count[c], 1));
      std::snprintf(buffer,
                    sizeof buffer,
                    "%s%s %zu, %.2f / %.2f mm",
                    c ? "; " : "",
                    names[c],
                    count[c],
                    1000.0 * sum[c][0] / n,
                    1000.0 * sum[c][1] / n);
      line += buffer;
    }
    print_info("%s: true edge points by kind (merge angle %.0f deg), mean distance "
               "finest uniform / selective: %s\n",
               name.c_str(),
               merge_deg,
               line.c_str());
  }
  pcl::selective_seg::RegionOfInterestStats all;
  all.selected = scanned.size();
  files_ok =
      files_ok &&
      selseg_apps::writeRegionsJson(
          outputs.stage(base + "_windows.json"), name, loop.regions, all, scanned);
  // Where the error is: every reference boundary point with its distance to the
  // nearest predicted boundary, for the finest uniform scan and the last round.
  std::ofstream errors(outputs.stage(base + "_boundary_errors.dat"));
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
  std::ofstream voxel(outputs.stage(base + "_min_voxel.txt"));
  voxel << std::setprecision(9) << min_voxel << "\n";
  std::ofstream dat(outputs.stage(base + ".dat"));
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

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 2 || find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help")) {
    printHelp(argv[0]);
    return argc < 2 ? kUsageError : 0;
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
