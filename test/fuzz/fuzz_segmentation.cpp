/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// libFuzzer target: SelectiveSegmentation::extract() on arbitrary points, parameters
// and sensor poses. Beyond crashes, hangs and sanitizer findings it aborts on garbage:
// an accepted invalid parameter, a refused valid one on a usable cloud, or a result
// whose labels, counts, clusters and mesh disagree. With bit 1 of the last parameter
// slot set (and not every parameter overridden), it also checks update(): extract() on
// the first three quarters of the points, update() with the rest, must give exactly
// extract() on the union with the first run's finest voxel
// (docs/incremental_update.md). With bit 2 set the cloud declares a layout that is not
// its size; the getters must still give one output point per input point. With bit 3
// set (and not every parameter overridden) the projection is panoramic. With bit 4 set
// (and not every parameter overridden), extract() restricted by indices (chosen by the
// slot's bits 16 and up) must equal extract() on a copy of the indexed points. Every
// successful run's regions of interest must be computed, inside the projection's
// range of angles and with a non-negative solid angle.
//
// Input layout (all little endian; missing bytes read as zero):
//   byte 0        point encoding: 0 raw float32 x y z; 1 int8 grid (x/16, y/16,
//                 1 + z/16); 2 int16 grid (/1024, z shifted to 1 + z/1024); 3 float32 x
//                 y and a range (a direction plus depth: many points per ray)
//   byte 1        which parameters to override (bit i: parameter i below)
//   bytes 2-3     sensor pose: 0 = identity, else a quaternion and origin from bytes
//   then          13 parameter slots of 8 bytes (double, or int in the low 4 bytes)
//   then          the points

#include <pcl_selective_seg/regions_of_interest.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

using pcl::selective_seg::SelectiveSegmentation;
using pcl::selective_seg::SelectiveSegmentationParameters;

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  std::size_t at = 0;
  template <typename T> T get()
  {
    T value{};
    unsigned char bytes[sizeof(T)] = {};
    for (std::size_t i = 0; i < sizeof(T) && at < size; ++i)
      bytes[i] = data[at++];
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }
  std::size_t left() const { return size - at; }
};

void
check(bool condition, const char* what)
{
  if (!condition) {
    std::fprintf(stderr, "fuzz_segmentation: invariant violated: %s\n", what);
    std::abort();
  }
}

/** The same bits: extreme inputs give infinite areas and NaN normals and centres,
 * which compare unequal to themselves. */
template <typename T>
bool
sameBits(const T& a, const T& b)
{
  return std::memcmp(&a, &b, sizeof a) == 0;
}

