/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "scan_io.h"

#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

namespace selseg_apps {
namespace {

std::string
lowerExtension(const std::string& path)
{
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos)
    return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
    return static_cast<char>(std::tolower(c));
  });
  return ext;
}

bool
hasXYZ(const pcl::PCLPointCloud2& blob)
{
  return pcl::getFieldIndex(blob, "x") >= 0 && pcl::getFieldIndex(blob, "y") >= 0 &&
         pcl::getFieldIndex(blob, "z") >= 0;
}

/** PCL 1.13's PCDReader::read crashes on some malformed headers (no fields): check the
 * header first. */
bool
pcdHeaderUsable(const std::string& path, std::string& error)
{
  pcl::PCLPointCloud2 header;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_index = 0;
  if (pcl::PCDReader().readHeader(
          path, header, origin, orientation, version, data_type, data_index) < 0 ||
      header.fields.empty()) {
    error = "cannot read '" + path + "' as PCD: its header is missing or malformed";
    return false;
  }
  if (!hasXYZ(header)) {
    error = "'" + path + "' has no x, y and z fields: give a cloud of 3-D points";
    return false;
  }
  return true;
}

bool
loadBinaryFormat(const std::string& path,
                 const std::string& ext,
                 pcl::PointCloud<pcl::PointXYZ>& cloud,
                 std::string& error)
{
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  int version = 0;
  if (ext == ".pcd" && !pcdHeaderUsable(path, error))
    return false;
  const int rc = ext == ".pcd"
                     ? pcl::PCDReader().read(path, blob, origin, orientation, version)
                     : pcl::PLYReader().read(path, blob, origin, orientation, version);
  if (rc < 0) {
    error = "cannot read '" + path + "' as " + (ext == ".pcd" ? "PCD" : "PLY") +
            ": check that the file exists, is readable and is not truncated";
    return false;
  }
  if (!hasXYZ(blob)) {
    error = "'" + path + "' has no x, y and z fields: give a cloud of 3-D points";
    return false;
  }
  pcl::fromPCLPointCloud2(blob, cloud);
  cloud.sensor_origin_ = origin;
  cloud.sensor_orientation_ = orientation;
  return true;
}

bool
loadText(const std::string& path,
         pcl::PointCloud<pcl::PointXYZ>& cloud,
         std::string& error)
{
  std::ifstream in(path);
  if (!in) {
    error = "cannot open '" + path + "': check the path and the permissions";
    return false;
  }
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#')
      continue;
    std::istringstream fields(line);
    float x, y, z;
    if (!(fields >> x >> y >> z)) {
      error = "'" + path + "' line " + std::to_string(line_number) +
              ": expected three numbers 'x y z'";
      return false;
    }
    cloud.push_back(pcl::PointXYZ(x, y, z));
  }
  if (cloud.empty()) {
    error = "'" + path + "' holds no 'x y z' line";
    return false;
  }
  return true;
}

} // namespace

bool
loadScan(const std::string& path,
         double unit_scale,
         pcl::PointCloud<pcl::PointXYZ>& cloud,
         std::string& error)
{
  cloud.clear();
  const std::string ext = lowerExtension(path);
  const bool ok = (ext == ".pcd" || ext == ".ply")
                      ? loadBinaryFormat(path, ext, cloud, error)
                      : loadText(path, cloud, error);
  if (!ok)
    return false;
  if (unit_scale != 1.0)
    for (auto& p : cloud)
      p.getVector3fMap() *= static_cast<float>(unit_scale);
  return true;
}

} // namespace selseg_apps
