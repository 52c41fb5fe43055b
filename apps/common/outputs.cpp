/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#define PCL_NO_PRECOMPILE
#include "outputs.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "segment_colors.h"

#include <unistd.h>

namespace selseg_apps {

/** One octree leaf as a PCD point. */
struct EIGEN_ALIGN16 LeafPoint {
  PCL_ADD_POINT4D;
  float size;
  std::uint32_t depth;
  std::uint32_t label;
  float normal_x, normal_y, normal_z;
  float sigma_theta, sigma_phi;
  std::uint32_t num_points;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

} // namespace selseg_apps

POINT_CLOUD_REGISTER_POINT_STRUCT(
    selseg_apps::LeafPoint,
    (float, x, x)(float, y, y)(float, z, z)(float, size, size)(
        std::uint32_t, depth, depth)(std::uint32_t, label, label)(
        float, normal_x, normal_x)(float, normal_y, normal_y)(
        float, normal_z, normal_z)(float, sigma_theta, sigma_theta)(
        float, sigma_phi, sigma_phi)(std::uint32_t, num_points, num_points))

namespace selseg_apps {
namespace {

using pcl::selective_seg::SegmentedMesh;

/** Vertices used by the triangles, renumbered densely in first-use order. */
struct CompactMesh {
  std::vector<pcl::index_t> points; ///< input index of each output vertex
  std::vector<std::array<std::uint32_t, 3>> faces;
};

CompactMesh
compact(const SegmentedMesh& mesh, std::size_t num_points)
{
  CompactMesh out;
  std::vector<std::int64_t> renumber(num_points, -1);
  out.faces.resize(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) {
      auto& slot = renumber[mesh.triangles[t][i]];
      if (slot < 0) {
        slot = static_cast<std::int64_t>(out.points.size());
        out.points.push_back(mesh.triangles[t][i]);
      }
      out.faces[t][i] = static_cast<std::uint32_t>(slot);
    }
  return out;
}

template <typename T>
void
putLittle(std::ostream& out, T value)
{
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
void
putBig(std::ostream& out, T value)
{
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  for (std::size_t i = sizeof(T); i-- > 0;)
    out.put(bytes[i]);
}

std::string
jsonString(const std::string& s)
{
  std::ostringstream out;
  out << '"';
  for (const char c : s) {
    if (c == '"' || c == '\\')
      out << '\\' << c;
    else if (static_cast<unsigned char>(c) < 0x20)
      out << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c)
          << std::dec;
    else
      out << c;
  }
  out << '"';
  return out.str();
}

} // namespace

OutputTransaction::~OutputTransaction()
{
  if (!committed_)
    for (const auto& f : files_)
      std::remove(f.first.c_str());
}

std::string
OutputTransaction::stage(const std::string& final_path)
{
  files_.emplace_back(final_path + ".tmp" + std::to_string(files_.size()), final_path);
  return files_.back().first;
}

bool
OutputTransaction::commit(std::string& error)
{
  namespace fs = std::filesystem;
  std::error_code ec;
  for (const auto& f : files_)
    if (fs::is_directory(f.second, ec)) {
      error = "cannot write '" + f.second + "': it is a folder; give a file name";
      return false;
    }
  // Old files of the same names are kept as hard links until every rename succeeded,
  // so that a failure part way restores them: all outputs change, or none.
  std::vector<std::string> backups(files_.size());
  for (std::size_t i = 0; i < files_.size(); ++i) {
    if (!fs::exists(files_[i].second, ec))
      continue;
    const std::string backup = files_[i].first + ".old";
    std::remove(backup.c_str());
    if (::link(files_[i].second.c_str(), backup.c_str()) == 0)
      backups[i] = backup;
  }
  for (std::size_t i = 0; i < files_.size(); ++i)
    if (std::rename(files_[i].first.c_str(), files_[i].second.c_str()) != 0) {
      error = "cannot rename '" + files_[i].first + "' to '" + files_[i].second +
              "': " + std::strerror(errno);
      for (std::size_t j = 0; j < i; ++j)
        if (backups[j].empty())
          std::remove(files_[j].second.c_str());
        else
          std::rename(backups[j].c_str(), files_[j].second.c_str());
      for (std::size_t j = i; j < files_.size(); ++j)
        if (!backups[j].empty())
          std::remove(backups[j].c_str());
      return false;
    }
  for (const auto& b : backups)
    if (!b.empty())
      std::remove(b.c_str());
  committed_ = true;
  return true;
}

bool
writeLabeledCloud(const std::string& path, const pcl::PointCloud<pcl::PointXYZL>& cloud)
{
  try {
    if (pcl::io::savePCDFileBinaryCompressed(path, cloud) == 0)
      return true;
  } catch (const pcl::IOException&) {
  }
  return false;
}

bool
writeMeshPly(const std::string& path,
             const pcl::PointCloud<pcl::PointXYZ>& cloud,
             const SegmentedMesh& mesh)
{
  const CompactMesh m = compact(mesh, cloud.size());
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\n"
      << "comment pcl_selective_seg segmented mesh: edge triangles white\n"
      << "element vertex " << m.points.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "element face " << m.faces.size() << "\n"
      << "property list uchar int vertex_indices\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "property uint label\nproperty uchar class\nend_header\n";
  for (const auto i : m.points)
    for (int k = 0; k < 3; ++k)
      putLittle(out, cloud[i].data[k]);
  for (std::size_t t = 0; t < m.faces.size(); ++t) {
    putLittle<std::uint8_t>(out, 3);
    for (const auto v : m.faces[t])
      putLittle<std::int32_t>(out, static_cast<std::int32_t>(v));
    for (const auto c : triangleColor(mesh.labels[t], mesh.classes[t]))
      putLittle(out, c);
    putLittle<std::uint32_t>(out, mesh.labels[t]);
    putLittle<std::uint8_t>(out, static_cast<std::uint8_t>(mesh.classes[t]));
  }
  out.close();
  return static_cast<bool>(out);
}

bool
writeMeshVtk(const std::string& path,
             const pcl::PointCloud<pcl::PointXYZ>& cloud,
             const SegmentedMesh& mesh)
{
  const CompactMesh m = compact(mesh, cloud.size());
  const std::size_t n = m.faces.size();
  std::ofstream out(path, std::ios::binary);
  out << "# vtk DataFile Version 3.0\npcl_selective_seg segmented mesh\nBINARY\n"
      << "DATASET POLYDATA\nPOINTS " << m.points.size() << " float\n";
  for (const auto i : m.points)
    for (int k = 0; k < 3; ++k)
      putBig(out, cloud[i].data[k]);
  out << "\nPOLYGONS " << n << " " << 4 * n << "\n";
  for (const auto& f : m.faces) {
    putBig<std::int32_t>(out, 3);
    for (const auto v : f)
      putBig<std::int32_t>(out, static_cast<std::int32_t>(v));
  }
  out << "\nCELL_DATA " << n << "\nCOLOR_SCALARS colors 3\n";
  for (std::size_t t = 0; t < n; ++t)
    for (const auto c : triangleColor(mesh.labels[t], mesh.classes[t]))
      out.put(static_cast<char>(c));
  out << "\nSCALARS label unsigned_int 1\nLOOKUP_TABLE default\n";
  for (std::size_t t = 0; t < n; ++t)
    putBig<std::uint32_t>(out, mesh.labels[t]);
  out << "\nSCALARS class unsigned_char 1\nLOOKUP_TABLE default\n";
  for (std::size_t t = 0; t < n; ++t)
    out.put(static_cast<char>(mesh.classes[t]));
  out << "\n";
  out.close();
  return static_cast<bool>(out);
}

bool
writeLeaves(const std::string& path,
            const std::vector<pcl::selective_seg::OctreeLeaf>& leaves)
{
  pcl::PointCloud<LeafPoint> cloud;
  cloud.resize(leaves.size());
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    const auto& in = leaves[l];
    auto& p = cloud[l];
    p.getVector3fMap() = in.centre;
    p.size = in.size;
    p.depth = in.depth;
    p.label = in.label;
    p.normal_x = in.normal.x();
    p.normal_y = in.normal.y();
    p.normal_z = in.normal.z();
    p.sigma_theta = in.sigma_theta;
    p.sigma_phi = in.sigma_phi;
    p.num_points = in.num_points;
  }
  try {
    if (!cloud.empty() && pcl::io::savePCDFileBinary(path, cloud) == 0)
      return true;
  } catch (const pcl::IOException&) {
  }
  return false;
}

bool
writeSummaryJson(const std::string& path,
                 const RunInfo& info,
                 const pcl::selective_seg::SegmentationResult& r)
{
  const auto& p = info.parameters;
  const auto& c = r.counts;
  const auto& t = r.timings;
  const double deg = 180.0 / M_PI;
  std::ofstream out(path);
  out << std::setprecision(9) << "{\n  \"input\": " << jsonString(info.input)
      << ",\n  \"points\": " << info.num_points << ",\n  \"parameters\": {"
      << "\"split_deg\": " << p.max_normal_std_dev * deg
      << ", \"merge_deg\": " << p.max_merge_angle * deg
      << ", \"edge_deg\": " << p.max_edge_triangle_angle * deg
      << ", \"incidence_deg\": " << p.max_view_incidence_angle * deg
      << ", \"min_voxel_m\": " << r.min_voxel_size
      << ", \"min_split_points\": " << p.min_points_to_split
      << ", \"backend\": " << jsonString(info.backend) << "},\n  \"counts\": {"
      << "\"labeled\": " << c.labeled << ", \"shared_vertex\": " << c.shared_vertex
      << ", \"non_finite\": " << c.non_finite
      << ", \"behind_sensor\": " << c.behind_sensor
      << ", \"outside_indices\": " << c.outside_indices
      << ", \"without_normal\": " << c.without_normal
      << ", \"vertices\": " << r.num_vertices
      << ", \"triangles\": " << r.mesh.triangles.size()
      << ", \"leaves\": " << r.leaves.size() << ", \"segments\": " << r.segments.size()
      << "},\n  \"median_spacing_m\": " << r.median_spacing
      << ",\n  \"timings_s\": {\"delaunay\": " << t.delaunay
      << ", \"normals\": " << t.normals << ", \"octree\": " << t.octree
      << ", \"merge\": " << t.merge << ", \"total\": " << t.total
      << "},\n  \"segments\": [";
  for (std::size_t s = 0; s < r.segments.size(); ++s) {
    const auto& seg = r.segments[s];
    out << (s ? ",\n    " : "\n    ") << "{\"label\": " << seg.label
        << ", \"points\": " << seg.num_points << ", \"leaves\": " << seg.num_leaves
        << ", \"area_m2\": " << seg.area << ", \"normal\": [" << seg.normal.x() << ", "
        << seg.normal.y() << ", " << seg.normal.z() << "]}";
  }
  out << "\n  ]\n}\n";
  out.close();
  return static_cast<bool>(out);
}

} // namespace selseg_apps
