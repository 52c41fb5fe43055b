/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "roi_options.h"

#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <tuple>
#include <vector>

#include "segmentation_options.h"

namespace selseg_apps {

namespace {
constexpr double kDeg = M_PI / 180.0;
} // namespace

const std::vector<std::string>&
regionFlags()
{
  static const std::vector<std::string> flags = {
      "-roi_max_sr",         "-roi_max_points",      "-roi_max_regions",
      "-roi_yield",          "-roi_step_deg",        "-roi_refine",
      "-roi_min_refinement", "-roi_max_window_deg",  "-roi_min_window_deg",
      "-roi_margin_deg",     "-roi_margin_spacings", "-roi_small_points",
      "-roi_min_component",  "-roi_valid_edges",     "-roi_sparse_factor",
      "-roi_leaf_sigma_deg", "-roi_side_deg",        "-roi_edge_on_deg",
      "-roi_edge_on",        "-roi_sparse_by_area",  "-roi_weights",
      "-roi_side_points",    "-roi_side_confidence", "-roi_disjoint"};
  return flags;
}

const std::vector<std::string>&
loopSetRegionFlags()
{
  static const std::vector<std::string> flags = {"-roi_max_sr",
                                                 "-roi_max_points",
                                                 "-roi_max_regions",
                                                 "-roi_yield",
                                                 "-roi_step_deg",
                                                 "-roi_refine"};
  return flags;
}

void
printRegionHelp(bool for_loop)
{
  const pcl::selective_seg::RegionOfInterestParameters d;
  if (for_loop)
    pcl::console::print_info("Regions of interest:\n");
  else
    pcl::console::print_info(
        "Regions of interest (with -roi_json; budgets of 0 = no limit):\n"
        "  -roi_max_sr X            total solid angle of the chosen windows [sr] "
        "(default %g)\n"
        "  -roi_max_points N        total estimated points of the chosen windows "
        "(default %zu)\n"
        "  -roi_max_regions N       number of windows (default %zu)\n"
        "  -roi_yield F             fraction of the rays that return a point, for the "
        "estimate (default %g)\n"
        "  -roi_step_deg X          angular step of the finer scan; 0 = current "
        "spacing / -roi_refine (default %g)\n"
        "  -roi_refine X            refinement of the step when -roi_step_deg is 0 "
        "(default %g)\n",
        d.max_solid_angle,
        d.max_points,
        d.max_regions,
        d.sample_yield,
        d.target_step / kDeg,
        d.refinement_factor);
  pcl::console::print_info(
      "  -roi_min_refinement X    windows (and, with -roi_step_deg, evidence) "
      "sampled within X times the\n"
      "                           suggested step already are left out (default %g)\n"
      "  -roi_max_window_deg X    largest window side (default %g)\n"
      "  -roi_min_window_deg X    smallest window side (default %g)\n"
      "  -roi_margin_deg X        margin around the evidence (default %g)\n"
      "  -roi_margin_spacings X   margin in units of the local spacing (default %g)\n"
      "  -roi_disjoint 0|1        windows that overlap one chosen before them are cut "
      "around it: no ray is\n"
      "                           scanned twice (default %d)\n"
      "  -roi_small_points N      segments with fewer points are evidence; 0 = off "
      "(default %zu)\n"
      "  -roi_valid_edges 0|1     valid edge triangles (segment borders) are "
      "transition evidence too (default %d)\n"
      "  -roi_min_component N     evidence in mesh-connected groups of fewer vertices "
      "is ignored (default %zu)\n"
      "  -roi_sparse_factor X     spacing above X times the median is evidence; 0 = "
      "off (default %g)\n"
      "  -roi_sparse_by_area 0|1  the typical spacing is the median over the view's "
      "area, not over the vertices\n"
      "                           (default %d)\n"
      "  -roi_leaf_sigma_deg X    finest leaves with a larger normal spread are "
      "evidence; 0 = off (default %g)\n"
      "  -roi_side_deg X          edge triangles are evidence only when seen "
      "edge-on or between segments\n"
      "                           whose normals differ by more than X; 0 = off "
      "(default %g)\n"
      "  -roi_side_points N       ... and only between segments of at least N "
      "points; 0 = off (default %zu)\n"
      "  -roi_side_confidence C   ... and only when the normals differ by more than "
      "X plus their cones of\n"
      "                           confidence at level C (0 < C < 1); 0 = off "
      "(default %g)\n"
      "  -roi_edge_on 0|1         triangles seen edge-on (depth jumps) are "
      "transition evidence (default %d)\n"
      "  -roi_edge_on_deg X       edge-on: more than X between the triangle normal "
      "and the line of sight (default %g)\n"
      "  -roi_weights I,L,V,S,P   priority weights of transition evidence from "
      "invalid edges, leaves, valid\n"
      "                           edges, and of small-segment and sparse evidence "
      "(default %g,%g,%g,%g,%g)\n\n",
      d.min_refinement,
      d.max_window_size / kDeg,
      d.min_window_size / kDeg,
      d.margin / kDeg,
      d.margin_spacings,
      d.disjoint_windows ? 1 : 0,
      d.small_segment_points,
      d.use_valid_edges ? 1 : 0,
      d.min_component_vertices,
      d.sparse_factor,
      d.sparse_by_area ? 1 : 0,
      d.leaf_sigma_threshold / kDeg,
      d.min_side_angle / kDeg,
      d.min_side_points,
      d.side_confidence,
      d.use_edge_on ? 1 : 0,
      d.edge_on_angle / kDeg,
      d.transition_weight,
      d.leaf_weight,
      d.valid_edge_weight,
      d.small_segment_weight,
      d.sparse_weight);
}

bool
parseRegionOptions(int argc,
                   char** argv,
                   pcl::selective_seg::RegionOfInterestParameters& p)
{
  double step = p.target_step / kDeg, max_window = p.max_window_size / kDeg,
         min_window = p.min_window_size / kDeg, margin = p.margin / kDeg,
         sigma = p.leaf_sigma_threshold / kDeg, side = p.min_side_angle / kDeg,
         edge_on = p.edge_on_angle / kDeg;
  double max_points = static_cast<double>(p.max_points),
         max_regions = static_cast<double>(p.max_regions),
         small = static_cast<double>(p.small_segment_points),
         side_points = static_cast<double>(p.min_side_points),
         component = static_cast<double>(p.min_component_vertices),
         valid_edges = p.use_valid_edges ? 1.0 : 0.0,
         edge_on_triangles = p.use_edge_on ? 1.0 : 0.0,
         by_area = p.sparse_by_area ? 1.0 : 0.0,
         disjoint = p.disjoint_windows ? 1.0 : 0.0;
  if (!parseNumber(argc, argv, "-roi_max_sr", p.max_solid_angle) ||
      !parseNumber(argc, argv, "-roi_max_points", max_points) ||
      !parseNumber(argc, argv, "-roi_max_regions", max_regions) ||
      !parseNumber(argc, argv, "-roi_yield", p.sample_yield) ||
      !parseNumber(argc, argv, "-roi_step_deg", step) ||
      !parseNumber(argc, argv, "-roi_refine", p.refinement_factor) ||
      !parseNumber(argc, argv, "-roi_min_refinement", p.min_refinement) ||
      !parseNumber(argc, argv, "-roi_max_window_deg", max_window) ||
      !parseNumber(argc, argv, "-roi_min_window_deg", min_window) ||
      !parseNumber(argc, argv, "-roi_margin_deg", margin) ||
      !parseNumber(argc, argv, "-roi_margin_spacings", p.margin_spacings) ||
      !parseNumber(argc, argv, "-roi_small_points", small) ||
      !parseNumber(argc, argv, "-roi_min_component", component) ||
      !parseNumber(argc, argv, "-roi_valid_edges", valid_edges) ||
      !parseNumber(argc, argv, "-roi_sparse_factor", p.sparse_factor) ||
      !parseNumber(argc, argv, "-roi_leaf_sigma_deg", sigma) ||
      !parseNumber(argc, argv, "-roi_side_deg", side) ||
      !parseNumber(argc, argv, "-roi_side_points", side_points) ||
      !parseNumber(argc, argv, "-roi_side_confidence", p.side_confidence) ||
      !parseNumber(argc, argv, "-roi_edge_on_deg", edge_on) ||
      !parseNumber(argc, argv, "-roi_edge_on", edge_on_triangles) ||
      !parseNumber(argc, argv, "-roi_sparse_by_area", by_area) ||
      !parseNumber(argc, argv, "-roi_disjoint", disjoint))
    return false;
  for (const auto& [flag, value] : {std::make_pair("-roi_max_points", max_points),
                                    std::make_pair("-roi_max_regions", max_regions),
                                    std::make_pair("-roi_small_points", small),
                                    std::make_pair("-roi_side_points", side_points),
                                    std::make_pair("-roi_min_component", component)})
    if (!(value >= 0.0 && value <= 1e15 && value == std::floor(value))) {
      pcl::console::print_error("Option %s needs a whole number >= 0.\n", flag);
      return false;
    }
  std::vector<double> w;
  if (!parseNumberList(argc, argv, "-roi_weights", 5, w))
    return false;
  if (!w.empty()) {
    p.transition_weight = w[0];
    p.leaf_weight = w[1];
    p.valid_edge_weight = w[2];
    p.small_segment_weight = w[3];
    p.sparse_weight = w[4];
  }
  p.max_points = static_cast<std::size_t>(max_points);
  p.max_regions = static_cast<std::size_t>(max_regions);
  p.small_segment_points = static_cast<std::size_t>(small);
  p.min_side_points = static_cast<std::size_t>(side_points);
  p.min_component_vertices = static_cast<std::size_t>(component);
  for (const auto& [flag, value, target] :
       {std::make_tuple("-roi_valid_edges", valid_edges, &p.use_valid_edges),
        std::make_tuple("-roi_edge_on", edge_on_triangles, &p.use_edge_on),
        std::make_tuple("-roi_sparse_by_area", by_area, &p.sparse_by_area),
        std::make_tuple("-roi_disjoint", disjoint, &p.disjoint_windows)}) {
    if (value != 0.0 && value != 1.0) {
      pcl::console::print_error("Option %s needs 0 or 1.\n", flag);
      return false;
    }
    *target = value == 1.0;
  }
  p.target_step = step * kDeg;
  p.max_window_size = max_window * kDeg;
  p.min_window_size = min_window * kDeg;
  p.margin = margin * kDeg;
  if (sigma < 0.0) { // the library reads any value <= 0 as off: one way to say it
    pcl::console::print_error(
        "Option -roi_leaf_sigma_deg needs 0 (off) or a positive angle.\n");
    return false;
  }
  p.leaf_sigma_threshold = sigma * kDeg;
  p.min_side_angle = side * kDeg;
  p.edge_on_angle = edge_on * kDeg;
  std::string why;
  if (!p.validate(&why)) {
    pcl::console::print_error(
        "%s.\n",
        explainDegrees("Region of interest " + why,
                       {{"-roi_step_deg", "target_step"},
                        {"-roi_max_window_deg", "max_window_size"},
                        {"-roi_min_window_deg", "min_window_size"},
                        {"-roi_margin_deg", "margin"},
                        {"-roi_leaf_sigma_deg", "leaf_sigma_threshold"},
                        {"-roi_side_deg", "min_side_angle"},
                        {"-roi_edge_on_deg", "edge_on_angle"}},
                       argc,
                       argv)
            .c_str());
    return false;
  }
  return true;
}

} // namespace selseg_apps
