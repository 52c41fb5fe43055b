/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// libFuzzer target: the tool's input reading (apps/common/scan_io: PCD, PLY and x y z
// text). Byte 0 picks the format (0 PCD, 1 PLY, else text); the rest is the file. A
// read either fails with a message or gives a cloud whose layout matches its size;
// never a crash, a hang or an allocation the file cannot back.

#include <pcl/console/print.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

#include "scan_io.h"

namespace {

std::string
scratchPath(const char* extension)
{
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir && *dir ? dir : "/tmp") + "/selseg_fuzz_scan_io_" +
         std::to_string(::getpid()) + extension;
}

} // namespace

extern "C" int
LLVMFuzzerInitialize(int*, char***)
{
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  return 0;
}

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  if (size == 0)
    return 0;
  const char* extension = data[0] == 0 ? ".pcd" : data[0] == 1 ? ".ply" : ".xyz";
  const std::string path = scratchPath(extension);
  FILE* file = std::fopen(path.c_str(), "wb");
  if (!file)
    std::abort();
  if (size > 1 && std::fwrite(data + 1, 1, size - 1, file) != size - 1)
    std::abort();
  std::fclose(file);

  pcl::PointCloud<pcl::PointXYZ> cloud;
  std::string error;
  const bool ok = selseg_apps::loadScan(path, 1.0, cloud, error);
  std::remove(path.c_str());
  if (!ok && error.empty()) {
    std::fprintf(stderr, "fuzz_scan_io: a failed read without a message\n");
    std::abort();
  }
  if (ok && cloud.size() != static_cast<std::size_t>(cloud.width) * cloud.height) {
    std::fprintf(stderr, "fuzz_scan_io: %zu points in a %u x %u layout\n",
                 cloud.size(), cloud.width, cloud.height);
    std::abort();
  }
  return 0;
}
