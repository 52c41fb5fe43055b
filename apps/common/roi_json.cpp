/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "roi_json.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string_view>

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
  // Searched in [begin, end) only: a key missing from every region must not cost a
  // search to the end of the file for each of them.
  const std::string_view range =
      std::string_view(text).substr(begin, end > begin ? end - begin : 0);
  const auto next = [&](std::size_t from) {
    const std::size_t found = range.find(quoted, from - begin);
    return found == std::string_view::npos ? std::string::npos : begin + found;
  };
  for (std::size_t at = next(begin); at != std::string::npos; at = next(at + 1)) {
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
  // A regular file of a sane size: a FIFO would block and a device never end.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::is_regular_file(status)) {
    error = "Cannot read '" + path + "': " +
            (ec || !std::filesystem::exists(status) ? "no such file"
                                                    : "not a regular file") +
            " (give a regions file written with -roi_json).";
    return false;
  }
  constexpr std::uintmax_t kMaxBytes = std::uintmax_t(1) << 31;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec || bytes > kMaxBytes) {
    error = "Cannot read '" + path + "': " +
            (ec ? ec.message() : "larger than 2 GiB (about 6 million windows)") + ".";
    return false;
  }
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
    const std::string region =
        "'" + path + "': region " + std::to_string(regions.size() + 1);
    if (!findNumber(text, at, end, "theta_min", r.theta_min) ||
        !findNumber(text, at, end, "theta_max", r.theta_max) ||
        !findNumber(text, at, end, "phi_min", r.phi_min) ||
        !findNumber(text, at, end, "phi_max", r.phi_max)) {
      error = region + " needs finite numbers theta_min, theta_max, phi_min and " +
              "phi_max [rad].";
      regions.clear();
      return false;
    }
    if (!(r.theta_min < r.theta_max && r.phi_min < r.phi_max)) {
      error = region + " needs theta_min < theta_max and phi_min < phi_max.";
      regions.clear();
      return false;
    }
    // The projection's angles: eq. 1's theta and phi in (-pi/2, pi/2); a panorama's
    // azimuth in [-pi, pi] and elevation in [-pi/2, pi/2].
    const bool panoramic = projection == pcl::selective_seg::ViewProjection::Panoramic;
    const double theta_limit = panoramic ? M_PI : M_PI / 2;
    const auto inside = [panoramic](double angle, double limit) {
      return panoramic ? std::abs(angle) <= limit : std::abs(angle) < limit;
    };
    if (!inside(r.theta_min, theta_limit) || !inside(r.theta_max, theta_limit) ||
        !inside(r.phi_min, M_PI / 2) || !inside(r.phi_max, M_PI / 2)) {
      error = region + " has angles outside the " +
              (panoramic ? std::string("panoramic projection's range (theta in [-pi, "
                                       "pi], phi in [-pi/2, pi/2])")
                         : std::string("forward projection's range (theta and phi in "
                                       "(-pi/2, pi/2))")) +
              ".";
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
  // A list of anything but windows is no regions file.
  if (regions.empty()) {
    const std::size_t open = text.find('[', findKey(text, 0, text.size(), "regions"));
    if (open == std::string::npos ||
        text.find_first_not_of(" \t\r\n", open + 1) != list_end) {
      error = "'" + path + "': the \"regions\" list holds something other than " +
              "windows (objects with theta_min, theta_max, phi_min and phi_max).";
      return false;
    }
  }
  return true;
}

} // namespace selseg_apps
