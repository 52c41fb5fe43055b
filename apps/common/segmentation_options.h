/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/parameters.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace selseg_apps {

/** \brief The value of option \a flag read as a number, whole when \a whole, in
 * [\a lowest, \a highest]; false after printing what is wrong (no value, not a
 * number, out of range, not whole). The whole text must be the number
 * (pcl::console::parse_argument would read "a" as 0 and "5x" as 5). */
bool readOptionNumber(const char* flag,
                      const char* text,
                      bool whole,
                      double lowest,
                      double highest,
                      double& value);

/** \brief A checked number: absent is fine; present and not a finite number of \a T's
 * range (an empty value included) prints an error and returns false. */
template <typename T>
bool
parseNumber(int argc, char** argv, const char* flag, T& value)
{
  const int at = pcl::console::find_argument(argc, argv, flag);
  if (at < 0)
    return true;
  const bool whole = std::numeric_limits<T>::is_integer;
  // Whole numbers within 1e15, exact in a double.
  const double highest = whole ? std::min(1e15, double(std::numeric_limits<T>::max()))
                               : double(std::numeric_limits<T>::max());
  double v = 0.0;
  if (!readOptionNumber(flag,
                        at + 1 < argc ? argv[at + 1] : nullptr,
                        whole,
                        whole
                            ? -std::min(1e15, -double(std::numeric_limits<T>::lowest()))
                            : double(std::numeric_limits<T>::lowest()),
                        highest,
                        v))
    return false;
  value = static_cast<T>(v);
  return true;
}

/** \brief Option \a flag's \a n comma-separated finite numbers: absent is fine (\a
 * values untouched); otherwise false after printing an error unless there are
 * exactly \a n, each read whole. */
bool parseNumberList(int argc,
                     char** argv,
                     const char* flag,
                     std::size_t n,
                     std::vector<double>& values);

/** \brief Option \a flag's file name: absent is fine (\a name untouched); an empty
 * value, none, or an option in its place (-o -json) prints an error and returns false.
 * A file whose name starts with '-' is given as ./-name. */
bool parseFileName(int argc, char** argv, const char* flag, std::string& name);

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