template <typename T>
bool
sameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/** update() against extract() on the union: the same result, array for array. */
void
checkUpdate(const pcl::PointCloud<pcl::PointXYZ>& cloud,
            const SelectiveSegmentationParameters& params,
            const Eigen::Affine3f* pose)
{
  const std::size_t first_new = cloud.size() * 3 / 4;
  auto old_points = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::PointCloud<pcl::PointXYZ> new_points;
  old_points->points.assign(cloud.begin(), cloud.begin() + first_new);
  new_points.points.assign(cloud.begin() + first_new, cloud.end());
  for (auto* c : {old_points.get(), &new_points}) {
    c->width = static_cast<std::uint32_t>(c->size());
    c->height = 1;
    c->is_dense = false;
  }
  const auto configure = [&](SelectiveSegmentation<pcl::PointXYZ>& s,
                              const SelectiveSegmentationParameters& p,
                              const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& input) {
    s.setParameters(p);
    if (pose)
      s.setSensorPose(*pose);
    s.setInputCloud(input);
  };
  SelectiveSegmentation<pcl::PointXYZ> seg;
  configure(seg, params, old_points);
  std::vector<pcl::PointIndices> clusters;
  if (!seg.extract(clusters))
    return; // nothing to update (checked: update() refuses)
  SelectiveSegmentationParameters kept = params;
  if (!(kept.min_voxel_size > 0.0))
    kept.min_voxel_size = seg.getResult().min_voxel_size;
  const bool updated = seg.update(new_points, clusters);

  auto all = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>(cloud);
  SelectiveSegmentation<pcl::PointXYZ> ref;
  configure(ref, kept, all);
  std::vector<pcl::PointIndices> ref_clusters;
  const bool ref_ok = ref.extract(ref_clusters);
  check(updated == ref_ok, "update() and extract() on the union disagree on success");
  if (!updated)
    return;
  const auto& a = seg.getResult();
  const auto& b = ref.getResult();
  check(a.labels == b.labels, "update(): labels differ from extract() on the union");
  check(a.segments.size() == b.segments.size(), "update(): segment count differs");
  for (std::size_t s = 0; s < a.segments.size(); ++s)
    check(a.segments[s].num_points == b.segments[s].num_points &&
              sameBits(a.segments[s].normal, b.segments[s].normal) &&
              sameBits(a.segments[s].area, b.segments[s].area),
          "update(): a segment differs");
  check(a.leaves.size() == b.leaves.size(), "update(): leaf count differs");
  for (std::size_t l = 0; l < a.leaves.size(); ++l)
    check(sameBits(a.leaves[l].centre, b.leaves[l].centre) &&
              a.leaves[l].label == b.leaves[l].label &&
              sameBits(a.leaves[l].area, b.leaves[l].area),
          "update(): a leaf differs");
  check(a.mesh.triangles == b.mesh.triangles, "update(): mesh triangles differ");
  check(a.mesh.neighbours == b.mesh.neighbours, "update(): mesh adjacency differs");
  check(a.mesh.labels == b.mesh.labels, "update(): mesh labels differ");
  check(a.mesh.classes == b.mesh.classes, "update(): mesh classes differ");
  check(sameBits(a.mesh.areas, b.mesh.areas), "update(): mesh areas differ");
  check(sameBits(a.mesh.normals, b.mesh.normals), "update(): mesh normals differ");
  check(a.min_voxel_size == b.min_voxel_size && a.num_vertices == b.num_vertices &&
            a.counts.labeled == b.counts.labeled &&
            a.counts.non_finite == b.counts.non_finite &&
            a.counts.behind_sensor == b.counts.behind_sensor &&
            a.counts.shared_vertex == b.counts.shared_vertex,
        "update(): the counts differ");
  check(clusters.size() == ref_clusters.size(), "update(): cluster count differs");
  for (std::size_t s = 0; s < clusters.size(); ++s)
    check(clusters[s].indices == ref_clusters[s].indices,
          "update(): a cluster differs");
}

/** extract() restricted by indices against extract() on a copy of the indexed points:
 * the same labels, segments and counts, point for point. The indices keep about three
 * quarters of the points, chosen by \a bits, in increasing or decreasing order, with
 * or without a repeat of some of them (a repeated index is the same point: it changes
 * nothing); with bit 2 one index is out of range, which extract() must refuse. */
