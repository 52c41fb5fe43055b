/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/parameters.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace selseg_apps {

/** \brief A checked number: absent is fine; present and not a finite number (an empty
 * value included) prints an error and returns false (pcl::console::parse_argument
 * alone would store 0). */
template <typename T>
bool
parseNumber(int argc, char** argv, const char* flag, T& value)
{
  const int at = pcl::console::find_argument(argc, argv, flag);
  if (at < 0)
    return true;
  if (at + 1 >= argc || argv[at + 1][0] == '\0' ||
      pcl::console::parse_argument(argc, argv, flag, value) < 0 ||
      !std::isfinite(static_cast<double>(value))) {
    pcl::console::print_error("Option %s needs a number (see -h).\n", flag);
    return false;
  }
  return true;
}

/** \brief Whether -h or --help stands as an option, for a tool whose every option
 * takes one value: at an odd position, not as another option's value (-o -h). */
bool helpAsked(int argc, char** argv);

/** \brief False, after printing an error, when an option is given more than once:
 * pcl::console's parsers use its first value and ignore the others. Arguments that
 * start with '-' and a letter are options; \a takes_value(option) tells whether the
 * next argument is its value (then it is not an option, whatever it looks like). */
bool optionsGivenOnce(int argc,
                      char** argv,
                      const std::function<bool(const std::string&)>& takes_value);

/** \brief The library's message \a why about an invalid parameter, led by the option
 * it came from when that option is given in degrees (the library checks radians: its
 * message alone does not say which option to fix, nor in what unit). \a flags pairs
 * each degree option with the name of its parameter; \a why is returned as it is when
 * it names none of them. */
std::string
explainDegrees(const std::string& why,
               const std::vector<std::pair<const char*, const char*>>& flags,
               int argc,
               char** argv);

/** \brief The flags of the segmentation parameters shared by the tools (each takes a
 * value). */
const std::vector<std::string>& segmentationFlags();

/** \brief Print the help lines of those flags, with units and defaults. */
void printSegmentationHelp();

/** \brief The command-line name of an enum option's value (as -segment_weight,
 * -merge_with, -spread_frame, -normal_triangles, -edge_normal and -projection take it).
 */
std::string choiceName(pcl::selective_seg::SegmentNormalWeight value);
std::string choiceName(pcl::selective_seg::MergeWith value);
std::string choiceName(pcl::selective_seg::NormalSpreadFrame value);
std::string choiceName(pcl::selective_seg::PointNormalTriangles value);
std::string choiceName(pcl::selective_seg::EdgeTriangleNormal value);
std::string choiceName(pcl::selective_seg::ViewProjection value);

/** \brief Read those flags into \a params (degrees on the command line, radians in the
 * struct) and validate the result.
 * \return false, after printing what is wrong, on a bad value */
bool parseSegmentationOptions(
    int argc, char** argv, pcl::selective_seg::SelectiveSegmentationParameters& params);

} // namespace selseg_apps
