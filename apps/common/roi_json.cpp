/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "roi_json.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "outputs.h"

namespace selseg_apps {

using pcl::selective_seg::RegionOfInterest;

namespace {

void
putVector(std::ostream& out, const Eigen::Vector3f& v)
{
  out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
}

/** Where the value of "key" starts in [begin, end) of text, or npos: an occurrence
 * that is a key of an object (after '{' or ',', before ':', with any spacing), not
 * the same letters inside a string value. */
std::size_t
findKey(const std::string& text,
        std::size_t begin,
        std::size_t end,
        const std::string& key)
{
  const std::string quoted = "\"" + key + "\"";
  const char* space = " \t\r\n";
  for (std::size_t at = text.find(quoted, begin); at != std::string::npos && at < end;
       at = text.find(quoted, at + 1)) {
    const std::size_t before =
        at == 0 ? std::string::npos : text.find_last_not_of(space, at - 1);
    if (before == std::string::npos || (text[before] != '{' && text[before] != ','))
      continue;
    const std::size_t colon = text.find_first_not_of(space, at + quoted.size());
    if (colon == std::string::npos || text[colon] != ':')
      continue;
    const std::size_t value = text.find_first_not_of(space, colon + 1);
    return value < end ? value : std::string::npos;
  }
  return std::string::npos;
}

/** The number after "key": inside [begin, end) of text, or false. */
bool
findNumber(const std::string& text,
           std::size_t begin,
           std::size_t end,
           const std::string& key,
           double& value)
{
  const std::size_t at = findKey(text, begin, end, key);
  if (at == std::string::npos)
    return false;
  const char* start = text.c_str() + at;
  char* stop = nullptr;
  value = std::strtod(start, &stop);
  return stop != start && std::isfinite(value);
}

/** The n numbers of the list after "key": inside [begin, end) of text, or false. */
template <int N>
bool
findVector(const std::string& text,
           std::size_t begin,
           std::size_t end,
           const std::string& key,
           Eigen::Matrix<float, N, 1>& v)
{
  const std::size_t at = findKey(text, begin, end, key);
  if (at == std::string::npos || text[at] != '[')
    return false;
  const char* p = text.c_str() + at + 1;
  for (int k = 0; k < N; ++k) {
    char* stop = nullptr;
    v[k] = std::strtof(p, &stop);
    if (stop == p || !std::isfinite(v[k]))
      return false;
    p = stop;
    while (*p == ',' || std::isspace(static_cast<unsigned char>(*p)))
      ++p;
  }
  return true;
}

} // namespace

bool
writeRegionsJson(const std::string& path,
                 const std::string& input,
                 const pcl::selective_seg::RegionOfInterestParameters& p,
                 const pcl::selective_seg::RegionOfInterestStats& s,
                 const std::vector<RegionOfInterest>& regions,
                 pcl::selective_seg::ViewProjection projection,
                 const Eigen::Affine3f* sensor_pose)
{
  const bool panoramic = projection == pcl::selective_seg::ViewProjection::Panoramic;
  std::ofstream out(path);
  out << std::setprecision(9) << "{\n  \"input\": " << jsonString(input)
      << ",\n  \"projection\": \"" << (panoramic ? "panoramic" : "forward")
      << "\",\n  \"frames\": \"windows: sensor frame, theta = atan2(x, z), phi = "
      << (panoramic ? "atan2(y, sqrt(x^2 + z^2))" : "atan2(y, z)")
      << " [rad]; boxes: cloud frame [m]\",\n";
  if (sensor_pose) {
    const Eigen::Quaternionf q(sensor_pose->linear());
    out << "  \"sensor_pose\": {\"origin\": ";
    putVector(out, sensor_pose->translation());
    out << ", \"orientation_wxyz\": [" << q.w() << ", " << q.x() << ", " << q.y()
        << ", " << q.z() << "]},\n";
  }
  out << "  \"budget\": {\"max_solid_angle_sr\": " << p.max_solid_angle
      << ", \"max_points\": " << p.max_points << ", \"max_regions\": " << p.max_regions
      << ", \"target_step_rad\": " << p.target_step
      << ", \"sample_yield\": " << p.sample_yield << "},\n"
      << "  \"counts\": {\"transition_vertices\": " << s.transition_vertices
      << ", \"small_segment_vertices\": " << s.small_segment_vertices
      << ", \"sparse_vertices\": " << s.sparse_vertices
      << ", \"candidates\": " << s.candidates << ", \"cut\": " << s.cut
      << ", \"already_fine\": " << s.already_fine
      << ", \"over_budget\": " << s.over_budget << ", \"selected\": " << s.selected
      << ", \"selected_solid_angle_sr\": " << s.selected_solid_angle
      << ", \"selected_points\": " << s.selected_points << "},\n  \"regions\": [";
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const auto& r = regions[i];
    // The window's angles to the last bit: neighbours that share a border, and thin
    // windows, read back as they were.
    out << std::setprecision(17) << (i ? ",\n    " : "\n    ")
        << "{\"theta_min\": " << r.theta_min << ", \"theta_max\": " << r.theta_max
        << ", \"phi_min\": " << r.phi_min << ", \"phi_max\": " << r.phi_max
        << std::setprecision(9) << ", \"box_min\": ";
    putVector(out, r.box_min);
    out << ", \"box_max\": ";
    putVector(out, r.box_max);
    out << ", \"priority\": " << r.priority
        << ", \"suggested_step\": " << r.suggested_step
        << ", \"current_step\": " << r.current_step << ", \"reasons\": \""
        << pcl::selective_seg::reasonsToString(r.reasons)
        << "\", \"evidence\": " << r.num_evidence << ", \"points\": " << r.num_points
        << ", \"estimated_points\": " << r.estimated_points
        << ", \"solid_angle_sr\": " << r.solid_angle << "}";
  }
  out << "\n  ]\n}\n";
  out.close();
  return static_cast<bool>(out);
}