void
checkIndices(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
             const SelectiveSegmentationParameters& params,
             const Eigen::Affine3f* pose,
             std::uint64_t bits)
{
  const std::size_t n = cloud->size();
  auto indices = pcl::make_shared<pcl::Indices>();
  for (std::size_t i = 0; i < n; ++i)
    if (((i * 2654435761u + (bits >> 3)) >> 7) % 4 != 0)
      indices->push_back(static_cast<pcl::index_t>(i));
  if (bits & 1)
    std::reverse(indices->begin(), indices->end());
  const pcl::Indices unique = *indices;
  if (bits & 2)
    for (std::size_t k = 0; k < unique.size(); k += 5)
      indices->push_back(unique[k]);
  if (bits & 4)
    indices->push_back(static_cast<pcl::index_t>(n));

  SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setParameters(params);
  if (pose)
    seg.setSensorPose(*pose);
  seg.setInputCloud(cloud);
  seg.setIndices(indices);
  std::vector<pcl::PointIndices> clusters;
  const bool ok = seg.extract(clusters);
  if (bits & 4) {
    check(!ok && clusters.empty(), "extract() accepted an index outside the cloud");
    return;
  }
  auto sub = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto i : unique)
    sub->push_back((*cloud)[static_cast<std::size_t>(i)]);
  sub->is_dense = false;
  SelectiveSegmentation<pcl::PointXYZ> ref;
  ref.setParameters(params);
  if (pose)
    ref.setSensorPose(*pose);
  ref.setInputCloud(sub);
  std::vector<pcl::PointIndices> ref_clusters;
  const bool ref_ok = ref.extract(ref_clusters);
  check(ok == ref_ok,
        "indices: extract() and extract() on the indexed points disagree "
        "on success");
  if (!ok)
    return;
  const auto& a = seg.getResult();
  const auto& b = ref.getResult();
  std::vector<char> listed(n, 0);
  for (std::size_t k = 0; k < unique.size(); ++k) {
    const auto i = static_cast<std::size_t>(unique[k]);
    listed[i] = 1;
    check(a.labels[i] == b.labels[k],
          "indices: a label differs from the indexed points'");
  }
  for (std::size_t i = 0; i < n; ++i)
    check(listed[i] || a.labels[i] == 0, "indices: a point outside them is labeled");
  check(a.segments.size() == b.segments.size(), "indices: segment count differs");
  for (std::size_t s = 0; s < a.segments.size(); ++s)
    check(a.segments[s].num_points == b.segments[s].num_points &&
              sameBits(a.segments[s].normal, b.segments[s].normal),
          "indices: a segment differs");
  check(a.counts.outside_indices == n - unique.size() &&
            a.counts.labeled == b.counts.labeled &&
            a.counts.non_finite == b.counts.non_finite &&
            a.counts.behind_sensor == b.counts.behind_sensor &&
            a.counts.without_normal == b.counts.without_normal &&
            a.counts.shared_vertex == b.counts.shared_vertex,
        "indices: the counts differ");
  check(a.mesh.triangles.size() == b.mesh.triangles.size() &&
            a.leaves.size() == b.leaves.size(),
        "indices: the mesh or the leaves differ");
  check(clusters.size() == ref_clusters.size(), "indices: cluster count differs");
  for (std::size_t s = 0; s < clusters.size(); ++s) {
    pcl::Indices mapped;
    for (const auto k : ref_clusters[s].indices)
      mapped.push_back(unique[static_cast<std::size_t>(k)]);
    std::sort(mapped.begin(), mapped.end());
    check(clusters[s].indices == mapped, "indices: a cluster differs");
  }
}

} // namespace

