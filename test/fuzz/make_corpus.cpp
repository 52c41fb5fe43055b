/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Writes the seed corpora of the fuzz targets (test/fuzz/corpus/) from real scans:
// small windows of organized scans, a few KB each, in the targets' input layouts.
// Usage: selseg_make_fuzz_corpus OUTPUT_FOLDER SCAN.pcd...
// (docs/reliability.md; the scans used and their licences: corpus/README.md).

#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;

namespace {

std::string
readAll(const fs::path& p)
{
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

void
writeAll(const fs::path& p, const std::string& bytes)
{
  std::ofstream(p, std::ios::binary) << bytes;
}

/** A w x h window of an organized cloud, starting at (c0, r0), every step-th point. */
pcl::PointCloud<pcl::PointXYZ>
window(const pcl::PointCloud<pcl::PointXYZ>& in, int c0, int r0, int w, int h, int step)
{
  pcl::PointCloud<pcl::PointXYZ> out(w, h);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const int x = std::min<int>(c0 + c * step, in.width - 1);
      const int y = std::min<int>(r0 + r * step, in.height - 1);
      out.at(c, r) = in.height > 1 ? in.at(x, y) : in[(y * w + x) % in.size()];
    }
  out.is_dense = false;
  return out;
}

/** fuzz_segmentation's layout: encoding, overrides, pose, 13 slots, the points. */
std::string
segmentationInput(const pcl::PointCloud<pcl::PointXYZ>& cloud, std::uint8_t encoding)
{
  std::string bytes(4 + 13 * 8, '\0');
  bytes[0] = static_cast<char>(encoding);
  for (const auto& p : cloud) {
    if (encoding == 2) {
      const std::int16_t v[3] = {static_cast<std::int16_t>(p.x * 1024.0f),
                                 static_cast<std::int16_t>(p.y * 1024.0f),
                                 static_cast<std::int16_t>((p.z - 1.0f) * 1024.0f)};
      bytes.append(reinterpret_cast<const char*>(v), sizeof v);
    } else
      bytes.append(reinterpret_cast<const char*>(p.data), 3 * sizeof(float));
  }
  return bytes;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 3) {
    std::fprintf(stderr, "Usage: %s OUTPUT_FOLDER SCAN.pcd...\n", argv[0]);
    return 2;
  }
  const fs::path out = argv[1];
  const fs::path seg_dir = out / "fuzz_segmentation", io_dir = out / "fuzz_scan_io";
  fs::create_directories(seg_dir);
  fs::create_directories(io_dir);
  const fs::path scratch =
      fs::temp_directory_path() / ("selseg_make_corpus_" + std::to_string(::getpid()));
  fs::create_directories(scratch);
  for (int a = 2; a < argc; ++a) {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    if (pcl::io::loadPCDFile(argv[a], cloud) != 0 || cloud.empty()) {
      std::fprintf(stderr, "cannot read %s\n", argv[a]);
      return 1;
    }
    const std::string stem = fs::path(argv[a]).stem().string();
    const int cx = static_cast<int>(cloud.width) / 2,
              cy = static_cast<int>(cloud.height) / 2;
    // Segmentation: a dense 16 x 12 window and a sparse one across the whole view.
    writeAll(seg_dir / (stem + "_window_f32"),
             segmentationInput(window(cloud, cx - 8, cy - 6, 16, 12, 1), 0));
    const std::string sparse = segmentationInput(
        window(cloud, 0, 0, 20, 15, std::max<int>(1, cloud.width / 20)), 2);
    writeAll(seg_dir / (stem + "_sparse_i16"), sparse);
    // The same with the update() check on (bit 1 of the last parameter slot).
    std::string update = sparse;
    update[4 + 12 * 8] = 2;
    writeAll(seg_dir / (stem + "_sparse_i16_update"), update);
    // The panoramic projection (bit 3).
    std::string panoramic = sparse;
    panoramic[4 + 12 * 8] = 8;
    writeAll(seg_dir / (stem + "_sparse_i16_panoramic"), panoramic);
    // Indices (bit 4): three quarters of the points, in increasing order; then in
    // decreasing order with some repeated (bits 16-17 of the slot).
    std::string indexed = sparse;
    indexed[4 + 12 * 8] = 16;
    writeAll(seg_dir / (stem + "_sparse_i16_indices"), indexed);
    indexed[4 + 12 * 8 + 2] = 3;
    writeAll(seg_dir / (stem + "_sparse_i16_indices_repeated"), indexed);
    // Reading: the same small window in every format the tool reads.
    const auto small = window(cloud, cx - 5, cy - 4, 10, 8, 3);
    const auto with_format = [&](char format, const fs::path& file) {
      return std::string(1, format) + readAll(file);
    };
    pcl::io::savePCDFileASCII((scratch / "a.pcd").string(), small);
    pcl::io::savePCDFileBinary((scratch / "b.pcd").string(), small);
    pcl::io::savePCDFileBinaryCompressed((scratch / "c.pcd").string(), small);
    pcl::io::savePLYFileASCII((scratch / "a.ply").string(), small);
    pcl::io::savePLYFileBinary((scratch / "b.ply").string(), small);
    writeAll(io_dir / (stem + "_ascii_pcd"), with_format(0, scratch / "a.pcd"));
    writeAll(io_dir / (stem + "_binary_pcd"), with_format(0, scratch / "b.pcd"));
    writeAll(io_dir / (stem + "_compressed_pcd"), with_format(0, scratch / "c.pcd"));
    writeAll(io_dir / (stem + "_ascii_ply"), with_format(1, scratch / "a.ply"));
    writeAll(io_dir / (stem + "_binary_ply"), with_format(1, scratch / "b.ply"));
    std::ostringstream text;
    text << "# " << stem << ", x y z in metres\n";
    for (const auto& p : small)
      text << p.x << " " << p.y << " " << p.z << "\n";
    writeAll(io_dir / (stem + "_text"), std::string(1, '\2') + text.str());
  }
  fs::remove_all(scratch);
  // A room seen all around from its middle (x +-3, y +-1.5, z +-4 m; 36 x 10 rays),
  // with the panoramic projection: the mesh closes across the seam.
  pcl::PointCloud<pcl::PointXYZ> room;
  for (int i = 0; i < 36; ++i)
    for (int j = 0; j < 10; ++j) {
      const double az =
          -M_PI + (i + 0.3 + 0.4 * ((i * 7 + j * 3) % 5) / 4.0) * M_PI / 18;
      const double el = -0.6 + (j + 0.5) * 0.12;
      const double d[3] = {
          std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
      const double half[3] = {3.0, 1.5, 4.0};
      double t = 1e30;
      for (int k = 0; k < 3; ++k)
        if (d[k] != 0.0)
          t = std::min(t, half[k] / std::abs(d[k]));
      room.push_back(pcl::PointXYZ(static_cast<float>(t * d[0]),
                                   static_cast<float>(t * d[1]),
                                   static_cast<float>(t * d[2])));
    }
  std::string room_input = segmentationInput(room, 0);
  room_input[4 + 12 * 8] = 8;
  writeAll(seg_dir / "room_panoramic_f32", room_input);
  return 0;
}