bool
readRegionsJson(const std::string& path,
                std::vector<RegionOfInterest>& regions,
                std::string& error)
{
  Eigen::Affine3f pose;
  bool has_pose = false;
  return readRegionsJson(path, regions, pose, has_pose, error);
}

bool
readRegionsJson(const std::string& path,
                std::vector<RegionOfInterest>& regions,
                Eigen::Affine3f& sensor_pose,
                bool& has_pose,
                std::string& error)
{
  regions.clear();
  sensor_pose = Eigen::Affine3f::Identity();
  has_pose = false;
  std::ifstream in(path);
  if (!in) {
    error = "Cannot read '" + path + "'.";
    return false;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  std::size_t at = findKey(text, 0, text.size(), "regions");
  if (at == std::string::npos) {
    error = "'" + path + "' has no \"regions\" list (write it with -roi_json).";
    return false;
  }
  const std::size_t list_end = text.rfind(']'); // the regions list comes last
  // A whole file ends with the list and the object: "] }" (a cut one does not).
  const std::size_t last = text.find_last_not_of(" \t\r\n");
  if (list_end == std::string::npos || list_end < at || last == std::string::npos ||
      text[last] != '}' || text.find_first_not_of(" \t\r\n", list_end + 1) != last) {
    error = "'" + path + "' ends before its \"regions\" list does (a cut or damaged " +
            "file; write it again with -roi_json).";
    return false;
  }
  // "projection": "panoramic", with any spacing (written by any JSON tool).
  auto projection = pcl::selective_seg::ViewProjection::Forward;
  const std::size_t value = findKey(text, 0, at, "projection");
  if (value != std::string::npos) {
    if (text.compare(value, 11, "\"panoramic\"") == 0)
      projection = pcl::selective_seg::ViewProjection::Panoramic;
    else if (text.compare(value, 9, "\"forward\"") != 0) {
      error = "'" + path + "' names a projection other than \"forward\" or " +
              "\"panoramic\".";
      return false;
    }
  }
  // "sensor_pose": {"origin": [x, y, z], "orientation_wxyz": [w, x, y, z]}, before
  // the list.
  const std::size_t pose_key = findKey(text, 0, at, "sensor_pose");
  if (pose_key != std::string::npos) {
    const std::size_t pose_end = text.find('}', pose_key);
    Eigen::Vector3f origin;
    Eigen::Vector4f wxyz;
    if (pose_end == std::string::npos || pose_end > at ||
        !findVector(text, pose_key, pose_end, "origin", origin) ||
        !findVector(text, pose_key, pose_end, "orientation_wxyz", wxyz) ||
        !(wxyz.norm() > 0.5f && wxyz.norm() < 2.0f)) {
      error = "'" + path + "': \"sensor_pose\" needs a finite \"origin\" [x, y, z] " +
              "and a unit quaternion \"orientation_wxyz\" [w, x, y, z].";
      return false;
    }
    sensor_pose = Eigen::Affine3f::Identity();
    sensor_pose.translation() = origin;
    sensor_pose.linear() = Eigen::Quaternionf(wxyz[0], wxyz[1], wxyz[2], wxyz[3])
                               .normalized()
                               .toRotationMatrix();
    has_pose = true;
  }
  while ((at = text.find('{', at)) != std::string::npos) {
    const std::size_t end = text.find('}', at);
    if (end == std::string::npos || end > list_end)
      break;
    RegionOfInterest r;
    r.projection = projection;
    double step = 0.0, current = 0.0, priority = 0.0;
    if (!findNumber(text, at, end, "theta_min", r.theta_min) ||
        !findNumber(text, at, end, "theta_max", r.theta_max) ||
        !findNumber(text, at, end, "phi_min", r.phi_min) ||
        !findNumber(text, at, end, "phi_max", r.phi_max) ||
        !(r.theta_min < r.theta_max && r.phi_min < r.phi_max)) {
      error = "'" + path + "': region " + std::to_string(regions.size() + 1) +
              " needs theta_min < theta_max and phi_min < phi_max.";
      regions.clear();
      return false;
    }
    findVector(text, at, end, "box_min", r.box_min);
    findVector(text, at, end, "box_max", r.box_max);
    if (findNumber(text, at, end, "priority", priority))
      r.priority = priority;
    if (findNumber(text, at, end, "suggested_step", step))
      r.suggested_step = step;
    if (findNumber(text, at, end, "current_step", current))
      r.current_step = current;
    const std::size_t reasons = findKey(text, at, end, "reasons");
    if (reasons != std::string::npos) {
      const std::string value = text.substr(reasons, end - reasons);
      if (value.find("transition") != std::string::npos)
        r.reasons |= pcl::selective_seg::kTransition;
      if (value.find("small_segment") != std::string::npos)
        r.reasons |= pcl::selective_seg::kSmallSegment;
      if (value.find("sparse") != std::string::npos)
        r.reasons |= pcl::selective_seg::kSparse;
    }
    regions.push_back(r);
    at = end;
  }
  return true;
}

} // namespace selseg_apps