extern "C" int
LLVMFuzzerInitialize(int*, char***)
{
  // SELSEG_FUZZ_VERBOSE set: the library's messages too (why a call refused an input).
  if (!std::getenv("SELSEG_FUZZ_VERBOSE"))
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  return 0;
}

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  Reader in{data, size};
  const std::uint8_t encoding = in.get<std::uint8_t>() % 4;
  const std::uint8_t overrides = in.get<std::uint8_t>();
  const std::uint16_t pose_bytes = in.get<std::uint16_t>();

  SelectiveSegmentationParameters p;
  std::uint64_t slot[13];
  for (auto& s : slot)
    s = in.get<std::uint64_t>();
  const auto dbl = [&](int i) {
    double v;
    std::memcpy(&v, &slot[i], sizeof v);
    return v;
  };
  const auto i32 = [&](int i) { return static_cast<std::int32_t>(slot[i]); };
  // Bit 0..7 of the override byte choose among the parameters; the rest of the slots
  // act only when the byte says "all" (0xff), to keep many inputs at the defaults.
  if (overrides & 1)
    p.max_normal_std_dev = dbl(0);
  if (overrides & 2)
    p.max_merge_angle = dbl(1);
  if (overrides & 4)
    p.max_edge_triangle_angle = dbl(2);
  if (overrides & 8)
    p.max_view_incidence_angle = dbl(3);
  if (overrides & 16)
    p.normal_rings = i32(4);
  if (overrides & 32)
    p.min_voxel_size = dbl(5);
  if (overrides & 64)
    p.min_points_to_split = i32(6);
  if (overrides & 128)
    p.max_octree_depth = i32(7);
  if (overrides == 0xff) {
    p.min_voxel_size_factor = dbl(8);
    p.angle_quantization = dbl(9);
    p.num_threads = i32(10) % 4; // valid 0-3 or invalid negatives: no thread storms
    p.edge_triangle_normal =
        static_cast<pcl::selective_seg::EdgeTriangleNormal>(slot[11] & 0xff);
    p.normal_spread_frame =
        static_cast<pcl::selective_seg::NormalSpreadFrame>((slot[11] >> 8) & 0xff);
    p.segment_normal_weight =
        static_cast<pcl::selective_seg::SegmentNormalWeight>((slot[11] >> 16) & 0xff);
    p.point_normal_triangles =
        static_cast<pcl::selective_seg::PointNormalTriangles>((slot[11] >> 24) & 0xff);
    p.delaunay_backend =
        static_cast<pcl::selective_seg::DelaunayBackend>(slot[12] & 0xff);
    p.projection =
        static_cast<pcl::selective_seg::ViewProjection>((slot[12] >> 8) & 0xff);
    p.merge_with = static_cast<pcl::selective_seg::MergeWith>((slot[12] >> 16) & 0xff);
  } else {
    p.edge_triangle_normal =
        static_cast<pcl::selective_seg::EdgeTriangleNormal>(slot[11] & 1);
    p.normal_spread_frame =
        static_cast<pcl::selective_seg::NormalSpreadFrame>((slot[11] >> 1) & 1);
    p.segment_normal_weight =
        static_cast<pcl::selective_seg::SegmentNormalWeight>((slot[11] >> 2) & 1);
    p.point_normal_triangles =
        static_cast<pcl::selective_seg::PointNormalTriangles>((slot[11] >> 3) & 1);
    p.merge_with = static_cast<pcl::selective_seg::MergeWith>((slot[11] >> 4) & 1);
    if (slot[12] & 1)
      p.delaunay_backend = pcl::selective_seg::DelaunayBackend::BoostVoronoi;
    // Bit 3: the panoramic projection (with the spread frame it requires).
    if (slot[12] & 8) {
      p.projection = pcl::selective_seg::ViewProjection::Panoramic;
      p.normal_spread_frame = pcl::selective_seg::NormalSpreadFrame::MeanNormal;
    }
  }
  // The vtk backend is not under test here (third-party floating point code).
  if (p.delaunay_backend == pcl::selective_seg::DelaunayBackend::Vtk)
    p.delaunay_backend = pcl::selective_seg::DelaunayBackend::Sweep;
  const bool valid = p.validate();
  const bool check_update = overrides != 0xff && (slot[12] & 2) != 0;
  const bool check_indices = overrides != 0xff && (slot[12] & 16) != 0;

  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  const std::size_t stride = encoding == 1 ? 3 : encoding == 2 ? 6 : 12;
  while (in.left() >= stride) {
    pcl::PointXYZ q;
    switch (encoding) {
    case 0:
      q.x = in.get<float>();
      q.y = in.get<float>();
      q.z = in.get<float>();
      break;
    case 1:
      q.x = in.get<std::int8_t>() / 16.0f;
      q.y = in.get<std::int8_t>() / 16.0f;
      q.z = 1.0f + in.get<std::int8_t>() / 16.0f;
      break;
    case 2:
      q.x = in.get<std::int16_t>() / 1024.0f;
      q.y = in.get<std::int16_t>() / 1024.0f;
      q.z = 1.0f + in.get<std::int16_t>() / 1024.0f;
      break;
    default: {
      const float dx = in.get<float>(), dy = in.get<float>(), r = in.get<float>();
      q.x = dx * r;
      q.y = dy * r;
      q.z = r;
    }
    }
    cloud->push_back(q);
  }
  cloud->is_dense = false;
  // Bit 2 of the last slot: a layout that is not the size (points pushed into the
  // vector of an organized cloud), which the getters must not trust.
  if ((slot[12] & 4) != 0 && !cloud->empty()) {
    cloud->width = static_cast<std::uint32_t>(cloud->size() / 2 + 1);
    cloud->height = 2;
  }

  SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setParameters(p);
  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  if (pose_bytes != 0) {
    const Eigen::Quaternionf q(1.0f,
                               (pose_bytes & 0xf) / 8.0f - 1.0f,
                               ((pose_bytes >> 4) & 0xf) / 8.0f - 1.0f,
                               ((pose_bytes >> 8) & 0xf) / 8.0f - 1.0f);
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3f(0.0f, 0.0f, ((pose_bytes >> 12) & 0xf) - 8.0f);
    seg.setSensorPose(pose);
  }
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  const bool ok = seg.extract(clusters);
  check(valid || !ok, "extract() accepted invalid parameters");
  if (!ok) {
    check(clusters.empty(), "failed extract() left clusters");
    check(!seg.getLabeledCloud(), "failed extract() left a labeled cloud");
    return 0;
  }
  const auto& r = seg.getResult();
  check(r.labels.size() == cloud->size(), "labels not one per point");
  check(!r.segments.empty() && clusters.size() == r.segments.size(),
        "clusters and segments disagree");
  std::size_t labeled = 0;
  for (const auto l : r.labels) {
    check(l <= r.segments.size(), "label out of range");
    labeled += l > 0;
  }
  const auto& c = r.counts;
  check(c.labeled == labeled, "labeled count wrong");
  check(c.labeled + c.without_normal + c.non_finite + c.behind_sensor +
                c.outside_indices ==
            cloud->size(),
        "counts do not add up to the points");
  std::size_t in_clusters = 0;
  for (std::size_t s = 0; s < clusters.size(); ++s) {
    check(!clusters[s].indices.empty(), "empty segment");
    check(clusters[s].indices.size() == r.segments[s].num_points, "segment size");
    for (const auto i : clusters[s].indices)
      check(r.labels[i] == s + 1, "cluster and label disagree");
    in_clusters += clusters[s].indices.size();
    check(r.segments[s].normal.allFinite(), "segment normal not finite");
  }
  check(in_clusters == labeled, "clusters miss labeled points");
  for (const auto& t : r.mesh.triangles)
    for (const auto v : t)
      check(v >= 0 && static_cast<std::size_t>(v) < cloud->size(), "mesh index");
  for (const auto& leaf : r.leaves)
    check(leaf.label >= 1 && leaf.label <= r.segments.size() && leaf.normal.allFinite(),
          "leaf label or normal");
  check(std::isfinite(r.min_voxel_size) && r.min_voxel_size > 0.0, "voxel size");
  // The getters: one output point per input point, whatever the declared layout.
  const auto labeled_cloud = seg.getLabeledCloud();
  check(labeled_cloud && labeled_cloud->size() == cloud->size(), "labeled cloud size");
  for (std::size_t i = 0; i < cloud->size(); ++i)
    check((*labeled_cloud)[i].label == r.labels[i], "labeled cloud label");
  const auto normals = seg.getPointNormals();
  check(normals && normals->size() == cloud->size(), "normal cloud size");
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const Eigen::Vector3f n = (*normals)[i].getNormalVector3fMap();
    check(r.labels[i] == 0 || std::abs(n.norm() - 1.0f) < 1e-3f,
          "labeled point normal");
  }
  pcl::PolygonMesh mesh;
  seg.getPolygonMesh(mesh);
  check(mesh.polygons.size() == r.mesh.triangles.size() &&
            static_cast<std::size_t>(mesh.cloud.width) * mesh.cloud.height ==
                cloud->size(),
        "polygon mesh");
  std::vector<pcl::selective_seg::RegionOfInterest> regions;
  check(pcl::selective_seg::computeRegionsOfInterest(
            r, seg.getTriangulation(), pose, {}, regions),
        "regions of interest refused a successful result");
  const double theta_limit =
      p.projection == pcl::selective_seg::ViewProjection::Panoramic ? M_PI : M_PI / 2;
  for (const auto& w : regions)
    check(w.projection == p.projection && w.theta_min >= -theta_limit &&
              w.theta_min < w.theta_max && w.theta_max <= theta_limit &&
              w.phi_min >= -M_PI / 2 && w.phi_min < w.phi_max &&
              w.phi_max <= M_PI / 2 && w.solid_angle >= 0.0,
          "region of interest window");
  // Selected windows overlap nowhere (disjoint_windows, the default).
  for (std::size_t i = 0; i < regions.size(); ++i)
    for (std::size_t j = i + 1; j < regions.size(); ++j)
      check(std::min(regions[i].theta_max, regions[j].theta_max) <=
                    std::max(regions[i].theta_min, regions[j].theta_min) ||
                std::min(regions[i].phi_max, regions[j].phi_max) <=
                    std::max(regions[i].phi_min, regions[j].phi_min),
            "overlapping regions of interest");
  if (check_update)
    checkUpdate(*cloud, p, pose_bytes != 0 ? &pose : nullptr);
  if (check_indices)
    checkIndices(cloud, p, pose_bytes != 0 ? &pose : nullptr, slot[12] >> 16);
  return 0;
}
