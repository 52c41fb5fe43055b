/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace selseg_apps {

/** \brief The file name's extension from its last dot, lower case (".pcd"), or "" when
 * it has none. */
std::string lowerExtension(const std::string& path);

/** \brief Called by loadScan() with the number of points a PCD or PLY file declares
 * (PCD: the larger of POINTS and WIDTH x HEIGHT; PLY: its vertex count), once its
 * header has been checked and before its points are read. */
using DeclaredPointsHook = std::function<void(std::size_t)>;

/** \brief Read a scan: PCD or PLY (any point type with x, y and z fields) or plain text
 * with "x y z" per line (further columns ignored, '#' comments and blank lines
 * skipped).
 *
 * The PCD's VIEWPOINT becomes the cloud's sensor_origin_ / sensor_orientation_; the
 * organized layout (width x height) is kept.
 * \param[in] path the file; its extension (.pcd, .ply, anything else = text) decides
 * \param[in] unit_scale factor applied to every coordinate and to the VIEWPOINT's
 * position (0.01 for centimetres)
 * \param[out] cloud the points, in input order
 * \param[out] error what is wrong with the file and what to do, when false
 * \param[in] before_reading if set, called with the points a PCD or PLY header declares
 * before they are read (not for text files)
 * \return false when the file cannot be read or has no x, y, z */
bool loadScan(const std::string& path,
              double unit_scale,
              pcl::PointCloud<pcl::PointXYZ>& cloud,
              std::string& error,
              const DeclaredPointsHook& before_reading = {});

/** \brief Whether a -unit_scale value is usable: in [1e-12, 1e12] (far beyond any unit
 * change; outside, coordinates overflow or underflow float), else false with a
 * message for the user. */
bool unitScaleUsable(double unit_scale);

/** \brief Read a ground-truth scan: a PCD with x, y, z and a "label" field (one
 * integer, not negative), checked as loadScan() checks a PCD.
 * \param[out] cloud the points, in file order, with the file's layout and VIEWPOINT
 * \param[out] labels the label of each point
 * \param[out] error what is wrong with the file, when false */
bool loadLabeledScan(const std::string& path,
                     pcl::PointCloud<pcl::PointXYZ>& cloud,
                     std::vector<std::uint32_t>& labels,
                     std::string& error);

} // namespace selseg_apps
